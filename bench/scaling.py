#!/usr/bin/python3
"""How ray casting grows with the scene: fredholm and Embree on the same rays.

Runs `fredholm bench spheres:N` for N from 1e2 to 1e7 (generated scenes: a floor under a
grid of bumped spheres), one process per size so each starts clean, and charts Mrays/s per
ray kind, BVH build seconds and bytes per triangle against the triangle count, fredholm and
Embree on the same axes. Writes bench/results/scaling.json and bench/results/scaling.png.

  bench/scaling.py [--sizes 1e2,1e3,...] [--repeats 5]
"""
import argparse
import json
import os
import tempfile

import benchlib


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    benchlib.add_arguments(p, "--binary")
    p.add_argument("--sizes", default="1e2,3e2,1e3,3e3,1e4,3e4,1e5,3e5,1e6,3e6,1e7")
    p.add_argument("--repeats", type=int, default=5)
    benchlib.add_arguments(p, "--out", out=dict(default=benchlib.results_path("scaling"),
                                                help="OUT.json and OUT.png are written"))
    p.add_argument("--replot", action="store_true", help="only redraw the chart from OUT.json")
    a = p.parse_args()
    scenes, records = [], []
    if a.replot:
        doc = json.load(open(a.out + ".json"))
        scenes, records = doc["scenes"], doc["records"]
    with tempfile.TemporaryDirectory() as tmp:
        for size in [] if a.replot else a.sizes.split(","):
            doc = benchlib.bench([f"spheres:{size}", "--repeats", str(a.repeats)], os.path.join(tmp, "b.json"),
                                 a.binary)
            scenes += doc["scenes"]
            records += doc["records"]
            s = doc["scenes"][0]
            print(f"{s['triangles']:>9} triangles: build {s['bvh_build_seconds']:.3f} s "
                  f"(Embree {s.get('embree_build_seconds', 0):.3f}), {s['bvh_bytes_per_triangle']:.1f} B/triangle "
                  f"(Embree {s.get('embree_bytes_per_triangle', 0):.1f}), SAH {s['bvh_sah_cost']:.2f}; " +
                  ", ".join(f"{r['ray_kind']} {r['mrays_per_s']:.1f}/{r.get('embree_mrays_per_s', 0):.1f}"
                            for r in doc["records"]) + " Mrays/s (fredholm/Embree)", flush=True)
    if not a.replot:
        json.dump({"scenes": scenes, "records": records}, open(a.out + ".json", "w"), indent=1)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2))
    colors = {"primary": "tab:blue", "bounce": "tab:green", "shadow": "tab:red"}
    for kind, color in colors.items():
        rows = [r for r in records if r["ray_kind"] == kind]
        tris = [r["triangles"] for r in rows]
        axes[0].plot(tris, [r["mrays_per_s"] for r in rows], "o-", color=color, label=f"fredholm {kind}")
        if all("embree_mrays_per_s" in r for r in rows):
            axes[0].plot(tris, [r["embree_mrays_per_s"] for r in rows], "s--", color=color, alpha=0.6,
                         label=f"Embree {kind}")
    axes[0].set(xscale="log", yscale="log", xlabel="triangles", ylabel="Mrays/s", title="Ray casting (2 cores)")
    tris = [s["triangles"] for s in scenes]
    axes[1].plot(tris, [s["bvh_build_seconds"] for s in scenes], "o-", label="fredholm")
    axes[1].plot(tris, [s.get("embree_build_seconds", 0) for s in scenes], "s--", label="Embree (high quality)")
    axes[1].set(xscale="log", yscale="log", xlabel="triangles", ylabel="seconds", title="BVH build")
    axes[2].plot(tris, [s["bvh_bytes_per_triangle"] for s in scenes], "o-", label="fredholm (nodes + leaf blocks)")
    axes[2].plot(tris, [s.get("embree_bytes_per_triangle", 0) for s in scenes], "s--",
                 label="Embree (geometry + BVH)")
    axes[2].set(xscale="log", xlabel="triangles", ylabel="bytes per triangle", title="Memory")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(a.out + ".png", dpi=110)
    print("wrote", a.out + ".json", a.out + ".png")


if __name__ == "__main__":
    benchlib.main(main)
