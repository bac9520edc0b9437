#!/usr/bin/python3
"""fredholm against an independent renderer: Blender Cycles (Debian's `blender`, headless).

usage: bench/cycles_compare.py [--out DIR] [--width W] [--height H] [--spp N] [--plane-spp N] [--block K]

1. Cycles' units: the closed-form plane under a light (`fredholm export builtin:plane-under-light`)
   rendered by Cycles and compared with its exact image (`fredholm reference`): the ratio of
   the means is the factor between Cycles' Emission strength and radiance (expected 1).
2. The Cornell box (`fredholm export`, so both renderers read the same files) rendered by
   Cycles and by fredholm (`mis`, box filter, 64 bounces) with two seeds each. If neither is
   biased, the error between the two renderers is only their noise:
       relMSE(fredholm, Cycles) ~ relMSE(fredholm seed 1, seed 2) / 2 + relMSE(Cycles 1, 2) / 2
   (each term of a pair of independent renders holds the noise of both). The script prints
   that ratio ("excess", 1 for no bias) per pixel and over KxK blocks (--block, where the
   noise is K^2 times smaller and a regional bias stands out), and the ratio of the channel
   means. bench/cycles_reference.py holds the Cycles set-up and why each setting is there.

Writes DIR/cycles_compare.json and DIR/cornell-fredholm-cycles.png (fredholm | Cycles | 8x difference).
"""
import argparse
import json
import os
import re
import shutil
import sys

import benchlib

CYCLES_SCRIPT = os.path.join(benchlib.ROOT, "bench", "cycles_reference.py")


def run(cmd):
    """Runs cmd; returns its stdout and stderr (Blender's progress lines)."""
    done = benchlib.run(cmd, stdout=True)
    return done.stdout + done.stderr


def cycles(obj, output, args, spp, seed):
    camera = os.path.splitext(obj)[0] + ".camera.json"
    # --require-exact: the comparison means something only for an exact twin; every core, as
    # fredholm has.
    log = run(["blender", "-b", "--factory-startup", "--python", CYCLES_SCRIPT, "--", obj, camera, output,
               "--width", str(args.width), "--height", str(args.height), "--spp", str(spp), "--seed", str(seed),
               "--max-bounces", "64", "--require-exact", "--threads", str(os.cpu_count() or 1)])
    # Cycles' own render time: the last "Time:MM:SS.ss" of its progress lines.
    minutes, seconds = re.findall(r"Time:(\d+):(\d+\.\d+)", log)[-1]
    return 60 * int(minutes) + float(seconds)


def fredholm(obj, output, args, spp, seed):
    return benchlib.render([obj, "--width", str(args.width), "--height", str(args.height), "--spp", str(spp),
                            "--method", "mis", "--filter", "box", "--max-depth", "64", "--seed", str(seed)], output,
                           args.binary)["seconds"]


def mean_ratio(a, b):
    return [x / y if y else float("nan") for x, y in zip(a, b)]


def check_units(args, out):
    obj = os.path.join(out, "plane-under-light.obj")
    exact = os.path.join(out, "plane-under-light-exact.exr")
    image = os.path.join(out, "plane-under-light-cycles.exr")
    run([args.binary, "export", "builtin:plane-under-light", "-o", obj, "--force"])
    run([args.binary, "reference", "builtin:plane-under-light", "--width", str(args.width), "--height",
         str(args.height), "-o", exact, "--force"])
    seconds = cycles(obj, image, args, args.plane_spp, 1)
    e = benchlib.compare(image, exact, args.binary, 1)
    factor = mean_ratio(e["mean_image"], e["mean_reference"])[0]
    print(f"plane under a light: Cycles / exact mean = {factor:.4f}, relMSE {e['relmse']:.2e} "
          f"({args.plane_spp} spp, {seconds:.1f} s)")
    return {"spp": args.plane_spp, "cycles_seconds": seconds, "mean_ratio_cycles_over_exact": factor,
            "relmse_cycles_vs_exact": e["relmse"]}


