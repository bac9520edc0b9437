#!/usr/bin/python3
"""Where each method's error sits on the caustic scene: relMSE at equal time, split into the
pixels that see the glass ball (light focused on the floor and seen through glass, L S D S E,
which only a camera path that finds the light by BSDF sampling can carry) and the pixels that
do not (the floor, the caustic seen directly: L S D E, which light tracing carries).

usage: bench/caustic_regions.py [--time T] [--seeds 1,2] [--methods mis,lt,bdpt]
                                [--ref-spp N] [--width W --height H] [--out DIR]

The reference is the mean of two long `lt` renders with different seeds; its own error in each
region is estimated from their difference ((a - b)^2 / 4 per pixel and channel, the variance
of their mean) and taken off each figure. relMSE as `fredholm compare` defines it (per pixel
and channel, (x - r)^2 / (r^2 + 0.01), averaged). The regions come from the scene's geometry
(scenes/failure/make_scenes.py: the ball's centre and radius, the camera file): a pixel is
"through the ball" when its centre or a corner looks at a sphere slightly larger than the
ball. Needs Debian's python3-numpy.
"""
import argparse
import json
import math
import os
import statistics

import numpy as np

import benchlib

SCENE = "scenes/failure/caustic.obj"
BALL_CENTRE, BALL_RADIUS = np.array([0.0, 1.14, 0.0]), 0.5
MARGIN = 0.02  # the faceted ball's vertices lie on the sphere; this covers rounding at its rim
EPSILON = 0.01  # fredholm compare's relMSE epsilon (host/image/error_metrics.h)


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        width, height = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.fromfile(f, dtype="<f4" if scale < 0 else ">f4")
    channels = 3 if kind == b"PF" else 1
    return data.reshape(height, width, channels)[::-1].astype(np.float64)  # rows from the top


def sees_ball(width, height):
    """Per pixel: whether the pinhole sees the ball through its centre or a corner."""
    with open(os.path.join(benchlib.ROOT, "scenes/failure/caustic.camera.json")) as f:
        cam = json.load(f)
    eye, target, up = (np.array(cam[k], dtype=float) for k in ("eye", "target", "up"))
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, up)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    tan_half = math.tan(math.radians(cam["fov_y_deg"]) / 2)
    aspect = width / height
    mask = np.zeros((height, width), dtype=bool)
    for dx, dy in ((0.5, 0.5), (0, 0), (1, 0), (0, 1), (1, 1)):
        px = np.arange(width)[None, :] + dx
        py = np.arange(height)[:, None] + dy
        sx = (2 * px / width - 1) * tan_half * aspect
        sy = (1 - 2 * py / height) * tan_half
        d = forward[None, None, :] + right * sx[..., None] + true_up * sy[..., None]
        d /= np.linalg.norm(d, axis=-1, keepdims=True)
        to_centre = BALL_CENTRE - eye
        along = d @ to_centre
        closest2 = to_centre @ to_centre - along ** 2
        mask |= (along > 0) & (closest2 <= (BALL_RADIUS + MARGIN) ** 2)
    return mask


def region_relmse(image, reference, reference_var, mask):
    denom = reference ** 2 + EPSILON
    error = ((image - reference) ** 2 - reference_var) / denom
    return float(error[mask].mean())


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    benchlib.add_arguments(p, "--binary", "--out", "--width", "--height", "--seeds", "--ref-spp",
                           out=benchlib.scratch_path("caustic_regions"), seeds="1,2", ref_spp=8192)
    p.add_argument("--time", type=float, default=10.0, help="seconds per render (default 10)")
    p.add_argument("--methods", default="mis,lt,bdpt", help="methods to render, in turn (default mis,lt,bdpt)")
    args = p.parse_args()
    methods = args.methods.split(",")
    os.makedirs(args.out, exist_ok=True)
    scene = os.path.join(benchlib.ROOT, SCENE)
    size = ["--width", str(args.width), "--height", str(args.height)]
    refs = []
    for seed in ("1000", "1001"):
        ref = os.path.join(args.out, f"ref-{args.width}x{args.height}-lt-{args.ref_spp}-{seed}.pfm")
        if not os.path.exists(ref):
            benchlib.render([scene] + size + ["--method", "lt", "--spp", str(args.ref_spp), "--seed", seed], ref,
                            args.binary)
        refs.append(read_pfm(ref))
    reference = (refs[0] + refs[1]) / 2
    reference_var = (refs[0] - refs[1]) ** 2 / 4
    through = sees_ball(args.width, args.height)[..., None] & np.ones((1, 1, 3), dtype=bool)
    regions = {"through the ball": through, "elsewhere": ~through, "whole image": np.ones_like(through)}
    errors = {(m, r): [] for m in methods for r in regions}
    spp = {m: [] for m in methods}
    for seed in args.seeds.split(","):
        for method in methods:  # alternated within each seed
            path = os.path.join(args.out, f"{method}-{seed}.pfm")
            stats = benchlib.render([scene] + size + ["--method", method, "--time", str(args.time), "--seed", seed],
                                    path, args.binary)
            spp[method].append(stats["samples"] / (args.width * args.height))
            image = read_pfm(path)
            for r, mask in regions.items():
                errors[(method, r)].append(region_relmse(image, reference, reference_var, mask))
    share = through[..., 0].mean()
    print(f"pixels through the ball: {share:.1%}; reference error taken off (whole image): "
          f"{float((reference_var / (reference ** 2 + EPSILON)).mean()):.2e}")
    print("| region | " + " | ".join(methods) + " | " +
          " | ".join(f"{m} / {methods[0]}" for m in methods[1:]) + " |")
    print("|---|" + "---|" * (2 * len(methods) - 1))
    for r in regions:
        means = [statistics.mean(errors[(m, r)]) for m in methods]
        ratios = [f"{v / means[0]:.2f}" for v in means[1:]]
        print(f"| {r} | " + " | ".join(f"{v:.2e}" for v in means) + " | " + " | ".join(ratios) + " |")
    print("| spp in the time | " + " | ".join(f"{statistics.mean(spp[m]):.0f}" for m in methods) + " |")


if __name__ == "__main__":
    benchlib.main(main)
