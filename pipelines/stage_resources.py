#!/usr/bin/env python3
"""The Slurm resources of one batch stage of one dataset, from the measured cost model.

pipelines/Snakefile requests each job's memory (mem_mb: sbatch --mem) and time limit (runtime,
minutes: sbatch --time) from here; the Slurm test (tests/e2e/slurm_test.cc) asks it what every
job should have been given. The model is bench/stage_costs.py's least-squares fit
(docs/results.md §14), with P positions, M photo megapixels, R2 = (slab texels per side)^2 / 10^6
and T threads:

  cpu_s   = c0 + c1 M + c2 P M + c3 P R2                (user + system seconds)
  peak_mb = m0 + m1 M min(T, P) + m2 R2 min(T, P) + m3 P R2

  mem_mb  = margin x peak_mb + job_mb, rounded up to 50 MB
  runtime = 1 + ceil(margin x cpu_s / min(T, P) / 60) minutes

margin (default 2: the measured peak memory is at most 1.34 times the fit, the CPU time at most
2.0 times, at the smallest sizes, where the minute added covers it; a cluster's cores may be
slower than the bench's) and job_mb (250: the Snakemake process that runs the job on the node
counts in its memory) and the coefficients can be changed in the workflow's config (keys
cost_margin, cost_job_mb, costs: {stage: {cpu_s: [c0..c3], peak_mb: [m0..m3]}}).

  python3 pipelines/stage_resources.py <stage> <dataset> [--threads T] [--resolution R]
  -> "mem_mb=<MB> runtime=<minutes>"
"""
import argparse
import json
import math
import os
import struct

# bench/stage_costs.py's fit (docs/results.md §14: 2 shared cores, Release build). tm25 was not
# measured: it reads the slab as export does, so it takes export's.
COSTS = {
    "calibrate": {"cpu_s": [0.060, 0.0718, 0.0, 0.0], "peak_mb": [20.7, 22.9, 0.0, 0.1]},
    "reconstruct": {"cpu_s": [0.0, 0.0914, 0.0321, 0.283], "peak_mb": [19.8, 34.5, 405.8, 0.0]},
    "export": {"cpu_s": [0.198, 0.0, 0.0260, 0.300], "peak_mb": [28.9, 0.0, 9.5, 15.5]},
    "tm25": {"cpu_s": [0.198, 0.0, 0.0260, 0.300], "peak_mb": [28.9, 0.0, 9.5, 15.5]},
    "preview": {"cpu_s": [0.163, 0.0, 0.0011, 0.104], "peak_mb": [158.0, 0.0, 0.0, 46.7]},
}
MARGIN = 2.0
JOB_MB = 250
DEFAULT_RESOLUTION = 300  # lumislab-reconstruct's --resolution default
DEFAULT_PHOTO_MP = 24.0  # when no photo size can be read: the largest measured
DEFAULT_POSITIONS = 225  # when dataset.json cannot be read: the largest grid measured (15 x 15)


def image_megapixels(path):
    """Width x height / 10^6 of a PNG or JPEG file from its header, or None."""
    try:
        with open(path, "rb") as f:
            head = f.read(32)
            if head[:8] == b"\x89PNG\r\n\x1a\n":
                w, h = struct.unpack(">II", head[16:24])
                return w * h / 1e6
            if head[:2] != b"\xff\xd8":
                return None
            f.seek(2)
            while True:  # JPEG: the first start-of-frame marker holds the size
                marker = f.read(4)
                if len(marker) < 4 or marker[0] != 0xFF:
                    return None
                length = struct.unpack(">H", marker[2:4])[0]
                if marker[1] in (0xC0, 0xC1, 0xC2, 0xC3, 0xC5, 0xC6, 0xC7, 0xC9, 0xCA, 0xCB,
                                 0xCD, 0xCE, 0xCF):
                    h, w = struct.unpack(">HH", f.read(5)[1:5])
                    return w * h / 1e6
                f.seek(length - 2, 1)
    except OSError:
        return None


def dataset_size(ds, photo_mp=None):
    """(positions, photo megapixels) of a dataset folder: the grid less its missing positions
    (225 when dataset.json cannot be read); the photos' size from calib/screen.json, else the
    calibration photo's header (PNG, JPEG), else photo_mp, else 24 MP."""
    try:
        with open(os.path.join(ds, "dataset.json")) as f:
            d = json.load(f)
        grid = d["setup"]["grid"]
        positions = max(1, int(grid["nu"]) * int(grid["nv"]) - len(d.get("missing_positions", [])))
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        # Unreadable: the largest measured grid, so that the stage runs and says what is wrong.
        return DEFAULT_POSITIONS, photo_mp or DEFAULT_PHOTO_MP
    mp = None
    try:
        with open(os.path.join(ds, "calib", "screen.json")) as f:
            w, h = json.load(f)["image_size"]
            mp = w * h / 1e6
    except (OSError, ValueError, KeyError, TypeError):
        photo = d.get("calibration", {}).get("photo")
        if photo:
            mp = image_megapixels(os.path.join(ds, d.get("photo_folder", "."), photo))
    return positions, mp or photo_mp or DEFAULT_PHOTO_MP


def resources(stage, ds, threads, resolution=None, config=None):
    """{"mem_mb": MB, "runtime": minutes} for the stage of the dataset."""
    config = config or {}
    costs = dict(COSTS, **config.get("costs", {}))[stage]
    margin = float(config.get("cost_margin", MARGIN))
    job_mb = float(config.get("cost_job_mb", JOB_MB))
    p, m = dataset_size(ds, config.get("photo_mp"))
    r2 = (resolution or DEFAULT_RESOLUTION) ** 2 / 1e6
    t = max(1, min(int(threads), p))
    c, k = costs["cpu_s"], costs["peak_mb"]
    cpu_s = c[0] + c[1] * m + c[2] * p * m + c[3] * p * r2
    # calibrate was measured with one thread only, and holds one photo at a time (the board's,
    # then the lux meter's position's): its memory does not take the threads.
    tm = 1 if stage == "calibrate" else t
    peak_mb = k[0] + k[1] * m * tm + k[2] * r2 * tm + k[3] * p * r2
    return {"mem_mb": int(math.ceil((margin * peak_mb + job_mb) / 50) * 50),
            "runtime": 1 + int(math.ceil(margin * cpu_s / t / 60))}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("stage", choices=sorted(COSTS))
    ap.add_argument("dataset")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--resolution", type=int)
    args = ap.parse_args()
    r = resources(args.stage, args.dataset, args.threads, args.resolution)
    print(f"mem_mb={r['mem_mb']} runtime={r['runtime']}")


if __name__ == "__main__":
    main()
