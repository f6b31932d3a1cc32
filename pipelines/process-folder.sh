#!/usr/bin/env bash
# Process one dataset folder: calibrate the screen, reconstruct the slab, render previews of it
# into <dataset>/renders/. Stops at the first
# failing stage (set -e) and resumes where it stopped (stages skip finished outputs).
# Usage: pipelines/process-folder.sh <dataset> [--force]
set -euo pipefail
if [ $# -lt 1 ] || [ "$1" = "-h" ] || [ "$1" = "--help" ]; then
  echo "usage: $0 <dataset> [--force]" >&2
  exit 2
fi
dataset="$1"
shift
bin="${LUMISLAB_BIN:-$(cd "$(dirname "$0")/.." && pwd)/build/bin}"
[ -f "$dataset/dataset.json" ] || { echo "$0: $dataset/dataset.json: not found" >&2; exit 2; }

"$bin/lumislab-calibrate" screen --dataset "$dataset" "$@"
"$bin/lumislab-reconstruct" --dataset "$dataset" "$@"
mkdir -p "$dataset/renders"
"$bin/lumislab-preview" --slab "$dataset/slab" --scene crypt --out "$dataset/renders/crypt.png"
"$bin/lumislab-preview" --slab "$dataset/slab" --scene plane --receiver-plane 1500 --extent 3000 \
  --out "$dataset/renders/beam_1500mm.exr"
echo "slab: $dataset/slab"
echo "renders: $dataset/renders"
