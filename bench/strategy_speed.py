#!/usr/bin/python3
"""Render speed of fredholm's strategies (and, optionally, an older binary) on several
scenes, alternated in one run (this machine drifts by tens of percent between runs, so
only interleaved figures compare).

  bench/strategy_speed.py [--rounds 3] [--strategies simd8,megakernel8] [--baseline OLD]
                          [--fredholm build/fredholm] [--scenes default] [--current-flags F]
                          -- render flags...

Scenes are the issue 13 set by default (the bunny-in-box, Sponza under a white sky, the
water box and Veach's scene, from ../shared/scenes) or --scenes PATH[,PATH...]. Every
scene is rendered once by each runner as a warm-up (kernel compilation), then --rounds
times with the runners' order rotated each round. Prints samples/s (--stats) per round,
the medians and each runner's median ratio to the first.
"""
import argparse, json, os, statistics, subprocess, sys, tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(ROOT, "..", "shared", "scenes")
DEFAULT_SCENES = [("bunny-box", ["bunny/CornellBox-Bunny.obj"]), ("sponza", ["sponza/sponza.obj", "--env", "1,1,1"]),
                  ("water", ["cornell-box/CornellBox-Water.obj"]), ("veach", ["veach-mis/veach_mis.obj"])]


def render(binary, strategy, scene, flags, workdir):
    stats = os.path.join(workdir, "s.json")
    choice = ["--strategy", strategy] if strategy else []
    subprocess.run([binary, "render", os.path.join(SHARED, scene[0])] + scene[1:] + flags + choice +
                   ["-o", os.path.join(workdir, "f.pfm"), "--force", "--stats", stats],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    with open(stats) as f:
        return json.load(f)["samples_per_second"] / 1e6


def main():
    argv = sys.argv[1:]
    flags = argv[argv.index("--") + 1:] if "--" in argv else []
    argv = argv[:argv.index("--")] if "--" in argv else argv
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--strategies", default="simd8,megakernel8")
    ap.add_argument("--fredholm", default=os.path.join(ROOT, "build", "fredholm"))
    ap.add_argument("--baseline", help="an older fredholm binary (run without --strategy), listed first")
    ap.add_argument("--scenes", help="comma-separated scene paths (default: the issue 13 set)")
    ap.add_argument("--current-flags", default="",
                    help="render flags for the current binary only (e.g. '--rr-depth 3': the baseline's roulette)")
    opts = ap.parse_args(argv)
    runners = [("baseline", opts.baseline, None, [])] if opts.baseline else []
    runners += [(s, opts.fredholm, s, opts.current_flags.split()) for s in opts.strategies.split(",")]
    scenes = [(os.path.basename(p), [os.path.abspath(p)]) for p in opts.scenes.split(",")] if opts.scenes \
        else DEFAULT_SCENES
    with tempfile.TemporaryDirectory() as workdir:
        for name, scene in scenes:
            for _, binary, strategy, own in runners:
                render(binary, strategy, scene, flags + own, workdir)  # warm-up
            results = {r[0]: [] for r in runners}
            for k in range(opts.rounds):
                for label, binary, strategy, own in runners[k % len(runners):] + runners[:k % len(runners)]:
                    results[label].append(render(binary, strategy, scene, flags + own, workdir))
            first = statistics.median(results[runners[0][0]])
            print("%s (%s):" % (name, " ".join(scene + flags)))
            for label, _, _, _ in runners:
                m = statistics.median(results[label])
                print("  %-12s median %.3f Msamples/s  (%s)  %.2fx %s" % (
                    label, m, ", ".join("%.3f" % v for v in results[label]), m / first, runners[0][0]), flush=True)


if __name__ == "__main__":
    main()