def compare_cornell(args, out):
    obj = os.path.join(out, "cornell-box.obj")
    run([args.binary, "export", "-o", obj, "--force"])
    images, seconds = {}, {}
    for seed in (1, 2):
        for name, renderer in (("fredholm", fredholm), ("cycles", cycles)):
            key = f"{name}{seed}"
            images[key] = os.path.join(out, f"cornell-{key}.exr")
            seconds[key] = renderer(obj, images[key], args, args.spp, seed)
            print(f"  {key}: {args.spp} spp in {seconds[key]:.1f} s")
    result = {"spp": args.spp, "width": args.width, "height": args.height, "seconds": seconds}
    for block in (1, args.block):
        def compare(image, reference):
            return benchlib.compare(images[image], images[reference], args.binary, block)

        across = [compare("fredholm1", "cycles1"), compare("fredholm2", "cycles2")]
        fh_noise = compare("fredholm1", "fredholm2")["relmse"]
        cy_noise = compare("cycles1", "cycles2")["relmse"]
        measured = sum(e["relmse"] for e in across) / 2
        expected = fh_noise / 2 + cy_noise / 2
        result[f"block{block}"] = {"relmse_fredholm_vs_cycles": measured, "relmse_expected_from_noise": expected,
                                   "excess": measured / expected, "relmse_fredholm_seed_pair": fh_noise,
                                   "relmse_cycles_seed_pair": cy_noise}
        print(f"  {block}x{block} blocks: relMSE fredholm vs Cycles {measured:.3e}, from noise alone {expected:.3e} "
              f"(excess {measured / expected:.3f}); seed pairs: fredholm {fh_noise:.3e}, Cycles {cy_noise:.3e}")
    # Block averages keep the means: the last pair of comparisons has them.
    result["mean_fredholm"] = [(a + b) / 2 for a, b in zip(across[0]["mean_image"], across[1]["mean_image"])]
    result["mean_cycles"] = [(a + b) / 2 for a, b in zip(across[0]["mean_reference"], across[1]["mean_reference"])]
    result["mean_ratio_fredholm_over_cycles"] = mean_ratio(result["mean_fredholm"], result["mean_cycles"])
    print("  channel means fredholm / Cycles: " +
          " ".join(f"{r:.4f}" for r in result["mean_ratio_fredholm_over_cycles"]))
    side_by_side(images["fredholm1"], images["cycles1"], os.path.join(out, "cornell-fredholm-cycles.png"))
    return result


def side_by_side(a, b, png):
    if not shutil.which("oiiotool"):
        return
    run(["oiiotool", a, b, "--sub", "--abs", "--mulc", "8", "-o", png + ".diff.exr"])
    run(["oiiotool", a, b, png + ".diff.exr", "--mosaic", "3x1", "--colorconvert", "linear", "sRGB",
         "-d", "uint8", "-o", png])
    os.remove(png + ".diff.exr")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    benchlib.add_arguments(p, "--binary", "--out", "--width", "--height", "--spp", out=benchlib.scratch_path("cycles"),
                           spp=4096)
    p.add_argument("--plane-spp", type=int, default=1024)
    p.add_argument("--block", type=int, default=8)
    args = p.parse_args()
    if not shutil.which("blender"):
        sys.exit("cycles_compare: blender not found (apt-get install blender)")
    if not os.access(args.binary, os.X_OK):
        sys.exit(f"cycles_compare: {args.binary} not built (./setup.sh build)")
    os.makedirs(args.out, exist_ok=True)
    print(run(["blender", "--version"]).splitlines()[0])
    result = {"blender": run(["blender", "--version"]).splitlines()[0], "units": check_units(args, args.out)}
    print("Cornell box:")
    result["cornell"] = compare_cornell(args, args.out)
    path = os.path.join(args.out, "cycles_compare.json")
    with open(path, "w") as f:
        json.dump(result, f, indent=2)
    print(f"wrote {path}")


if __name__ == "__main__":
    benchlib.main(main)
