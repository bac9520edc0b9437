#!/usr/bin/env python3
"""Gathers what bench/gpu/run_mitsuba.sh measured into OUT/results.json and checks it.

Usage: collect_mitsuba.py OUT VARIANT SIZE SPP SMALL(0|1), OUT being run_mitsuba.sh's
OUTDIR/mitsuba. Per round: Mitsuba's Msamples/s (its timed render, after a warm-up that
compiles its kernels) and, where fredholm ran, fredholm's and their ratio; the medians, and
each renderer's channel means over the rounds (the same scene should agree within noise and
the two BSDF models' small differences). Exits non-zero when no Mitsuba round left a
result. Standard library only.
"""
import json
import os
import statistics
import struct
import sys


def load_json(path):
    """A JSON file, or the last JSON line of a program's output; None if there is none."""
    try:
        with open(path) as f:
            text = f.read()
    except OSError:
        return None
    for candidate in [text] + [line for line in reversed(text.splitlines()) if line.startswith("{")]:
        try:
            return json.loads(candidate)
        except ValueError:
            continue
    return None


def pfm_means(path):
    """Channel means of an RGB PFM (fredholm's output)."""
    try:
        with open(path, "rb") as f:
            kind = f.readline().strip()
            width, height = (int(v) for v in f.readline().split())
            scale = float(f.readline())
            data = f.read()
    except (OSError, ValueError):
        return None
    if kind != b"PF" or len(data) < width * height * 12:
        return None
    values = struct.unpack(("<" if scale < 0 else ">") + "%df" % (width * height * 3), data[:width * height * 12])
    return [sum(values[c::3]) / (width * height) for c in range(3)]


def summary(values):
    return {"median": statistics.median(values), "min": min(values), "max": max(values)} if values else None


def mean_of(vectors):
    return [sum(v[c] for v in vectors) / len(vectors) for c in range(3)] if vectors else None


def main():
    out, variant, size, spp, small = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), sys.argv[5] == "1"
    rounds, r = [], 1
    while os.path.exists(os.path.join(out, "round%d-mitsuba.json" % r)):
        mi = load_json(os.path.join(out, "round%d-mitsuba.json" % r))
        fh = load_json(os.path.join(out, "round%d-fredholm.json" % r))
        row = {"round": r, "mitsuba_msamples_per_s": mi and mi["samples_per_second"] / 1e6,
               "mitsuba_seconds": mi and mi["seconds_render"],
               "mitsuba_jit_compile_seconds_in_render": mi and mi.get("jit_compile_seconds_in_render"),
               "mitsuba_mean_rgb": mi and mi.get("mean_rgb")}
        if fh:
            row.update(fredholm_msamples_per_s=fh["samples_per_second"] / 1e6,
                       fredholm_steady_msamples_per_s=fh.get("steady_samples_per_second", 0) / 1e6,
                       fredholm_seconds=fh["seconds"],
                       fredholm_mean_rgb=pfm_means(os.path.join(out, "fredholm-%d.pfm" % r)))
            if mi:
                row["fredholm_over_mitsuba"] = row["fredholm_msamples_per_s"] / row["mitsuba_msamples_per_s"]
        rounds.append(row)
        r += 1

    def column(key):
        return [row[key] for row in rounds if row.get(key) is not None]

    first_mi = next((load_json(os.path.join(out, "round%d-mitsuba.json" % row["round"])) for row in rounds
                     if row["mitsuba_msamples_per_s"]), None)
    first_fh = next((load_json(os.path.join(out, "round%d-fredholm.json" % row["round"])) for row in rounds
                     if row.get("fredholm_msamples_per_s")), None)
    results = {
        "small": small, "variant": variant, "width": size, "height": size, "spp": spp,
        "settings": "Cornell box (CornellBox-Original and its camera); Mitsuba path max_depth 17 rr_depth 5, "
                    "fredholm mis --max-depth 16 --rr-depth 6",
        "mitsuba": first_mi and {k: first_mi.get(k) for k in ("mitsuba", "drjit", "variant", "sampler", "threads",
                                                              "materials", "triangles")},
        "fredholm_device": first_fh and first_fh["devices"][0]["name"],
        "rounds": rounds,
        "mitsuba_msamples_per_s": summary(column("mitsuba_msamples_per_s")),
        "fredholm_msamples_per_s": summary(column("fredholm_msamples_per_s")),
        "fredholm_over_mitsuba": summary(column("fredholm_over_mitsuba")),
        "mitsuba_mean_rgb": mean_of(column("mitsuba_mean_rgb")),
        "fredholm_mean_rgb": mean_of(column("fredholm_mean_rgb")),
    }
    if results["mitsuba_mean_rgb"] and results["fredholm_mean_rgb"]:
        results["channel_mean_differences"] = [m / f - 1.0 if f else None for m, f in
                                               zip(results["mitsuba_mean_rgb"], results["fredholm_mean_rgb"])]
    results["missing"] = [] if column("mitsuba_msamples_per_s") else ["Mitsuba renders"]
    with open(os.path.join(out, "results.json"), "w") as f:
        json.dump(results, f, indent=2)
    print(json.dumps({k: results.get(k) for k in ("variant", "mitsuba_msamples_per_s", "fredholm_msamples_per_s",
                                                  "fredholm_over_mitsuba", "channel_mean_differences", "missing")},
                     indent=2))
    return 1 if results["missing"] else 0


if __name__ == "__main__":
    sys.exit(main())
