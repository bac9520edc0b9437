#!/usr/bin/python3
"""Checks --noise's error estimate against the truth (issue 16).

For each scene: a long reference (two replicates too, so its own estimated relMSE is known
and taken off), then renders stopped by --noise at each target with two seeds; prints the
estimate when the render stopped, the relMSE measured against the reference (minus the
reference's own), their ratio, spp and seconds, as a Markdown table.

  bench/noise_check.py --scene SCENE.obj --size 96x64 --ref-spp 16384 --targets 1e-2,3e-3 [--adaptive]
"""
import argparse
import json
import os
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def render(binary, scene, size, out, extra):
    w, h = size.split("x")
    args = [binary, "render"] + ([scene] if scene else []) + ["--width", w, "--height", h, "-o", out, "--force"] + extra
    log = subprocess.run(args, check=True, capture_output=True, text=True).stderr
    meta = subprocess.run(["oiiotool", "--info", "-v", out], check=True, capture_output=True, text=True).stdout
    fields = {}
    for line in meta.splitlines():
        line = line.strip()
        if line.startswith("fredholm:"):
            key, value = line[len("fredholm:"):].split(":", 1)
            fields[key.strip()] = value.strip().strip('"')
    return fields, log


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--binary", default=os.path.join(ROOT, "build", "fredholm"))
    p.add_argument("--scene", default="", help="OBJ (default: the built-in Cornell box)")
    p.add_argument("--size", default="128x128")
    p.add_argument("--ref-spp", type=int, default=4096)
    p.add_argument("--targets", default="1e-2,3e-3,1e-3")
    p.add_argument("--seeds", default="1,2")
    p.add_argument("--adaptive", action="store_true", help="the stopped renders sample adaptively")
    a = p.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        ref = os.path.join(tmp, "ref.exr")
        meta, _ = render(a.binary, a.scene, a.size, ref, ["--spp", str(a.ref_spp), "--noise", "1e-12", "--seed", "1000"])
        ref_error = float(meta["estimated_relmse"])
        print(f"scene {a.scene or 'built-in Cornell box'}, {a.size}; reference {a.ref_spp} spp, "
              f"its estimated relMSE {ref_error:.2e} (taken off)\n")
        print("| --noise | seed | spp | seconds | estimate | measured | measured / estimate |")
        print("|---|---|---|---|---|---|---|")
        for target in a.targets.split(","):
            for seed in a.seeds.split(","):
                out = os.path.join(tmp, "img.exr")
                flags = ["--noise", target, "--seed", seed] + (["--adaptive"] if a.adaptive else [])
                meta, _ = render(a.binary, a.scene, a.size, out, flags)
                cmp = json.loads(subprocess.run([a.binary, "compare", out, ref], check=True, capture_output=True,
                                                text=True).stdout)
                estimate, measured = float(meta["estimated_relmse"]), cmp["relmse"] - ref_error
                print(f"| {target} | {seed} | {float(meta['spp']):.0f} | {meta['seconds']} | {estimate:.3e} | "
                      f"{measured:.3e} | {measured / estimate:.2f} |")


if __name__ == "__main__":
    main()
