#!/usr/bin/python3
"""fredholm against Mitsuba 3 on the Cornell box, alternated in one run (this machine
drifts by tens of percent between runs, so only interleaved figures compare).

  bench/peer_speed.py [--rounds 3] [--spp 64] [--mitsuba-python /opt/mi-venv/bin/python]
                      [--strategies megakernel8,simd8] [--rr-depths 6] [--fredholm build/fredholm]
                      [--baseline OLD] [--scene OBJ]

Each round renders the Cornell box at 512x512 with at most 16 bounces (the camera of the
issue: eye 0,1,3.5, target 0,1,0, fov 40; or --scene OBJ with its camera sidecar) with
fredholm `mis` under each strategy and with Mitsuba's llvm_ad_rgb variant (bench/peers/mitsuba_render.py), the order rotated every
round (and, with --baseline, an older fredholm binary without --strategy), and prints each
renderer's Msamples/s per round and median, then each fredholm kernel's median time per
sample (--stats "kernels"). The first render of each is a warm-up (kernel compilation,
Mitsuba's JIT) and is not counted.
"""
import argparse, os, statistics, tempfile

import benchlib


def views(scene):
    """(fredholm's, Mitsuba's) flags for the scene: the peer view of the Cornell box, or an
    OBJ's own camera sidecar, at 512x512 and at most 16 bounces."""
    if not scene:
        return benchlib.PEER_VIEW, benchlib.MITSUBA_PEER_VIEW
    size = ["--width", "512", "--height", "512"]
    return [scene] + size + ["--max-depth", "16"], [scene] + size + ["--max-bounces", "16"]


def fredholm(binary, strategy, spp, workdir, rr_depth=None, scene=""):
    """Renders; returns the --stats JSON."""
    choice = (["--strategy", strategy] if strategy else []) + (["--rr-depth", str(rr_depth)] if rr_depth else [])
    return benchlib.render(["--spp", str(spp), "--method", "mis"] + views(scene)[0] + choice,
                           os.path.join(workdir, "f.pfm"), binary, stats=os.path.join(workdir, "s.json"))


def mitsuba(opts, workdir):
    """Renders with Mitsuba; returns its JSON line (samples_per_second...)."""
    return benchlib.mitsuba(opts.mitsuba_python, ["--variant", "llvm_ad_rgb", "--spp", str(opts.spp), "--threads", "2",
                                                  "--out", os.path.join(workdir, "mi.exr")] + views(opts.scene)[1])


def main():
    ap = argparse.ArgumentParser()
    benchlib.add_arguments(ap, "--rounds", "--spp", "--mitsuba-python", rounds=3, spp=64)
    ap.add_argument("--strategies", default="megakernel8,simd8")
    benchlib.add_arguments(ap, "--binary", "--scene")
    ap.add_argument("--baseline", help="an older fredholm binary (run without --strategy)")
    ap.add_argument("--rr-depths", default="6",
                    help="fredholm's roulette starts to run (6 is Mitsuba's rr_depth 5: the same work per sample)")
    opts = ap.parse_args()
    with tempfile.TemporaryDirectory() as workdir:
        def current(strategy, rr_depth):
            return lambda r: fredholm(opts.binary, strategy, opts.spp, workdir, rr_depth, opts.scene)

        runners = {"fredholm mis %s rr%s" % (s, rr): current(s, rr)
                   for rr in opts.rr_depths.split(",") for s in opts.strategies.split(",")}
        if opts.baseline:
            runners["fredholm mis baseline"] = lambda r: fredholm(opts.baseline, None, opts.spp, workdir, scene=opts.scene)
        runners["mitsuba llvm_ad_rgb"] = lambda r: mitsuba(opts, workdir)
        names = list(runners)

        def rate(doc):
            return doc["samples_per_second"] / 1e6

        def progress(r, docs):
            print("round %d: " % (r + 1) + ", ".join("%s %.3f" % (n, rate(docs[n][-1])) for n in names), flush=True)

        docs = benchlib.alternate(runners, opts.rounds, after_round=progress)
    results = {n: [rate(doc) for doc in docs[n]] for n in names}
    base = statistics.median(results["mitsuba llvm_ad_rgb"])
    for n in names:
        print(benchlib.median_line(n, results[n], base, "Mitsuba", width=28))
    for n in names:  # fredholm's: each kernel's time per sample
        kernels = {}
        for doc in docs[n]:
            for kernel, k in doc.get("kernels", {}).items():
                kernels.setdefault(kernel, []).append(k["seconds"] / doc["samples"] * 1e9)
        if kernels:
            by_cost = sorted(kernels.items(), key=lambda kv: -max(kv[1]))
            print("%-28s ns/sample: %s" % (n, ", ".join("%s %.0f" % (k, statistics.median(v)) for k, v in by_cost)))


if __name__ == "__main__":
    benchlib.main(main)
