#!/usr/bin/env bash
# One command from a fresh Debian 12 machine to a result:
#   ./setup.sh render [fredholm render options...]   build, then render (default: the Cornell box)
#   ./setup.sh test                                  build, run the whole test suite, then the
#                                                    sanitizer builds and fuzzers (tests/sanitize.sh)
#   ./setup.sh build                                 only install what is missing and build
# Installs the Debian packages that are missing (needs root or sudo), configures and
# builds into build/ (Release), and is quick when everything is already in place.
set -euo pipefail
cd "$(dirname "$0")"

PACKAGES=(build-essential cmake ninja-build pkg-config
          pocl-opencl-icd ocl-icd-opencl-dev opencl-headers opencl-clhpp-headers clinfo
          libopenimageio-dev openimageio-tools libtinyobjloader-dev libgtest-dev
          libcli11-dev nlohmann-json3-dev
          openmpi-bin libopenmpi-dev   # renders shared by the ranks of an mpirun job
          clang oclgrind   # the portability gates: offline compiles for other targets, a device simulator
          libclang-rt-14-dev   # sanitizers and libFuzzer for clang (tests/sanitize.sh)
          python3-pip)  # fetches Open Image Denoise (--denoise) from PyPI: install_oidn
# Optional: Embree for the bench comparison, matplotlib for the charts.
OPTIONAL_PACKAGES=(libembree-dev python3-matplotlib)

missing_packages() {
  local p
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || echo "$p"
  done
}

install_packages() {
  local missing
  missing=$(missing_packages "${PACKAGES[@]}" "${OPTIONAL_PACKAGES[@]}")
  [ -z "$missing" ] && return 0
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  echo "setup: installing missing Debian packages:" $missing >&2
  $sudo apt-get update -qq
  # shellcheck disable=SC2086
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends $missing >&2
}

# Intel Open Image Denoise for --denoise: not in Debian 12, so the library comes from PyPI's
# pyoidn wheel (pinned by version and hash), unpacked into /opt/oidn/lib with the wheel's own
# layout (its libraries find each other through $ORIGIN/../lib). fredholm loads it at run
# time (host/image/denoiser.h); the CPU device alone is installed.
OIDN_WHEEL=pyoidn-2.5.1.0-py3-none-manylinux2014_x86_64.whl
OIDN_SHA256=32ad13368f8de1ef63001942ad05b02a00cd732d1206d97f352d3a3f606d823e
OIDN_DIR=/opt/oidn
install_oidn() {
  [ -f "$OIDN_DIR/lib/libOpenImageDenoise.so.2" ] && return 0
  [ "$(uname -m)" = x86_64 ] || { echo "setup: no Open Image Denoise wheel for $(uname -m): --denoise is off" >&2; return 0; }
  local sudo="" tmp
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  tmp=$(mktemp -d)
  echo "setup: installing Intel Open Image Denoise into $OIDN_DIR (from PyPI's pyoidn wheel)" >&2
  /usr/bin/python3 -m pip download --quiet --no-deps --only-binary=:all: --platform manylinux2014_x86_64 \
    --dest "$tmp" "pyoidn==2.5.1.0" >&2
  echo "$OIDN_SHA256  $tmp/$OIDN_WHEEL" | sha256sum --check --quiet
  /usr/bin/python3 - "$tmp/$OIDN_WHEEL" "$tmp/lib" <<'PY'
import os, sys, zipfile
wheel, out = sys.argv[1:]
keep = ("libOpenImageDenoise.so.2", "libOpenImageDenoise_core.so.", "libOpenImageDenoise_device_cpu.so.",
        "libtbb.so.12")
os.makedirs(out)
with zipfile.ZipFile(wheel) as z:
    for name in z.namelist():
        base = os.path.basename(name)
        if name.startswith("pyoidn/oidn/lib/") and base.startswith(keep):
            with z.open(name) as src, open(os.path.join(out, base), "wb") as dst:
                dst.write(src.read())
PY
  $sudo mkdir -p "$OIDN_DIR"
  $sudo rm -rf "$OIDN_DIR/lib"
  $sudo cp -r "$tmp/lib" "$OIDN_DIR/lib"
  rm -rf "$tmp"
}

build() {
  local generator=()
  [ -f build/CMakeCache.txt ] || generator=(-G Ninja)
  cmake -S . -B build "${generator[@]}" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build build --parallel "$(nproc)"
}

action=${1:-build}
[ $# -gt 0 ] && shift
install_packages
install_oidn
build
case "$action" in
  build) ;;
  render) exec build/fredholm render "$@" ;;
  test)
    # The whole suite; a skipped test counts as a failure (tests/run_ctest.sh).
    tests/run_ctest.sh build -j"$(nproc)" "$@"
    # Then the sanitizer builds and the fuzzers (FREDHOLM_SANITIZERS=0 skips them locally).
    [ "${FREDHOLM_SANITIZERS:-1}" = 0 ] || tests/sanitize.sh ;;
  *) echo "setup.sh: unknown action '$action' (use: build, render, test)" >&2; exit 2 ;;
esac
