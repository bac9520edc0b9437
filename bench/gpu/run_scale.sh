#!/usr/bin/env bash
# Renders past 2^32 samples on a GPU machine: the Cornell box at 3840x2160 with 1024 spp, at
# 1920x1080 with 4096 spp and at 7680x4320 with 256 spp (8.5e9 samples each), with the
# seconds each took, the host's peak memory (/usr/bin/time -v where the machine has it) and each image's channel means.
#
#   bench/gpu/run_scale.sh [--small] FREDHOLM OUTDIR
#
# FREDHOLM is a bundle from bench/gpu/make_bundle.sh or a fredholm binary. --small renders
# 64x36 at 4 spp instead (a check of the script on any machine); SCALE_SIZES="W H SPP;..."
# picks other sizes. OUTDIR/scale.txt has the
# figures; OUTDIR/log.txt every command and its output.
set -uo pipefail

here=$(cd "$(dirname "$0")" && pwd)
# The arguments ([--small] FREDHOLM OUTDIR), the machine, its OpenCL driver, and fh.
# shellcheck source=bench/gpu/gpu_env.sh
. "$here/gpu_env.sh"

if fh 60 devices --device gpu; then gpu=gpu; else gpu=0; fi
if [ $small -eq 1 ]; then
  sizes=("64 36 4" "32 18 16")
else
  sizes=("3840 2160 1024" "1920 1080 4096" "7680 4320 256")
fi
if [ -n "${SCALE_SIZES:-}" ]; then IFS=';' read -r -a sizes <<<"$SCALE_SIZES"; fi
timer=()
[ -x /usr/bin/time ] && timer=(/usr/bin/time -v)

{
  echo "device: $("${fredholm[@]}" devices --device "$gpu" 2>&1 | tail -n 1)"
  for size in "${sizes[@]}"; do
    read -r width height spp <<<"$size"
    name="cornell-${width}x${height}-${spp}spp"
    start=$(date +%s%N)
    echo "\$ fredholm render --width $width --height $height --spp $spp --device $gpu" >>"$log"
    "${timer[@]}" timeout 900 "${fredholm[@]}" render --width "$width" --height "$height" --spp "$spp" \
      --device "$gpu" -o "$out/$name.pfm" --stats "$out/$name.json" --force >>"$log" 2>"$out/$name.time"
    rc=$?
    cat "$out/$name.time" >>"$log"
    seconds=$(awk -v a="$start" -v b="$(date +%s%N)" 'BEGIN {printf "%.1f", (b - a) / 1e9}')
    peak=$(awk -F': ' '/Maximum resident set size/ {print $2 " KiB"}' "$out/$name.time")
    means=$(timeout 120 "${fredholm[@]}" compare "$out/$name.pfm" "$out/$name.pfm" 2>&1 | tr -d '\n')
    echo "$name: exit $rc, $seconds s wall, peak host memory ${peak:-not measured}; compare: $means"
  done
} >"$out/scale.txt" 2>&1
cat "$out/scale.txt"
