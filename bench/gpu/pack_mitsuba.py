#!/usr/bin/python3
"""Packs Mitsuba 3 and Dr.Jit wheels small enough to travel to the GPU machine.

  bench/gpu/pack_mitsuba.py [--python 3.12] [--variants cuda_ad_rgb[,llvm_ad_rgb...]]
                            [--plugins EXTRA,...] [--out gpu-bundle/wheels] [--cache DIR]

The full wheels (mitsuba 3.9.1, drjit 1.5.0) are about 67 MB; a device call carries 64 MiB
with everything else in it. This downloads them for the given CPython (pip download, kept
in --cache) and rewrites them with only what bench/peers/mitsuba_render.py needs:
- the variants asked for (each variant is its own Python extension; the shared libraries
  and plugins hold every variant's code, so they stay whole);
- the plugins that an OBJ scene, as mitsuba_render.py translates it, loads (list below;
  --plugins adds more), among them those Mitsuba adds by itself (srgb, uniform, merge);
- data/srgb.coeff only for a spectral variant (rgb variants never open it); the conductor
  IOR tables (small);
- no headers, CMake files, type stubs, the `mitsuba` command line binary or test helpers.
RECORD is rewritten so `pip install --no-index --no-deps --target` takes the wheels.
mi.variants() still lists all thirteen (the list is compiled in); mi.set_variant of one
left out fails with an ImportError.
On the GPU machine: bench/gpu/run_mitsuba.sh (see its header).
"""
import argparse
import base64
import glob
import hashlib
import os
import re
import subprocess
import sys
import zipfile

MITSUBA, DRJIT = "3.9.1", "1.5.0"
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PLATFORMS = ["manylinux_2_28_x86_64", "manylinux_2_27_x86_64", "manylinux_2_17_x86_64", "manylinux2014_x86_64"]
# What a scene from mitsuba_render.py loads: shapes, BSDFs, the emitter, integrator, sensor,
# film, filters, samplers; srgb/uniform wrap colours and floats, merge joins meshes that
# share a BSDF, gaussian is hdrfilm's filter when a scene names none, d65 the emitters'
# default illuminant.
PLUGINS = ["ply", "merge", "diffuse", "twosided", "roughplastic", "plastic", "conductor", "roughconductor",
           "dielectric", "area", "path", "perspective", "hdrfilm", "box", "gaussian", "independent", "ldsampler",
           "srgb", "uniform", "d65"]
VARIANT_MODULE = re.compile(r"^mitsuba/((?:scalar|llvm|cuda)_[a-z_]+)\.cpython-[^/]*\.so$")


def fail(message):
    print(f"pack_mitsuba: error: {message}", file=sys.stderr)
    sys.exit(1)


def download(python, cache):
    """Paths of the two full wheels for CPython `python`, fetched into `cache` when absent."""
    tag = "cp" + python.replace(".", "")
    wanted = {"mitsuba": f"mitsuba-{MITSUBA}-{tag}-{tag}-*.whl", "drjit": f"drjit-{DRJIT}-{tag}-{tag}-*.whl"}
    found = {name: glob.glob(os.path.join(cache, pattern)) for name, pattern in wanted.items()}
    missing = [f"{name}=={MITSUBA if name == 'mitsuba' else DRJIT}" for name, paths in found.items() if not paths]
    if missing:
        os.makedirs(cache, exist_ok=True)
        command = [sys.executable, "-m", "pip", "download", "--no-deps", "--only-binary=:all:", "--python-version",
                   python, "--implementation", "cp", "-d", cache]
        for platform in PLATFORMS:
            command += ["--platform", platform]
        print("$ " + " ".join(command + missing), flush=True)
        if subprocess.call(command + missing) != 0:
            fail("pip download failed")
        found = {name: glob.glob(os.path.join(cache, pattern)) for name, pattern in wanted.items()}
    for name, paths in found.items():
        if len(paths) != 1:
            fail(f"expected one {name} wheel for {tag} in {cache}, found {paths}")
    return found["mitsuba"][0], found["drjit"][0]


def keep_mitsuba(path, variants, plugins):
    """Whether the mitsuba wheel's member `path` is needed (dist-info handled by the caller)."""
    if path.endswith(".pyi") or path.startswith(("mitsuba/include/", "mitsuba/cmake/", "mitsuba/pkgconfig/",
                                                 "mitsuba/mitsuba_stubs/", "mitsuba/python/test/")):
        return False
    if path == "mitsuba/mitsuba":  # the command line renderer
        return False
    variant = VARIANT_MODULE.match(path)
    if variant:
        return variant.group(1) in variants
    if path.startswith("mitsuba/plugins/"):
        return os.path.splitext(os.path.basename(path))[0] in plugins
    if path.startswith("mitsuba/data/"):
        if path == "mitsuba/data/srgb.coeff":
            return any("spectral" in v for v in variants)
        return path.startswith("mitsuba/data/ior/")
    return True


