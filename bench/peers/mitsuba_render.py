#!/usr/bin/env python3
"""Renders an OBJ+MTL scene with Mitsuba 3, as fredholm would read it, and times the render:
the peer for fredholm's speed and error (bench/peer_speed.py, bench/peer_charts.py).

  /opt/mi-venv/bin/python bench/peers/mitsuba_render.py [SCENE.obj] --out OUT.exr --spp N
      [--variant llvm_ad_rgb|cuda_ad_rgb|scalar_rgb] [--sampler independent|ldsampler|...]
      [--seed S] [--width 512 --height 512] [--max-bounces 16] [--rr-depth 5] [--threads 2]
      [--eye x,y,z --target x,y,z --up x,y,z --fov DEG] [--warmup-spp N]

It prints one JSON line: samples_per_second (width * height * spp / seconds_render),
seconds_render (the timed mi.render, after an untimed warm-up render that compiles the JIT
kernels), seconds_total, spp, mean_rgb, the materials as translated, and notes.
SCENE defaults to scenes/cornell-box/CornellBox-Original.obj; the camera is the scene's
SCENE.camera.json (eye, target, up, fov_y_deg), each field replaced by a flag given.

Geometry: one mesh per material; polygons fan-triangulated (0,1,2), (0,2,3), ... as
tinyobjloader does; a face that repeats an earlier one (same positions, same winding) is
dropped, as Embree would otherwise see two coincident surfaces. Vertex normals (vn) become
Mitsuba's interpolated shading normals, as they are fredholm's; without them, face normals.

Materials (fredholm's model: kernels/bsdf.h; one MTL value means grey):
- Ke > 0: an `area` emitter of radiance Ke on the counter-clockwise side (Mitsuba's and
  fredholm's front), over the material's own BSDF.
- illum 0-2 with Ks = 0: `diffuse` Kd, two-sided.
- illum 2 with Ks > 0, or 3/5/8 with Ns < 1000: fredholm's own glossy model, as a Mitsuba
  plugin (bench/peers/fh_glossy.py): Mitsuba's roughplastic weighs the diffuse part by its
  coating's transmissions and internal reflections and has a separable Smith term, which
  darken the glossy Cornell box against fredholm's (bench/history/paths_vs_peers.md).
- illum 3/5/8 with Ns >= 1000: a perfect mirror: a `conductor` of reflectance Ks where the
  diffuse part fredholm keeps, (1 - max Ks) Kd, is negligible (luminance < 0.01), else a
  `plastic` (a smooth dielectric coating over Kd whose Fresnel reflectance at normal
  incidence is max Ks, tinted Ks / max Ks). Where they differ: the conductor's reflectance
  stays Ks where fredholm's Schlick term rises to 1 at grazing angles; the coating's Fresnel
  is exact where fredholm's is Schlick's, and it weighs the diffuse part by its own model.
- illum 4/6/7/9: `dielectric`, interior index Ni (1.5 if none), exterior 1, transmission
  tinted by Tf: the same model as fredholm's (exact Fresnel, radiance scaled by 1/eta^2).
Textures are not translated (a scene with map_Kd fails).
"""
import argparse
import json
import math
import os
import sys
import tempfile
import time

T_START = time.perf_counter()

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEFAULT_SCENE = os.path.join(ROOT, "scenes", "cornell-box", "CornellBox-Original.obj")
LIBLLVM = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"  # drjit 1.5 cannot use Debian's LLVM 15
NS_MIRROR = 1000.0  # kernels/bsdf.h: FH_NS_MIRROR


def fail(message):
    print(f"mitsuba_render: error: {message}", file=sys.stderr)
    sys.exit(1)


def vector(text, name):
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 3:
        fail(f"{name} {text!r}: expected x,y,z")
    return values


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene", nargs="?", default=DEFAULT_SCENE)
    ap.add_argument("--out", required=True, help="output EXR (linear float32 RGB)")
    ap.add_argument("--spp", type=int, required=True)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--sampler", default="independent",
                    choices=["independent", "ldsampler", "multijitter", "stratified", "orthogonal"])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--width", type=int, default=512)
    ap.add_argument("--height", type=int, default=512)
    ap.add_argument("--max-bounces", type=int, default=16, help="scattering events (Mitsuba's max_depth is one more)")
    ap.add_argument("--rr-depth", type=int, default=5, help="Mitsuba's rr_depth (fredholm's --rr-depth 6)")
    ap.add_argument("--threads", type=int, default=2, help="render threads, the calling one included")
    ap.add_argument("--eye")
    ap.add_argument("--target")
    ap.add_argument("--up")
    ap.add_argument("--fov", type=float, help="vertical field of view, degrees")
    ap.add_argument("--warmup-spp", type=int,
                    help="spp of the untimed warm-up render (0: none; default 1 for the independent sampler, "
                         "else --spp, as the other samplers' kernels depend on the sample count)")
    return ap.parse_args()


