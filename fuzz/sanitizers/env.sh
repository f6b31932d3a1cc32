# Sourced by scripts/test.sh and fuzz/run.sh: the sanitizer run-time options of the sanitizer
# build's test suite and of the fuzz targets (fuzz/README.md). Options already in the environment
# are kept and come last, so they win over these on a clash.
_lumislab_sanitizers="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
# Every ASan error is fatal; leaks are checked at exit (LSan, suppressions in lsan.supp).
# exitcode=66: a process that a sanitizer stops exits 66, never one of lumislab's codes 0-3, so a
# test that runs a tool and expects exit 1, 2 or 3 fails when the tool hit a sanitizer report.
# detect_stack_use_after_return stays off (ASan's default): it makes the CPU-bound tests markedly
# slower; set ASAN_OPTIONS=detect_stack_use_after_return=1 before sourcing to have it.
export ASAN_OPTIONS="exitcode=66:detect_leaks=1:check_initialization_order=1:\
strict_init_order=1:handle_abort=1:symbolize=1${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export LSAN_OPTIONS="exitcode=66:suppressions=$_lumislab_sanitizers/lsan.supp:print_suppressions=0\
${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
# UBSan: the build uses -fno-sanitize-recover=undefined (an error ends the process); stack
# traces for the report.
export UBSAN_OPTIONS="exitcode=66:print_stacktrace=1:halt_on_error=1:\
suppressions=$_lumislab_sanitizers/ubsan.supp${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
if [ -z "${ASAN_SYMBOLIZER_PATH:-}" ]; then
  for _s in llvm-symbolizer llvm-symbolizer-14; do
    if command -v "$_s" >/dev/null; then
      export ASAN_SYMBOLIZER_PATH="$(command -v "$_s")"
      break
    fi
  done
  unset _s
fi
unset _lumislab_sanitizers
