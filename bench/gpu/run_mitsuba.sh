#!/usr/bin/env bash
# Mitsuba 3 beside fredholm on the GPU machine: the Cornell box of run_gpu.sh (built-in
# CornellBox-Original and its camera, 512x512, 1024 spp) rendered in alternating rounds by
# Mitsuba's path integrator (bench/peers/mitsuba_render.py) and, with --fredholm, by fredholm
# `mis` at the same work per sample (--max-depth 16 --rr-depth 6; Mitsuba max_depth 17,
# rr_depth 5), so each round gives a ratio taken in one sitting.
#
#   bench/gpu/run_mitsuba.sh [--small] [--variant cuda_ad_rgb] [--rounds N] [--spp N]
#                            [--fredholm BUNDLE_OR_BINARY] WHEELS OUTDIR
#
# WHEELS holds the packed mitsuba and drjit wheels (bench/gpu/pack_mitsuba.py) for this
# machine's python3 ($PYTHON to name another); they are installed into a temporary folder,
# nothing else of the machine's is touched. Results go to OUTDIR/mitsuba/: results.json
# (bench/gpu/collect_mitsuba.py), each round's JSON, log.txt. --small: 32x32, 16 spp, two
# rounds. Tested on the CPU with --variant llvm_ad_rgb (docs/benchmarking.md).
#
# One device call for both (carry gpu-bundle, which holds the bundle and gpu-bundle/wheels
# from `bench/gpu/pack_mitsuba.py`; a few minutes, timeout_s 480):
#   o=/tmp/gpu; bench/gpu/run_gpu.sh gpu-bundle $o; bench/gpu/run_mitsuba.sh --fredholm gpu-bundle
#   gpu-bundle/wheels $o; cp $o/results.json $OUT/gpu.json; cp $o/mitsuba/results.json $OUT/mitsuba.json;
#   tar czf $OUT/logs.tgz --exclude='*.pfm' --exclude='*.exr' --exclude=program-cache -C /tmp gpu
set -uo pipefail

here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
small=0 variant=cuda_ad_rgb rounds="" spp="" target=""
while [ $# -gt 0 ]; do
  case $1 in
    --small) small=1; shift ;;
    --variant) variant=$2; shift 2 ;;
    --rounds) rounds=$2; shift 2 ;;
    --spp) spp=$2; shift 2 ;;
    --fredholm) target=$2; shift 2 ;;
    -*) echo "$0: unknown option $1" >&2; exit 2 ;;
    *) break ;;
  esac