# ---- The scene as fredholm reads it -------------------------------------------------------

def grey_or_rgb(words, where):
    values = [float(v) for v in words]
    if len(values) == 1:
        return values * 3
    if len(values) < 3:
        fail(f"{where}: expected one or three values")
    return values[:3]


def read_mtl(path):
    materials, current = {}, None
    with open(path) as f:
        for number, line in enumerate(f, 1):
            words = line.split("#", 1)[0].split()
            if not words:
                continue
            key, where = words[0], f"{path}:{number}"
            if key == "newmtl":
                current = materials.setdefault(words[1], {"Kd": [0.0] * 3, "Ks": [0.0] * 3, "Ke": [0.0] * 3,
                                                          "Tf": [1.0] * 3, "Ns": 0.0, "Ni": 0.0, "illum": 2})
            elif current is None:
                continue
            elif key in ("Kd", "Ks", "Ke", "Tf"):
                current[key] = grey_or_rgb(words[1:], where)
            elif key in ("Ns", "Ni"):
                current[key] = float(words[1])
            elif key == "illum":
                current[key] = int(words[1])
            elif key.startswith("map_") or key in ("bump", "disp", "norm"):
                fail(f"{where}: {key}: textures are not translated")
    return materials


def read_obj(path):
    """{material: (positions (n,3), normals (n,3) or None, faces (m,3))}, the mtllib paths."""
    positions, normals, polygons, libraries, material = [], [], [], [], None
    with open(path) as f:
        for line in f:
            words = line.split("#", 1)[0].split()
            if not words:
                continue
            key = words[0]
            if key == "v":
                positions.append([float(v) for v in words[1:4]])
            elif key == "vn":
                normals.append([float(v) for v in words[1:4]])
            elif key == "f":
                corners = []
                for token in words[1:]:
                    fields = token.split("/")
                    v = int(fields[0])
                    n = int(fields[2]) if len(fields) > 2 and fields[2] else None
                    corners.append((v - 1 if v > 0 else len(positions) + v,
                                    None if n is None else (n - 1 if n > 0 else len(normals) + n)))
                polygons.append((material, corners))
            elif key == "usemtl":
                material = words[1]
            elif key == "mtllib":
                libraries.append(os.path.join(os.path.dirname(path), line.split(None, 1)[1].split("#")[0].strip()))
    seen, meshes, dropped = set(), {}, 0
    for material, corners in polygons:
        points = [tuple(positions[v]) for v, _ in corners]
        key = min(tuple(points[(i + k) % len(points)] for k in range(len(points))) for i in range(len(points)))
        if key in seen:
            dropped += 1
            continue
        seen.add(key)
        mesh = meshes.setdefault(material, {"corners": {}, "faces": []})
        ids = [mesh["corners"].setdefault(c, len(mesh["corners"])) for c in corners]
        mesh["faces"] += [(ids[0], ids[k], ids[k + 1]) for k in range(1, len(ids) - 1)]
    out = {}
    for material, mesh in meshes.items():
        corners = list(mesh["corners"])
        p = np.array([positions[v] for v, _ in corners], dtype=np.float32)
        has_normals = all(n is not None for _, n in corners)
        n = np.array([normals[k] for _, k in corners], dtype=np.float32) if has_normals else None
        out[material] = (p, n, np.array(mesh["faces"], dtype=np.uint32))
    return out, libraries, dropped


def luminance(c):
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]


def index_for_reflectance(f0):
    """The dielectric index whose Fresnel reflectance at normal incidence is f0."""
    s = math.sqrt(min(max(f0, 1e-4), 0.999))
    return (1.0 + s) / (1.0 - s)


def rgb(c):
    return {"type": "rgb", "value": [float(v) for v in c]}


