#!/usr/bin/python3
"""Ray-casting speed of two fredholm binaries side by side, alternated in one run: the
`fredholm bench` counterpart of ab_speed.py (this machine drifts by tens of percent between
runs, so only interleaved figures compare).

  bench/ab_rays.py OLD NEW [--rounds 4] [--repeats 3] [-- SCENES...]

Each round runs `bench SCENES --repeats R --json` with OLD then NEW (the order swapped every
other round) and reports, per scene and ray kind, each binary's median Mrays/s and ratio to
Embree over the rounds, and NEW/OLD of the Mrays/s medians. SCENES default to the bench's.
"""
import argparse, os, statistics, sys, tempfile

import benchlib


def bench(binary, scenes, repeats, path):
    doc = benchlib.bench(scenes + ["--repeats", str(repeats)], path, binary)
    return {(r["scene"], r["ray_kind"]): (r["mrays_per_s"], r.get("ratio_to_embree")) for r in doc["records"]}


def main():
    parser = argparse.ArgumentParser(description="ab_rays.py OLD NEW [--rounds N] [--repeats R] [-- SCENES...]")
    parser.add_argument("old")
    parser.add_argument("new")
    benchlib.add_arguments(parser, "--rounds", rounds=4)
    parser.add_argument("--repeats", type=int, default=3)
    opts, scenes = benchlib.parse_with_rest(parser)
    with tempfile.TemporaryDirectory() as workdir:
        runners = {tag: lambda r, tag=tag: bench(getattr(opts, tag), scenes, opts.repeats,
                                                 os.path.join(workdir, tag + ".json")) for tag in ("old", "new")}
        runs = benchlib.alternate(runners, opts.rounds, warmup=False,
                                  after_round=lambda r, _: print(f"round {r + 1} done", file=sys.stderr))
    keys = sorted(set(runs["old"][0]) & set(runs["new"][0]))
    print(f"{'scene':<12} {'kind':<8} {'old Mrays/s':>12} {'new Mrays/s':>12} {'new/old':>8} "
          f"{'old ratio':>10} {'new ratio':>10}")
    for key in keys:
        med = {}
        for tag in ("old", "new"):
            speeds = [run[key][0] for run in runs[tag]]
            ratios = [run[key][1] for run in runs[tag] if run[key][1] is not None]
            med[tag] = (statistics.median(speeds), statistics.median(ratios) if ratios else float("nan"), speeds)
        print(f"{key[0]:<12} {key[1]:<8} {med['old'][0]:>12.2f} {med['new'][0]:>12.2f} "
              f"{med['new'][0] / med['old'][0]:>8.2f} {med['old'][1]:>10.2f} {med['new'][1]:>10.2f}"
              f"   (old {benchlib.runs(med['old'][2], '%.1f')}; new {benchlib.runs(med['new'][2], '%.1f')})")


if __name__ == "__main__":
    benchlib.main(main)
