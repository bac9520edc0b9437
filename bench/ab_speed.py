#!/usr/bin/python3
"""Render speed of two fredholm binaries side by side, alternated in one run (this machine
drifts by tens of percent between runs, so only interleaved figures compare).

  bench/ab_speed.py OLD NEW [--rounds 5] [--old-args "..."] [--new-args "..."] -- render ARGS...

OLD and NEW may be the same binary with different flags: --old-args and --new-args are added
to each one's command (e.g. --new-args "--display-server 127.0.0.1:14158" with
bench/tev_sink.py listening: a render with a live viewer attached against one without).

Each round renders ARGS with OLD then NEW (the order swapped every other round), reads
samples/s from --stats and times the whole process (start-up, scene, BVH and kernel set-up
included, which --stats may leave out), and reports each binary's medians and NEW/OLD.
The first render of each binary is a warm-up (kernel compilation) and is not counted.
"""
import argparse, os, statistics, sys, tempfile

import benchlib


def render(binary, args, workdir, tag, extra=()):
    """(samples/s from --stats, samples per second of the whole process)."""
    stats = benchlib.render(args[1:] + list(extra), os.path.join(workdir, tag + ".pfm"), binary)
    return stats["samples_per_second"], stats["samples"] / stats.wall_seconds


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("old")
    parser.add_argument("new")
    benchlib.add_arguments(parser, "--rounds", rounds=5)
    parser.add_argument("--old-args", default="")
    parser.add_argument("--new-args", default="")
    opts, args = benchlib.parse_with_rest(parser)
    if "--" not in sys.argv[1:] or args[:1] != ["render"]:
        sys.exit("usage: ab_speed.py OLD NEW [--rounds N] -- render ARGS...")
    extras = {"old": opts.old_args.split(), "new": opts.new_args.split()}
    binaries = {"old": opts.old, "new": opts.new}
    with tempfile.TemporaryDirectory() as workdir:  # each result: (stats samples/s, samples per process second)
        speeds = benchlib.alternate({tag: lambda r, tag=tag: render(binaries[tag], args, workdir, tag, extras[tag])
                                     for tag in ("old", "new")}, opts.rounds)
    print("fredholm " + " ".join(args) + "".join(f"  [{t}: {' '.join(e)}]" for t, e in extras.items() if e))
    medians = {}
    for tag in ("old", "new"):
        rate = [s for s, _ in speeds[tag]]
        whole = [w for _, w in speeds[tag]]
        medians[tag] = (statistics.median(rate), statistics.median(whole))
        print("  %-3s median %.3f Msamples/s rendering, %.3f per process second  (runs: %s)"
              % (tag, medians[tag][0] / 1e6, medians[tag][1] / 1e6, benchlib.runs([s / 1e6 for s in rate])))
    print("  new/old %.3f rendering, %.3f per process second"
          % (medians["new"][0] / medians["old"][0], medians["new"][1] / medians["old"][1]))
    # The machine drifts within a run too: the two renders of one round ran close together.
    per_round = benchlib.ratios([n for n, _ in speeds["new"]], [o for o, _ in speeds["old"]])
    print("  new/old per round: median %.3f  (%s)" % (statistics.median(per_round), benchlib.runs(per_round, "%.2f")))


if __name__ == "__main__":
    benchlib.main(main)
