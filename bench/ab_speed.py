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
import argparse, json, os, statistics, subprocess, sys, tempfile, time


def render(binary, args, workdir, tag, extra=()):
    out, stats = os.path.join(workdir, tag + ".pfm"), os.path.join(workdir, tag + ".json")
    for path in (out, stats):
        if os.path.exists(path):
            os.remove(path)
    start = time.monotonic()
    subprocess.run([binary] + args + list(extra) + ["-o", out, "--stats", stats], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.monotonic() - start
    with open(stats) as f:
        doc = json.load(f)
    return doc["samples_per_second"], doc["samples"] / wall


def main():
    argv = sys.argv[1:]
    if "--" not in argv:
        sys.exit("usage: ab_speed.py OLD NEW [--rounds N] -- render ARGS...")
    split = argv.index("--")
    parser = argparse.ArgumentParser()
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--old-args", default="")
    parser.add_argument("--new-args", default="")
    opts = parser.parse_args(argv[:split])
    extras = {"old": opts.old_args.split(), "new": opts.new_args.split()}
    args = argv[split + 1:]
    speeds = {"old": [], "new": []}  # (stats samples/s, samples per process second)
    binaries = {"old": opts.old, "new": opts.new}
    with tempfile.TemporaryDirectory() as workdir:
        for tag in ("old", "new"):
            render(binaries[tag], args, workdir, tag, extras[tag])  # warm-up
        for r in range(opts.rounds):
            for tag in (("old", "new") if r % 2 == 0 else ("new", "old")):
                speeds[tag].append(render(binaries[tag], args, workdir, tag, extras[tag]))
    print("fredholm " + " ".join(args) + "".join(f"  [{t}: {' '.join(e)}]" for t, e in extras.items() if e))
    medians = {}
    for tag in ("old", "new"):
        rate = [s for s, _ in speeds[tag]]
        whole = [w for _, w in speeds[tag]]
        medians[tag] = (statistics.median(rate), statistics.median(whole))
        runs = ", ".join("%.3f" % (s / 1e6) for s in rate)
        print("  %-3s median %.3f Msamples/s rendering, %.3f per process second  (runs: %s)"
              % (tag, medians[tag][0] / 1e6, medians[tag][1] / 1e6, runs))
    print("  new/old %.3f rendering, %.3f per process second"
          % (medians["new"][0] / medians["old"][0], medians["new"][1] / medians["old"][1]))
    # The machine drifts within a run too: the two renders of one round ran close together.
    per_round = [n[0] / o[0] for o, n in zip(speeds["old"], speeds["new"])]
    print("  new/old per round: median %.3f  (%s)" % (statistics.median(per_round),
                                                      ", ".join("%.2f" % r for r in per_round)))

if __name__ == "__main__":
    main()
