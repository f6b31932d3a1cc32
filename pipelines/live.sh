#!/usr/bin/env bash
# Live acquisition with a live preview, one command:
#   lumislab-acquire synth --interval  (positions appear one by one)
#   lumislab-calibrate screen          (as soon as the calibration photo exists)
#   lumislab-reconstruct --watch       (each position -> slab/pos_<i>_<j>.exr)
#   lumislab-preview --watch           (each new position added to the picture)
# The preview opens a window when $DISPLAY is set, otherwise renders headless into
# <out>/renders/live.png after every new position. Ctrl-C stops all of them cleanly.
# Usage: pipelines/live.sh [output folder, default out/live] [seconds between positions, default 1]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
bin="${LUMISLAB_BIN:-$here/../build/bin}"
out="${1:-out/live}"
interval="${2:-1}"
scene="${LUMISLAB_PREVIEW_SCENE:-crypt}"
pids=()

stop_all() {
  trap - INT TERM EXIT
  for pid in "${pids[@]}"; do kill -TERM "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
}
trap 'echo "live.sh: stopping" >&2; stop_all; exit 130' INT TERM
trap stop_all EXIT

for tool in acquire calibrate reconstruct preview; do
  [[ -x "$bin/lumislab-$tool" ]] || { echo "live.sh: $bin/lumislab-$tool is not built" >&2; exit 1; }
done
mkdir -p "$out/renders"

"$bin/lumislab-acquire" synth --scene default --out "$out" --interval "$interval" &
pids+=($!)
acquire_pid=$!

# The calibration photo comes first: calibrate the screen as soon as it is there.
for _ in $(seq 600); do
  [[ -f "$out/dataset.json" && -f "$out/photos/calib_0.png" ]] && break
  kill -0 "$acquire_pid" 2>/dev/null || break
  sleep 0.1
done
"$bin/lumislab-calibrate" screen --dataset "$out"

"$bin/lumislab-reconstruct" --dataset "$out" --watch &
pids+=($!)
reconstruct_pid=$!

if [[ -n "${DISPLAY:-}" ]]; then
  "$bin/lumislab-preview" --window --watch --slab "$out/slab" --scene "$scene" &
else
  "$bin/lumislab-preview" --watch --slab "$out/slab" --scene "$scene" --out "$out/renders/live.png" &
fi
pids+=($!)
preview_pid=$!

wait "$acquire_pid"
wait "$reconstruct_pid"
echo "live.sh: acquisition and reconstruction complete: $out/slab"
wait "$preview_pid"
