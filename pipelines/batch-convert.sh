#!/usr/bin/env bash
# Converts many datasets: each through calibrate screen -> reconstruct -> export (IES, EULUMDAT,
# polar plot, irradiance at D; TM-25 with --tm25) -> a preview render, several datasets at once.
#
#   pipelines/batch-convert.sh <dataset|folder>... [--out batch-out] [--jobs N]
#       [--distance-mm 1500] [--tm25 [--rays 100000]] [--preview-size 640x360] [--resolution N]
#       [--lab L] [--manufacturer M] [--metadata meta.json] [--dry-run] [--summary-only]
#
# A dataset is a folder with dataset.json; any other folder stands for the datasets directly in it.
# The IES and EULUMDAT files need --lab and --manufacturer (or --metadata) and a slab in lux: a
# dataset's lux meter reading (reference.json; a synthetic dataset's truth/reference.json from
# `acquire synth --meter lux`) scales it in the calibrate stage; without them the export stage
# fails, and the summary says why.
# A dataset named summary.csv is refused (exit 2): the summary is <out>/summary.csv.
# --jobs N: the cores to use (default, and at most: all there are; more is all, with a notice);
#   min(N, datasets) datasets run at once, each stage with N / that many threads. Resumable: a
#   stage runs only when one of its outputs is missing or older than one of its inputs (or, for
#   reconstruct, the slab is partial), so a rerun does only what is missing or stale; --dry-run lists those stages ("<stage> <dataset>") and stops.
# A failing stage stops its dataset only: the others carry on, and the summary names the stage
# and the last lines of its log. Exit code 1 when any dataset failed (2: bad arguments).
# Writes <out>/<name>/ (the exports, preview.png), <out>/log/<name>/<stage>.log and .time, and
# <out>/summary.csv; prints the summary table. --summary-only writes only the summary.
# The stages' commands and outputs: pipelines/batch-stage.sh. The same as a Snakemake workflow:
# pipelines/Snakefile.
set -euo pipefail
usage() {
  sed -n '2,/^set /{ /^#/ s/^# \{0,1\}//p; }' "$0" >&2
  exit "${1:-2}"
}
here="$(cd "$(dirname "$0")" && pwd)"
out=batch-out jobs="" distance=1500 tm25=0 dry=0 summary_only=0 stage_args=()
inputs=()
while [ $# -gt 0 ]; do
  case "$1" in
    -h | --help) usage 0 ;;
    --tm25) tm25=1; shift ;;
    -n | --dry-run) dry=1; shift ;;
    --summary-only) summary_only=1; shift ;;
    --out | --jobs | --distance-mm | --rays | --preview-size | --resolution | --lab | --manufacturer | \
      --metadata)
      [ $# -ge 2 ] || { echo "$0: $1 needs a value" >&2; exit 2; }
      case "$1" in
        --out) out="${2%/}" ;;
        --jobs) jobs="$2" ;;
        --distance-mm) distance="$2"; stage_args+=("$1" "$2") ;;
        *) stage_args+=("$1" "$2") ;;
      esac
      shift 2
      ;;
    -*) echo "$0: unknown option: $1" >&2; exit 2 ;;
    *) inputs+=("${1%/}"); shift ;;
  esac
