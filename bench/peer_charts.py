#!/usr/bin/python3
"""Error against time for fredholm, Mitsuba 3 and Blender Cycles on the same axes, one chart
per scene: the glossy Cornell box, the water box (mirror, glass and water), the Cornell box,
and Veach's MIS scene where its OBJ is given (it does not ship: no licence is stated for it).

  bench/peer_charts.py [--scenes glossy,water,cornell] [--veach PATH/veach_mis.obj]
                       [--size 256x256] [--spp 4,16,64,256] [--ref-spp 4096] [--rounds 1]
                       [--cycles-ref-spp 1024] [--no-cycles] [--mitsuba-python ...] [--out DIR]

Every renderer renders the same OBJ+MTL and camera sidecar, at most 16 bounces, roulette
after the same number of bounces (fredholm --rr-depth 6, Mitsuba rr_depth 5):
- fredholm `mis`: seconds are --stats `seconds` (after a warm-up render has compiled the kernels);
- Mitsuba 3 `llvm_ad_rgb`, its independent and ldsampler samplers (bench/peers/mitsuba_render.py,
  which gives it fredholm's glossy model): seconds_render, after its JIT warm-up;
- Cycles (bench/cycles_reference.py): the wall time of its render call, 2 threads.
Each image's relMSE (fredholm compare: per channel, epsilon 1e-2) is taken against one
reference: fredholm `mis` at --ref-spp, which Mitsuba's images also measure against (the
two solve the same equation: their means agree, see bench/RESULTS.md). Cycles' glossy, mirror
and glass nodes are not fredholm's model, so on a scene that has them its images measure
against a Cycles reference of its own (--cycles-ref-spp) and the chart says so.
Renders run one at a time, the renderers alternated at each spp (rotated each round).
Writes OUT/peer-charts.csv and OUT/peer-charts.png.
"""
import argparse, csv, json, os, shutil

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import benchlib  # noqa: E402

SCENES = {
    "glossy": ("scenes/cornell-box/legacy-glossy-2011/CornellBox-Glossy.obj", "glossy Cornell box"),
    "water": ("scenes/cornell-box/CornellBox-Water.obj", "water box"),
    "cornell": ("scenes/cornell-box/CornellBox-Original.obj", "Cornell box"),
}
MITSUBA_RENDER = os.path.join(benchlib.ROOT, "bench", "peers", "mitsuba_render.py")
CYCLES_SCRIPT = os.path.join(benchlib.ROOT, "bench", "cycles_reference.py")
MAX_BOUNCES = 16


def fredholm(opts, obj, spp, out, seed=1):
    """(image, seconds)."""
    stats = benchlib.render([obj, "--width", str(opts.width), "--height", str(opts.height), "--spp", str(spp),
                             "--method", "mis", "--max-depth", str(MAX_BOUNCES), "--rr-depth", "6",
                             "--seed", str(seed)], out, opts.binary)
    return out, stats["seconds"]


def mitsuba(opts, obj, sampler, spp, out, seed=1):
    doc = benchlib.run([opts.mitsuba_python, MITSUBA_RENDER, obj, "--out", out, "--spp", str(spp),
                        "--sampler", sampler, "--seed", str(seed), "--width", str(opts.width),
                        "--height", str(opts.height), "--max-bounces", str(MAX_BOUNCES), "--threads", "2"],
                       stdout=True)
    return out, json.loads(doc.stdout.strip().splitlines()[-1])["seconds_render"]


def cycles(opts, obj, spp, out, seed=1):
    camera = os.path.splitext(obj)[0] + ".camera.json"
    doc = benchlib.run(["blender", "-b", "--factory-startup", "--python", CYCLES_SCRIPT, "--", obj, camera, out,
                        "--width", str(opts.width), "--height", str(opts.height), "--spp", str(spp),
                        "--seed", str(seed), "--max-bounces", str(MAX_BOUNCES), "--threads", "2"], stdout=True)
    lines = [line for line in doc.stdout.splitlines() if line.lstrip().startswith("{")]
    result = json.loads(lines[-1])
    return out, result["seconds_render"], result.get("exact", True)


def cached(path, make):
    """make(path) unless path exists from an earlier run with the same settings."""
    if not os.path.exists(path):
        make(path + ".tmp.exr")
        os.replace(path + ".tmp.exr", path)
    return path


