#!/usr/bin/python3
"""Error against time on the Cornell box at 512x512 (at most 16 bounces, the issue's camera):
fredholm's methods and Mitsuba 3 (llvm_ad_rgb, ldsampler and independent samplers) on the
same axes, each image measured against one long reference with Mitsuba's compare.py
(relMSE with epsilon 1e-2, the reference box-downsampled if larger).

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
import argparse, csv, json, os, statistics, subprocess, sys, tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PEER = os.path.join(ROOT, "..", "shared", "peers", "mitsuba")
CAMERA = ["--eye", "0,1,3.5", "--target", "0,1,0", "--fov", "40", "--max-depth", "16"]


def relmse(python, ref, image):
    out = subprocess.run([python, os.path.join(PEER, "compare.py"), ref, image], check=True, capture_output=True,
                         text=True).stdout
    return json.loads(out.strip().splitlines()[-1])["relMSE"]


def fredholm(method, spp, extra, workdir, seconds=None, seed=None):
    """Renders spp samples per pixel, or as many as fit in `seconds`; returns the image, the
    seconds taken and the samples per pixel rendered."""
    image, stats = os.path.join(workdir, "f.exr"), os.path.join(workdir, "f.json")
    budget = ["--time", str(seconds)] if seconds else []
    subprocess.run([os.path.join(ROOT, "build", "fredholm"), "render", "--width", "512", "--height", "512",
                    "--spp", str(spp), "--method", method, "--seed", str(seed or spp)] + budget + CAMERA + extra +
                   ["-o", image, "--force", "--stats", stats], check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    with open(stats) as f:
        doc = json.load(f)
    return image, doc["seconds"], doc["samples"] // (512 * 512)


def mitsuba(python, sampler, spp, workdir, seed=None):
    image = os.path.join(workdir, "m.exr")
    out = subprocess.run([python, os.path.join(PEER, "cbox.py"), "--variant", "llvm_ad_rgb", "--sampler", sampler,
                          "--spp", str(spp), "--seed", str(seed or spp), "--max-bounces", "16", "--out", image],
                         check=True, capture_output=True, text=True).stdout
    return image, json.loads([l for l in out.splitlines() if l.startswith("{")][-1])["seconds_render"]


def main():
    argv = sys.argv[1:]
    extra = argv[argv.index("--") + 1:] if "--" in argv else []
    argv = argv[:argv.index("--")] if "--" in argv else argv
    ap = argparse.ArgumentParser()
    ap.add_argument("--ref", required=True)
    ap.add_argument("--spp", default="4,16,64,256")
    ap.add_argument("--methods", default="mis,nee,pt")
    ap.add_argument("--mitsuba-python", default="/opt/mi-venv/bin/python")
    ap.add_argument("--out", default=os.path.join(ROOT, "bench", "results", "peers"))
    ap.add_argument("--equal-time-rounds", type=int, default=0)
    opts = ap.parse_args(argv)
    os.makedirs(opts.out, exist_ok=True)
    if opts.equal_time_rounds:
        return equal_time_rounds(opts, extra)
    rows, equal_time = [], []
    with tempfile.TemporaryDirectory() as workdir:
        for method in opts.methods.split(","):
            fredholm(method, 1, extra, workdir)  # PoCL compiles a kernel at its first launch: keep that out
        for spp in [int(s) for s in opts.spp.split(",")]:
            for method in opts.methods.split(","):
                image, seconds, _ = fredholm(method, spp, extra, workdir)
                rows.append(("fredholm " + method, spp, seconds, relmse(opts.mitsuba_python, opts.ref, image)))
                print(*rows[-1], flush=True)
            for sampler in ("ldsampler", "independent"):
                image, seconds = mitsuba(opts.mitsuba_python, sampler, spp, workdir)
                rows.append(("mitsuba " + sampler, spp, seconds, relmse(opts.mitsuba_python, opts.ref, image)))
                print(*rows[-1], flush=True)
        budget = [r for r in rows if r[0] == "mitsuba ldsampler"][-1]
        for method in opts.methods.split(","):
            image, seconds, spp = fredholm(method, 4096, extra, workdir, seconds=budget[2])
            equal_time.append(("fredholm " + method, spp, seconds, relmse(opts.mitsuba_python, opts.ref, image)))
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
            fredholm(method, 1, extra, workdir)  # kernel compilation, kept out of the rounds
        mitsuba(opts.mitsuba_python, "ldsampler", spp, workdir)  # the same for Mitsuba's JIT cache
        budget = None
        for k in range(1, opts.equal_time_rounds + 1):
            seed = 1000 * k + spp

            def peer():
                image, seconds = mitsuba(opts.mitsuba_python, "ldsampler", spp, workdir, seed)
                return ("mitsuba ldsampler", k, spp, seconds, relmse(opts.mitsuba_python, opts.ref, image))

            def ours(budget):
                out = []
                for method in methods:
                    image, seconds, reached = fredholm(method, 4096, extra, workdir, seconds=budget, seed=seed)
                    error = relmse(opts.mitsuba_python, opts.ref, image)
                    out.append(("fredholm " + method, k, reached, seconds, error))
                return out

            # Mitsuba first in odd rounds; fredholm first in even ones, for the seconds
            # Mitsuba took in the round before.
            if k % 2:
                round_rows = [peer()]
                budget = round_rows[0][3]
                round_rows += ours(budget)
            else:
                round_rows = ours(budget)
                round_rows.append(peer())
                budget = round_rows[-1][3]
            rows += round_rows
            for r in round_rows:
                print("round", k, r[0], "spp", r[2], "seconds %.2f" % r[3], "relMSE %.4g" % r[4], flush=True)
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
    main()
