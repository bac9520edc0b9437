#!/usr/bin/env bash
# Runs one fuzz target longer than CI does, on demand:
#   tests/fuzz/run.sh scene_loader|camera_json|image_read|checkpoint|bvh_build [SECONDS, default 3600]
# after `tests/sanitize.sh` (or any build-asan with -DFREDHOLM_FUZZ=ON). New inputs that
# widen coverage are kept in build-asan/fuzz-corpus-TARGET; a crash, hang or memory blow-up
# is written to build-asan/fuzz-TARGET-*: add it to tests/fuzz/corpus/ once fixed, as a
# regression input CI replays.
set -euo pipefail
cd "$(dirname "$0")/../.."
target=${1:?usage: tests/fuzz/run.sh scene_loader|camera_json|image_read|checkpoint|bvh_build [SECONDS]}
seconds=${2:-3600}
case "$target" in
  scene_loader) seeds=scene ;;
  camera_json) seeds=camera ;;
  image_read) seeds=image ;;
  checkpoint) seeds=checkpoint ;;
  bvh_build) seeds=bvh ;;
  *) echo "run.sh: unknown target '$target'" >&2; exit 2 ;;
esac
corpus="build-asan/fuzz-corpus-$target"
mkdir -p "$corpus"
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1:quarantine_size_mb=64 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
exec "build-asan/tests/fuzz/fuzz_$target" -max_total_time="$seconds" -timeout=2 -rss_limit_mb=2560 \
  -artifact_prefix="build-asan/fuzz-$target-" "$corpus" "tests/fuzz/corpus/$seeds"
