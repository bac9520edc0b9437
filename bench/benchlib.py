"""What the bench scripts share: their common arguments, one way to run fredholm (render,
bench, compare), the alternation of peers within one run, its median summaries, and where
results go. The scripts import it from beside themselves (`import benchlib`).

- Arguments: `add_arguments(parser, "--binary", "scene", "--width", ..., out=DEFAULT)` adds
  the common ones by flag, with a script's own defaults by destination; `parse_with_rest`
  parses a script's own arguments and returns those after `--` (for fredholm) apart.
- Running: `run(cmd)` runs any command with fredholm's caches defaulting to build/pocl-cache
  and build/program-cache (POCL_CACHE_DIR, FREDHOLM_CACHE_DIR: the environment's, else
  those) and raises `BenchError` (the command line, its output's tail) when it fails;
  `render(flags, out)` runs `fredholm render` and returns its `--stats` JSON; `bench` does
  the same for `fredholm bench --json`, `compare` returns `fredholm compare`'s JSON and
  `image_metadata` the fredholm:* fields of an image (oiiotool).
- Alternation: this machine drifts by tens of percent between runs, so peers are compared
  within one run, round by round, the order rotated every round: `alternate(runners, rounds)`
  returns each runner's results, one a round; `median_line`, `runs`, `ratios` print them.
- Where things go: `results_path(...)` under bench/results/ (charts, CSVs and JSON that are
  kept), `scratch_path(...)` under bench/out/ (images, references; git-ignored).
"""
import json
import os
import shlex
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FREDHOLM = os.path.join(ROOT, "build", "fredholm")
# Mitsuba 3 on an OBJ+MTL scene, as fredholm reads it (run under --mitsuba-python).
MITSUBA_RENDER = os.path.join(ROOT, "bench", "peers", "mitsuba_render.py")
# The Cornell box view of the comparisons with Mitsuba (the peer issue's camera, at most 16 bounces, 512x512).
PEER_VIEW = ["--width", "512", "--height", "512", "--eye", "0,1,3.5", "--target", "0,1,0", "--fov", "40",
             "--max-depth", "16"]
PEER_PIXELS = 512 * 512
# The same view for bench/peers/mitsuba_render.py (its scene is the same Cornell box by default).
MITSUBA_PEER_VIEW = ["--width", "512", "--height", "512", "--eye", "0,1,3.5", "--target", "0,1,0", "--fov", "40",
                     "--max-bounces", "16"]


def results_path(*parts):
    """A path under bench/results/: charts, CSVs and JSON that are kept (and committed)."""
    return os.path.join(ROOT, "bench", "results", *parts)


def scratch_path(*parts):
    """A path under bench/out/: images, references and other scratch (git-ignored)."""
    return os.path.join(ROOT, "bench", "out", *parts)


# ---- Arguments ----------------------------------------------------------------------------

_COMMON = {  # flag: (its flags, argparse settings)
    "--binary": (("--binary", "--fredholm"),
                 dict(dest="binary", default=FREDHOLM, help="the fredholm binary (default: build/fredholm)")),
    "scene": (("scene",), dict(nargs="?", default="", help="OBJ file (default: the built-in Cornell box)")),
    "--scene": (("--scene",), dict(default="", help="OBJ file (default: the built-in Cornell box)")),
    "--size": (("--size",), dict(default="128x128", help="image size WxH")),
    "--width": (("--width",), dict(type=int, default=128, help="image width")),
    "--height": (("--height",), dict(type=int, default=128, help="image height")),
    "--spp": (("--spp",), dict(type=int, help="samples per pixel")),
    "--method": (("--method",), dict(default="mis", help="render method: pt, nee or mis")),
    "--methods": (("--methods",), dict(default="pt,nee,mis", help="comma-separated render methods")),
    "--seeds": (("--seeds",), dict(default="1,2", help="comma-separated seeds")),
    "--out": (("--out",), dict(help="output folder")),
    "--rounds": (("--rounds",), dict(type=int, help="rounds of the alternation")),
    "--ref": (("--ref",), dict(help="a reference EXR already rendered")),
    "--ref-spp": (("--ref-spp",), dict(type=int, default=4096, help="samples per pixel of the reference")),
    "--mitsuba-python": (("--mitsuba-python",),
                         dict(default="/opt/mi-venv/bin/python", help="a Python that imports mitsuba")),
}