done
[ ${#inputs[@]} -gt 0 ] || { echo "$0: no dataset or folder given" >&2; usage; }
cores=$(nproc)
[ -n "$jobs" ] || jobs=$cores
[[ "$jobs" =~ ^[1-9][0-9]{0,3}$ ]] || { echo "$0: --jobs: expected an integer in [1, 9999], got $jobs" >&2; exit 2; }
# More jobs than cores would only hand the tools more threads than there are cores (and above
# their limit of 256, exit 2): the cores are what the batch uses.
if [ "$jobs" -gt "$cores" ]; then
  echo "$0: --jobs $jobs is more than the $cores core(s) here: using $cores" >&2
  jobs=$cores
fi

# The datasets, in the order given (a folder's in name order); names must be unique, since
# outputs and logs are filed under them.
datasets=()
for x in "${inputs[@]}"; do
  if [ -f "$x/dataset.json" ]; then
    datasets+=("$x")
  elif [ -d "$x" ]; then
    mapfile -t found < <(find "$x" -mindepth 2 -maxdepth 2 -name dataset.json ! -path '*/.*' \
      -printf '%h\n' | sort)
    [ ${#found[@]} -gt 0 ] || { echo "$0: $x: no dataset folders in it (none has dataset.json)" >&2; exit 2; }
    datasets+=("${found[@]}")
  else
    echo "$0: $x: not a dataset folder (no dataset.json) nor a folder" >&2
    exit 2
  fi
done
declare -A seen=()
for ds in "${datasets[@]}"; do
  name="$(basename "$ds")"
  [ -z "${seen[$name]:-}" ] || { echo "$0: two datasets named $name: ${seen[$name]} and $ds" >&2; exit 2; }
  # <out>/summary.csv is the batch's own file: a dataset of that name would take its place.
  [ "$name" != summary.csv ] || {
    echo "$0: $ds: a dataset cannot be named summary.csv (the batch writes <out>/summary.csv): rename its folder" >&2
    exit 2
  }
  seen[$name]="$ds"
done

stages=(calibrate reconstruct export)
[ $tm25 = 0 ] || stages+=(tm25)
stages+=(preview)

# The outputs and inputs of a stage (kept in step with batch-stage.sh and the Snakefile).
outputs_of() {  # stage dataset
  local n; n="$(basename "$2")"
  case "$1" in
    calibrate) echo "$2/calib/screen.json" ;;
    reconstruct) echo "$2/slab/slab.json" ;;
    export) printf '%s\n' "$out/$n/$n.ies" "$out/$n/$n.ldt" "$out/$n/polar.png" \
      "$out/$n/irradiance_${distance}mm.png" ;;
    tm25) echo "$out/$n/$n.ray" ;;
    preview) echo "$out/$n/preview.png" ;;
  esac
}
inputs_of() {  # stage dataset
  case "$1" in
    calibrate) echo "$2/dataset.json" ;;
    reconstruct) printf '%s\n' "$2/dataset.json" "$2/calib/screen.json" ;;
    *) echo "$2/slab/slab.json" ;;
  esac
}
# stale <stage> <dataset> <upstream ran>: whether the stage has to run (make's rule: an output
# missing or older than an input; a partial slab; or a stage before it ran or would run).
stale() {
  [ "$3" = 0 ] || return 0
  local o i
  while read -r o; do
    [ -f "$o" ] || return 0
    while read -r i; do
      [ ! "$i" -nt "$o" ] || return 0
    done < <(inputs_of "$1" "$2")
  done < <(outputs_of "$1" "$2")
  if [ "$1" = reconstruct ] && ! grep -q '"complete": true' "$2/slab/slab.json"; then return 0; fi
  return 1
}

# Runs the stages of one dataset in order and stops at the first failure (batch-stage.sh records
# it in <log>/<stage>.failed). $ran/<name> lists the stages run by this batch.
convert() {  # dataset threads
  local ds="$1" n logdir upstream=0 s rc
  n="$(basename "$ds")"
  logdir="$out/log/$n"
  for s in "${stages[@]}"; do
    stale "$s" "$ds" "$upstream" || continue
    upstream=1
    echo "$s" >>"$ran/$n"
    rc=0
    "$here/batch-stage.sh" "$s" "$ds" "$out" --threads "$2" "${stage_args[@]}" || rc=$?
    if [ $rc != 0 ]; then
      echo "$n: $s failed (exit $rc); log: $logdir/$s.log" >&2
      return 0
    fi
  done
  echo "$n: done ($(paste -sd' ' "$ran/$n" | sed 's/^$/nothing to do/'))" >&2
}

if [ $dry = 1 ]; then
  for ds in "${datasets[@]}"; do
    upstream=0
    for s in "${stages[@]}"; do
      if stale "$s" "$ds" "$upstream"; then upstream=1; echo "$s $(basename "$ds")"; fi
    done
  done
  exit 0
fi

