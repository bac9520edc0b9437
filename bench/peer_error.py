#!/usr/bin/python3
"""Error against time on the Cornell box at 512x512 (at most 16 bounces, the issue's camera):
fredholm's methods and Mitsuba 3 (llvm_ad_rgb, ldsampler and independent samplers) on the
same axes, each image measured against one long reference of the same size by `fredholm
compare` (relMSE per channel, epsilon 1e-2).

  bench/peer_error.py --ref REF.exr [--spp 4,16,64,256] [--methods mis,nee,pt]
                      [--mitsuba-python /opt/mi-venv/bin/python] [--out bench/results/peers]
                      [-- EXTRA fredholm render flags]

Then, at equal time, each fredholm method renders with --time set to the seconds Mitsuba
ldsampler took for the largest spp (the issue's target: fredholm's relMSE there <= Mitsuba's).

  bench/peer_error.py --ref REF.exr --equal-time-rounds N [--spp 256] [--methods mis]

measures only the equal-time point, N times: each round renders Mitsuba ldsampler at the
largest spp, then each fredholm method for the seconds that render took (the order
swapped every other round, new seeds each round), and prints every round and the medians.

Renders run one after another (never two at once): fredholm's seconds are --stats
`seconds` (devices ready to last pass merged, after a warm-up render per method has filled
PoCL's kernel cache), Mitsuba's `seconds_render` (after its JIT
warm-up). Writes OUT/cornell-peers.csv and OUT/cornell-peers.png (log-log, with a slope -1
guide: an unbiased estimator's relMSE falls as 1/time).
"""
import argparse, csv, os, statistics, tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import benchlib  # noqa: E402  (beside this script)


def relmse(opts, image):
    """relMSE of image against opts.ref."""
    return benchlib.compare(image, opts.ref, opts.binary)["relmse"]


def fredholm(opts, method, spp, extra, workdir, seconds=None, seed=None):
    """Renders spp samples per pixel, or as many as fit in `seconds`; returns the image, the
    seconds taken and the samples per pixel rendered."""
    image = os.path.join(workdir, "f.exr")
    budget = ["--time", str(seconds)] if seconds else []
    stats = benchlib.render(["--spp", str(spp), "--method", method, "--seed", str(seed or spp)] + budget +
                            benchlib.PEER_VIEW + extra, image, opts.binary, stats=os.path.join(workdir, "f.json"))
    return image, stats["seconds"], stats["samples"] // benchlib.PEER_PIXELS


def mitsuba(opts, sampler, spp, workdir, seed=None):
    image = os.path.join(workdir, "m.exr")
    doc = benchlib.mitsuba(opts.mitsuba_python, ["--variant", "llvm_ad_rgb", "--sampler", sampler, "--spp", str(spp),
                                                 "--seed", str(seed or spp), "--out", image] + benchlib.MITSUBA_PEER_VIEW)
    return image, doc["seconds_render"]


