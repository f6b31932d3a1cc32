#!/usr/bin/env bash
# Snakemake's --cluster-status for the Slurm profile: prints running, success or failed for the
# job id that sbatch --parsable gave ("<id>" or "<id>;<cluster>").
#
#   pipelines/slurm/status.sh <jobid>
#
# Without it Snakemake waits for a file that the job writes at its end, so a job that Slurm ends
# (scancel, its time limit, its memory limit, a node lost) is never seen to fail and the
# workflow waits for ever. The job's state comes from the accounting database (sacct), else
# from the controller's memory (scontrol, for MinJobAge after the end), else from the job
# completion records (sacct -c, JobCompType=jobcomp/filetxt, as pipelines/slurm/local-cluster.sh
# sets up). A job none of them knows is still running if squeue lists it; otherwise failed.
set -uo pipefail
[ $# = 1 ] || { echo "usage: $0 <jobid>" >&2; exit 2; }
id="${1%%;*}"
state="$(sacct -n -X -P -j "$id" -o State 2>/dev/null | head -n 1)"
[ -n "$state" ] ||
  state="$(scontrol show job -o "$id" 2>/dev/null | sed -n 's/.* JobState=\([A-Z_]*\).*/\1/p')"
[ -n "$state" ] || state="$(sacct -c -n -X -P -j "$id" -o State 2>/dev/null | tail -n 1)"
[ -n "$state" ] || { [ -z "$(squeue -h -j "$id" -o %T 2>/dev/null)" ] || state=RUNNING; }
case "${state%% *}" in
  COMPLETED) echo success ;;
  PENDING | CONFIGURING | RUNNING | COMPLETING | SUSPENDED | REQUEUED | REQUEUE_HOLD | \
    REQUEUE_FED | RESIZING | SIGNALING | STAGE_OUT | STOPPED | RESV_DEL_HOLD) echo running ;;
  *) echo failed ;;  # CANCELLED, FAILED, TIMEOUT, OUT_OF_MEMORY, NODE_FAIL, BOOT_FAIL, ...
esac
