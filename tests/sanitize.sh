#!/usr/bin/env bash
# The sanitizer part of `./setup.sh test` (and so of CI), after the main suite:
#  1. an AddressSanitizer + UndefinedBehaviorSanitizer build (clang) that runs the fast
#     suites (ctest -L fast) and each libFuzzer target for about FUZZ_SECONDS over a copy of
#     the seed corpus, failing on any crash, hang (> 2 s per input) or memory blow-up;
#  2. a ThreadSanitizer build that runs the multi-device suites (several devices, a device
#     failing mid-render) and the live view's threads in one process.
# Build trees: build-asan/ and build-tsan/. FUZZ_SECONDS (default 60) sets the fuzzing time.
set -euo pipefail
cd "$(dirname "$0")/.."
fuzz_seconds=${FUZZ_SECONDS:-60}

configure() {  # DIR SANITIZERS [extra cmake args]
  local dir=$1 sanitizers=$2
  shift 2
  local generator=()
  [ -f "$dir/CMakeCache.txt" ] || generator=(-G Ninja)
  cmake -S . -B "$dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
    -DFREDHOLM_SANITIZE="$sanitizers" -DFREDHOLM_WITH_EMBREE=OFF "$@" >/dev/null
}

# PoCL and its LLVM are not built with the sanitizers: leaks inside them are not ours.
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export TSAN_OPTIONS="suppressions=$PWD/tests/tsan.supp:halt_on_error=1:second_deadlock_stack=1"
start=$SECONDS

echo "sanitize: AddressSanitizer + UndefinedBehaviorSanitizer, fast suites and fuzzing" >&2
configure build-asan address,undefined -DFREDHOLM_FUZZ=ON
cmake --build build-asan --parallel "$(nproc)"
tests/run_ctest.sh build-asan -L fast -j"$(nproc)"

# A fixed seed and a fixed number of inputs (about FUZZ_SECONDS each on this project's CI
# machine) make CI's fuzzing reproducible: it finds the same thing or nothing on every run.
# tests/fuzz/run.sh explores with random seeds.
fuzz() {  # TARGET SEEDS RUNS_PER_SECOND
  local target=$1 seeds=$2 runs=$(( $3 * fuzz_seconds ))
  local work
  work=$(mktemp -d)
  cp -r "tests/fuzz/corpus/$seeds/." "$work/"
  echo "sanitize: fuzzing $target, $runs inputs" >&2
  # -timeout: an input taking over 2 s is a hang; -rss_limit_mb: memory blow-up.
  ASAN_OPTIONS="$ASAN_OPTIONS:quarantine_size_mb=64" \
  "build-asan/tests/fuzz/fuzz_$target" -seed=1 -runs="$runs" -timeout=2 -rss_limit_mb=2560 \
    -print_final_stats=1 -artifact_prefix="build-asan/fuzz-$target-" "$work" 2>&1 | tail -n 12 >&2
  rm -rf "$work"
}
fuzz scene_loader scene 1200
fuzz camera_json camera 12000
fuzz image_read image 200
fuzz checkpoint checkpoint 1000
fuzz bvh_build bvh 2000

echo "sanitize: ThreadSanitizer, multi-device suites and the live view" >&2
configure build-tsan thread
cmake --build build-tsan --parallel "$(nproc)" --target fredholm test_multi_device test_display
tests/run_ctest.sh build-tsan -R "TwoDevices|MultiDeviceCli|LiveView.InProcess"
echo "sanitize: done in $((SECONDS - start)) s" >&2
