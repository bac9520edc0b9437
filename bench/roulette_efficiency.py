#!/usr/bin/python3
"""Where Russian roulette should start: the Cornell box at 512x512 (at most 16 bounces, the
issue's camera, peer_error.py's settings) rendered at a fixed sample count with roulette from
each bounce given, each image measured against one long reference (`fredholm compare`:
relMSE per channel with epsilon 1e-2). An unbiased estimator's relMSE falls as 1/time, so relMSE x
seconds is its cost at equal error: the lower, the better the start.

  bench/roulette_efficiency.py --ref REF.exr [--depths 4,5,6,7,8] [--spp 256] [--rounds 2]
                               [--method mis] [-- EXTRA fredholm render flags]

The depths alternate within each round (their order reversed every other round); a round
uses one seed for every depth, a new one per round. Prints each render and, per depth, the
medians. The renders are deterministic for a seed, so only the seconds vary between rounds
of one seed; the seeds vary the relMSE.
"""
import argparse, statistics, tempfile

import benchlib
import peer_error


def main():
    ap = argparse.ArgumentParser()
    benchlib.add_arguments(ap, "--ref", ref=dict(required=True, help="long reference render of the same view (EXR)"))
    ap.add_argument("--depths", default="4,5,6,7,8", help="roulette starts to compare (--rr-depth values)")
    benchlib.add_arguments(ap, "--spp", "--rounds", "--method", "--binary",
                           spp=256, rounds=2)
    opts, extra = benchlib.parse_with_rest(ap)
    depths = [int(d) for d in opts.depths.split(",")]

    def depth(d):  # renders with roulette from bounce d; (relMSE, seconds)
        def render(r):
            seed = 1000 + r
            image, seconds, _ = peer_error.fredholm(opts, opts.method, opts.spp, ["--rr-depth", str(d)] + extra,
                                                    workdir, seed=seed)
            error = peer_error.relmse(opts, image)
            print(f"round {r + 1} rr-depth {d} seed {seed} seconds {seconds:.2f} relMSE {error:.4g} "
                  f"relMSE*s {error * seconds:.4g}", flush=True)
            return error, seconds
        return render

    with tempfile.TemporaryDirectory() as workdir:
        peer_error.fredholm(opts, opts.method, 1, extra, workdir)  # fills PoCL's kernel cache
        results = benchlib.alternate({d: depth(d) for d in depths}, opts.rounds, warmup=False, order="reverse")
    print("\n| roulette from bounce | relMSE (median) | seconds (median) | relMSE × seconds (median) |")
    print("|---|---|---|---|")
    for d in depths:
        errors, seconds = [e for e, _ in results[d]], [s for _, s in results[d]]
        product = statistics.median(e * s for e, s in results[d])
        print(f"| {d} | {statistics.median(errors):.3e} | {statistics.median(seconds):.2f} | {product:.3e} |")


if __name__ == "__main__":
    benchlib.main(main)
