#!/usr/bin/python3
"""How strong is the suite? Plants one-line bugs, one at a time, and runs tests against each.

  tests/mutate.py [--build build] [--all-tests] [--only NAME ...]

Each mutation replaces one exact piece of source text (which must occur exactly once),
rebuilds, and runs the tests that should catch it (its CTest regex), or the whole suite
with --all-tests (minutes per mutation). A mutation the tests pass is a gap. The source is
restored after each, and the build rebuilt at the end. Re-run after big changes (the CPU
speed work) to see the suite still catches what it caught.
"""
import argparse, os, subprocess, sys

# name, file, original text, mutated text, what it models, tests that should catch it
MUTATIONS = [
    ("crack", "kernels/intersect.h", "((u < zero) | (v < zero) | (w < zero))",
     "((u <= zero) | (v < zero) | (w < zero))", "a one-sided crack in the watertight test", "Watertight"),
    ("nearest-texel", "kernels/surface.h", "const float tx = x - fx, ty = y - fy;",
     "const float tx = round(x - fx), ty = round(y - fy);", "nearest instead of bilinear lookup", "Textures"),
    ("gaussian-as-box", "host/render/pixel_filter.cpp",
     "return std::max(0.0, std::exp(-x * x / (2 * sigma * sigma)) - std::exp(-radius * radius / (2 * sigma * sigma)));",
     "return 1.0 + 0.0 * sigma;", "the Gaussian filter sampled as a box", "PixelFilters"),
    ("no-owen-values", "kernels/sampler.h", "return u32_to_unit_float(reverse_bits_u32(owen_hash(digits_reversed, seed)));",
     "return u32_to_unit_float(reverse_bits_u32(digits_reversed + 0u * seed));",
     "sample values not Owen-scrambled (index shuffle kept)", "PixelSampler"),
    ("ggx-pdf", "kernels/bsdf.h", "return ggx_g1(wo, a) * ggx_d(h, a) / (4.0f * wo.z);",
     "return 1.1f * ggx_g1(wo, a) * ggx_d(h, a) / (4.0f * wo.z);", "a 10 % GGX pdf error", "Bsdf|WhiteFurnace"),
    ("mis-half", "kernels/lights.h", "return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;",
     "return a2 + b2 > 0.0f ? 0.5f : 0.0f;", "a constant one-half MIS weight", "PathTracer|WhereMethodsFail"),
    ("roulette", "kernels/shade.cl", "else beta /= survive;", "else beta /= 1.0f;",
     "Russian roulette without dividing by survival", "PathTracer|WhereMethodsFail"),
    ("light-pdf", "kernels/lights.h", "if (l->seen.solid_angle > 0.0f) return l->pick / l->seen.solid_angle;",
     "if (l->seen.solid_angle > 0.0f) return 2.0f * l->pick / l->seen.solid_angle;", "a doubled light pdf",
     "PathTracer|WhereMethodsFail"),
    ("back-emission", "kernels/shade.cl", "if (cos_front > 0.0f && (ke.x > 0.0f",
     "if (cos_front != 0.0f && (ke.x > 0.0f", "emission from the back side too", "PathTracer|WhereMethodsFail"),
]


def run(cmd, cwd):
    return subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--build", default="build")
    parser.add_argument("--all-tests", action="store_true")
    parser.add_argument("--only", nargs="*")
    opts = parser.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    env_dirs = {"POCL_CACHE_DIR": os.path.join(root, opts.build, "pocl-cache"),
                "FREDHOLM_CACHE_DIR": os.path.join(root, opts.build, "program-cache")}
    os.environ.update({k: os.environ.get(k, v) for k, v in env_dirs.items()})
    results = []
    for name, path, original, mutated, what, tests in MUTATIONS:
        if opts.only and name not in opts.only:
            continue
        full = os.path.join(root, path)
        with open(full) as f:
            text = f.read()
        if text.count(original) != 1:
            results.append((name, what, "stale: the original text is not in " + path + " exactly once"))
            continue
        try:
            with open(full, "w") as f:
                f.write(text.replace(original, mutated))
            build = run(["cmake", "--build", opts.build, "-j2"], root)
            if build.returncode != 0:
                results.append((name, what, "does not build"))
                continue
            cmd = ["ctest", "--test-dir", opts.build, "-j2"] + ([] if opts.all_tests else ["-R", tests])
            caught = run(cmd, root).returncode != 0
            results.append((name, what, "caught" if caught else "MISSED"))
        finally:
            with open(full, "w") as f:
                f.write(text)
        print("%-16s %-8s %s" % (name, results[-1][2], what), flush=True)
    run(["cmake", "--build", opts.build, "-j2"], root)
    missed = [r for r in results if r[2] != "caught"]
    print("%d of %d mutations caught" % (len(results) - len(missed), len(results)))
    sys.exit(1 if missed else 0)


if __name__ == "__main__":
    main()
