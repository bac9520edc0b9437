#!/usr/bin/env bash
# Renders the README's thumbnails of the scenes in $FREDHOLM_SCENES (the archive's scenes) into
# bench/results/thumbnails/, small and with enough samples to judge the materials.
# usage: bench/render_thumbnails.sh [SPP]   (run after ./setup.sh build)
set -euo pipefail
cd "$(dirname "$0")/.."
spp=${1:-256}
scenes=${FREDHOLM_SCENES:?set FREDHOLM_SCENES to the folder of the archive scenes}
out=bench/results/thumbnails
mkdir -p "$out"
render() {  # name obj width height [extra flags]
  local name=$1 obj=$2 w=$3 h=$4
  shift 4
  build/fredholm render "$scenes/$obj" --width "$w" --height "$h" --spp "$spp" -o "$out/$name.png" --force "$@" \
    2>&1 | grep -E "error|rendered" || true
}
render cornell-mirror cornell-box/CornellBox-Mirror.obj 160 160
render cornell-sphere cornell-box/CornellBox-Sphere.obj 160 160
render cornell-water cornell-box/CornellBox-Water.obj 160 160
render cornell-glossy-2011 cornell-box/legacy-glossy-2011/CornellBox-Glossy.obj 160 160
render cornell-bunny bunny/CornellBox-Bunny.obj 160 160
render veach-mis veach-mis/veach_mis.obj 240 160
render mori-knob mori-knob/testObj.obj 160 160 --env 0.3,0.3,0.3
render sponza sponza/sponza.obj 240 160 --env 2,2,2
