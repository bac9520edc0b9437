#!/usr/bin/python3
"""Adaptive against uniform sampling: renders a scene with and without
--adaptive at a series of sample budgets, alternating the two, measures each image's relMSE
against a long uniform reference, and writes a CSV and a log-log chart of relMSE against
render seconds. Prints, for a target relMSE, the seconds each takes to reach it (log-log
interpolation between the budgets that bracket it) and their ratio, as Markdown.

  bench/adaptive.py SCENE.obj --name NAME [--width W --height H] [--ref REF.exr | --ref-spp N]
                    [--spps 16,32,64,128,256] [--target 1e-2] [--out DIR] [-- RENDER FLAGS]

Seconds are the render's own (`--stats` seconds: set-up and compile excluded). The reference
(uniform, seed 1000) is rendered with two replicates, and its own estimated relMSE is taken
off each measurement. Needs Debian's python3-matplotlib.
"""
import argparse
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import benchlib  # noqa: E402  (beside this script)


def render(a, out, flags):
    return benchlib.render(benchlib.image_flags(a) + flags, out, a.binary)


def seconds_to(target, points):
    """Seconds at which relMSE reaches target, interpolated in log-log; None if not bracketed."""
    points = sorted(points)
    for (t0, e0), (t1, e1) in zip(points, points[1:]):
        if e0 >= target >= e1 and e0 > e1:
            f = (math.log(e0) - math.log(target)) / (math.log(e0) - math.log(e1))
            return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
    return None


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    benchlib.add_arguments(p, "scene", "--binary", "--width", "--height", "--ref", "--ref-spp")
    p.add_argument("--name", required=True)
    p.add_argument("--spps", default="16,32,64,128,256")
    p.add_argument("--target", type=float, default=1e-2)
    benchlib.add_arguments(p, "--seeds", "--out", out=benchlib.scratch_path("adaptive"),
                           seeds=dict(default="1", help="seeds per budget (their relMSE and seconds are averaged)"))
    a, extra = benchlib.parse_with_rest(p)
    os.makedirs(a.out, exist_ok=True)
    ref = a.ref
    if not ref:  # with two replicates (a target it never meets), for its own error estimate
        ref = os.path.join(a.out, f"{a.name}-ref-{a.ref_spp}.exr")
        if not os.path.exists(ref):
            render(a, ref, ["--spp", str(a.ref_spp), "--seed", "1000", "--noise", "1e-12"] + extra)
    # The reference's own error adds to every image's relMSE against it (they are independent).
    ref_error = float(benchlib.image_metadata(ref)["estimated_relmse"])
    print(f"reference {ref}: its estimated relMSE {ref_error:.2e} is taken off", file=sys.stderr)
    for mode in ([], ["--adaptive"]):  # PoCL compiles kernels at their first launch: not timed
        render(a, os.path.join(a.out, a.name + "-warm.exr"), ["--spp", "16"] + mode + extra)
    rows, points = [], {"uniform": [], "adaptive": []}
    for spp in [int(s) for s in a.spps.split(",")]:
        for mode in ("uniform", "adaptive"):  # alternated, so a noisy neighbour hits both
            errors, times = [], []
            for seed in a.seeds.split(","):
                img = os.path.join(a.out, f"{a.name}-{mode}-{spp}.exr")
                flags = ["--spp", str(spp), "--seed", seed] + (["--adaptive"] if mode == "adaptive" else []) + extra
                stats = render(a, img, flags)
                errors.append(benchlib.compare(img, ref, a.binary)["relmse"] - ref_error)
                times.append(stats["seconds"])
            e, t = sum(errors) / len(errors), sum(times) / len(times)
            rows.append({"mode": mode, "spp": spp, "seconds": t, "relmse": e})
            points[mode].append((t, e))
            each = " ".join(f"{x:.2e}" for x in errors)
            print(f"{mode:8s} {spp:6d} spp  {t:8.3f} s  relMSE {e:.4e}  ({each})", file=sys.stderr)
    with open(os.path.join(a.out, a.name + ".csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["mode", "spp", "seconds", "relmse"])
        w.writeheader()
        w.writerows(rows)
    plt.figure(figsize=(6, 4.5))
    for mode, style in (("uniform", "o-"), ("adaptive", "s-")):
        t, e = zip(*sorted(points[mode]))
        plt.loglog(t, e, style, label=mode)
    plt.axhline(a.target, color="grey", lw=0.8, ls=":")
    plt.xlabel("render seconds")
    plt.ylabel("relMSE against the reference")
    plt.title(f"{a.name}: adaptive against uniform sampling")
    plt.legend()
    plt.grid(True, which="both", alpha=0.3)
    plt.tight_layout()
    plt.savefig(os.path.join(a.out, a.name + ".png"), dpi=110)
    tu, ta = seconds_to(a.target, points["uniform"]), seconds_to(a.target, points["adaptive"])
    fmt = lambda t: f"{t:.2f}" if t else "not reached"
    ratio = f"{ta / tu:.2f}" if tu and ta else "-"
    print(f"| {a.name} | {a.width}x{a.height} | {a.target:g} | {fmt(tu)} | {fmt(ta)} | {ratio} |")


if __name__ == "__main__":
    benchlib.main(main)