def add_arguments(parser, *names, **defaults):
    """Adds the common arguments named by their flag ("--binary", "scene" for an optional
    positional OBJ, "--scene" for the same as an option, "--size" WxH or "--width" and
    "--height", "--spp", "--method", "--seeds", "--out", "--rounds", "--ref", "--ref-spp", ...).
    Keywords, by destination, set a script's own default (ref_spp=8192) or, as a dict, its
    own argparse settings (ref=dict(required=True, help=...)). Returns the parser."""
    dests = {}
    for name in names:
        flags, settings = _COMMON[name]
        dests[settings.get("dest", flags[0].lstrip("-").replace("-", "_"))] = (flags, dict(settings))
    unknown = set(defaults) - set(dests)
    if unknown:
        raise ValueError(f"add_arguments: defaults for arguments not added: {sorted(unknown)}")
    for dest, (flags, settings) in dests.items():
        own = defaults.get(dest)
        if isinstance(own, dict):
            if own.get("required"):
                settings.pop("default", None)
            settings.update(own)
        elif dest in defaults:
            settings["default"] = own
        parser.add_argument(*flags, **settings)
    return parser


def split_rest(argv=None):
    """(a script's own arguments, those after the first `--`, which go to fredholm)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    if "--" not in argv:
        return argv, []
    split = argv.index("--")
    return argv[:split], argv[split + 1:]


def parse_with_rest(parser, argv=None):
    """Parses the arguments before `--` with parser; returns (namespace, the list after `--`)."""
    own, rest = split_rest(argv)
    return parser.parse_args(own), rest


def image_flags(args):
    """The render flags of the scene and size arguments a script declared (scene, --size or
    --width and --height)."""
    flags = [args.scene] if getattr(args, "scene", "") else []
    if getattr(args, "size", None):
        width, height = args.size.split("x")
        flags += ["--width", width, "--height", height]
    elif getattr(args, "width", None):
        flags += ["--width", str(args.width), "--height", str(args.height)]
    return flags


# ---- Running fredholm ---------------------------------------------------------------------

class BenchError(RuntimeError):
    """A command failed; the message has its command line and its output's tail."""


class Run(dict):
    """A finished command: the JSON it wrote (`--stats`, `--json`; empty when none), and as
    attributes its command (a list), wall_seconds (the whole process), stdout ("" unless
    captured) and stderr."""


def environment(env=None):
    """os.environ with fredholm's and PoCL's caches defaulting to build/, then env over it."""
    merged = dict(os.environ)
    merged.setdefault("POCL_CACHE_DIR", os.path.join(ROOT, "build", "pocl-cache"))
    merged.setdefault("FREDHOLM_CACHE_DIR", os.path.join(ROOT, "build", "program-cache"))
    merged.update(env or {})
    return merged


def run(cmd, env=None, json_file=None, stdout=False):
    """Runs cmd (stdout discarded unless stdout=True, stderr kept); returns a Run with the
    JSON file json_file it wrote (removed first, so a stale one is never read). Raises
    BenchError with the command line and the output's tail if it fails."""
    cmd = [str(c) for c in cmd]
    if json_file and os.path.exists(json_file):
        os.remove(json_file)
    start = time.monotonic()
    try:
        done = subprocess.run(cmd, env=environment(env), stdout=subprocess.PIPE if stdout else subprocess.DEVNULL,
                              stderr=subprocess.PIPE, encoding="utf-8", errors="replace")
    except OSError as error:  # not there, not executable (being linked?)
        raise BenchError(f"{shlex.join(cmd)}: {error.strerror}") from error
    wall = time.monotonic() - start
    if done.returncode != 0:
        tail = ((done.stdout or "")[-2000:] + done.stderr[-2000:]).rstrip()
        raise BenchError(f"{shlex.join(cmd)} failed (exit {done.returncode})" + (f":\n{tail}" if tail else ""))
    result = Run()
    if json_file:
        with open(json_file) as f:
            result.update(json.load(f))
    result.command, result.wall_seconds, result.stdout, result.stderr = cmd, wall, done.stdout or "", done.stderr
    return result


