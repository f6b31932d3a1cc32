#!/usr/bin/env bash
# A real capture with a live preview, one command: the real-lab twin of pipelines/live.sh.
#   lumislab-acquire capture           (the stage and camera driven; dataset.json grows)
#   lumislab-calibrate screen          (as soon as the board photo is in dataset.json)
#   lumislab-reconstruct --watch       (each complete position -> slab/pos_<i>_<j>.exr)
#   lumislab-preview --watch           (each new position added to the picture)
# The preview opens a window when $DISPLAY is set, otherwise renders headless into
# <out>/renders/live.png after every new position. Ctrl-C stops all of them cleanly (the
# stage first: feed hold); the same command goes on where the capture stopped.
# Usage: pipelines/capture.sh <setup.json> <stage URI> <camera URI> <dataset folder>
#        [more lumislab-acquire capture options, e.g. --operator <program>]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
bin="${LUMISLAB_BIN:-$here/../build/bin}"
if [[ $# -lt 4 ]]; then
  echo "usage: pipelines/capture.sh <setup.json> <stage URI> <camera URI> <dataset folder> [capture options]" >&2
  exit 2
fi
setup="$1" stage="$2" camera="$3" out="$4"
shift 4
scene="${LUMISLAB_PREVIEW_SCENE:-crypt}"
pids=()

stop_all() {
  trap - INT TERM EXIT
  for pid in "${pids[@]}"; do kill -TERM "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
}
trap 'echo "capture.sh: stopping" >&2; stop_all; exit 130' INT TERM
trap stop_all EXIT

for tool in acquire calibrate reconstruct preview; do
  [[ -x "$bin/lumislab-$tool" ]] || { echo "capture.sh: $bin/lumislab-$tool is not built" >&2; exit 1; }
done

# --force captures again: the screen calibration and the slab are made again too.
force=()
for arg in "$@"; do [[ "$arg" == --force ]] && force=(--force); done

# The capture talks to the operator on this terminal: it keeps stdin (a background job of a
# script would otherwise read /dev/null).
"$bin/lumislab-acquire" capture --setup "$setup" --stage "$stage" --camera "$camera" \
  --out "$out" "$@" <&0 &
pids+=($!)
capture_pid=$!

# dataset.json is first written once the board photo is taken and the bracket chosen: calibrate
# the screen then.
for _ in $(seq 36000); do
  [[ -f "$out/dataset.json" ]] && break
  kill -0 "$capture_pid" 2>/dev/null || break
  sleep 0.1
done
if [[ ! -f "$out/dataset.json" ]]; then
  wait "$capture_pid"  # its exit code and message tell why
  exit 1
fi
if [[ ! -f "$out/calib/screen.json" || ${#force[@]} -gt 0 ]]; then
  "$bin/lumislab-calibrate" screen --dataset "$out" "${force[@]}"
fi

"$bin/lumislab-reconstruct" --dataset "$out" --watch "${force[@]}" &
pids+=($!)
reconstruct_pid=$!

mkdir -p "$out/renders"
if [[ -n "${DISPLAY:-}" ]]; then
  "$bin/lumislab-preview" --window --watch --slab "$out/slab" --scene "$scene" &
else
  "$bin/lumislab-preview" --watch --slab "$out/slab" --scene "$scene" --out "$out/renders/live.png" &
fi
pids+=($!)

status=0
wait "$capture_pid" || status=$?
if [[ $status -ne 0 ]]; then
  echo "capture.sh: the capture ended with exit $status; run the same command to go on" >&2
  exit "$status"
fi
wait "$reconstruct_pid"
echo "capture.sh: capture and reconstruction complete: $out/slab"
wait "${pids[-1]}"
