#!/usr/bin/env python3
"""Gathers what bench/gpu/run_gpu.sh measured into OUTDIR/results.json and checks it.

Usage: collect_results.py OUTDIR SMALL(0|1). Exits non-zero when a step that must work
(devices, the Cornell renders and their comparison, bench, the sweep) left no result.
"""
import json
import os
import sys


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def text(path):
    try:
        with open(path) as f:
            return f.read()
    except OSError:
        return None


def rate(stats, key):
    return stats.get(key) if stats else None


def main():
    out, small = sys.argv[1], sys.argv[2] == "1"
    p = lambda name: os.path.join(out, name)
    results = {"small": small, "machine": text(p("probe.txt")), "devices": text(p("devices.txt"))}
    missing = []

    gpu = load(p("gpu-stats.json"))
    seeds = load(p("compare-gpu-seeds.json"))
    cpu = load(p("cpu-stats.json"))
    versus_cpu = load(p("compare-gpu-cpu.json"))
    cornell = {
        "device": gpu["devices"][0]["name"] if gpu else None,
        "msamples_per_s": rate(gpu, "samples_per_second") and gpu["samples_per_second"] / 1e6,
        "mrays_per_s": rate(gpu, "rays_per_second") and gpu["rays_per_second"] / 1e6,
        "seconds": rate(gpu, "seconds"),
        "kernels": gpu.get("kernels") if gpu else None,
        "relmse_between_gpu_seeds": seeds and seeds["relmse"],
    }
    if versus_cpu and seeds:
        ratios = [a / b - 1.0 for a, b in zip(versus_cpu["mean_image"], versus_cpu["mean_reference"])]
        cornell["cpu"] = {
            "device": cpu["devices"][0]["name"] if cpu else None,
            "msamples_per_s": cpu and cpu["samples_per_second"] / 1e6,
            "channel_mean_differences": ratios,
            "means_within_0.1_percent": all(abs(r) < 1e-3 for r in ratios),
            "relmse_gpu_vs_cpu": versus_cpu["relmse"],
            # Two independent renders of equal spp differ by twice one render's variance,
            # whichever device made them: the ratio is about 1 when the estimators agree.
            "relmse_ratio_to_two_gpu_seeds": versus_cpu["relmse"] / seeds["relmse"] if seeds["relmse"] else None,
        }
    elif not small:
        cornell["cpu"] = "no CPU device and no CPU reference image"
    if not gpu or not seeds:
        missing.append("Cornell renders")
    results["cornell_mis"] = cornell

    bench = load(p("bench.json"))
    results["bench"] = bench
    if not bench:
        missing.append("bench")
    else:
        bounce = [r for r in bench.get("records", []) if r["scene"] == "bunny-box" and r["ray_kind"] == "bounce"]
        if bounce:
            results["bunny_box_bounce_grays_per_s"] = bounce[0]["mrays_per_s"] / 1e3

    sweep = []
    for name in sorted(os.listdir(out)):
        if name.startswith("sweep-") and name.endswith(".json"):
            s = load(p(name))
            if s:
                sweep.append({"wavefront": s["wavefront"], "msamples_per_s": s["samples_per_second"] / 1e6,
                              "mrays_per_s": s["rays_per_second"] / 1e6, "queue_occupancy": s["queue_occupancy"]})
    sweep.sort(key=lambda r: r["wavefront"])
    results["wavefront_sweep"] = sweep
    if sweep:
        results["best_wavefront"] = max(sweep, key=lambda r: r["msamples_per_s"])["wavefront"]
    else:
        missing.append("wavefront sweep")

    big = load(p("bunnies-1m.json"))
    if big:
        results["bunnies_1m"] = {"msamples_per_s": big["samples_per_second"] / 1e6,
                                 "mrays_per_s": big["rays_per_second"] / 1e6, "seconds": big["seconds"]}

    results["goals"] = {
        "bunny_box_bounce_at_least_1_grays_per_s": results.get("bunny_box_bounce_grays_per_s", 0) >= 1.0,
        "cornell_512_mis_at_least_100_msamples_per_s": (cornell["msamples_per_s"] or 0) >= 100.0,
    }
    results["missing"] = missing
    with open(p("results.json"), "w") as f:
        json.dump(results, f, indent=2)
    print(json.dumps({k: results[k] for k in ("cornell_mis", "best_wavefront", "goals", "missing") if k in results},
                     indent=2))
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