def main():
    ap = argparse.ArgumentParser()
    benchlib.add_arguments(ap, "--ref", ref=dict(required=True))
    ap.add_argument("--spp", default="4,16,64,256")
    benchlib.add_arguments(ap, "--methods", "--mitsuba-python", "--out", "--binary",
                           methods="mis,nee,pt", out=benchlib.results_path("peers"))
    ap.add_argument("--equal-time-rounds", type=int, default=0)
    opts, extra = benchlib.parse_with_rest(ap)
    os.makedirs(opts.out, exist_ok=True)
    if opts.equal_time_rounds:
        return equal_time_rounds(opts, extra)
    rows, equal_time = [], []
    with tempfile.TemporaryDirectory() as workdir:
        for method in opts.methods.split(","):
            fredholm(opts, method, 1, extra, workdir)  # PoCL compiles a kernel at its first launch: keep that out
        for spp in [int(s) for s in opts.spp.split(",")]:
            for method in opts.methods.split(","):
                image, seconds, _ = fredholm(opts, method, spp, extra, workdir)
                rows.append(("fredholm " + method, spp, seconds, relmse(opts, image)))
                print(*rows[-1], flush=True)
            for sampler in ("ldsampler", "independent"):
                image, seconds = mitsuba(opts, sampler, spp, workdir)
                rows.append(("mitsuba " + sampler, spp, seconds, relmse(opts, image)))
                print(*rows[-1], flush=True)
        budget = [r for r in rows if r[0] == "mitsuba ldsampler"][-1]
        for method in opts.methods.split(","):
            image, seconds, spp = fredholm(opts, method, 4096, extra, workdir, seconds=budget[2])
            equal_time.append(("fredholm " + method, spp, seconds, relmse(opts, image)))
            print("equal time:", *equal_time[-1], "against mitsuba ldsampler", *budget[1:], flush=True)
    with open(os.path.join(opts.out, "cornell-peers.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["renderer", "spp", "seconds", "relmse"])
        w.writerows(rows)
    with open(os.path.join(opts.out, "cornell-equal-time.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["renderer", "spp", "seconds", "relmse"])
        w.writerows([budget] + equal_time)
    plt.figure(figsize=(6.4, 4.8))
    for name in dict.fromkeys(r[0] for r in rows):
        pts = [(r[2], r[3]) for r in rows if r[0] == name]
        plt.loglog([p[0] for p in pts], [p[1] for p in pts], "o-" if name.startswith("fredholm") else "s--",
                   label=name)
    t0, e0 = rows[0][2], rows[0][3]
    plt.loglog([t0, t0 * 100], [e0, e0 / 100], ":", color="gray", label="slope -1")
    plt.xlabel("seconds")
    plt.ylabel("relMSE against the reference")
    plt.title("Cornell box 512x512, at most 16 bounces")
    plt.legend(fontsize=8)
    plt.grid(True, which="both", alpha=0.3)
    plt.savefig(os.path.join(opts.out, "cornell-peers.png"), dpi=100, bbox_inches="tight")


def equal_time_rounds(opts, extra):
    spp, methods = max(int(s) for s in opts.spp.split(",")), opts.methods.split(",")
    rows = []
    with tempfile.TemporaryDirectory() as workdir:
        for method in methods:
            fredholm(opts, method, 1, extra, workdir)  # kernel compilation, kept out of the rounds
        mitsuba(opts, "ldsampler", spp, workdir)  # the same for Mitsuba's JIT cache
        state = {"budget": None}  # the seconds Mitsuba took in the latest round

        def report(row):  # (renderer, round, spp, seconds, relMSE)
            rows.append(row)
            print("round", row[1], row[0], "spp", row[2], "seconds %.2f" % row[3], "relMSE %.4g" % row[4], flush=True)

        def peer(r):
            image, seconds = mitsuba(opts, "ldsampler", spp, workdir, 1000 * (r + 1) + spp)
            state["budget"] = seconds
            report(("mitsuba ldsampler", r + 1, spp, seconds, relmse(opts, image)))

        def ours(r):
            for method in methods:
                image, seconds, reached = fredholm(opts, method, 4096, extra, workdir, seconds=state["budget"],
                                                   seed=1000 * (r + 1) + spp)
                report(("fredholm " + method, r + 1, reached, seconds, relmse(opts, image)))

        # Mitsuba first in odd rounds; fredholm first in even ones, for the seconds Mitsuba
        # took in the round before.
        benchlib.alternate({"mitsuba": peer, "fredholm": ours}, opts.equal_time_rounds, warmup=False)
    names = list(dict.fromkeys(r[0] for r in rows))
    for name in names:
        mine = [r for r in rows if r[0] == name]
        print("median", name, "relMSE %.4g" % statistics.median(r[4] for r in mine),
              "spp %g" % statistics.median(r[2] for r in mine), "seconds %.2f" % statistics.median(r[3] for r in mine))
    with open(os.path.join(opts.out, "cornell-equal-time-rounds.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["renderer", "round", "spp", "seconds", "relmse"])
        w.writerows(rows)


if __name__ == "__main__":
    benchlib.main(main)
