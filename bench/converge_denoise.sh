#!/bin/sh
# Where --denoise pays: relMSE against time for mis and mis+denoise (the denoiser's time added)
# against long mis renders, on the Cornell box, the glossy Cornell box and, given its OBJ,
# Veach's multiple-importance scene (not shipped: its files state no license). The crossover,
# where the denoiser's bias exceeds the noise it removes, is printed and marked on each chart.
# After ./setup.sh build (which installs Open Image Denoise); about 25 minutes on 2 cores.
#   bench/converge_denoise.sh [VEACH_MIS.obj]
# CSVs and charts land in bench/results/convergence/denoise/, images and references in bench/out/converge/.
set -eu
cd "$(dirname "$0")/.."
out=bench/out/converge
mkdir -p "$out" bench/results/convergence/denoise

chart() {  # chart NAME converge.py-arguments...
  name=$1
  shift
  echo "== $name"
  bench/converge.py "$@" --methods mis,mis+denoise --name "$name" --out "$out"
  cp "$out/$name.csv" "$out/$name.png" bench/results/convergence/denoise/
}

chart denoise-cornell-box --ref-spp 32768 --max-spp 4096
chart denoise-CornellBox-Glossy scenes/cornell-box/legacy-glossy-2011/CornellBox-Glossy.obj --ref-spp 65536 --max-spp 8192
if [ $# -gt 0 ]; then
  chart denoise-veach_mis "$1" --width 192 --height 128 --ref-spp 16384 --max-spp 4096
fi
