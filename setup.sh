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
          libclang-rt-14-dev)  # sanitizers and libFuzzer for clang (tests/sanitize.sh)
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

build() {
  local generator=()
  [ -f build/CMakeCache.txt ] || generator=(-G Ninja)
  cmake -S . -B build "${generator[@]}" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build build --parallel "$(nproc)"
}

action=${1:-build}
[ $# -gt 0 ] && shift
install_packages
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
