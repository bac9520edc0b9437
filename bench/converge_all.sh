#!/bin/sh
# Every error-against-time chart of bench/RESULTS.md and the method x scene table, from a
# fresh clone (after ./setup.sh build; Veach's scene, which does not ship, where
# FREDHOLM_SCENES names the folder that holds veach-mis/). About 20 minutes on 2 cores. CSVs and charts land in bench/results/convergence/,
# images and references in bench/out/converge/.
set -eu
cd "$(dirname "$0")/.."
out=bench/out/converge
mkdir -p "$out" bench/results/convergence

chart() {  # chart NAME converge.py-arguments...
  name=$1
  shift
  echo "== $name"
  bench/converge.py "$@" --out "$out"
  cp "$out/$name.csv" "$out/$name.png" bench/results/convergence/
}

# Every method, light tracing, bidirectional path tracing, vcm and --method auto included (auto's
# points count its pilots).
methods=pt,nee,mis,lt,bdpt,vcm,auto

# The closed-form scene against its exact image.
build/fredholm reference builtin:plane-under-light --width 128 --height 128 -o "$out/plane-exact.exr" --force
chart builtin-plane-under-light builtin:plane-under-light --ref "$out/plane-exact.exr" --max-spp 256 --methods $methods
# The rest against long mis renders of fredholm itself.
chart cornell-box --ref-spp 4096 --max-spp 256 --methods $methods
# The caustic against light tracing's: a mis reference is itself too noisy in the caustic.
chart caustic scenes/failure/caustic.obj --ref-spp 4096 --ref-method lt --max-spp 256 --methods $methods
for s in hidden-light tiny-light; do
  chart "$s" "scenes/failure/$s.obj" --ref-spp 4096 --max-spp 256 --methods $methods
done
chart CornellBox-Glossy scenes/cornell-box/legacy-glossy-2011/CornellBox-Glossy.obj --ref-spp 2048 --max-spp 128 \
  --methods $methods
chart CornellBox-Water scenes/cornell-box/CornellBox-Water.obj --ref-spp 2048 --max-spp 128 --methods $methods
veach=${FREDHOLM_SCENES:-}/veach-mis/veach_mis.obj
if [ -n "${FREDHOLM_SCENES:-}" ] && [ -f "$veach" ]; then
  chart veach_mis "$veach" --width 192 --height 128 --ref-spp 2048 --max-spp 128 --methods $methods
else
  echo "(FREDHOLM_SCENES names no folder with veach-mis/veach_mis.obj: Veach's scene is left out)"
fi
/usr/bin/python3 bench/converge_table.py bench/results/convergence
