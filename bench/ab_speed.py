#!/usr/bin/python3
"""Render speed of two fredholm binaries side by side, alternated in one run (this machine
drifts by tens of percent between runs, so only interleaved figures compare).

  bench/ab_speed.py OLD NEW [--rounds 5] -- render ARGS...

Each round renders ARGS with OLD then NEW (the order swapped every other round), reads
samples/s from --stats, and the table reports each binary's median and the ratio NEW/OLD.
The first render of each binary is a warm-up (kernel compilation) and is not counted.
"""
import argparse, json, os, statistics, subprocess, sys, tempfile


def render(binary, args, workdir, tag):
    out, stats = os.path.join(workdir, tag + ".pfm"), os.path.join(workdir, tag + ".json")
    for path in (out, stats):
        if os.path.exists(path):
            os.remove(path)
    subprocess.run([binary] + args + ["-o", out, "--stats", stats], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    with open(stats) as f:
        return json.load(f)["samples_per_second"]


def main():
    argv = sys.argv[1:]
    if "--" not in argv:
        sys.exit("usage: ab_speed.py OLD NEW [--rounds N] -- render ARGS...")
    split = argv.index("--")
    parser = argparse.ArgumentParser()
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("--rounds", type=int, default=5)
    opts = parser.parse_args(argv[:split])
    args = argv[split + 1:]
    speeds = {"old": [], "new": []}
    binaries = {"old": opts.old, "new": opts.new}
    with tempfile.TemporaryDirectory() as workdir:
        for tag in ("old", "new"):
            render(binaries[tag], args, workdir, tag)  # warm-up
        for r in range(opts.rounds):
            for tag in (("old", "new") if r % 2 == 0 else ("new", "old")):
                speeds[tag].append(render(binaries[tag], args, workdir, tag))
    old, new = statistics.median(speeds["old"]), statistics.median(speeds["new"])
    print("render " + " ".join(args))
    for tag in ("old", "new"):
        runs = ", ".join("%.3f" % (s / 1e6) for s in speeds[tag])
        print("  %-3s median %.3f Msamples/s  (runs: %s)" % (tag, statistics.median(speeds[tag]) / 1e6, runs))
    print("  new/old %.3f" % (new / old))


if __name__ == "__main__":
    main()
