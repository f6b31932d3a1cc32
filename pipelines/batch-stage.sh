#!/usr/bin/env bash
# One stage of one dataset of a batch conversion: the commands that pipelines/batch-convert.sh and
# pipelines/Snakefile both run (one implementation), with the stage's log and time.
#
#   pipelines/batch-stage.sh <stage> <dataset> <out> [--threads N] [--distance-mm D]
#       [--rays N] [--preview-size WxH] [--resolution N] [--lab L] [--manufacturer M]
#       [--metadata meta.json]
#
# <stage>: calibrate | reconstruct | export | tm25 | preview. <out>: the batch's output folder.
# The dataset's name is its folder's name. What each stage writes (docs/architecture.md §6):
#   calibrate    <dataset>/calib/screen.json        (lumislab-calibrate screen), and
#                <dataset>/calib/scale.json from a lux meter reading when the dataset has one
#                (lumislab-calibrate scale --reference): <dataset>/reference.json (the lab's,
#                docs/formats.md) or, for a synthetic dataset, truth/reference.json when its
#                unit is lux (`acquire synth --meter lux`): IES and EULUMDAT need a lux slab
#   reconstruct  <dataset>/slab/                    (lumislab-reconstruct; --resolution: its
#                texels per side, default the tool's)
#   export       <out>/<name>/<name>.ies, <name>.ldt, polar.png, irradiance_<D>mm.png; the
#                IES/EULUMDAT name the lab and the maker: --lab and --manufacturer (or
#                --metadata) are required (exit 2 without), and state their coverage of the
#                C/gamma grid (--allow-partial: the screen sees a cone of it; [_COVERAGE])
#   tm25         <out>/<name>/<name>.ray            (lumislab-export tm25)
#   preview      <out>/<name>/preview.png           (lumislab-preview, the crypt)
# and always <out>/log/<name>/<stage>.log (the tools' output), and <stage>.time (seconds) when the
# stage succeeds or <stage>.failed (its exit code) when it fails. A stage is run only when its outputs are missing or older than its
# inputs (the caller decides), so it redoes them whole (--force): calibrate and the exports
# would otherwise skip an existing output. reconstruct is the exception: it resumes a partial
# slab (positions already there are kept) unless a position is older than dataset.json or
# calib/screen.json, i.e. made from another calibration, and then redoes the slab (--force).
# Exit code: the failing tool's.
set -euo pipefail
usage() {
  sed -n '2,/^set /{ /^#/ s/^# \{0,1\}//p; }' "$0" >&2
  exit 2
}
[ $# -ge 3 ] || usage
stage="$1" dataset="${2%/}" out="${3%/}"
shift 3
threads=0 distance=1500 rays=100000 size=640x360 resolution=() keywords=()
while [ $# -gt 0 ]; do
  [ $# -ge 2 ] || { echo "$0: $1 needs a value" >&2; exit 2; }
  case "$1" in
    --threads) threads="$2" ;;
    --distance-mm) distance="$2" ;;
    --rays) rays="$2" ;;
    --preview-size) size="$2" ;;
    --resolution) resolution=(--resolution "$2") ;;
    --lab | --manufacturer | --metadata) keywords+=("$1" "$2") ;;
    *) echo "$0: unknown argument: $1" >&2; exit 2 ;;
  esac
  shift 2
done
bin="${LUMISLAB_BIN:-$(cd "$(dirname "$0")/.." && pwd)/build/bin}"
name="$(basename "$dataset")"
dest="$out/$name"
logdir="$out/log/$name"
mkdir -p "$logdir"
log="$logdir/$stage.log"

# run <command...>: runs a tool with its output appended to the stage's log.
run() {
  echo "\$ $*" >>"$log"
  "$@" >>"$log" 2>&1
}

