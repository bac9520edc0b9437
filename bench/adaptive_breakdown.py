#!/usr/bin/python3
"""Where adaptive sampling's error goes, and what the best allocation could gain.

Renders a scene uniformly and with --adaptive at one sample budget (seeds alternating),
measures each pixel's relative squared error against a long uniform reference, and groups
the pixels by the sample count the adaptive render gave them: per group, the error of the
uniform and of the adaptive render, their ratio, and the ratio independent samples would
give (budget / count). Then, from uniform renders' variance layers at a series of budgets,
the most any allocation could gain over uniform sampling were samples independent:
G = mean(c) / mean(sqrt(c))^2, with c a pixel's relative sample variance (its 3x3 block's
mean, as the rounds smooth it), the optimum giving each pixel samples in proportion to
sqrt(c).

  bench/adaptive_breakdown.py [SCENE.obj] --size 128x128 --spp 512 --ref-spp 8192 [--seeds 1,2]
                              [--bound-spps 16,32,64,128,256,512]

Needs Debian's python3-numpy and python3-openimageio (apt-get install python3-openimageio).
"""
import argparse
import os
import tempfile

import numpy as np

import benchlib

EPSILON = 1e-2  # relMSE's (host/image/error_metrics.h)


def render(a, out, flags):
    benchlib.render(benchlib.image_flags(a) + flags, out, a.binary, stats=False)


def layer(exr, channels):
    """Channels of an EXR (e.g. "R,G,B" or "spp.Y") as an h x w x n array."""
    import OpenImageIO as oiio  # here, so that --help works without it

    image = oiio.ImageBuf(exr)
    names = list(image.spec().channelnames)
    pixels = image.get_pixels(oiio.FLOAT)
    return pixels[:, :, [names.index(c) for c in channels.split(",")]].astype(np.float64)


def relative_error(image, reference):
    return (((image - reference) ** 2) / (reference * reference + EPSILON)).mean(axis=2)


def block_mean(v):
    padded = np.pad(v, 1, mode="edge")
    h, w = v.shape
    return sum(padded[1 + dy:1 + dy + h, 1 + dx:1 + dx + w] for dy in (-1, 0, 1) for dx in (-1, 0, 1)) / 9.0


def breakdown(a, tmp, reference):
    groups = [(0.0, 0.9), (0.9, 1.1), (1.1, 1.5), (1.5, 2.0), (2.0, 1e9)]
    print(f"| seed | spp / budget | pixels | uniform | adaptive | adaptive / uniform | independent samples | "
          f"adaptive - uniform, of the image's relMSE |")
    print("|---|---|---|---|---|---|---|---|")
    for seed in a.seeds.split(","):
        errors = {}
        for mode in ("uniform", "adaptive"):
            out = os.path.join(tmp, mode + ".exr")
            render(a, out, ["--spp", str(a.spp), "--seed", seed, "--aovs", "spp"]
                   + (["--adaptive"] if mode == "adaptive" else []))
            errors[mode] = relative_error(layer(out, "R,G,B"), reference)
        spp = layer(os.path.join(tmp, "adaptive.exr"), "spp.Y")[:, :, 0]
        u, ad = errors["uniform"], errors["adaptive"]
        for lo, hi in groups:
            mask = (spp >= lo * a.spp) & (spp < hi * a.spp)
            if not mask.any():
                continue
            iid = a.spp / spp[mask].mean()
            print(f"| {seed} | {lo:g}-{hi:g} | {mask.mean():.1%} | {u[mask].mean():.3e} | {ad[mask].mean():.3e} | "
                  f"{ad[mask].mean() / u[mask].mean():.2f} | {iid:.2f} | {(ad[mask].sum() - u[mask].sum()) / u.sum():+.1%} |")
        print(f"| {seed} | all | 100% | {u.mean():.3e} | {ad.mean():.3e} | {ad.mean() / u.mean():.3f} | | |")


def bound(a, tmp):
    print("\n| spp | G (best allocation's gain, independent samples) |")
    print("|---|---|")
    for spp in a.bound_spps.split(","):
        out = os.path.join(tmp, "bound.exr")
        render(a, out, ["--spp", spp, "--seed", "1", "--aovs", "variance"])
        mean, variance = layer(out, "R,G,B"), layer(out, "variance.R,variance.G,variance.B")
        c = block_mean((variance * float(spp) / (mean * mean + EPSILON)).mean(axis=2)).ravel()
        print(f"| {spp} | {c.mean() / np.sqrt(c).mean() ** 2:.2f} |")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    benchlib.add_arguments(p, "scene", "--binary", "--size", "--spp", "--ref-spp", "--ref", "--seeds", spp=512,
                           ref_spp=8192)
    p.add_argument("--bound-spps", default="16,32,64,128,256,512")
    a = p.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        ref = a.ref or os.path.join(tmp, "ref.exr")
        if not a.ref:
            render(a, ref, ["--spp", str(a.ref_spp), "--seed", "1000"])
        print(f"scene {a.scene or 'built-in Cornell box'}, {a.size}, budget {a.spp} spp; reference {ref}\n")
        breakdown(a, tmp, layer(ref, "R,G,B"))
        bound(a, tmp)


if __name__ == "__main__":
    benchlib.main(main)
