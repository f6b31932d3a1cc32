#!/usr/bin/env bash
# Process one capture into a slab and previews of it, stopping at the first failing stage
# (set -e); a rerun resumes where it stopped (stages skip finished outputs; --force redoes them).
#
# A dataset folder (dataset.json, e.g. from `lumislab-acquire synth`):
#   pipelines/process-folder.sh <dataset> [--force]
# A folder of camera photos and the lab's setup file:
#   pipelines/process-folder.sh --photos <camera folder> --setup <setup.json> --out <dataset>
#       [--order capture|name [--scan rows|serpentine|columns] [--brackets n] [--exposures e,..]
#        | --manifest <captures.csv> | --pattern <template>]
#       [--response <folder>] [--dark <folder>] [--flat <folder>] [--reference <reading.json>]
#       [--force]
# Either form also takes reconstruct's options, passed through: --resolution n, --lambda x,
#   --samples-per-texel k, --bracket-ratios recorded|estimated, --full-well e, --read-noise e;
#   and --threads n for every tool.
#   runs acquire import, then the calibrations whose frames are given, in the order each needs
#   (response, dark, screen, flat, scale; docs/formats.md §13 - §16), then reconstruct.
#   --response, --dark, --flat: folders of calibration frames (a bracketed series of any scene
#   with a wide range; frames with the lens capped; frames of the evenly lit screen); their
#   exposures come from EXIF. --reference: a meter reading at a screen point (calibrate scale).
# Outputs: <dataset>/calib/, <dataset>/slab/, <dataset>/renders/{crypt.png,beam_1500mm.exr}.
# At the end, and when a stage stops it, the dataset's consistency report (checks.json: what
# each stage verified about the capture, docs/verifies.md) is printed.
set -euo pipefail
usage() {
  awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0" >&2
  exit 2
}
[ $# -ge 1 ] || usage
bin="${LUMISLAB_BIN:-$(cd "$(dirname "$0")/.." && pwd)/build/bin}"

photos="" setup="" dataset="" response="" dark="" flat="" reference=""
import_args=() force=() reconstruct_args=() threads=()
if [ "${1#-}" = "$1" ]; then  # a dataset folder
  dataset="$1"
  shift
fi
while [ $# -gt 0 ]; do
  case "$1" in
    -h | --help) usage ;;
    --photos | --setup | --out | --response | --dark | --flat | --reference | --order | --scan | \
      --brackets | --exposures | --manifest | --pattern)
      [ $# -ge 2 ] || { echo "$0: $1 needs a value" >&2; exit 2; }
      case "$1" in
        --photos) photos="$2" ;;
        --setup) setup="$2" ;;
        --out) dataset="$2" ;;
        --response) response="$2" ;;
        --dark) dark="$2" ;;
        --flat) flat="$2" ;;
        --reference) reference="$2" ;;
        *) import_args+=("$1" "$2") ;;
      esac
      shift 2
      ;;
    --resolution | --lambda | --samples-per-texel | --bracket-ratios | --full-well | --read-noise)
      [ $# -ge 2 ] || { echo "$0: $1 needs a value" >&2; exit 2; }
      reconstruct_args+=("$1" "$2")
      shift 2
      ;;
    --threads)
      [ $# -ge 2 ] || { echo "$0: $1 needs a value" >&2; exit 2; }
      threads=(--threads "$2")
      shift 2
      ;;
    --force) force=(--force); shift ;;
    *) echo "$0: unknown argument: $1" >&2; exit 2 ;;
  esac
done
[ -n "$dataset" ] || { echo "$0: no dataset folder (give one, or --out)" >&2; exit 2; }

# The consistency report, whether the run ends here or a stage stops it (set -e).
report_checks() {
  local code=$?
  if [ -f "$dataset/checks.json" ]; then
    echo "consistency report ($dataset/checks.json):"
    "$bin/lumislab-acquire" checks "$dataset" || true
  fi
  return $code
}
trap report_checks EXIT

if [ -n "$photos" ]; then
  [ -n "$setup" ] || { echo "$0: --photos needs --setup" >&2; exit 2; }
  [ ${#import_args[@]} -gt 0 ] || import_args=(--order capture)
  "$bin/lumislab-acquire" import --photos "$photos" --setup "$setup" --out "$dataset" \
    "${import_args[@]}" "${threads[@]}" "${force[@]}"
elif [ -n "$setup$response$dark$flat$reference${import_args[*]}" ] && [ ! -f "$dataset/dataset.json" ]; then
  echo "$0: $dataset/dataset.json: not found (import a camera folder with --photos)" >&2
  exit 2
fi
[ -f "$dataset/dataset.json" ] || { echo "$0: $dataset/dataset.json: not found" >&2; exit 2; }

# files=(the frames of folder $1): its regular files that are not hidden, sorted by name.
frames_of() {
  [ -d "$1" ] || { echo "$0: $1: not a folder of calibration frames" >&2; exit 2; }
  mapfile -t files < <(find "$1" -maxdepth 1 -type f ! -name '.*' | sort)
  [ ${#files[@]} -gt 0 ] || { echo "$0: $1: no calibration frames in it" >&2; exit 2; }
}
calibrate="$bin/lumislab-calibrate"
if [ -n "$response" ]; then
  frames_of "$response"
  "$calibrate" response --dataset "$dataset" --frames "${files[@]}" "${threads[@]}" "${force[@]}"
fi
if [ -n "$dark" ]; then
  frames_of "$dark"
  "$calibrate" dark --dataset "$dataset" --frames "${files[@]}" "${threads[@]}" "${force[@]}"
fi
"$calibrate" screen --dataset "$dataset" "${threads[@]}" "${force[@]}"
if [ -n "$flat" ]; then
  frames_of "$flat"
  "$calibrate" flat --dataset "$dataset" --frames "${files[@]}" "${threads[@]}" "${force[@]}"
fi
if [ -n "$reference" ]; then
  "$calibrate" scale --dataset "$dataset" --reference "$reference" "${threads[@]}" "${force[@]}"
fi
"$bin/lumislab-reconstruct" --dataset "$dataset" "${reconstruct_args[@]}" "${threads[@]}" \
  "${force[@]}"
mkdir -p "$dataset/renders"
"$bin/lumislab-preview" --slab "$dataset/slab" --scene crypt --out "$dataset/renders/crypt.png" \
  "${threads[@]}"
"$bin/lumislab-preview" --slab "$dataset/slab" "${threads[@]}" --scene plane --receiver-plane 1500 --extent 3000 \
  --out "$dataset/renders/beam_1500mm.exr"
echo "slab: $dataset/slab"
echo "renders: $dataset/renders"
