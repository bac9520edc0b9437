#!/usr/bin/python3
"""Checks --noise's error estimate against the truth.

For each scene: a long reference (two replicates too, so its own estimated relMSE is known
and taken off), then renders stopped by --noise at each target with two seeds; prints the
estimate when the render stopped, the relMSE measured against the reference (minus the
reference's own), their ratio, spp and seconds, as a Markdown table.

  bench/noise_check.py --scene SCENE.obj --size 96x64 --ref-spp 16384 --targets 1e-2,3e-3 [--adaptive]
"""
import argparse
import os
import tempfile

import benchlib


def render(a, out, flags):
    """Renders; returns the image's fredholm:* metadata (estimated_relmse, spp, seconds)."""
    benchlib.render(benchlib.image_flags(a) + flags, out, a.binary, stats=False)
    return benchlib.image_metadata(out)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    benchlib.add_arguments(p, "--binary", "--scene", "--size", "--ref-spp")
    p.add_argument("--targets", default="1e-2,3e-3,1e-3")
    benchlib.add_arguments(p, "--seeds")
    p.add_argument("--adaptive", action="store_true", help="the stopped renders sample adaptively")
    a = p.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        ref = os.path.join(tmp, "ref.exr")
        meta = render(a, ref, ["--spp", str(a.ref_spp), "--noise", "1e-12", "--seed", "1000"])
        ref_error = float(meta["estimated_relmse"])
        print(f"scene {a.scene or 'built-in Cornell box'}, {a.size}; reference {a.ref_spp} spp, "
              f"its estimated relMSE {ref_error:.2e} (taken off)\n")
        print("| --noise | seed | spp | seconds | estimate | measured | measured / estimate |")
        print("|---|---|---|---|---|---|---|")
        for target in a.targets.split(","):
            for seed in a.seeds.split(","):
                out = os.path.join(tmp, "img.exr")
                meta = render(a, out, ["--noise", target, "--seed", seed] + (["--adaptive"] if a.adaptive else []))
                measured = benchlib.compare(out, ref, a.binary)["relmse"] - ref_error
                estimate = float(meta["estimated_relmse"])
                print(f"| {target} | {seed} | {float(meta['spp']):.0f} | {meta['seconds']} | {estimate:.3e} | "
                      f"{measured:.3e} | {measured / estimate:.2f} |")


if __name__ == "__main__":
    benchlib.main(main)
