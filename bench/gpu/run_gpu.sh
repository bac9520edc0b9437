#!/usr/bin/env bash
# Measures fredholm on whatever OpenCL devices a machine has (written for a GPU machine
# that has NVIDIA's driver but nothing of fredholm's), and writes what it found as JSON.
#
#   bench/gpu/run_gpu.sh [--small] FREDHOLM OUTDIR
#
# FREDHOLM is a bundle from bench/gpu/make_bundle.sh (run through the bundle's own
# dynamic loader, so the machine's glibc does not matter) or a fredholm binary. --small
# shrinks every size so the whole script runs in a minute on PoCL (the test suite does).
# Steps: probe the machine; find NVIDIA's OpenCL library when no ICD file names it;
# `fredholm devices`; the Cornell box at 512x512, mis, 1024 spp on the GPU (twice, two
# seeds: the noise level) and on a CPU device or against the bundle's CPU render, compared;
# `fredholm bench` on the four default scenes; a wavefront-size sweep; a render of the
# 1.1M-triangle scene. OUTDIR/results.json holds it all; OUTDIR/log.txt every command.
set -uo pipefail

here=$(cd "$(dirname "$0")" && pwd)
# The arguments ([--small] FREDHOLM OUTDIR), the machine, its OpenCL driver, and fh.
# shellcheck source=bench/gpu/gpu_env.sh
. "$here/gpu_env.sh"

if [ $small -eq 1 ]; then
  size=32; spp=16; sweep_spp=4; sweep="1024 2048 4096"; bench_size=32; repeats=1; big_size=32; big_spp=2
else
  size=512; spp=1024; sweep_spp=64; sweep="262144 524288 1048576 2097152 4194304"; bench_size=512; repeats=5
  big_size=512; big_spp=64
fi

if ! fh 60 devices; then
  # Say why no platform was found: the ICD loader's own account.
  OCL_ICD_DEBUG=15 timeout 60 "${fredholm[@]}" devices >>"$log" 2>&1
fi
"${fredholm[@]}" devices >"$out/devices.txt" 2>&1
if fh 60 devices --device gpu; then gpu=gpu; else gpu=0; fi
if fh 60 devices --device cpu; then cpu=cpu; else cpu=""; fi
echo "gpu_device=$gpu cpu_device=${cpu:-none}" >>"$out/probe.txt"

# ---- The Cornell box on the GPU and on a CPU --------------------------------------------
cornell=(render --method mis --width $size --height $size --spp $spp --force)
fh 900 "${cornell[@]}" --device "$gpu" --seed 1 -o "$out/gpu.pfm" --stats "$out/gpu-stats.json"
fh 900 "${cornell[@]}" --device "$gpu" --seed 2 -o "$out/gpu-seed2.pfm"
fh 60 compare "$out/gpu.pfm" "$out/gpu-seed2.pfm" && "${fredholm[@]}" compare "$out/gpu.pfm" "$out/gpu-seed2.pfm" \
  >"$out/compare-gpu-seeds.json" 2>>"$log"
if [ -n "$cpu" ]; then
  fh 1800 "${cornell[@]}" --device "$cpu" --seed 3 -o "$out/cpu.pfm" --stats "$out/cpu-stats.json"
elif [ -n "$cpu_reference" ] && [ -f "$cpu_reference" ] && [ $small -eq 0 ]; then
  cp "$cpu_reference" "$out/cpu.pfm"
  cp "${cpu_reference%.pfm}.json" "$out/cpu-stats.json" 2>/dev/null
fi
if [ -f "$out/cpu.pfm" ]; then
  "${fredholm[@]}" compare "$out/gpu.pfm" "$out/cpu.pfm" >"$out/compare-gpu-cpu.json" 2>>"$log"
fi

# ---- Ray casting, the wavefront sweep, the 1.1M-triangle scene -------------------------
bench_scenes=(cornell)
if [ -n "${FREDHOLM_SCENES:-}" ] && [ -f "$FREDHOLM_SCENES/sponza/sponza.obj" ] && [ -f "$FREDHOLM_SCENES/bunny/CornellBox-Bunny.obj" ]; then
  bench_scenes=(cornell bunny-box sponza bunnies-1m)
fi
fh 900 bench "${bench_scenes[@]}" --device "$gpu" --width $bench_size --height $bench_size --repeats $repeats \
  --json "$out/bench.json" --force
for wavefront in $sweep; do
  fh 600 render --method mis --width $size --height $size --spp $sweep_spp --device "$gpu" --wavefront "$wavefront" \
    -o "$out/sweep.pfm" --stats "$out/sweep-$wavefront.json" --force
done
if [ ${#bench_scenes[@]} -gt 1 ]; then
  fh 900 render bench:bunnies-1m --method mis --width $big_size --height $big_size --spp $big_spp --device "$gpu" \
    -o "$out/bunnies-1m.pfm" --stats "$out/bunnies-1m.json" --force
fi

python3 "$here/collect_results.py" "$out" $small
