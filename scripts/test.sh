#!/usr/bin/env bash
# Install what is missing, build, and run the whole test suite (what CI runs), in four stages:
#   1. tests:      the Release build in build/ (scripts/setup.sh, which also installs what is
#                  missing) and ctest over it: every test
#   2. format:     every tracked C++ file against .clang-format (clang-format --dry-run --Werror)
#   3. sanitizers: the same sources built with clang, -fsanitize=address,undefined, -O2, into
#                  build-asan/, and ctest over the tiers where memory errors live (below; fuzz/
#                  sanitizers/ holds the run-time options and the third-party suppressions)
#   4. fuzz:       the libFuzzer targets of fuzz/ built into build-fuzz/, each run for
#                  LUMISLAB_FUZZ_SECONDS (default 10) on its seed corpus, mutating from a fixed
#                  seed (-seed=1; LUMISLAB_FUZZ_ARGS overrides) so that a finding in CI replays
#                  on another machine (fuzz/run.sh; 0 s replays every seed once)
# Every stage runs even when an earlier one failed; each prints a summary line, and the script
# exits non-zero when any stage failed (a format difference, a build error, a failed test, a
# sanitizer report or a fuzz finding). CI runs all four. Developers may skip a stage:
# LUMISLAB_SKIP_FORMAT=1, LUMISLAB_SKIP_TESTS=1, LUMISLAB_SKIP_SANITIZERS=1, LUMISLAB_SKIP_FUZZ=1
# (skipping the tests also skips scripts/setup.sh, so the packages must already be installed).
#
# The test tiers (CTest labels, tests/CMakeLists.txt): unit, e2e, robustness, accuracy. The
# Release stage runs all of them. The sanitizer stage runs unit, e2e and robustness, which between
# them drive every reader, writer and tool on small inputs, bad input, kills and signals: that is
# where a memory error or undefined behaviour shows. It leaves out `accuracy` (ctest -LE
# accuracy): the long chains measured against the truth run the same code as the e2e tests with
# bigger numbers, several times slower under ASan, and their figures are the Release build's.
# Most of them skip themselves in a sanitized build anyway (testing::kSanitized); the ones that
# did not are EndToEnd.StageErrorIsMeasurableAgainstTheTruth, Plan.RecommendationMeasuredByTheStudy
# and JpegCodingNoise.ModelPredictsTheCodingErrorOfAKnownPicture (their code runs sanitized in the
# e2e tests, the study and plan tests and lib/photo's codec tests). The executables that hold only
# accuracy tests are not built there (LUMISLAB_TEST_SKIP_TIERS).
set -uo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)
fuzz_seconds=${LUMISLAB_FUZZ_SECONDS:-5}
# The sanitizer and fuzz builds: -O2 with line tables (readable stack traces). Not -O1: Eigen
# needs its inlining: at -O1 under ASan the calibrate tests run many times slower than Release.
# Unity builds and lld, as scripts/setup.sh's.
clang_args=(-G Ninja -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_UNITY_BUILD=ON
  -DCMAKE_EXE_LINKER_FLAGS=-fuse-ld=lld
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

# ctest over a build folder, summarised in one line; extra arguments go to ctest (-LE accuracy).
# ctest starts the long tests first, also on a fresh build folder: they declare their COST
# (tests/CMakeLists.txt).
run_ctest() {
  local dir=$1 log rc
  shift
  log=$(mktemp)
  ctest --test-dir "$dir" --output-on-failure -j "${ctest_jobs:-$jobs}" "$@" 2>&1 | tee "$log"
  rc=${PIPESTATUS[0]}
  grep -E "tests passed|tests failed" "$log" | tail -1 | sed "s|^|$dir: |"
  rm -f "$log"
  return "$rc"
}

# clang-format over every tracked C++ file (and nothing generated): about 2 s of CPU.
format_stage() {
  local cf
  cf=$(command -v clang-format || command -v clang-format-14) || {
    echo "format: clang-format not installed (scripts/setup.sh installs it)"
    return 1
  }
  git ls-files -z '*.cc' '*.h' '*.cpp' '*.hpp' | xargs -0 -P "$jobs" -n 50 "$cf" --dry-run --Werror
}

tests_stage() {
  # One job more than cores (here and under the sanitizers): several e2e tests mostly wait (the
  # Slurm cluster's polling, the virtual lab's stage and camera emulators), and their slots
  # would otherwise idle a core.
  scripts/setup.sh && ctest_jobs=$((jobs + 1)) run_ctest build
}

sanitizers_stage() {
  cmake -S . -B build-asan "${clang_args[@]}" -DLUMISLAB_SANITIZE=address,undefined \
    -DLUMISLAB_BUILD_BENCH=OFF -DLUMISLAB_TEST_SKIP_TIERS=accuracy >/dev/null &&
    cmake --build build-asan -j "$jobs" &&
    (source fuzz/sanitizers/env.sh && ctest_jobs=$((jobs + 1)) run_ctest build-asan -LE accuracy)
}

fuzz_stage() {
  cmake -S . -B build-fuzz "${clang_args[@]}" -DLUMISLAB_BUILD_FUZZ=ON \
    -DLUMISLAB_BUILD_STAGES=OFF -DLUMISLAB_BUILD_PREVIEW=OFF -DLUMISLAB_BUILD_TESTS=OFF \
    -DLUMISLAB_BUILD_BENCH=OFF >/dev/null &&
    cmake --build build-fuzz -j "$jobs" --target lumislab_fuzzers &&
    LUMISLAB_FUZZ_ARGS="${LUMISLAB_FUZZ_ARGS:--seed=1}" fuzz/run.sh "$fuzz_seconds" build-fuzz
}

if [ "${LUMISLAB_SKIP_TESTS:-0}" = 1 ]; then
  skipped tests LUMISLAB_SKIP_TESTS  # and scripts/setup.sh: the packages are assumed there
else
  stage tests tests_stage
fi
if [ "${LUMISLAB_SKIP_FORMAT:-0}" = 1 ]; then
  skipped format LUMISLAB_SKIP_FORMAT
else
  stage format format_stage
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
