#!/usr/bin/env bash
# The main job on the built-in synthetic dataset: install what is missing, build, then
# acquire -> calibrate -> reconstruct, and print where the slab is and how far it is from the truth.
# Usage: pipelines/demo.sh [output folder, default out/default]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
out="${1:-out/default}"
bin=build/bin
"$bin/lumislab-acquire" synth --scene default --out "$out"
pipelines/process-folder.sh "$out"
