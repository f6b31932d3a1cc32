#!/usr/bin/env bash
# Runs the lumislab-preview GLFW window under Xvfb and saves a screenshot of it: the crypt lit by
# the default luminaire, shadows on.
#   pipelines/screenshot-window.sh [out.png] [slab dir]
# Without a slab dir, the exact slab of the built-in point-emitter luminaire is written to a
# temporary folder first. LUMISLAB_BIN overrides the folder with the executables.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
bin="${LUMISLAB_BIN:-$here/../build/bin}"
out="${1:-renders/window-crypt.png}"
slab="${2:-}"
tmp=""
cleanup() { if [[ -n "$tmp" ]]; then rm -rf "$tmp"; fi; }
trap cleanup EXIT
extra=()
if [[ -z "$slab" ]]; then
  tmp="$(mktemp -d)"
  slab="$tmp/slab"
  extra=(--write-test-slab)
fi
mkdir -p "$(dirname "$out")"
command -v xvfb-run >/dev/null || { echo "screenshot-window.sh: xvfb-run is missing" >&2; exit 1; }
xvfb-run -a -s "-screen 0 1280x1024x24" \
  "$bin/lumislab-preview" --window --slab "$slab" "${extra[@]}" --scene crypt --size 800x600 \
  --screenshot "$out"
test -s "$out"
echo "screenshot-window.sh: wrote $out"
