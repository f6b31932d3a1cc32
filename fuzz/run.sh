#!/usr/bin/env bash
# Runs every fuzz target (one per folder of fuzz/corpus/) for a bounded time on its seed corpus
# and prints one line per target; exits non-zero when any target found something (a crash,
# sanitizer report, timeout, out-of-memory, leak or an exception that is not a lumislab::Error).
#
# Usage: fuzz/run.sh [seconds per target] [fuzz build folder]
#   defaults: 25 s, build-fuzz (configure it as scripts/test.sh does, or see fuzz/README.md);
#   0 s replays the seed corpus once without mutating it (deterministic). CI does not replay:
#   scripts/test.sh mutates each target for LUMISLAB_FUZZ_SECONDS (10) from -seed=1
# Environment:
#   LUMISLAB_FUZZ_TARGETS  space-separated targets to run (default: all of fuzz/corpus/)
#   LUMISLAB_FUZZ_JOBS     targets run side by side (default: nproc)
#   LUMISLAB_FUZZ_ARGS     extra libFuzzer flags for every target (e.g. -seed=1)
# Findings are saved under fuzz/findings/<target>/ (not committed; fuzz/.gitignore); each
# target's log is <build>/fuzz-logs/<target>.log and the inputs it found that add coverage are in
# <build>/fuzz-corpus/<target>/ (the committed seeds in fuzz/corpus/ are only read).
set -uo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-25}
build=${2:-build-fuzz}
jobs=${LUMISLAB_FUZZ_JOBS:-$(nproc)}
source fuzz/sanitizers/env.sh

targets=${LUMISLAB_FUZZ_TARGETS:-$(cd fuzz/corpus && ls -d fuzz_* | tr '\n' ' ')}
mkdir -p "$build/fuzz-logs" "$build/fuzz-corpus" fuzz/findings

dict_of() {
  case $1 in
    fuzz_scene | fuzz_dataset | fuzz_slab_info | fuzz_screen_calibration | fuzz_camera_calibration) echo fuzz/dict/json.dict ;;
    fuzz_radiometric_calibration) echo fuzz/dict/radiometric.dict ;;
    fuzz_photo) echo fuzz/dict/photo.dict ;;
    fuzz_slab_position) echo fuzz/dict/exr.dict ;;
    fuzz_mesh_ply) echo fuzz/dict/ply.dict ;;
    fuzz_mesh_obj) echo fuzz/dict/obj.dict ;;
    fuzz_ies) echo fuzz/dict/ies.dict ;;
    fuzz_eulumdat) echo fuzz/dict/eulumdat.dict ;;
    fuzz_tm25 | fuzz_photometry_info) echo fuzz/dict/tm25.dict ;;
  esac
}

run_one() {
  local t=$1 exe="$build/fuzz/$1" log="$build/fuzz-logs/$1.log" dict
  if [ ! -x "$exe" ]; then
    echo "fuzz: $t: MISSING ($exe not built)"
    return 1
  fi
  mkdir -p "$build/fuzz-corpus/$t" "fuzz/findings/$t"
  dict=$(dict_of "$t")
  # -timeout: one input may take 10 s; -rss_limit_mb also caps a single malloc (malloc_limit_mb).
  # -print_final_stats: the execution count for the summary.
  # 0 s: replay the seeds once (-runs=0, deterministic); otherwise mutate for that long.
  local budget=(-max_total_time="$seconds")
  [ "$seconds" = 0 ] && budget=(-runs=0)
  "$exe" "${budget[@]}" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
    -artifact_prefix="fuzz/findings/$t/" ${dict:+-dict="$dict"} ${LUMISLAB_FUZZ_ARGS:-} \
    "$build/fuzz-corpus/$t" "fuzz/corpus/$t" >"$log" 2>&1
  local rc=$?
  local execs cov ft corp rate
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  cov=$(grep -oE 'cov: [0-9]+' "$log" | tail -1 | cut -d' ' -f2)
  ft=$(grep -oE 'ft: [0-9]+' "$log" | tail -1 | cut -d' ' -f2)
  corp=$(grep -oE 'corp: [0-9]+/[0-9]+[a-zA-Z]*' "$log" | tail -1 | cut -d' ' -f2)
  local stats="${execs:-?} execs (${rate:-?}/s), cov ${cov:-?}, ft ${ft:-?}, corpus ${corp:-?}"
  if [ $rc -eq 0 ]; then
    echo "fuzz: $t: ok, ${seconds} s: $stats"
  else
    local what artifact
    what=$(grep -m1 -oE '(ai_assert failure.*|ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer): [^ ]+( [^ ]+)?|runtime error: .*|==lumislab-fuzz== FINDING: .*|ALARM: .*|out-of-memory.*|deadly signal)' "$log")
    artifact=$(grep -oE "fuzz/findings/$t/[^ ]+" "$log" | tail -1)
    # The report itself (the first 40 lines from the error on), for CI logs that keep no files.
    local report
    report=$(grep -m1 -n -E '(==ERROR|ERROR: libFuzzer|runtime error|==lumislab-fuzz==|ai_assert|ALARM|DEADLYSIGNAL)' "$log" |
      cut -d: -f1 | { read -r at && tail -n +"$at" "$log" | head -40 | sed "s|^|  $t: |"; })
    printf '%s\n%s\n' "fuzz: $t: FINDING (exit $rc): ${what:-see $log}; input ${artifact:-?}; log $log; $stats" "$report"
  fi
  return $rc
}

failed=0
running=0
for t in $targets; do
  run_one "$t" &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then
    wait -n || failed=$((failed + 1))
    running=$((running - 1))
  fi
done
while [ "$running" -gt 0 ]; do
  wait -n || failed=$((failed + 1))
  running=$((running - 1))
done
n=$(echo $targets | wc -w)
if [ "$failed" -ne 0 ]; then
  echo "fuzz: $failed of $n targets FAILED (inputs under fuzz/findings/, logs under $build/fuzz-logs/)"
  exit 1
fi
echo "fuzz: all $n targets ran ${seconds} s without a finding"
