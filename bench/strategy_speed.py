#!/usr/bin/python3
"""Render speed of fredholm's strategies (and, optionally, an older binary) on several
scenes, alternated in one run (this machine drifts by tens of percent between runs, so
only interleaved figures compare).

  bench/strategy_speed.py [--rounds 3] [--strategies simd8,megakernel8] [--baseline OLD]
                          [--fredholm build/fredholm] [--scenes default] [--current-flags F]
                          -- render flags...

Scenes are the CPU-speed set by default (the bunny-in-box, Sponza under a white sky, the
water box and Veach's scene, from the folder $FREDHOLM_SCENES names) or --scenes PATH[,PATH...]. Every
scene is rendered once by each runner as a warm-up (kernel compilation), then --rounds
times with the runners' order rotated each round. Prints samples/s (--stats) per round,
the medians and each runner's median ratio to the first.
"""
import argparse, os, statistics, tempfile

import benchlib

DEFAULT_SCENES = [("bunny-box", ["bunny/CornellBox-Bunny.obj"]), ("sponza", ["sponza/sponza.obj", "--env", "1,1,1"]),
                  ("water", ["cornell-box/CornellBox-Water.obj"]), ("veach", ["veach-mis/veach_mis.obj"])]


def scenes_folder():
    """The folder of the larger scenes (they do not ship): $FREDHOLM_SCENES."""
    folder = os.environ.get("FREDHOLM_SCENES", "")
    if not folder:
        raise benchlib.BenchError("the default scenes need FREDHOLM_SCENES (their folder), or pass --scenes")
    return folder


def render(binary, strategy, scene, flags, workdir):
    choice = ["--strategy", strategy] if strategy else []
    stats = benchlib.render([os.path.join(scenes_folder(), scene[0])] + scene[1:] + flags + choice,
                            os.path.join(workdir, "f.pfm"), binary, stats=os.path.join(workdir, "s.json"))
    return stats["samples_per_second"] / 1e6


def main():
    ap = argparse.ArgumentParser()
    benchlib.add_arguments(ap, "--rounds", rounds=3)
    ap.add_argument("--strategies", default="simd8,megakernel8")
    benchlib.add_arguments(ap, "--binary")
    ap.add_argument("--baseline", help="an older fredholm binary (run without --strategy), listed first")
    ap.add_argument("--scenes", help="comma-separated scene paths (default: the CPU-speed set)")
    ap.add_argument("--current-flags", default="",
                    help="render flags for the current binary only (e.g. '--rr-depth 3': the baseline's roulette)")
    opts, flags = benchlib.parse_with_rest(ap)
    runners = [("baseline", opts.baseline, None, [])] if opts.baseline else []
    runners += [(s, opts.binary, s, opts.current_flags.split()) for s in opts.strategies.split(",")]
    scenes = [(os.path.basename(p), [os.path.abspath(p)]) for p in opts.scenes.split(",")] if opts.scenes \
        else DEFAULT_SCENES
    first = runners[0][0]
    with tempfile.TemporaryDirectory() as workdir:
        def runner(binary, strategy, scene, own):
            return lambda r: render(binary, strategy, scene, flags + own, workdir)

        for name, scene in scenes:
            results = benchlib.alternate({label: runner(binary, strategy, scene, own)
                                          for label, binary, strategy, own in runners}, opts.rounds)
            print("%s (%s):" % (name, " ".join(scene + flags)))
            for label in results:
                print("  " + benchlib.median_line(label, results[label], statistics.median(results[first]), first),
                      flush=True)


if __name__ == "__main__":
    benchlib.main(main)