mkdir -p "$out"
# What this batch ran, per dataset (for the summary; a folder of its own, removed at the end, so
# that a batch with nothing to do rewrites nothing but the summary).
ran="$(mktemp -d "$out/.ran.XXXXXX")"
tmp="$out/.summary.csv.tmp$$"
trap 'rm -rf "$ran" "$tmp"' EXIT
for ds in "${datasets[@]}"; do : >"$ran/$(basename "$ds")"; done
if [ $summary_only = 0 ]; then
  parallel=$((jobs < ${#datasets[@]} ? jobs : ${#datasets[@]}))
  threads=$((jobs / parallel))
  [ $threads -le 256 ] || threads=256  # the tools' --threads limit (core/parallel.h)
  batch_start=$(date +%s.%N)
  running=0
  for ds in "${datasets[@]}"; do
    if [ $running -ge $parallel ]; then
      wait -n || true
      running=$((running - 1))
    fi
    convert "$ds" "$threads" &
    running=$((running + 1))
  done
  wait
  echo "batch: ${#datasets[@]} dataset(s) in $(awk -v a="$batch_start" -v b="$(date +%s.%N)" \
    'BEGIN { printf "%.1f", b - a }') s, $parallel at once with $threads thread(s) each" >&2
fi

# The summary: one row per dataset, from the files the stages left (so it also describes
# datasets whose stages ran in an earlier batch).
csv_field() {  # quotes a CSV field when it needs it
  case "$1" in
    *[,\"]* | *$'\n'*) printf '"%s"' "${1//\"/\"\"}" ;;
    *) printf '%s' "$1" ;;
  esac
}
{
  printf 'dataset,status,positions,error_overall_pct,error_max_pct'
  for s in "${stages[@]}"; do printf ',%s_s' "$s"; done
  printf ',ran,outputs,failure\n'
} >"$tmp"
table=()
failures=0
for ds in "${datasets[@]}"; do
  n="$(basename "$ds")"
  logdir="$out/log/$n"
  status=ok failure="" positions="" err="" errmax=""
  stages_ran="$(paste -sd' ' "$ran/$n")"
  for s in "${stages[@]}"; do
    if [ -f "$logdir/$s.failed" ]; then
      status=failed failures=$((failures + 1))
      # The failing stage, its exit code and the last lines of its log (without the commands).
      # (its error line, or the last three lines when it has none).
      reason="$(grep 'error:' "$logdir/$s.log" | tail -n 1 || true)"
      [ -n "$reason" ] || reason="$(grep -v '^\$ ' "$logdir/$s.log" | tail -n 3 | paste -sd'|')"
      failure="$s (exit $(cat "$logdir/$s.failed")): $reason"
      break
    elif stale "$s" "$ds" 0; then
      status=incomplete failures=$((failures + 1)) failure="$s: not done"
      break
    fi
  done
  if [ -f "$ds/slab/slab.json" ]; then
    # Positions present / the grid's, from slab.json (the reconstruct log may be older).
    j="$(tr -d ' \t\r\n' <"$ds/slab/slab.json")"
    present="${j#*\"present\":[}"
    present="${present%%]]*}"
    present="${present//[^\[]/}"
    [[ "$j" != *'"present":[]'* ]] || present=""
    positions="${#present}/$(($(sed -n 's/.*"nu":\([0-9]*\).*/\1/p' <<<"$j") * \
      $(sed -n 's/.*"nv":\([0-9]*\).*/\1/p' <<<"$j")))"
  fi
  # The error against truth/ (synthetic datasets) as reconstruct logged it for this slab.
  if [ -f "$logdir/reconstruct.log" ]; then
    line="$(grep 'error against truth/:' "$logdir/reconstruct.log" | tail -n 1 || true)"
    err="$(sed -n 's/.*overall \([0-9.]*\) %.*/\1/p' <<<"$line")"
    errmax="$(sed -n 's/.*max \([0-9.]*\) %.*/\1/p' <<<"$line")"
  fi
  times=()
  for s in "${stages[@]}"; do
    t=""
    [ ! -f "$logdir/$s.time" ] || t="$(cat "$logdir/$s.time")"
    times+=("$t")
  done
  outs=()
  for s in "${stages[@]}"; do
    case "$s" in calibrate | reconstruct) continue ;; esac
    while read -r o; do [ ! -f "$o" ] || outs+=("${o#"$out"/}"); done < <(outputs_of "$s" "$ds")
  done
  {
    printf '%s,%s,%s,%s,%s' "$(csv_field "$n")" "$status" "$positions" "$err" "$errmax"
    for t in "${times[@]}"; do printf ',%s' "$t"; done
    printf ',%s,%s,%s\n' "$(csv_field "$stages_ran")" "$(csv_field "${outs[*]:-}")" "$(csv_field "$failure")"
  } >>"$tmp"
  table+=("$(printf '%-20s %-10s %-9s %-8s %s' "$n" "$status" "${positions:--}" \
    "${err:--}" "$(IFS=/; echo "${times[*]}")")")
  [ -z "$failure" ] || table+=("    $failure")
done
mv -f "$tmp" "$out/summary.csv"
printf '%-20s %-10s %-9s %-8s %s\n' dataset status positions "err %" \
  "seconds ($(IFS=/; echo "${stages[*]}"))"
printf '%s\n' "${table[@]}"
echo "summary: $out/summary.csv"
[ $failures = 0 ] || exit 1