calibrate() {
  run "$bin/lumislab-calibrate" screen --dataset "$dataset" --force --threads "$threads"
  local reference=""
  if [ -f "$dataset/reference.json" ]; then
    reference="$dataset/reference.json"
  elif [ -f "$dataset/truth/reference.json" ] &&
    tr -d ' \t\r\n' <"$dataset/truth/reference.json" | grep -q '"unit":"lux"'; then
    reference="$dataset/truth/reference.json"  # the synthetic lux meter's reading
  fi
  if [ -n "$reference" ]; then
    run "$bin/lumislab-calibrate" scale --dataset "$dataset" --reference "$reference" --force \
      --threads "$threads"
  fi
}

reconstruct() {
  local force=()
  # A position older than its inputs comes from another calibration or capture: redo them all.
  if [ -d "$dataset/slab" ] && [ -n "$(find "$dataset/slab" -maxdepth 1 -name 'pos_*.exr' \
    \( ! -newer "$dataset/dataset.json" -o ! -newer "$dataset/calib/screen.json" \) -print -quit)" ]; then
    force=(--force)
  fi
  run "$bin/lumislab-reconstruct" --dataset "$dataset" --threads "$threads" "${resolution[@]}" \
    "${force[@]}"
}

export_files() {
  local export="$bin/lumislab-export" slab="$dataset/slab"
  mkdir -p "$dest"
  # A lab's IES file must name the test, the lab and the maker (docs/architecture.md §7.8); the
  # test is the dataset. No made-up lab: without them the stage fails (and the summary says so).
  local ids=(--test "$name") given=" ${keywords[*]-} "
  if [[ "$given" != *" --metadata "* ]] &&
    { [[ "$given" != *" --lab "* ]] || [[ "$given" != *" --manufacturer "* ]]; }; then
    echo "export: IES and EULUMDAT files name the lab and the luminaire's maker: give --lab and" \
      "--manufacturer (or --metadata meta.json)" | tee -a "$log" >&2
    exit 2
  fi
  run "$export" ies --slab "$slab" --out "$dest/$name.ies" --force --allow-partial \
    --threads "$threads" "${ids[@]}" "${keywords[@]}"
  run "$export" ldt --slab "$slab" --out "$dest/$name.ldt" --force --allow-partial \
    --threads "$threads" "${ids[@]}" "${keywords[@]}"
  run "$export" polar --slab "$slab" --out "$dest/polar.png" --title "$name" --force \
    --threads "$threads"
  run "$export" irradiance --slab "$slab" --distance-mm "$distance" \
    --out "$dest/irradiance_${distance}mm.png" --force --threads "$threads"
}

tm25() {
  mkdir -p "$dest"
  run "$bin/lumislab-export" tm25 --slab "$dataset/slab" --out "$dest/$name.ray" --rays "$rays" \
    --name "$name" --force --allow-partial --threads "$threads"
}

preview() {
  mkdir -p "$dest"
  run "$bin/lumislab-preview" --slab "$dataset/slab" --scene crypt --size "$size" \
    --out "$dest/preview.png" --threads "$threads"
}

: >"$log"
rm -f "$logdir/$stage.failed"
# A failure is recorded beside the log ("<exit code>"), for the summary.
# shellcheck disable=SC2154  # rc is set inside the trap
trap 'rc=$?; [ $rc = 0 ] || echo $rc >"$logdir/$stage.failed"' EXIT
start=$(date +%s.%N)
case "$stage" in
  calibrate) calibrate ;;
  reconstruct) reconstruct ;;
  export) export_files ;;
  tm25) tm25 ;;
  preview) preview ;;
  *) echo "$0: unknown stage: $stage" >&2; exit 2 ;;
esac
end=$(date +%s.%N)
# The time, written whole: a summary never reads half a number.
tmp="$logdir/.$stage.time.tmp$$"
awk -v a="$start" -v b="$end" 'BEGIN { printf "%.2f\n", b - a }' >"$tmp"
mv -f "$tmp" "$logdir/$stage.time"
