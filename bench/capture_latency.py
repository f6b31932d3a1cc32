#!/usr/bin/env python3
"""Does `reconstruct --watch` keep up with a capture? (docs/results.md, README "Capturing with
lumislab".)

Runs a whole capture in the virtual lab (tests/acquire/virtual_lab_main.cc: the emulated GRBL
stage at real speed, the emulated PTP/IP camera through the real libgphoto2) with 6000 x 4000
photos, 3 brackets per slide, once with JPEG and once with DNG photos, while
`lumislab-calibrate screen` and `lumislab-reconstruct --watch` run as pipelines/capture.sh runs
them. For every position it records when dataset.json first lists it complete (its last photo
is in) and when its slab file slab/pos_<i>_<j>.exr appears, and prints per format:

  * latency: slab file time - position complete time (what the lab waits for a position), and
  * the capture time per position: between two positions completing in the virtual lab (whose
    camera renders each photo with lib/synthetic, slower than a real camera), and the lab
    model's (lumislab-plan: --move-s + 6 photos x --exposure-s).

reconstruct keeps up when the latency is below the capture time per position. The virtual lab,
the capture and reconstruct share this machine's cores: the latency is an upper bound of what a
lab's separate camera would leave.

Usage: bench/capture_latency.py [--build build] [--grid 3] [--formats jpeg,dng] [--keep DIR]
"""
import argparse
import json
import os
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time

SCENE = """{ "schema_version": 1,
  "setup": { "distance_mm": 750, "grid": {"nu": %(n)d, "nv": %(n)d, "spacing_mm": 5},
             "screen_mm": [1200, 1200] },
  "luminaire": { "emitters": [
      {"position_mm": [1.5, -2, -20], "intensity_w_sr": [1.0, 0.9, 0.8], "lobe_exponent": 8},
      {"position_mm": [-3, 1, -12], "intensity_w_sr": [0.5, 0.6, 0.9], "lobe_exponent": 3} ] },
  "camera": { "size_px": [6000, 4000], "focal_px": 5000, "position_mm": [0, -400, 2400],
              "look_at_mm": [0, 0, 750] },
  "effects": %(effects)s }"""

EFFECTS = {
    "jpeg": '[{"type": "response", "curve": "srgb", "quality": 95}]',
    "dng": '[{"type": "raw"}]',
}

LAB = {
    "stage": {"origin_mm": [150, 150],
              "travel_mm": {"X": [0, 300], "Y": [0, 300], "Z": [0, 100]},
              "home": True, "feed_mm_min": 1500, "settle_s": 0.2},
    "slides": {"axis": "Z", "p_mm": 10, "n_mm": 40},
    "camera": {"brackets": 3, "bracket_stops": 2, "delete_from_card": True,
               "capture_timeout_s": 300},
}

MOVE_S, EXPOSURE_S = 2.0, 0.5  # lumislab-plan's lab model defaults
SOURCE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def wait_for(path, proc, timeout):
    end = time.time() + timeout
    while time.time() < end:
        if os.path.exists(path):
            return True
        if proc.poll() is not None:
            return False
        time.sleep(0.05)
    return False


def complete_positions(dataset_json):
    try:
        with open(dataset_json) as f:
            d = json.load(f)
    except (OSError, ValueError):
        return None
    g = d["setup"]["grid"]
    missing = {tuple(p) for p in d.get("missing_positions", [])}
    return {(i, j) for j in range(g["nv"]) for i in range(g["nu"]) if (i, j) not in missing}


