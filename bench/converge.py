#!/usr/bin/python3
"""Error against render time for pt, nee, mis, lt, bdpt and vcm (and mis+denoise: mis with --denoise, the
denoised image measured and the denoiser's time added; auto: --method auto, its pilots' time
added): renders a scene at 1, 2, 4, ... spp with
each method, measures each image against a reference (`fredholm compare`: relMSE, RMSE,
MAE), and writes a CSV and a log-log chart of relMSE against seconds, with a slope -1
guide (an unbiased estimator's relMSE falls as 1/time).

usage: bench/converge.py [SCENE.obj] [--out DIR] [--width W] [--height H] [--max-spp N]
                         [--ref REF.exr | --ref-spp N] [--ref-method M] [--methods pt,nee,mis]
                         [--name NAME]
                         [-- RENDER FLAGS]

Without --ref, the reference is a long render of fredholm itself (--ref-spp samples,
default 4096, with --ref-method, default mis; lt where a caustic dominates the error): it cannot reveal a bias fredholm shares with itself, and its own noise is
about relMSE(max-spp run) * max-spp / ref-spp. Needs Debian's python3-matplotlib.
"""
import argparse
import csv
import os
import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import benchlib  # noqa: E402  (beside this script)
from converge_table import equal_time  # noqa: E402


def render(out, spp, method, seed, args, extra):
    """Renders; returns the --stats JSON, and for mis+denoise the denoised image's path and the
    render's seconds with the denoiser's added."""
    denoise = method == "mis+denoise"
    flags = benchlib.image_flags(args) + ["--spp", str(spp), "--method", "mis" if denoise else method,
                                          "--seed", str(seed)] + (["--denoise"] if denoise else []) + extra
    stats = benchlib.render(flags, out, args.binary)
    if method == "auto":  # the pilots run before the render's clock starts
        stats["seconds"] += stats["method_choice"]["seconds"]
    if denoise:
        took = re.search(r"fredholm: denoised in ([0-9.]+) s", stats.stderr)
        stats["seconds"] += float(took.group(1))
        stats["image"] = out[:-len(".exr")] + ".denoised.exr"
    return stats


