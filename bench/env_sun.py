#!/usr/bin/python3
"""Error against time under an HDR environment map with a small, bright sun: pt, nee, mis, bdpt
and vcm (lt traces no environment).

  bench/env_sun.py [--out bench/out/env-sun] [--width 192] [--height 144] [--max-spp 256] [--ref-spp 4096]
                   [--methods pt,nee,mis,bdpt,vcm]

Writes, into OUT:
  - sun-sky.exr: a 512x256 latitude-longitude map, a sky of radiance 0.4-1.0 (brighter
    towards the zenith), a dim ground, and a sun 1 degree in radius at 40 degrees
    elevation whose radiance gives it most of the light on a horizontal plane;
  - sun-blob.obj: the generated test blob (build/test-scenes/blob) standing on a ground square,
    with a camera that sees the blob's shadow.
Then runs bench/converge.py on it with `--env-map sun-sky.exr` (reference: a long mis render)
and prints relMSE at equal time per method; the CSV and chart (OUT/sun-blob.csv, .png) are
copied to bench/results/convergence/. Needs a build
(build/fredholm and the test scenes), Debian's python3-numpy, python3-matplotlib and oiiotool.
"""
import argparse
import math
import os
import shutil
import subprocess
import sys

import numpy as np

import benchlib

BLOB = os.path.join(benchlib.ROOT, "build", "test-scenes", "blob", "blob.obj")

SUN_ELEVATION_DEG, SUN_AZIMUTH_DEG, SUN_RADIUS_DEG = 40.0, 60.0, 1.0


def direction(u, v):
    """Unit directions of map coordinates (u, v), with the map's conventions (+y up, u = 0.5 along -z,
    u growing towards +x): host/scene/environment_map.h."""
    theta, phi = math.pi * v, 2.0 * math.pi * (u - 0.5)
    return np.stack([np.sin(theta) * np.sin(phi), np.cos(theta), -np.sin(theta) * np.cos(phi)], axis=-1)


def sun_sky(width=512, height=256):
    v, u = np.meshgrid((np.arange(height) + 0.5) / height, (np.arange(width) + 0.5) / width, indexing="ij")
    d = direction(u, v)
    up = d[..., 1]
    sky = np.where(up[..., None] > 0, np.array([0.4, 0.55, 1.0]) * (0.4 + 0.6 * np.clip(up, 0, 1))[..., None],
                   np.array([0.15, 0.13, 0.1]))
    el, az = math.radians(SUN_ELEVATION_DEG), math.radians(SUN_AZIMUTH_DEG)
    sun = np.array([math.cos(el) * math.sin(az), math.sin(el), -math.cos(el) * math.cos(az)])
    in_sun = d @ sun > math.cos(math.radians(SUN_RADIUS_DEG))
    # The sun's irradiance on a horizontal plane, about 10x the sky's (pi * ~0.6).
    solid_angle = 2.0 * math.pi * (1.0 - math.cos(math.radians(SUN_RADIUS_DEG)))
    radiance = 10.0 * math.pi * 0.6 / (solid_angle * math.sin(el))
    sky[in_sun] = radiance * np.array([1.0, 0.95, 0.85])
    return sky.astype(np.float32), int(in_sun.sum())


def write_exr(path, rgb):
    """Through PFM (rows bottom to top, little-endian floats) and oiiotool."""
    pfm = path + ".pfm"
    with open(pfm, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (rgb.shape[1], rgb.shape[0]))
        f.write(np.ascontiguousarray(rgb[::-1]).astype("<f4").tobytes())
    benchlib.run(["oiiotool", pfm, "-d", "float", "-o", path])
    os.remove(pfm)


def write_scene(folder):
    obj, mtl = os.path.join(folder, "sun-blob.obj"), os.path.join(folder, "sun-blob.mtl")
    with open(mtl, "w") as f:
        f.write("newmtl ground\nKd 0.5 0.5 0.5\nnewmtl blob\nKd 0.7 0.6 0.5\n")
    lines = [line for line in open(BLOB) if line.startswith(("v ", "f "))]
    count = sum(1 for line in lines if line.startswith("v "))
    low = min(float(line.split()[2]) for line in lines if line.startswith("v "))
    with open(obj, "w") as f:
        f.write("# The generated blob on a ground square under a sun (bench/env_sun.py)\nmtllib sun-blob.mtl\n")
        f.write("usemtl blob\n")
        f.writelines(lines)
        f.write("usemtl ground\n")
        for x, z in ((-8, -8), (-8, 8), (8, 8), (8, -8)):
            f.write(f"v {x} {low} {z}\n")
        f.write(f"f {count + 1} {count + 2} {count + 3} {count + 4}\n")
    with open(os.path.join(folder, "sun-blob.camera.json"), "w") as f:
        f.write('{"eye": [-3.5, 2.2, 4.5], "target": [0.3, -0.4, 0], "up": [0, 1, 0], "fov_y_deg": 45}\n')
    return obj


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    benchlib.add_arguments(p, "--out", "--width", "--height", out=benchlib.scratch_path("env-sun"), width=192,
                           height=144)
    p.add_argument("--max-spp", type=int, default=256)
    benchlib.add_arguments(p, "--ref-spp", "--methods", methods="pt,nee,mis,bdpt,vcm")
    args = p.parse_args()
    if not os.path.exists(BLOB):
        sys.exit(f"{BLOB} is missing: build first (cmake --build build)")
    folder = args.out
    os.makedirs(folder, exist_ok=True)
    sky, sun_texels = sun_sky()
    env = os.path.join(folder, "sun-sky.exr")
    write_exr(env, sky)
    print(f"wrote {env}: the sun covers {sun_texels} of {sky.shape[0] * sky.shape[1]} texels")
    scene = write_scene(folder)
    subprocess.run([sys.executable, os.path.join(benchlib.ROOT, "bench", "converge.py"), scene, "--out", args.out,
                    "--width", str(args.width), "--height", str(args.height), "--max-spp", str(args.max_spp),
                    "--ref-spp", str(args.ref_spp), "--methods", args.methods, "--", "--env-map", env], check=True)
    for ext in (".csv", ".png"):
        shutil.copy(os.path.join(args.out, "sun-blob" + ext), benchlib.results_path("convergence"))


if __name__ == "__main__":
    benchlib.main(main)