def run_format(bin_dir, root, fmt, n):
    work = os.path.join(root, fmt)
    os.makedirs(work, exist_ok=True)
    with open(os.path.join(work, "scene.json"), "w") as f:
        f.write(SCENE % {"n": n, "effects": EFFECTS[fmt]})
    with open(os.path.join(work, "lab.json"), "w") as f:
        json.dump(LAB, f)
    env = dict(os.environ)
    logs = {name: open(os.path.join(work, name + ".log"), "w")
            for name in ("lab", "capture", "calibrate", "reconstruct")}
    lab = subprocess.Popen([os.path.join(bin_dir, "virtual_lab"), "--scene", "scene.json",
                            "--lab", "lab.json", "--dir", "lab", "--seconds", "7200"],
                           cwd=work, stdout=logs["lab"], stderr=subprocess.STDOUT)
    procs = [lab]
    try:
        if not wait_for(os.path.join(work, "lab", "ready"), lab, 600):
            sys.exit("capture_latency: the virtual lab did not start; see " + work + "/lab.log")
        camera = open(os.path.join(work, "lab", "camera")).read().strip()
        start = time.time()
        # The virtual lab's operator puts the board and the slides in (its control files).
        env["LUMISLAB_LAB_CONTROL"] = os.path.join(work, "lab", "control")
        capture = subprocess.Popen(
            [os.path.join(bin_dir, "lumislab-acquire"), "capture", "--setup", "lab/setup.json",
             "--stage", "grbl:lab/grbl", "--camera", "gphoto2@" + camera, "--out", "cap",
             "--operator", os.path.join(SOURCE_DIR, "tests", "acquire", "lab_operator.sh")],
            cwd=work, stdout=logs["capture"], stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
            env=env)
        procs.append(capture)
        dataset = os.path.join(work, "cap", "dataset.json")
        if not wait_for(dataset, capture, 3600):
            sys.exit("capture_latency: the capture wrote no dataset.json; see " + work +
                     "/capture.log")
        subprocess.run([os.path.join(bin_dir, "lumislab-calibrate"), "screen", "--dataset", "cap"],
                       cwd=work, stdout=logs["calibrate"], stderr=subprocess.STDOUT, check=True)
        reconstruct = subprocess.Popen(
            [os.path.join(bin_dir, "lumislab-reconstruct"), "--dataset", "cap", "--watch"],
            cwd=work, stdout=logs["reconstruct"], stderr=subprocess.STDOUT)
        procs.append(reconstruct)
        complete_at, slab_at = {}, {}
        positions = {(i, j) for i in range(n) for j in range(n)}
        deadline = time.time() + 7200
        while len(slab_at) < len(positions) and time.time() < deadline:
            now = time.time()
            done = complete_positions(dataset) or set()
            for p in done:
                complete_at.setdefault(p, now)
            for (i, j) in positions - set(slab_at):
                if os.path.exists(os.path.join(work, "cap", "slab", "pos_%d_%d.exr" % (i, j))):
                    slab_at[(i, j)] = now
            if capture.poll() not in (None, 0) or reconstruct.poll() not in (None, 0):
                sys.exit("capture_latency: a tool failed; see " + work + "/*.log")
            time.sleep(0.05)
        capture.wait(timeout=600)
        reconstruct.wait(timeout=600)
        total = time.time() - start
    finally:
        for p in procs[::-1]:
            if p.poll() is None:
                p.send_signal(signal.SIGTERM)
                try:
                    p.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    p.kill()
    order = sorted(complete_at, key=complete_at.get)
    latency = [slab_at[p] - complete_at[p] for p in order if p in slab_at]
    per_position = [complete_at[b] - complete_at[a] for a, b in zip(order, order[1:])]
    return {"latency": latency, "per_position": per_position, "total": total,
            "positions": len(order)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--grid", type=int, default=3)
    ap.add_argument("--formats", default="jpeg,dng")
    ap.add_argument("--keep", help="work in this folder and keep it")
    args = ap.parse_args()
    bin_dir = os.path.abspath(os.path.join(args.build, "bin"))
    root = os.path.abspath(args.keep) if args.keep else tempfile.mkdtemp(prefix="capture_latency_")
    if args.keep and os.path.exists(root) and os.listdir(root):
        sys.exit("capture_latency: --keep %s: not an empty folder" % root)
    os.makedirs(root, exist_ok=True)
    model = MOVE_S + 2 * 3 * EXPOSURE_S
    rows = []
    for fmt in args.formats.split(","):
        r = run_format(bin_dir, root, fmt, args.grid)
        lat, per = r["latency"], r["per_position"]
        rows.append((fmt, r["positions"], statistics.median(lat), max(lat),
                     statistics.median(per) if per else float("nan"), model, r["total"]))
    print("capture_latency: %dx%d grid, 6000 x 4000 px, 3 brackets per slide, %d cores" %
          (args.grid, args.grid, os.cpu_count()))
    print("| photos | positions | latency median (s) | latency max (s) | virtual-lab capture "
          "per position median (s) | lab-model capture per position (s) | whole run (s) |")
    print("|---|---|---|---|---|---|---|")
    for row in rows:
        print("| %s | %d | %.2f | %.2f | %.2f | %.1f | %.0f |" % row)
    if not args.keep:
        shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    main()