def crossover(rows, a, b):
    """Where b's relMSE-against-time curve (log-log, piecewise linear) last rises above a's for
    good, after being below it: (seconds, relMSE), or None (b below at the end, or never below)."""
    import math

    def curve(m):
        return sorted((math.log(r["seconds"]), math.log(r["relMSE"])) for r in rows if r["method"] == m)

    def at(points, t):
        for (t0, e0), (t1, e1) in zip(points, points[1:]):
            if t0 <= t <= t1:
                return e0 + (e1 - e0) * (t - t0) / (t1 - t0) if t1 > t0 else e0
        return None

    ca, cb = curve(a), curve(b)
    if len(ca) < 2 or len(cb) < 2:
        return None
    lo, hi = max(ca[0][0], cb[0][0]), min(ca[-1][0], cb[-1][0])
    steps = 400
    previous, last = None, None
    for i in range(steps + 1):
        t = lo + (hi - lo) * i / steps
        ea, eb = at(ca, t), at(cb, t)
        if ea is None or eb is None:
            continue
        below = eb < ea
        if previous is True and not below:
            last = (math.exp(t), math.exp(ea))
        previous = below
    return last if previous is False else None


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    benchlib.add_arguments(p, "scene", "--binary", "--out", "--width", "--height",
                           out=benchlib.scratch_path("converge"))
    p.add_argument("--max-spp", type=int, default=256)
    benchlib.add_arguments(p, "--ref", "--ref-spp", "--methods")
    p.add_argument("--ref-method", default="mis", help="the reference's method (default mis)")
    p.add_argument("--name", help="the CSV's and chart's name (default: the scene's)")
    p.add_argument("--from-csv", help="chart an earlier run's CSV again, rendering nothing")
    args, extra = benchlib.parse_with_rest(p)
    os.makedirs(args.out, exist_ok=True)
    scene_name = os.path.splitext(os.path.basename(args.scene))[0].replace(":", "-") if args.scene else "cornell-box"
    name = args.name or scene_name

    reference = args.ref
    if args.from_csv:
        with open(args.from_csv) as f:
            rows = [{**r, "spp": int(r["spp"]), "seconds": float(r["seconds"]), "relMSE": float(r["relMSE"])}
                    for r in csv.DictReader(f)]
        return chart(rows, name, args)
    if not reference:
        suffix = "" if args.ref_method == "mis" else f"-{args.ref_method}"
        reference = os.path.join(args.out, f"{scene_name}-reference-{args.ref_spp}{suffix}.exr")
        if os.path.exists(reference):  # the same scene, size and spp: made by an earlier chart
            print(f"reference: {reference} (kept)")
        else:
            stats = render(reference, args.ref_spp, args.ref_method, 1000, args, extra)
            print(f"reference: {args.ref_method}, {args.ref_spp} spp, {stats['seconds']:.1f} s -> {reference}")

    rows = []
    for method in args.methods.split(","):
        # A throw-away render first: PoCL compiles each kernel at its first launch, which
        # would otherwise count in the first point's time.
        render(os.path.join(args.out, f"{name}-{method}-warmup.exr"), 1, method, 999, args, extra)
        spp = 1
        while spp <= args.max_spp:
            image = os.path.join(args.out, f"{name}-{method}-{spp}.exr")
            stats = render(image, spp, method, spp, args, extra)
            err = benchlib.compare(stats.get("image", image), reference, args.binary)
            rows.append({"scene": name, "method": method, "spp": spp, "seconds": stats["seconds"],
                         "relMSE": err["relmse"], "RMSE": err["rmse"], "MAE": err["mae"],
                         "chose": stats["method"]})
            print(f"{method:4s} {spp:6d} spp {stats['seconds']:8.2f} s  relMSE {err['relmse']:.3e}")
            spp *= 2

    chart(rows, name, args)


def chart(rows, name, args):
    table = os.path.join(args.out, f"{name}.csv")
    with open(table, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)

    fig, ax = plt.subplots(figsize=(6, 4.5))
    for method, color in (("pt", "tab:blue"), ("nee", "tab:orange"), ("mis", "tab:green"),
                          ("lt", "tab:purple"), ("bdpt", "tab:brown"), ("vcm", "tab:olive"), ("auto", "black"),
                          ("mis+denoise", "tab:red")):
        pts = [r for r in rows if r["method"] == method]
        if pts:
            ax.loglog([r["seconds"] for r in pts], [r["relMSE"] for r in pts], "o-", color=color, label=method)
    mis = [r for r in rows if r["method"] == "mis"] or rows
    t0, e0 = mis[0]["seconds"], mis[0]["relMSE"]
    ts = [t0, mis[-1]["seconds"]]
    ax.loglog(ts, [e0 * t0 / t for t in ts], "k--", lw=0.8, label="slope -1")
    crossing = crossover(rows, "mis", "mis+denoise")
    if crossing:
        ax.axvline(crossing[0], color="tab:red", ls=":", lw=1, label=f"denoising stops paying ({crossing[0]:.1f} s)")
    ax.set_xlabel("render time (s)")
    ax.set_ylabel("relMSE")
    ax.set_title(f"{name}, {args.width}x{args.height}", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    image = os.path.join(args.out, f"{name}.png")
    fig.savefig(image, dpi=110)

    # relMSE at equal time: each method's curve read at the longest time all reached.
    target, values = equal_time(rows)
    print(f"relMSE at {target:.2f} s: " + ", ".join(f"{m} {v:.3e}" for m, v in values.items()))
    if crossing:
        print(f"mis+denoise stops paying at {crossing[0]:.2f} s (relMSE {crossing[1]:.3e}): beyond it the "
              "denoiser's bias exceeds the noise it removes")
    elif any(r["method"] == "mis+denoise" for r in rows):
        print("mis+denoise: no crossover within the chart's times")
    print(f"wrote {table} and {image}")


if __name__ == "__main__":
    benchlib.main(main)
