#!/usr/bin/env bash
# Install what is missing, build, and run the whole test suite (what CI runs), in three stages:
#   1. tests:      the Release build in build/ (pipelines/setup.sh) and ctest over it
#   2. sanitizers: the same sources built with clang, -fsanitize=address,undefined, -O2, into
#                  build-asan/, and ctest over the same tests (fuzz/sanitizers/ holds the run-time
#                  options and the third-party suppressions)
#   3. fuzz:       the libFuzzer targets of fuzz/ built into build-fuzz/, each run for
#                  LUMISLAB_FUZZ_SECONDS (default 15) on its seed corpus, mutating from a fixed
#                  seed (-seed=1; LUMISLAB_FUZZ_ARGS overrides) so that a finding in CI replays
#                  on another machine (fuzz/run.sh; 0 s replays every seed once)
# Every stage runs even when an earlier one failed; each prints a summary line, and the script
# exits non-zero when any stage failed (a build error, a failed test, a sanitizer report or a fuzz
# finding). CI runs all three. Developers may skip a stage: LUMISLAB_SKIP_TESTS=1,
# LUMISLAB_SKIP_SANITIZERS=1, LUMISLAB_SKIP_FUZZ=1 (skipping the first also skips
# pipelines/setup.sh, so the packages must already be installed).
set -uo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)
fuzz_seconds=${LUMISLAB_FUZZ_SECONDS:-15}
# The sanitizer and fuzz builds: -O2 with line tables (readable stack traces). Not -O1: Eigen
# needs its inlining: at -O1 under ASan the calibrate tests run many times slower than Release.
# Unity builds, as pipelines/setup.sh's.
clang_args=(-G Ninja -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_UNITY_BUILD=ON
  -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG"
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG")

summary=()
failed=0
stage() {  # stage <name> <function>: runs it, records "name: ok|FAILED (s)"
  local name=$1 start=$SECONDS rc
  echo "=== $name ==="
  "$2"
  rc=$?
  local line="$name: $([ $rc -eq 0 ] && echo ok || echo "FAILED (exit $rc)") in $((SECONDS - start)) s"
  echo "=== $line ==="
  summary+=("$line")
  [ $rc -eq 0 ] || failed=1
}
skipped() {
  echo "=== $1: skipped ($2=1) ==="
  summary+=("$1: skipped ($2=1)")
}

# ctest over a build folder, summarised in one line. ctest starts the tests it knows to be long
# first (from Testing/Temporary/CTestCostData.txt); a fresh build folder has no such file, so the
# long end-to-end tests could start last and run alone on one core at the end. tests/ctest_costs/
# holds the test times of a CI run (seconds, regenerated now and then from a build folder's file:
# see docs/design.md §8.2); they seed a build folder that has none.
run_ctest() {
  local dir=$1 costs=$2 log rc
  local seeded="$dir/Testing/Temporary/CTestCostData.txt"
  if [ ! -f "$seeded" ] && [ -f "$costs" ]; then
    mkdir -p "$dir/Testing/Temporary" && cp "$costs" "$seeded"
  fi
  log=$(mktemp)
  ctest --test-dir "$dir" --output-on-failure -j "$jobs" 2>&1 | tee "$log"
  rc=${PIPESTATUS[0]}
  grep -E "tests passed|tests failed" "$log" | tail -1 | sed "s|^|$dir: |"
  rm -f "$log"
  return "$rc"
}

tests_stage() {
  pipelines/setup.sh && run_ctest build tests/ctest_costs/release.txt
}

sanitizers_stage() {
  cmake -S . -B build-asan "${clang_args[@]}" -DLUMISLAB_SANITIZE=address,undefined \
    -DLUMISLAB_BUILD_BENCH=OFF >/dev/null &&
    cmake --build build-asan -j "$jobs" &&
    (source fuzz/sanitizers/env.sh && run_ctest build-asan tests/ctest_costs/sanitizers.txt)
}

fuzz_stage() {
  cmake -S . -B build-fuzz "${clang_args[@]}" -DLUMISLAB_BUILD_FUZZ=ON \
    -DLUMISLAB_BUILD_STAGES=OFF -DLUMISLAB_BUILD_PREVIEW=OFF -DLUMISLAB_BUILD_TESTS=OFF \
    -DLUMISLAB_BUILD_BENCH=OFF >/dev/null &&
    cmake --build build-fuzz -j "$jobs" --target lumislab_fuzzers &&
    LUMISLAB_FUZZ_ARGS="${LUMISLAB_FUZZ_ARGS:--seed=1}" fuzz/run.sh "$fuzz_seconds" build-fuzz
}

if [ "${LUMISLAB_SKIP_TESTS:-0}" = 1 ]; then
  skipped tests LUMISLAB_SKIP_TESTS  # and pipelines/setup.sh: the packages are assumed there
else
  stage tests tests_stage
fi
if [ "${LUMISLAB_SKIP_SANITIZERS:-0}" = 1 ]; then
  skipped sanitizers LUMISLAB_SKIP_SANITIZERS
else
  stage sanitizers sanitizers_stage
fi
if [ "${LUMISLAB_SKIP_FUZZ:-0}" = 1 ]; then
  skipped fuzz LUMISLAB_SKIP_FUZZ
else
  stage fuzz fuzz_stage
fi

echo "=== summary ==="
printf '%s\n' "${summary[@]}"
exit $failed