def chart_scene(opts, key, obj, workdir, rows):
    size = f"{opts.width}x{opts.height}"
    reference = cached(benchlib.scratch_path("peers", f"ref-{key}-{size}-{opts.ref_spp}.exr"),
                       lambda p: fredholm(opts, obj, opts.ref_spp, p, seed=999))
    runners = {"fredholm mis": lambda spp, seed, out: fredholm(opts, obj, spp, out, seed),
               "mitsuba independent": lambda spp, seed, out: mitsuba(opts, obj, "independent", spp, out, seed),
               "mitsuba ldsampler": lambda spp, seed, out: mitsuba(opts, obj, "ldsampler", spp, out, seed)}
    references = dict.fromkeys(runners, reference)
    if opts.cycles:
        # A small render tells whether Cycles' translation of this scene is exact.
        _, _, exact = cycles(opts, obj, 1, os.path.join(workdir, "probe.exr"))
        runners["cycles"] = lambda spp, seed, out: cycles(opts, obj, spp, out, seed)[:2]
        references["cycles"] = reference if exact else cached(
            benchlib.scratch_path("peers", f"cycles-ref-{key}-{size}-{opts.cycles_ref_spp}.exr"),
            lambda p: cycles(opts, obj, opts.cycles_ref_spp, p, seed=999))
    names = list(runners)
    for name in names:  # warm-ups: kernel compilation, JIT
        runners[name](1, 7, os.path.join(workdir, "warm.exr"))
    def measure(name, spp):
        def go(r):
            image, seconds = runners[name](spp, 100 * (r + 1) + spp, os.path.join(workdir, "img.exr"))
            error = benchlib.compare(image, references[name], opts.binary)["relmse"]
            row = (key, name, spp, r + 1, seconds, error, "own" if references[name] != reference else "common")
            print(*row, flush=True)
            rows.append(row)
        return go

    for spp in opts.spp:
        benchlib.alternate({name: measure(name, spp) for name in names}, opts.rounds, warmup=False)


def plot(rows, opts, titles):
    scenes = list(dict.fromkeys(r[0] for r in rows))
    fig, axes = plt.subplots(1, len(scenes), figsize=(5.2 * len(scenes), 4.4), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        mine = [r for r in rows if r[0] == scene]
        for name in dict.fromkeys(r[1] for r in mine):
            points = sorted((r[4], r[5]) for r in mine if r[1] == name)
            own = any(r[6] == "own" for r in mine if r[1] == name)
            style = "o-" if name.startswith("fredholm") else ("s--" if name.startswith("mitsuba") else "^:")
            ax.loglog([p[0] for p in points], [p[1] for p in points], style,
                      label=name + (" (own reference)" if own else ""))
        ax.set_title(titles[scene])
        ax.set_xlabel("seconds (render only)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    axes[0][0].set_ylabel("relMSE against the reference")
    fig.savefig(os.path.join(opts.out, "peer-charts.png"), dpi=90, bbox_inches="tight")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", default="glossy,water,cornell")
    ap.add_argument("--veach", help="Veach's MIS scene (veach_mis.obj with its .mtl and .camera.json)")
    benchlib.add_arguments(ap, "--size", "--ref-spp", "--rounds", "--mitsuba-python", "--out", "--binary",
                           size="256x256", ref_spp=4096, rounds=1, out=benchlib.results_path("peers"))
    ap.add_argument("--spp", default="4,16,64,256")
    ap.add_argument("--cycles-ref-spp", type=int, default=1024)
    ap.add_argument("--no-cycles", dest="cycles", action="store_false")
    opts = ap.parse_args()
    opts.width, opts.height = (int(v) for v in opts.size.split("x"))
    opts.spp = [int(s) for s in opts.spp.split(",")]
    if opts.cycles and not shutil.which("blender"):
        raise benchlib.BenchError("blender is not installed (apt-get install blender), or pass --no-cycles")
    scenes = {k: (os.path.join(benchlib.ROOT, SCENES[k][0]), SCENES[k][1]) for k in opts.scenes.split(",") if k}
    if opts.veach:
        scenes["veach"] = (os.path.abspath(opts.veach), "Veach's MIS scene")
    os.makedirs(opts.out, exist_ok=True)
    os.makedirs(benchlib.scratch_path("peers"), exist_ok=True)
    rows = []
    workdir = benchlib.scratch_path("peers", "work")
    os.makedirs(workdir, exist_ok=True)
    sizes = {}
    for key, (obj, _) in scenes.items():
        view = argparse.Namespace(**vars(opts))
        if key == "veach":  # its camera frames a 3:2 image
            view.width = opts.height * 3 // 2
        sizes[key] = f"{view.width}x{view.height}"
        chart_scene(view, key, obj, workdir, rows)
    with open(os.path.join(opts.out, "peer-charts.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scene", "renderer", "spp", "round", "seconds", "relmse", "reference"])
        w.writerows(rows)
    plot(rows, opts, {k: f"{v[1]}, {sizes[k]}" for k, v in scenes.items()})


if __name__ == "__main__":
    benchlib.main(main)