def render(flags, out=None, binary=FREDHOLM, stats=True, env=None):
    """`BINARY render FLAGS -o OUT --force --stats OUT.json`: returns the --stats JSON as a Run
    (wall_seconds: the whole process, start-up and compilation included; stderr: its log).
    stats: True for OUT + ".json", a path, or False for none."""
    if stats is True:
        if not out:
            raise ValueError("render: --stats beside the image needs an output image")
        stats = out + ".json"
    outputs = (["-o", out, "--force"] if out else []) + (["--stats", stats] if stats else [])
    return run([binary, "render"] + list(flags) + outputs, env=env, json_file=stats or None)


def bench(args, json_file, binary=FREDHOLM):
    """`BINARY bench ARGS --json JSON_FILE --force`: returns the JSON (records, scenes...)."""
    return run([binary, "bench"] + list(args) + ["--json", json_file, "--force"], json_file=json_file)


def compare(image, reference, binary=FREDHOLM, block=None):
    """`fredholm compare`'s JSON: relmse, rmse, mae, mean_image, mean_reference."""
    cmd = [binary, "compare"] + (["--block", str(block)] if block is not None else []) + [image, reference]
    return json.loads(run(cmd, stdout=True).stdout)


def image_metadata(image):
    """The fredholm:* fields of an image's metadata (oiiotool --info -v), as strings by name
    (estimated_relmse, spp, seconds, ...)."""
    fields = {}
    for line in run(["oiiotool", "--info", "-v", image], stdout=True).stdout.splitlines():
        line = line.strip()
        if line.startswith("fredholm:"):
            key, value = line[len("fredholm:"):].split(":", 1)
            fields[key.strip()] = value.strip().strip('"')
    return fields


def mitsuba(python, args):
    """Renders with Mitsuba 3 (bench/peers/mitsuba_render.py ARGS) under python; returns the
    JSON line it prints (samples_per_second, seconds_render, spp, mean_rgb, ...)."""
    out = run([python, MITSUBA_RENDER] + list(args), stdout=True).stdout
    return json.loads([line for line in out.splitlines() if line.lstrip().startswith("{")][-1])


def main(function):
    """Runs a script's main; a failed command ends it with the command and its output's tail."""
    try:
        sys.exit(function())
    except BenchError as error:
        sys.exit(f"{os.path.basename(sys.argv[0])}: {error}")


# ---- Alternation and its summaries ------------------------------------------------------

def alternate(runners, rounds, warmup=True, order="rotate", after_round=None):
    """Runs every runner once a round for `rounds` rounds, in an order that changes each round
    so drift hits all alike: "rotate" starts round r at the r-th runner (for two: swapped every
    other round), "reverse" reverses the order every other round. runners maps names to
    callables, called with the round's index (None for the warm-up), or to command lines (run
    by `run`, giving Runs). warmup: each once first, in order, not counted (kernel compilation,
    JIT). after_round(r, results) follows each round. Returns {name: [result of each round]}."""
    names = list(runners)

    def call(name, r):
        runner = runners[name]
        return run(runner) if isinstance(runner, (list, tuple)) else runner(r)

    if warmup:
        for name in names:
            call(name, None)
    results = {name: [] for name in names}
    for r in range(rounds):
        if order == "rotate":
            sequence = names[r % len(names):] + names[:r % len(names)]
        elif order == "reverse":
            sequence = names if r % 2 == 0 else names[::-1]
        else:
            raise ValueError(f"alternate: order {order!r} is neither rotate nor reverse")
        for name in sequence:
            results[name].append(call(name, r))
        if after_round:
            after_round(r, results)
    return results


def runs(values, fmt="%.3f"):
    """Each round's value, comma-separated."""
    return ", ".join(fmt % v for v in values)


def ratios(numerators, denominators):
    """Round by round ratios (the two runs of a round ran close together)."""
    return [n / d for n, d in zip(numerators, denominators)]


def median_line(name, values, base, base_name, width=12, unit="Msamples/s"):
    """`NAME median M UNIT  (each round)  R.RRx BASE_NAME`, R the median's ratio to base."""
    m = statistics.median(values)
    return "%-*s median %.3f %s  (%s)  %.2fx %s" % (width, name, m, unit, runs(values), m / base, base_name)
