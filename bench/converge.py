#!/usr/bin/python3
"""Error against render time for pt, nee and mis: renders a scene at 1, 2, 4, ... spp with
each method, measures each image against a reference (`fredholm compare`: relMSE, RMSE,
MAE), and writes a CSV and a log-log chart of relMSE against seconds, with a slope -1
guide (an unbiased estimator's relMSE falls as 1/time).

usage: bench/converge.py [SCENE.obj] [--out DIR] [--width W] [--height H] [--max-spp N]
                         [--ref REF.exr | --ref-spp N] [--methods pt,nee,mis] [-- RENDER FLAGS]

Without --ref, the reference is a long `mis` render of fredholm itself (--ref-spp samples,
default 4096): it cannot reveal a bias fredholm shares with itself, and its own noise is
about relMSE(max-spp run) * max-spp / ref-spp. Needs Debian's python3-matplotlib.
"""
import argparse
import csv
import json
import os
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from converge_table import equal_time  # noqa: E402  (beside this script)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FREDHOLM = os.path.join(ROOT, "build", "fredholm")


def render(scene, out, spp, method, seed, args, extra):
    cmd = [FREDHOLM, "render"] + ([scene] if scene else []) + [
        "--width", str(args.width), "--height", str(args.height), "--spp", str(spp), "--method", method,
        "--seed", str(seed), "-o", out, "--stats", out + ".json", "--force"] + extra
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    with open(out + ".json") as f:
        return json.load(f)


def compare(image, reference):
    out = subprocess.run([FREDHOLM, "compare", image, reference], check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def main():
    argv = sys.argv[1:]
    extra = []
    if "--" in argv:
        extra = argv[argv.index("--") + 1:]
        argv = argv[:argv.index("--")]
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene", nargs="?", default="", help="OBJ file (default: the built-in Cornell box)")
    p.add_argument("--out", default="bench/out/converge")
    p.add_argument("--width", type=int, default=128)
    p.add_argument("--height", type=int, default=128)
    p.add_argument("--max-spp", type=int, default=256)
    p.add_argument("--ref")
    p.add_argument("--ref-spp", type=int, default=4096)
    p.add_argument("--methods", default="pt,nee,mis")
    args = p.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    name = os.path.splitext(os.path.basename(args.scene))[0].replace(":", "-") if args.scene else "cornell-box"

    reference = args.ref
    if not reference:
        reference = os.path.join(args.out, f"{name}-reference.exr")
        stats = render(args.scene, reference, args.ref_spp, "mis", 1000, args, extra)
        print(f"reference: mis, {args.ref_spp} spp, {stats['seconds']:.1f} s -> {reference}")

    rows = []
    for method in args.methods.split(","):
        # A throw-away render first: PoCL compiles each kernel at its first launch, which
        # would otherwise count in the first point's time.
        render(args.scene, os.path.join(args.out, f"{name}-{method}-warmup.exr"), 1, method, 999, args, extra)
        spp = 1
        while spp <= args.max_spp:
            image = os.path.join(args.out, f"{name}-{method}-{spp}.exr")
            stats = render(args.scene, image, spp, method, spp, args, extra)
            err = compare(image, reference)
            rows.append({"scene": name, "method": method, "spp": spp, "seconds": stats["seconds"],
                         "relMSE": err["relmse"], "RMSE": err["rmse"], "MAE": err["mae"]})
            print(f"{method:4s} {spp:6d} spp {stats['seconds']:8.2f} s  relMSE {err['relmse']:.3e}")
            spp *= 2

    table = os.path.join(args.out, f"{name}.csv")
    with open(table, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)

    fig, ax = plt.subplots(figsize=(6, 4.5))
    for method, color in (("pt", "tab:blue"), ("nee", "tab:orange"), ("mis", "tab:green")):
        pts = [r for r in rows if r["method"] == method]
        if pts:
            ax.loglog([r["seconds"] for r in pts], [r["relMSE"] for r in pts], "o-", color=color, label=method)
    mis = [r for r in rows if r["method"] == "mis"] or rows
    t0, e0 = mis[0]["seconds"], mis[0]["relMSE"]
    ts = [t0, mis[-1]["seconds"]]
    ax.loglog(ts, [e0 * t0 / t for t in ts], "k--", lw=0.8, label="slope -1")
    ax.set_xlabel("render time (s)")
    ax.set_ylabel("relMSE")
    ax.set_title(f"{name}, {args.width}x{args.height}", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    chart = os.path.join(args.out, f"{name}.png")
    fig.savefig(chart, dpi=110)

    # relMSE at equal time: each method's curve read at the longest time all reached.
    target, values = equal_time(rows)
    print(f"relMSE at {target:.2f} s: " + ", ".join(f"{m} {v:.3e}" for m, v in values.items()))
    print(f"wrote {table} and {chart}")


if __name__ == "__main__":
    main()
