#!/usr/bin/python3
"""Chart of ray-casting throughput against scene size from `fredholm bench --json`.

usage: bench/plot_throughput.py bench.json [out.png]

One line per ray kind for fredholm (solid) and, when the JSON has them, Embree's best API
(dashed). Needs Debian's python3-matplotlib.
"""
import argparse
import json

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("json", help="`fredholm bench --json` output")
    p.add_argument("png", nargs="?", help="the chart (default: the JSON's name with .png)")
    a = p.parse_args()
    with open(a.json) as f:
        doc = json.load(f)
    out = a.png or a.json.rsplit(".", 1)[0] + ".png"
    fig, ax = plt.subplots(figsize=(7, 4.5))
    colors = {"primary": "tab:blue", "bounce": "tab:red", "shadow": "tab:green"}
    for kind, color in colors.items():
        rows = sorted((r for r in doc["records"] if r["ray_kind"] == kind), key=lambda r: r["triangles"])
        if not rows:
            continue
        tris = [r["triangles"] for r in rows]
        ax.plot(tris, [r["mrays_per_s"] for r in rows], "o-", color=color, label=f"fredholm {kind}")
        if all("embree_mrays_per_s" in r for r in rows):
            ax.plot(tris, [r["embree_mrays_per_s"] for r in rows], "s--", color=color, alpha=0.6,
                    label=f"Embree best API {kind}")
        for r in rows:
            ax.annotate(r["scene"], (r["triangles"], r["mrays_per_s"]), fontsize=7, alpha=0.6,
                        textcoords="offset points", xytext=(3, 3))
    ax.set_xscale("log")
    ax.set_xlabel("triangles")
    ax.set_ylabel("Mrays/s")
    ax.set_title(f"Ray casting throughput on {', '.join(doc['devices']) if 'devices' in doc else doc['device']}\n"
                 f"({doc['primary_rays']} primary rays per batch, median of {doc['repeats']})", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