def translate(m):
    """(Mitsuba BSDF dict, a short description) of an MTL material, by kernels/bsdf.h's rules."""
    illum, ks = m["illum"], [min(max(v, 0.0), 1.0) for v in m["Ks"]]
    if illum in (4, 6, 7, 9):
        ior = m["Ni"] if m["Ni"] > 0 else 1.5
        tf = [min(max(v, 0.0), 1.0) for v in m["Tf"]]
        return {"type": "dielectric", "int_ior": ior, "ext_ior": 1.0, "specular_transmittance": rgb(tf)}, \
            f"dielectric ior {ior:g}"
    diffuse = {"type": "diffuse", "reflectance": rgb(m["Kd"])}
    if max(ks) <= 0.0 or illum < 2:
        return {"type": "twosided", "material": diffuse}, "diffuse"
    if illum not in (3, 5, 8) or m["Ns"] < NS_MIRROR:
        alpha = max(math.sqrt(2.0 / (max(m["Ns"], 0.0) + 2.0)), 1e-3)
        bsdf = {"type": "fh_glossy", "alpha": alpha}
        bsdf.update({f"kd_{c}": float(v) for c, v in zip("rgb", m["Kd"])})
        bsdf.update({f"ks_{c}": float(v) for c, v in zip("rgb", ks)})
        return {"type": "twosided", "material": bsdf}, f"fredholm's GGX, alpha {alpha:.4g}"
    f0 = max(ks)
    if luminance(m["Kd"]) * (1.0 - f0) < 0.01:  # the diffuse part fredholm keeps is negligible
        bsdf, what = {"type": "conductor", "material": "none", "specular_reflectance": rgb(ks)}, "mirror"
    else:
        bsdf = {"type": "plastic", "diffuse_reflectance": rgb(m["Kd"]), "specular_reflectance": rgb(
            [v / f0 for v in ks]), "int_ior": index_for_reflectance(f0), "ext_ior": 1.0, "nonlinear": False}
        what = f"smooth coating ior {bsdf['int_ior']:.4g} over Kd"
    return {"type": "twosided", "material": bsdf}, what


def write_ply(path, positions, normals, faces):
    """A binary little-endian PLY of a triangle mesh (with per-vertex normals if given)."""
    header = ["ply", "format binary_little_endian 1.0", f"element vertex {len(positions)}",
              "property float x", "property float y", "property float z"]
    vertex = positions
    if normals is not None:
        header += ["property float nx", "property float ny", "property float nz"]
        vertex = np.hstack([positions, normals])
    header += [f"element face {len(faces)}", "property list uchar uint vertex_indices", "end_header"]
    rows = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<u4", (3,))])
    rows["n"], rows["i"] = 3, faces
    with open(path, "wb") as f:
        f.write(("\n".join(header) + "\n").encode("ascii"))
        f.write(np.ascontiguousarray(vertex, dtype="<f4").tobytes())
        f.write(rows.tobytes())


def camera(args):
    view = {"eye": [0.0, 1.0, 3.5], "target": [0.0, 1.0, 0.0], "up": [0.0, 1.0, 0.0], "fov_y_deg": 40.0}
    sidecar = os.path.splitext(args.scene)[0] + ".camera.json"
    if os.path.exists(sidecar):
        with open(sidecar) as f:
            view.update(json.load(f))
    for field in ("eye", "target", "up"):
        if getattr(args, field):
            view[field] = vector(getattr(args, field), "--" + field)
    if args.fov:
        view["fov_y_deg"] = args.fov
    return view


# ---- Mitsuba ------------------------------------------------------------------------------

def load_mitsuba(variant, threads):
    if variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(LIBLLVM):
        os.environ["DRJIT_LIBLLVM_PATH"] = LIBLLVM
    import drjit as dr
    import mitsuba as mi
    if variant not in mi.variants():
        fail(f"variant {variant} is not in this Mitsuba: {mi.variants()}")
    mi.set_variant(variant)
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import fh_glossy
    fh_glossy.register(mi, dr)
    mi.set_log_level(mi.LogLevel.Error)
    # The thread count includes the calling thread, which works while it waits.
    dr.set_thread_count(max(threads, 1))
    return dr, mi


