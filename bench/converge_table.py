#!/usr/bin/python3
"""The "method x scene -> relMSE at equal time" table from the CSVs bench/converge.py writes.

usage: bench/converge_table.py [DIR]     (default bench/results/convergence)

For each scene, every method's relMSE is read off its error-against-time curve (log-log
interpolation) at the longest time every method reached, and printed as a Markdown table
with each entry's ratio to the best method of its row (1.0 = best).
"""
import argparse
import csv
import glob
import math
import os

import benchlib

METHODS = ("pt", "nee", "mis", "lt", "bdpt", "vcm", "auto")


def read_rows(path):
    """converge.py's rows; none from another CSV (adaptive.py's lie beside them)."""
    with open(path) as f:
        return [dict(r, spp=int(r["spp"]), seconds=float(r["seconds"]), relMSE=float(r["relMSE"]))
                for r in csv.DictReader(f) if "method" in r and "relMSE" in r]


def relmse_at(points, target):
    """relMSE of one method's (seconds, relMSE) curve at `target` seconds, log-log interpolated."""
    below = [p for p in points if p["seconds"] <= target]
    above = [p for p in points if p["seconds"] >= target]
    if not below or not above:
        return math.nan
    a, b = below[-1], above[0]
    if a is b or a["seconds"] == b["seconds"]:
        return a["relMSE"]
    f = (math.log(target) - math.log(a["seconds"])) / (math.log(b["seconds"]) - math.log(a["seconds"]))
    return math.exp(math.log(a["relMSE"]) + f * (math.log(b["relMSE"]) - math.log(a["relMSE"])))


def equal_time(rows):
    """(time, {method: relMSE}) at the longest time every method reached."""
    by_method = {m: sorted((r for r in rows if r["method"] == m), key=lambda r: r["seconds"]) for m in METHODS}
    by_method = {m: pts for m, pts in by_method.items() if pts}
    target = min(pts[-1]["seconds"] for pts in by_method.values())
    return target, {m: relmse_at(pts, target) for m, pts in by_method.items()}


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("folder", nargs="?", default=benchlib.results_path("convergence"), help="where the CSVs are")
    folder = p.parse_args().folder
    print("| scene | time | " + " | ".join(f"`{m}` relMSE (× best)" for m in METHODS) + " |")
    print("|---|---|" + "---|" * len(METHODS))
    for path in sorted(glob.glob(os.path.join(folder, "*.csv"))):
        rows = read_rows(path)
        if not rows:
            continue
        target, values = equal_time(rows)
        best = min(v for v in values.values() if not math.isnan(v))
        cells = []
        for m in METHODS:
            v = values.get(m, math.nan)
            cell = "–" if math.isnan(v) else f"{v:.2e} ({v / best:.1f})"
            cells.append(f"**{cell}**" if v == best else cell)
        print(f"| {rows[0]['scene']} | {target:.2f} s | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
