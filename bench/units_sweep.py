#!/usr/bin/python3
"""A scene in other units: every vertex (and normal) and the camera's eye and target times
2^k, rendered with each method and compared with the unscaled render (the same seed, so the
same image bits are expected: the loader brings a scene far from unit size near it by an
exact power of two, docs/architecture.md "Units"). With --radiance, every Ke times 2^k
instead: the image is expected to scale with it.

usage: bench/units_sweep.py [--scene OBJ] [--exponents -120,-60,...] [--methods mis,lt,bdpt,vcm]
                            [--radiance] [--fredholm build/fredholm] [--out DIR]

Prints one line per exponent and method: the relMSE against the unscaled image (0: the same
bits) and the image mean (with --radiance, the mean over 2^k, and its ratio to the unscaled
image's mean). The OBJ needs a SCENE.camera.json beside it.
"""
import argparse
import json
import math
import os
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def scaled_copy(obj, exponent, out_dir, radiance=False):
    """The OBJ and its camera with every length times 2^exponent (with radiance, the MTL with
    every Ke times 2^exponent), written into out_dir."""
    base = os.path.splitext(os.path.basename(obj))[0]
    name = os.path.join(out_dir, "%s-2^%d%s" % (base, exponent, "-radiance" if radiance else ""))
    lines = []
    with open(obj) as f:
        for line in f:
            kind = line.split(" ", 1)[0]
            if kind in ("v", "vn") and not radiance:
                xyz = [math.ldexp(float(x), exponent) for x in line.split()[1:4]]
                line = "%s %r %r %r\n" % (kind, *xyz)
            elif kind == "mtllib":
                mtl = os.path.join(os.path.dirname(os.path.abspath(obj)), line.split(None, 1)[1].strip())
                if radiance:
                    with open(mtl) as m:
                        text = [("Ke %r %r %r\n" % tuple(math.ldexp(float(x), exponent) for x in l.split()[1:4]))
                                if l.split(" ", 1)[0] == "Ke" else l for l in m]
                    mtl = name + ".mtl"
                    with open(mtl, "w") as m:
                        m.writelines(text)
                line = "mtllib %s\n" % mtl
            lines.append(line)
    with open(name + ".obj", "w") as f:
        f.writelines(lines)
    with open(os.path.splitext(obj)[0] + ".camera.json") as f:
        camera = json.load(f)
    for key in ("eye", "target"):
        camera[key] = [x if radiance else math.ldexp(x, exponent) for x in camera[key]]
    with open(name + ".camera.json", "w") as f:
        json.dump(camera, f)
    return name + ".obj"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", default=os.path.join(ROOT, "scenes/failure/caustic.obj"))
    ap.add_argument("--exponents", default="-120,-100,-60,-30,-12,8,30,60,100,120")
    ap.add_argument("--methods", default="mis,lt,bdpt,vcm")
    ap.add_argument("--radiance", action="store_true", help="scale every Ke instead of every length")
    ap.add_argument("--fredholm", default=os.path.join(ROOT, "build/fredholm"))
    ap.add_argument("--out", default=os.path.join(ROOT, "bench/out/units"))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    flags = ["--width", "32", "--height", "32", "--spp", "16", "--seed", "3", "--force"]

    def render(obj, method, out):
        r = subprocess.run([a.fredholm, "render", obj, "--method", method, *flags, "-o", out],
                           capture_output=True, text=True)
        warnings = [l for l in r.stderr.splitlines() if "warning" in l or "error" in l]
        return r.returncode, warnings

    for method in a.methods.split(","):
        unscaled = os.path.join(a.out, "unscaled-%s.exr" % method)
        render(a.scene, method, unscaled)
        for exponent in [int(e) for e in a.exponents.split(",")]:
            out = os.path.join(a.out, "2^%d-%s.exr" % (exponent, method))
            rc, warnings = render(scaled_copy(a.scene, exponent, a.out, a.radiance), method, out)
            if rc != 0:
                print("2^%-5d %-5s failed: %s" % (exponent, method, "; ".join(warnings)))
                continue
            c = json.loads(subprocess.run([a.fredholm, "compare", out, unscaled], capture_output=True,
                                          text=True).stdout)
            note = ("  " + "; ".join(warnings)) if warnings else ""
            if a.radiance:
                mean = math.ldexp(c["mean_image"][0], -exponent)
                print("2^%-5d %-5s mean / 2^k %.9g  ratio %.9f%s" % (exponent, method, mean,
                                                                   mean / c["mean_reference"][0], note))
            else:
                print("2^%-5d %-5s relMSE %.3e  mean %.6f%s" % (exponent, method, c["relmse"], c["mean_image"][0], note))


if __name__ == "__main__":
    main()
