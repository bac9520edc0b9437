#!/usr/bin/python3
"""--method auto at equal time: each failure-suite scene (and the Cornell box) rendered for the
same --time with every method and with auto (its pilots inside that time), each image measured
against a long reference, over a few seeds; prints the method x scene table of relMSE with
auto's ratio to the best single method and what auto chose.

usage: bench/method_choice.py [--time T] [--seeds 1,2,3] [--ref-spp N] [--width W --height H]
                              [--methods pt,nee,mis,lt,bdpt,vcm,auto] [--scenes caustic,...] [--out DIR]

References are long renders of fredholm itself (lt where a caustic is the error, else mis),
kept under --out between runs. Their own error (their estimated relMSE) is taken off each
figure, so a reference that is too short shows as a small or negative figure, not a false one.
"""
import argparse
import os
import statistics

import benchlib

# (name, scene, the reference's method)
SCENES = [("cornell-box", "scenes/cornell-box/CornellBox-Original.obj", "mis"),
          ("caustic", "scenes/failure/caustic.obj", "lt"),
          ("hidden-light", "scenes/failure/hidden-light.obj", "mis"),
          ("tiny-light", "scenes/failure/tiny-light.obj", "mis")]
METHODS = "pt,nee,mis,lt,bdpt,vcm,auto"


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    benchlib.add_arguments(p, "--binary", "--out", "--width", "--height", "--seeds", "--ref-spp",
                           out=benchlib.scratch_path("method_choice"), seeds="1,2,3", ref_spp=16384)
    p.add_argument("--time", type=float, default=5.0, help="seconds per render (default 5)")
    p.add_argument("--methods", default=METHODS, help=f"methods to render, in turn (default {METHODS})")
    p.add_argument("--scenes", default=",".join(s[0] for s in SCENES),
                   help="the scenes to render, by name (default all: %(default)s)")
    args = p.parse_args()
    methods = args.methods.split(",")
    os.makedirs(args.out, exist_ok=True)
    size = ["--width", str(args.width), "--height", str(args.height)]
    auto = "auto" in methods
    print(f"| scene | {' | '.join(methods)} |" + (" auto / best | auto chose |" if auto else ""))
    print("|---|" + "---|" * (len(methods) + (2 if auto else 0)))
    for name, scene, ref_method in (s for s in SCENES if s[0] in args.scenes.split(",")):
        scene = os.path.join(benchlib.ROOT, scene)
        ref = os.path.join(args.out, f"{name}-{args.width}x{args.height}-{ref_method}-{args.ref_spp}.exr")
        if not os.path.exists(ref):
            benchlib.render([scene] + size + ["--method", ref_method, "--spp", str(args.ref_spp), "--seed", "1000",
                                              "--noise", "1e-30"], ref, args.binary)
        ref_error = float(benchlib.image_metadata(ref)["estimated_relmse"])
        errors = {m: [] for m in methods}
        chose = []
        for seed in args.seeds.split(","):
            for method in methods:  # alternated within each seed
                image = os.path.join(args.out, f"{name}-{method}-{seed}.exr")
                stats = benchlib.render([scene] + size + ["--method", method, "--time", str(args.time),
                                                          "--seed", seed], image, args.binary)
                if method == "auto":
                    chose.append(stats["method"])
                errors[method].append(benchlib.compare(image, ref, args.binary)["relmse"] - ref_error)
        means = {m: statistics.mean(v) for m, v in errors.items()}
        best = min(v for m, v in means.items() if m != "auto")
        cells = [f"{means[m]:.2e}" for m in methods]
        tail = f" {means['auto'] / best:.2f} | {', '.join(chose)} |" if auto else ""
        print(f"| {name} | {' | '.join(cells)} |" + tail, flush=True)


if __name__ == "__main__":
    benchlib.main(main)