done
if [ $# -ne 2 ]; then
  echo "usage: $0 [--small] [--variant V] [--rounds N] [--spp N] [--fredholm BUNDLE_OR_BINARY] WHEELS OUTDIR" >&2
  exit 2
fi
wheels=$(cd "$1" && pwd) || exit 2
outdir=$2
python=${PYTHON:-python3}
if [ $small -eq 1 ]; then size=32; : "${spp:=16}" "${rounds:=2}"; else size=512; : "${spp:=1024}" "${rounds:=5}"; fi

out="$outdir/mitsuba"
rm -rf "$out"
if [ -n "$target" ]; then
  # The probe, the OpenCL set-up and `fh` of run_gpu.sh, with its log in $out.
  small_flag=()
  [ $small -eq 1 ] && small_flag=(--small)
  set -- "${small_flag[@]}" "$target" "$out"
  # shellcheck source=bench/gpu/gpu_env.sh
  . "$here/gpu_env.sh"
  # run_gpu.sh's kernel cache, when it ran first into the same OUTDIR.
  [ -d "$outdir/program-cache" ] && export FREDHOLM_CACHE_DIR="$outdir/program-cache"
  if fh 60 devices --device gpu; then device=gpu; else device=0; fi
else
  mkdir -p "$out" || exit 2
  log="$out/log.txt"
  : >"$log"
  { uname -a; nproc; nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv 2>&1; } \
    >"$out/probe.txt" 2>&1
fi

# Dr.Jit looks for the CUDA driver and OptiX by name only; the driver's libraries may sit
# where the loader's cache does not list them (as NVIDIA's OpenCL library does).
find_driver_lib() {
  local d
  for d in /usr/local/nvidia/lib64 /usr/local/nvidia/lib /usr/lib/x86_64-linux-gnu /usr/lib64 /usr/lib \
           /usr/local/cuda/compat; do
    [ -e "$d/$1" ] && { echo "$d/$1"; return; }
  done
  ldconfig -p 2>/dev/null | awk -v lib="$1" '$1 == lib {print $NF; exit}'
}
if [[ $variant == cuda* ]]; then
  lib=$(find_driver_lib libcuda.so.1)
  [ -n "$lib" ] && [ -z "${DRJIT_LIBCUDA_PATH:-}" ] && export DRJIT_LIBCUDA_PATH=$lib
  lib=$(find_driver_lib libnvoptix.so.1)
  [ -n "$lib" ] && [ -z "${DRJIT_LIBOPTIX_PATH:-}" ] && export DRJIT_LIBOPTIX_PATH=$lib
elif [[ $variant == llvm* ]] && [ -z "${DRJIT_LIBLLVM_PATH:-}" ]; then
  # Dr.Jit 1.5 takes the first libLLVM it finds, which on Debian 12 is 15, too old for it.
  lib=$(for f in /usr/lib/x86_64-linux-gnu/libLLVM*.so.*; do
          [ -e "$f" ] && echo "$(basename "$f" | grep -o '[0-9]\+' | head -1) $f"
        done | sort -n | tail -1 | cut -d' ' -f2)
  [ -n "$lib" ] && export DRJIT_LIBLLVM_PATH=$lib
fi

# ---- Mitsuba and Dr.Jit into a folder of their own --------------------------------------
site=$(mktemp -d "${TMPDIR:-/tmp}/fh-mitsuba-site.XXXXXX") || exit 2
trap 'rm -rf "$site"' EXIT
{
  echo "\$ $python -m pip install --no-index --no-deps --target $site $wheels/*.whl"
  "$python" -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target "$site" \
    "$wheels"/*.whl
} >>"$log" 2>&1 || { echo "run_mitsuba: installing the wheels failed (see $log)" >&2; exit 1; }
export PYTHONPATH="$site${PYTHONPATH:+:$PYTHONPATH}"
{
  echo "== mitsuba"
  echo "python: $("$python" --version 2>&1); wheels: $(cd "$wheels" && echo *.whl)"
  echo "DRJIT_LIBCUDA_PATH=${DRJIT_LIBCUDA_PATH:-} DRJIT_LIBOPTIX_PATH=${DRJIT_LIBOPTIX_PATH:-}"
  # A Mitsuba found elsewhere first would measure something else.
  "$python" -c "import mitsuba as mi, drjit as dr, sys; assert mi.__file__.startswith(sys.argv[1]), mi.__file__
mi.set_variant(sys.argv[2]); print('mitsuba', mi.__version__, 'drjit', dr.__version__, 'variant', mi.variant())" \
    "$site" "$variant"
} >>"$out/probe.txt" 2>&1 || { echo "run_mitsuba: mitsuba $variant does not load (see $out/probe.txt)" >&2; exit 1; }

# ---- The rounds ---------------------------------------------------------------------------
mitsuba() {  # mitsuba ROUND
  local command=("$python" "$root/bench/peers/mitsuba_render.py" --variant "$variant" --spp "$spp"
                 --width "$size" --height "$size" --max-bounces 16 --rr-depth 5 --seed "$1" --threads "$(nproc)"
                 --out "$out/mitsuba-$1.exr")
  echo "\$ ${command[*]}" >>"$log"
  timeout 900 "${command[@]}" >"$out/round$1-mitsuba.json" 2>>"$log"
  echo "(exit $?)" >>"$log"
}
fredholm_round() {  # fredholm_round ROUND
  fh 900 render --method mis --width $size --height $size --spp "$spp" --max-depth 16 --rr-depth 6 \
    --device "$device" --seed "$1" -o "$out/fredholm-$1.pfm" --stats "$out/round$1-fredholm.json" --force
}
for ((r = 1; r <= rounds; r++)); do
  # Who goes first alternates, so drift and warm caches favour neither.
  if [ -z "$target" ]; then
    mitsuba $r
  elif [ $((r % 2)) -eq 1 ]; then
    mitsuba $r; fredholm_round $r
  else
    fredholm_round $r; mitsuba $r
  fi
done

"$python" "$here/collect_mitsuba.py" "$out" "$variant" "$size" "$spp" $small