def keep_drjit(path):
    return not (path.endswith(".pyi") or path.endswith("/stubs.pat")
                or path.startswith(("drjit/include/", "drjit/cmake/")))


def record_line(name, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{name},sha256={digest},{len(data)}"


def repack(source, target, keep):
    """Copies the wheel `source` to `target` with the members `keep` accepts, a fresh RECORD."""
    with zipfile.ZipFile(source) as zin:
        record = [n for n in zin.namelist() if n.endswith(".dist-info/RECORD")]
        if len(record) != 1:
            fail(f"{source}: no single RECORD")
        record = record[0]
        lines, dropped = [], 0
        with zipfile.ZipFile(target + ".part", "w", zipfile.ZIP_DEFLATED) as zout:
            for info in zin.infolist():
                name = info.filename
                if name == record or name.endswith("/"):
                    continue
                if ".dist-info/" not in name and not keep(name):
                    dropped += 1
                    continue
                data = zin.read(info)
                entry = zipfile.ZipInfo(name, date_time=info.date_time)
                entry.external_attr = info.external_attr  # keeps the libraries' execute bits
                entry.compress_type = zipfile.ZIP_DEFLATED
                zout.writestr(entry, data, compresslevel=9)
                lines.append(record_line(name, data))
            lines.append(f"{record},,")
            zout.writestr(record, "\n".join(lines) + "\n")
    os.replace(target + ".part", target)
    return dropped


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--python", default="3.12", help="CPython version of the machine that installs them")
    ap.add_argument("--variants", default="cuda_ad_rgb", help="comma-separated Mitsuba variants to keep")
    ap.add_argument("--plugins", default="", help="comma-separated plugins to keep besides the default set")
    ap.add_argument("--out", default=os.path.join(ROOT, "gpu-bundle", "wheels"),
                    help="folder for the packed wheels (its older mitsuba/drjit wheels are removed)")
    ap.add_argument("--cache", default=os.path.join(ROOT, "bench", "out", "wheels-full"),
                    help="folder for the full wheels as downloaded")
    args = ap.parse_args()
    if not re.fullmatch(r"3\.\d+", args.python):
        fail(f"--python {args.python!r}: expected 3.N")

    variants = [v for v in args.variants.split(",") if v]
    plugins = set(PLUGINS) | {p for p in args.plugins.split(",") if p}
    mitsuba, drjit = download(args.python, args.cache)
    with zipfile.ZipFile(mitsuba) as z:
        names = z.namelist()
        have_variants = {m.group(1) for m in map(VARIANT_MODULE.match, names) if m}
        have_plugins = {os.path.splitext(os.path.basename(n))[0] for n in names if n.startswith("mitsuba/plugins/")}
    for v in variants:
        if v not in have_variants:
            fail(f"variant {v} is not in {os.path.basename(mitsuba)}: {sorted(have_variants)}")
    for p in sorted(plugins - have_plugins):
        fail(f"plugin {p} is not in {os.path.basename(mitsuba)}")

    os.makedirs(args.out, exist_ok=True)
    for old in glob.glob(os.path.join(args.out, "mitsuba-*.whl")) + glob.glob(os.path.join(args.out, "drjit-*.whl")):
        os.remove(old)  # pip refuses two versions of one package in one install
    rows = []
    for source, keep in ((mitsuba, lambda n: keep_mitsuba(n, variants, plugins)), (drjit, keep_drjit)):
        target = os.path.join(args.out, os.path.basename(source))
        dropped = repack(source, target, keep)
        rows.append((os.path.basename(source), os.path.getsize(source), os.path.getsize(target), dropped))
    print(f"variants {','.join(variants)}; plugins {','.join(sorted(plugins))}")
    for name, full, packed, dropped in rows:
        print(f"{name}: {full / 1e6:.1f} MB -> {packed / 1e6:.1f} MB ({dropped} files dropped)")
    full, packed = sum(r[1] for r in rows), sum(r[2] for r in rows)
    print(f"total: {full / 1e6:.1f} MB ({full / 2**20:.1f} MiB) -> {packed / 1e6:.1f} MB ({packed / 2**20:.1f} MiB)"
          f" in {args.out}")


if __name__ == "__main__":
    main()
