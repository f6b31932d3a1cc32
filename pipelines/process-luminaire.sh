#!/usr/bin/env bash
# Process a luminaire folder (docs/formats.md §19: luminaire.json and one dataset folder per
# orientation) into one light field and its exports, stopping at the first failing stage
# (set -e); a rerun resumes where it stopped (stages skip finished outputs, the registration
# and the exports are redone when older than what they are made from; --force redoes all).
#   pipelines/process-luminaire.sh <lum> [--force] [--threads n] [--reference <reading.json>]
#       [--metadata <keywords.json>] [reconstruct's options]
# Each orientation's dataset goes through pipelines/process-folder.sh (its calibrations,
# reconstruct, previews; reconstruct's options --resolution, --lambda, ... are passed through;
# --reference names each orientation's meter reading relative to its dataset folder, e.g.
# truth/reference.json of `acquire synth --meter lux`, for calibrate scale: IES and EULUMDAT need
# lux slabs),
# then `lumislab-calibrate orientations` registers the orientations (<lum>/registration.json;
# exit 2 naming the pair when their overlaps are too small or disagree), then the luminaire's
# exports are written from the merged light field into <lum>/exports/: luminaire.ies,
# luminaire.ldt, luminaire.tm25 and report.html (lumislab-export reading a luminaire folder),
# with the file keywords of --metadata (lumislab-export's --metadata: LM-63 requires [TEST],
# [TESTLAB], [ISSUEDATE], [MANUFAC]).
set -euo pipefail
usage() {
  awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0" >&2
  exit 2
}
[ $# -ge 1 ] || usage
case "$1" in -h | --help) usage ;; esac
here="$(cd "$(dirname "$0")" && pwd)"
bin="${LUMISLAB_BIN:-$(cd "$here/.." && pwd)/build/bin}"
lum="${1%/}"
shift
force=() threads=() folder_args=() export_args=() reference=
while [ $# -gt 0 ]; do
  case "$1" in
    -h | --help) usage ;;
    --force) force=(--force); shift ;;
    --threads)
      [ $# -ge 2 ] || { echo "$0: $1 needs a value" >&2; exit 2; }
      threads=(--threads "$2")
      shift 2
      ;;
    --reference | --metadata)
      [ $# -ge 2 ] || { echo "$0: $1 needs a value" >&2; exit 2; }
      if [ "$1" = --reference ]; then reference="$2"; else export_args=(--metadata "$2"); fi
      shift 2
      ;;
    --resolution | --lambda | --samples-per-texel | --bracket-ratios | --full-well | --read-noise)
      [ $# -ge 2 ] || { echo "$0: $1 needs a value" >&2; exit 2; }
      folder_args+=("$1" "$2")
      shift 2
      ;;
    *) echo "$0: unknown argument: $1" >&2; exit 2 ;;
  esac
done
[ -f "$lum/luminaire.json" ] || { echo "$0: $lum/luminaire.json: not found" >&2; exit 2; }

# The orientations' dataset folders, in luminaire.json's order: the file checked by the tools'
# own reader first (exit 2 naming the file and field), so that nothing runs on a bad list.
info=$("$bin/lumislab-export" info "$lum" --json) || exit $?
mapfile -t datasets < <(python3 -c '
import json, sys
for o in json.load(sys.stdin)["orientations"]:
    print(o["dataset"])' <<<"$info")
[ ${#datasets[@]} -gt 0 ] || { echo "$0: $lum/luminaire.json: no orientations" >&2; exit 2; }
for d in "${datasets[@]}"; do
  echo "== orientation dataset $lum/$d"
  reading=()
  [ -z "$reference" ] || reading=(--reference "$lum/$d/$reference")
  LUMISLAB_BIN="$bin" "$here/process-folder.sh" "$lum/$d" "${reading[@]}" "${folder_args[@]}" \
    "${threads[@]}" "${force[@]}"
done

# A result is current when it is newer than everything it is made from; a stale one is redone.
newer_than_all() {  # newer_than_all <file> <input>...: the file exists and is newer than each
  local out=$1 input
  shift
  [ -f "$out" ] || return 1
  for input in "$@"; do [ "$out" -nt "$input" ] || return 1; done
}
slabs=()
for d in "${datasets[@]}"; do slabs+=("$lum/$d/slab/slab.json"); done

echo "== registration"
if [ ${#datasets[@]} -lt 2 ]; then
  # One orientation has nothing to register against; its exports use its nominal pose.
  rm -f "$lum/registration.json"
  echo "one orientation: nothing to register"
elif [ ${#force[@]} -eq 0 ] && newer_than_all "$lum/registration.json" "$lum/luminaire.json" \
  "${slabs[@]}"; then
  echo "$lum/registration.json: current (--force redoes it)"
else
  "$bin/lumislab-calibrate" orientations --luminaire "$lum" "${threads[@]}" --force
fi

echo "== exports"
mkdir -p "$lum/exports"
inputs=("$lum/luminaire.json" "${slabs[@]}")
[ ! -f "$lum/registration.json" ] || inputs+=("$lum/registration.json")
export_one() {  # export_one <subcommand> <file> [args]: skipped when current, unless --force
  if [ ${#force[@]} -eq 0 ] && newer_than_all "$lum/exports/$2" "${inputs[@]}"; then
    echo "$lum/exports/$2: current (--force redoes it)"
    return
  fi
  "$bin/lumislab-export" "$1" --slab "$lum" --out "$lum/exports/$2" "${@:3}" "${threads[@]}" \
    --force
}
export_one ies luminaire.ies "${export_args[@]}"
export_one ldt luminaire.ldt "${export_args[@]}"
export_one tm25 luminaire.tm25
export_one report report.html
echo "registration: $lum/registration.json"
echo "exports: $lum/exports"
