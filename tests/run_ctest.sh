#!/usr/bin/env bash
# tests/run_ctest.sh BUILD_DIR [ctest arguments...]: runs a build tree's CTest suites the
# way setup.sh and sanitize.sh do (kernel caches in the tree, output on failure) and fails
# when any test was skipped: every test a clone runs is the suite CI runs, so a skip means
# something the suite needs is missing, and it is reported, not passed over.
set -euo pipefail
build=$1
shift
log="$build/ctest.log"
# PoCL's kernel cache and fredholm's program cache live in the build tree, so a clean clone
# compiles each kernel once and reruns are fast.
POCL_CACHE_DIR="$PWD/$build/pocl-cache" FREDHOLM_CACHE_DIR="$PWD/$build/program-cache" \
  ctest --test-dir "$build" --output-on-failure --timeout 900 "$@" 2>&1 | tee "$log"
# CTest lists each skipped test under "The following tests did not run:" as "N - name (Skipped)".
skipped=$(grep -cE '^[[:space:]]*[0-9]+ - .*\(Skipped\)$' "$log" || true)
echo "run_ctest: $skipped skipped in $build" >&2
if [ "$skipped" -ne 0 ]; then
  echo "run_ctest: error: $skipped tests skipped (listed above): a skipped test fails the suite" >&2
  exit 1
fi
