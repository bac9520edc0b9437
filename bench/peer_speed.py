#!/usr/bin/python3
"""fredholm against Mitsuba 3 on the Cornell box, alternated in one run (this machine
drifts by tens of percent between runs, so only interleaved figures compare).

  bench/peer_speed.py [--rounds 3] [--spp 64] [--mitsuba-python /opt/mi-venv/bin/python]
                      [--strategies megakernel8,simd8] [--rr-depths 6] [--fredholm build/fredholm]
                      [--baseline OLD]

Each round renders the Cornell box at 512x512 with at most 16 bounces (the camera of the
issue: eye 0,1,3.5, target 0,1,0, fov 40) with fredholm `mis` under each strategy and with
Mitsuba's llvm_ad_rgb variant (../shared/peers/mitsuba/cbox.py), the order rotated every
round (and, with --baseline, an older fredholm binary without --strategy), and prints each
renderer's Msamples/s per round and median, then each fredholm kernel's median time per
sample (--stats "kernels"). The first render of each is a warm-up (kernel compilation,
Mitsuba's JIT) and is not counted.
"""
import argparse, json, os, statistics, subprocess, tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


KERNEL_NS = {}  # runner name -> kernel -> [ns per sample, one per round]


def fredholm(binary, strategy, spp, workdir, name=None, rr_depth=None):
    stats = os.path.join(workdir, "s.json")
    choice = (["--strategy", strategy] if strategy else []) + (["--rr-depth", str(rr_depth)] if rr_depth else [])
    subprocess.run([binary, "render", "--width", "512", "--height", "512", "--spp", str(spp), "--method", "mis",
                    "--eye", "0,1,3.5", "--target", "0,1,0", "--fov", "40", "--max-depth", "16",
                    ] + choice + ["-o", os.path.join(workdir, "f.pfm"), "--force", "--stats", stats],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    with open(stats) as f:
        st = json.load(f)
    if name:
        for kernel, k in st.get("kernels", {}).items():
            KERNEL_NS.setdefault(name, {}).setdefault(kernel, []).append(k["seconds"] / st["samples"] * 1e9)
    return st["samples_per_second"] / 1e6


def mitsuba(python, spp, workdir):
    script = os.path.join(ROOT, "..", "shared", "peers", "mitsuba", "cbox.py")
    out = subprocess.run([python, script, "--variant", "llvm_ad_rgb", "--spp", str(spp), "--max-bounces", "16",
                          "--threads", "2", "--out", os.path.join(workdir, "mi.exr")],
                         check=True, capture_output=True, text=True).stdout
    line = [l for l in out.splitlines() if l.startswith("{")][-1]
    return json.loads(line)["samples_per_second"] / 1e6


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--mitsuba-python", default="/opt/mi-venv/bin/python")
    ap.add_argument("--strategies", default="megakernel8,simd8")
    ap.add_argument("--fredholm", default=os.path.join(ROOT, "build", "fredholm"))
    ap.add_argument("--baseline", help="an older fredholm binary (run without --strategy)")
    ap.add_argument("--rr-depths", default="6",
                    help="fredholm's roulette starts to run (6 is Mitsuba's rr_depth 5: the same work per sample)")
    opts = ap.parse_args()
    runners = {"fredholm mis %s rr%s" % (s, rr): (lambda s=s, rr=rr, w=None, n=None:
                                                    fredholm(opts.fredholm, s, opts.spp, w, n, rr))
               for rr in opts.rr_depths.split(",") for s in opts.strategies.split(",")}
    if opts.baseline:
        runners["fredholm mis baseline"] = lambda w=None, n=None: fredholm(opts.baseline, None, opts.spp, w, n)
    runners["mitsuba llvm_ad_rgb"] = lambda w=None, n=None: mitsuba(opts.mitsuba_python, opts.spp, w)
    names = list(runners)
    results = {n: [] for n in names}
    with tempfile.TemporaryDirectory() as workdir:
        for n in names:
            runners[n](w=workdir)  # warm-up
        for r in range(opts.rounds):
            order = names[r % len(names):] + names[:r % len(names)]
            for n in order:
                results[n].append(runners[n](w=workdir, n=n))
            print("round %d: " % (r + 1) + ", ".join("%s %.3f" % (n, results[n][-1]) for n in names), flush=True)
    base = statistics.median(results["mitsuba llvm_ad_rgb"])
    for n in names:
        m = statistics.median(results[n])
        print("%-28s median %.3f Msamples/s  (%s)  %.2fx Mitsuba" % (n, m, ", ".join("%.3f" % v for v in results[n]),
                                                                      m / base))
    for n, kernels in KERNEL_NS.items():
        print("%-28s ns/sample: %s" % (n, ", ".join("%s %.0f" % (k, statistics.median(v))
                                                       for k, v in sorted(kernels.items(), key=lambda kv: -max(kv[1])))))


if __name__ == "__main__":
    main()