def main():
    args = parse_args()
    meshes, libraries, dropped = read_obj(args.scene)
    materials = {}
    for library in libraries:
        materials.update(read_mtl(library))
    view = camera(args)
    jit = args.variant.startswith(("llvm", "cuda"))
    dr, mi = load_mitsuba(args.variant, args.threads)
    if jit:
        dr.set_flag(dr.JitFlag.KernelHistory, True)

    folder = tempfile.TemporaryDirectory(prefix="fh-mitsuba-")
    scene = {"type": "scene"}
    translated = {}
    for k, (name, (positions, normals, faces)) in enumerate(meshes.items()):
        m = materials.get(name)
        if m is None:  # fredholm warns and gives its faces the default grey diffuse
            print(f"mitsuba_render: warning: material {name!r} is in no mtllib: grey diffuse", file=sys.stderr)
            m = {"Kd": [0.5] * 3, "Ks": [0.0] * 3, "Ke": [0.0] * 3, "Tf": [1.0] * 3, "Ns": 0.0, "Ni": 0.0, "illum": 2}
        bsdf, translated[name] = translate(m)
        path = os.path.join(folder.name, f"mesh{k}.ply")
        write_ply(path, positions, normals, faces)
        shape = {"type": "ply", "filename": path, "face_normals": normals is None, "bsdf": bsdf}
        if max(m["Ke"]) > 0:
            shape["emitter"] = {"type": "area", "radiance": rgb(m["Ke"])}
            translated[name] += f", emits {m['Ke']}"
        scene[f"shape{k}"] = shape
    scene["integrator"] = {"type": "path", "max_depth": args.max_bounces + 1, "rr_depth": args.rr_depth,
                           "hide_emitters": False}
    scene["sensor"] = {
        "type": "perspective", "fov_axis": "y", "fov": view["fov_y_deg"], "near_clip": 1e-4, "far_clip": 1e5,
        "to_world": mi.ScalarTransform4f().look_at(origin=view["eye"], target=view["target"], up=view["up"]),
        "sampler": {"type": args.sampler, "sample_count": args.spp, "seed": args.seed},
        "film": {"type": "hdrfilm", "width": args.width, "height": args.height, "pixel_format": "rgb",
                 "component_format": "float32", "sample_border": False, "rfilter": {"type": "box"}},
    }
    loaded = mi.load_dict(scene)

    def render(spp, seed):
        image = mi.render(loaded, spp=spp, seed=seed)
        if jit:
            dr.sync_thread()
        return image

    warmup_spp = args.warmup_spp if args.warmup_spp is not None else (
        1 if args.sampler == "independent" else args.spp)
    if warmup_spp > 0:
        render(warmup_spp, args.seed + 7919)
    if jit:
        dr.kernel_history()  # read and cleared: the timed render's own follow
    start = time.perf_counter()
    image = render(args.spp, args.seed)
    seconds = time.perf_counter() - start
    compile_seconds = 0.0
    if jit:
        compile_seconds = sum(k.get("codegen_time", 0) + k.get("backend_time", 0) for k in dr.kernel_history()
                              if k.get("type") == dr.KernelType.JIT) / 1000.0
    spp = int(loaded.sensors()[0].sampler().sample_count())  # some samplers round it
    pixels = np.ascontiguousarray(np.array(image, dtype=np.float32)[..., :3])
    if dr.thread_count() < 2:
        dr.set_thread_count(2)  # Mitsuba 3.9's EXR writer deadlocks with no worker thread
    out = os.path.abspath(args.out)
    os.makedirs(os.path.dirname(out), exist_ok=True)
    mi.Bitmap(pixels, pixel_format=mi.Bitmap.PixelFormat.RGB).write(out)
    print(json.dumps({
        "renderer": "mitsuba", "variant": args.variant, "sampler": args.sampler, "seed": args.seed,
        "spp": spp, "width": args.width, "height": args.height, "threads": args.threads,
        "samples_per_second": args.width * args.height * spp / seconds, "seconds_render": seconds,
        "jit_compile_seconds_in_render": compile_seconds, "seconds_total": time.perf_counter() - T_START,
        "mean_rgb": [float(v) for v in pixels.reshape(-1, 3).astype(np.float64).mean(0)],
        "nonfinite_pixels": int((~np.isfinite(pixels)).any(-1).sum()),
        "scene": os.path.abspath(args.scene), "camera": view, "materials": translated,
        "triangles": int(sum(len(f) for _, _, f in meshes.values())), "duplicate_faces_dropped": dropped,
        "out": out, "mitsuba": mi.__version__, "drjit": dr.__version__,
    }), flush=True)
    folder.cleanup()


if __name__ == "__main__":
    main()
