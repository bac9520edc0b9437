#!/usr/bin/env bash
# Builds a self-contained fredholm for a machine that has only a GPU driver (no package
# registry, unknown glibc): bench/gpu/make_bundle.sh [BUNDLE_DIR] (default gpu-bundle/).
#
# The bundle holds a lean build (no OpenImageIO, whose dependencies run to hundreds of
# megabytes: images are PFM; no Embree), every shared library it loads, Debian's own
# dynamic loader to run it with (so the machine's glibc does not matter), the bench scenes
# (bunny, Sponza) and a CPU render of the Cornell box to compare the GPU's with.
# Then, on the GPU machine: bench/gpu/run_gpu.sh BUNDLE_DIR OUTDIR.
set -euo pipefail
cd "$(dirname "$0")/../.."
bundle=${1:-gpu-bundle}

cmake -S . -B build-gpu -G Ninja -DCMAKE_BUILD_TYPE=Release -DFREDHOLM_WITH_OIIO=OFF -DFREDHOLM_WITH_EMBREE=OFF \
  -DFREDHOLM_BUILD_TESTS=OFF -DCMAKE_EXE_LINKER_FLAGS="-static-libstdc++ -static-libgcc" >/dev/null
cmake --build build-gpu

mkdir -p "$bundle/bin" "$bundle/lib" "$bundle/scenes" "$bundle/reference"
cp build-gpu/fredholm "$bundle/bin/"
strip "$bundle/bin/fredholm"
# Every library the binary loads, the C library and the loader included.
ldd build-gpu/fredholm | awk '/=> \// {print $3} /^\s*\/.*ld-linux/ {print $1}' | while read -r lib; do
  cp -L "$lib" "$bundle/lib/"
done
[ -f "$bundle/lib/ld-linux-x86-64.so.2" ] || cp -L /lib64/ld-linux-x86-64.so.2 "$bundle/lib/"
# The rest of this glibc that a GPU driver's libraries may ask for: found first here, so
# none of the machine's own (another glibc version) is mixed in.
for lib in libdl.so.2 libpthread.so.0 librt.so.1 libgcc_s.so.1; do
  cp -L "/lib/x86_64-linux-gnu/$lib" "$bundle/lib/"
done

# The larger bench scenes, where FREDHOLM_SCENES names their folder (they do not ship).
for scene in bunny sponza; do
  [ -n "${FREDHOLM_SCENES:-}" ] && [ -d "$FREDHOLM_SCENES/$scene" ] && cp -r "$FREDHOLM_SCENES/$scene" "$bundle/scenes/"
done

# The CPU side of the GPU/CPU comparison, rendered here on PoCL with the full build
# (seed 3; the GPU renders use seeds 1 and 2). Kept when already there.
reference="$bundle/reference/cornell-mis"
if [ ! -f "$reference.pfm" ]; then
  [ -x build/fredholm ] || ./setup.sh build
  build/fredholm render --method mis --width 512 --height 512 --spp 1024 --seed 3 --device cpu \
    -o "$reference.pfm" --stats "$reference.json" --force
fi
du -sh "$bundle"
