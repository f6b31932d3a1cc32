#!/usr/bin/env python3
"""stage_costs: how each batch stage's time and peak memory grow (docs/results.md §14).

Renders synthetic datasets (lumislab-acquire synth) and runs each stage of the batch
(pipelines/batch-stage.sh: calibrate, reconstruct, export, preview) on them, one factor varied
at a time from a base (3 x 3 positions, 0.3 MP photos, slab 150, 1 thread):
  positions  3x3, 7x7, 11x11, 15x15
  photo      1, 6, 12, 24 MP (2 x 2 positions: 24 MP photos are large)
  slab       150, 300, 600, 1200 texels per side
  threads    1, 2 (7 x 7 positions, slab 300)
and the whole batch (pipelines/batch-convert.sh) on 4 datasets with --jobs 1 and 2. Each stage
is measured by its process tree's rusage (os.wait4: user + system CPU seconds, peak RSS of the
largest process) and its wall time. Prints the tables, the log-log slope of each series (the
exponent of the growth) and the least-squares fit of the formulas that pipelines/Snakefile
uses to request Slurm resources (--mem, --time); writes stage_costs.csv and
stage_costs_fit.json and stage_costs.svg (the growth, log-log; docs/images/) in --out. Run it under nice: it is a measurement, never a test.

  python3 bench/stage_costs.py --bin build/bin [--out /tmp/stage_costs] [--quick]
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
STAGE = os.path.join(HERE, "..", "pipelines", "batch-stage.sh")
CONVERT = os.path.join(HERE, "..", "pipelines", "batch-convert.sh")
STAGES = ["calibrate", "reconstruct", "export", "preview"]


def scene(n, mp):
    """A scene of n x n positions photographed at mp megapixels (4:3, the default framing)."""
    w = int(round(math.sqrt(mp * 1e6 * 4 / 3)))
    h = int(round(w * 3 / 4))
    return {
        "schema_version": 1,
        "setup": {"distance_mm": 750, "grid": {"nu": n, "nv": n, "spacing_mm": 5},
                  "screen_mm": [1200, 1200]},
        "luminaire": {"emitters": [{"position_mm": [1.5, -2, -20],
                                    "intensity_w_sr": [1.0, 0.9, 0.8], "lobe_exponent": 8}]},
        "camera": {"size_px": [w, h], "focal_px": 330 * w / 400,
                   "position_mm": [0, -100, 2400], "look_at_mm": [0, 0, 750]},
        "effects": []}


def measure(cmd, env):
    """Runs cmd; returns (cpu seconds, peak RSS MB, wall seconds, exit code)."""
    t0 = time.monotonic()
    p = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, ru = os.wait4(p.pid, 0)
    wall = time.monotonic() - t0
    return ru.ru_utime + ru.ru_stime, ru.ru_maxrss / 1024.0, wall, os.waitstatus_to_exitcode(status)


def dataset(work, bin_dir, n, mp):
    folder = os.path.join(work, f"d_{n}x{n}_{mp}mp")
    if not os.path.isfile(os.path.join(folder, "dataset.json")):
        with open(folder + ".scene.json", "w") as f:
            json.dump(scene(n, mp), f)
        subprocess.run([os.path.join(bin_dir, "lumislab-acquire"), "synth", "--meter", "lux",
                        "--scene", folder + ".scene.json", "--out", folder,
                        "--truth-resolution", "16", "--threads", "2"],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return folder


def run_stages(work, bin_dir, env, n, mp, res, threads):
    """The four stages of one dataset (calibrate once per dataset): one row each."""
    ds = dataset(work, bin_dir, n, mp)
    out = os.path.join(work, "out")
    rows = []
    for stage in STAGES:
        if stage == "calibrate" and os.path.isfile(os.path.join(ds, "calib", "screen.json")):
            continue
        if stage == "reconstruct":
            shutil.rmtree(os.path.join(ds, "slab"), ignore_errors=True)
        cpu, mem, wall, rc = measure(
            [STAGE, stage, ds, out, "--threads", str(threads), "--resolution", str(res),
             "--lab", "Bench", "--manufacturer", "Bench"], env)
        if rc != 0:
            sys.exit(f"stage_costs: {stage} of {ds} failed (exit {rc}): "
                     f"{out}/log/{os.path.basename(ds)}/{stage}.log")
        rows.append(dict(stage=stage, positions=n * n, photo_mp=mp, resolution=res,
                         threads=threads, cpu_s=cpu, peak_mb=mem, wall_s=wall))
        print(f"  {stage:12s} {n:2d}x{n:<2d} {mp:5.1f} MP res {res:4d} T{threads}: "
              f"cpu {cpu:7.2f} s  wall {wall:7.2f} s  peak {mem:7.1f} MB", flush=True)
    return rows


def solve(a, b):
    """Least squares a x = b (normal equations, Gaussian elimination; a few unknowns). A term
    the measurements cannot tell from the others (a singular pivot) gets 0."""
    k = len(a[0])
    m = [[sum(r[i] * r[j] for r in a) for j in range(k)] + [sum(r[i] * y for r, y in zip(a, b))]
         for i in range(k)]
    scale = max(abs(m[i][i]) for i in range(k)) or 1.0
    used = []
    for c in range(k):
        rows = [r for r in range(k) if r not in used]
        p = max(rows, key=lambda r: abs(m[r][c]))
        if abs(m[p][c]) < 1e-9 * scale:
            continue
        used.append(p)
        for r in range(k):
            if r != p:
                f = m[r][c] / m[p][c]
                m[r] = [x - f * y for x, y in zip(m[r], m[p])]
    x = [0.0] * k
    for p in used:
        c = next(c for c in range(k) if abs(m[p][c]) >= 1e-9 * scale)
        x[c] = m[p][k] / m[p][c]
    return x


def fit_nonnegative(a, b):
    """Least squares with every coefficient >= 0: a term fitted negative is dropped, the rest
    refitted (a cost does not fall as a size grows)."""
    keep = list(range(len(a[0])))
    while True:
        x = solve([[r[i] for i in keep] for r in a], b)
        if min(x) >= 0 or len(keep) == 1:
            break
        del keep[x.index(min(x))]
    x = [max(v, 0.0) for v in x]
    full = [0.0] * len(a[0])
    for i, v in zip(keep, x):
        full[i] = max(v, 0.0)
    return full


def slope(xs, ys):
    """The log-log slope: y ~ x^slope."""
    lx = [math.log(x) for x in xs]
    ly = [math.log(max(y, 1e-3)) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    den = sum((x - mx) ** 2 for x in lx)
    return sum((x - mx) * (y - my) for x, y in zip(lx, ly)) / den if den else 0.0


# The formulas' terms (pipelines/stage_resources.py): P positions, M photo megapixels,
# R2 = slab texels per side squared / 10^6, T threads.
def time_terms(r):
    p, m, r2 = r["positions"], r["photo_mp"], r["resolution"] ** 2 / 1e6
    return [1.0, m, p * m, p * r2]


def mem_terms(r):
    p, m, r2, t = r["positions"], r["photo_mp"], r["resolution"] ** 2 / 1e6, r["threads"]
    return [1.0, m * min(t, p), r2 * min(t, p), p * r2]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bin", required=True, help="the lumislab binaries (build/bin)")
    ap.add_argument("--out", default="/tmp/stage_costs", help="work folder, CSV and fit")
    ap.add_argument("--quick", action="store_true", help="the smallest point of each series")
    ap.add_argument("--from-csv", action="store_true",
                    help="no measuring: the tables and fit of --out's stage_costs.csv")
    args = ap.parse_args()
    work = os.path.abspath(args.out)
    os.makedirs(work, exist_ok=True)
    env = dict(os.environ, LUMISLAB_BIN=os.path.abspath(args.bin))
    series = {
        "positions": [(n, 0.3, 150, 1) for n in (3, 7, 11, 15)],
        "photo": [(2, mp, 150, 1) for mp in (1, 6, 12, 24)],
        "slab": [(3, 0.3, res, 1) for res in (150, 300, 600, 1200)],
        "threads": [(7, 0.3, 300, t) for t in (1, 2)],
    }
    if args.quick:
        series = {k: v[:2] for k, v in series.items()}
    if args.from_csv:
        report(work, series, read_csv(os.path.join(work, "stage_costs.csv")), None)
        return
    rows = []
    for name, points in series.items():
        print(f"series {name}", flush=True)
        for n, mp, res, t in points:
            for r in run_stages(work, args.bin, env, n, mp, res, t):
                r["series"] = name
                rows.append(r)

    # Batch throughput against --jobs: 4 datasets of the base size, converted whole.
    print("series jobs", flush=True)
    batch = os.path.join(work, "batch")
    for k in range(4):
        ds = dataset(work, args.bin, 3, 0.3 + 0.001 * k)
        dest = os.path.join(batch, f"lamp_{k}")
        if not os.path.isdir(dest):
            shutil.copytree(ds, dest)
    throughput = []
    for jobs in (1, 2):
        for k in range(4):
            shutil.rmtree(os.path.join(batch, f"lamp_{k}", "slab"), ignore_errors=True)
            shutil.rmtree(os.path.join(batch, f"lamp_{k}", "calib"), ignore_errors=True)
        cpu, mem, wall, rc = measure(
            [CONVERT, batch, "--out", os.path.join(work, "batch_out"), "--jobs", str(jobs),
             "--resolution", "150", "--lab", "Bench", "--manufacturer", "Bench"], env)
        throughput.append(dict(jobs=jobs, datasets=4, wall_s=wall, cpu_s=cpu,
                               per_hour=4 * 3600 / wall, exit=rc))
        print(f"  --jobs {jobs}: 4 datasets in {wall:.1f} s wall ({cpu:.1f} s CPU), "
              f"{4 * 3600 / wall:.0f} datasets/hour, exit {rc}", flush=True)

    with open(os.path.join(work, "stage_costs.csv"), "w") as f:
        keys = ["series", "stage", "positions", "photo_mp", "resolution", "threads", "cpu_s",
                "wall_s", "peak_mb"]
        f.write(",".join(keys) + "\n")
        for r in rows:
            f.write(",".join(f"{r[k]:.3f}" if isinstance(r[k], float) else str(r[k])
                             for k in keys) + "\n")

    report(work, series, rows, throughput)


COLOURS = {"calibrate": "#1b9e77", "reconstruct": "#d95f02", "export": "#7570b3",
           "preview": "#e7298a"}


def plot(path, rows):
    """An SVG of three log-log panels (positions, photo MP, slab texels): each stage's CPU time
    (solid) and peak memory (dashed) relative to the series' first point, with the lines of
    slope 1 and 2 (grey) for the complexity expected."""
    panels = [("positions", "positions"), ("photo", "photo_mp"), ("slab", "resolution")]
    w, h, pad = 300, 260, 40
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{3 * w}" height="{h + 30}" '
           'font-family="sans-serif" font-size="11">']
    for k, (name, key) in enumerate(panels):
        x0 = k * w
        pts = [r for r in rows if r["series"] == name]
        if not pts:
            continue
        xs = sorted({r[key] for r in pts})
        lx0, lx1 = math.log(xs[0]), math.log(xs[-1])
        ly1 = math.log(64.0)  # the y axis: 1x ... 64x the first point

        def px(x, y):
            return (x0 + pad + (math.log(x) - lx0) / (lx1 - lx0) * (w - 2 * pad),
                    h - pad - math.log(max(y, 1e-3)) / ly1 * (h - 2 * pad))
        out.append(f'<rect x="{x0 + pad}" y="{pad}" width="{w - 2 * pad}" height="{h - 2 * pad}" '
                   'fill="none" stroke="#999"/>')
        out.append(f'<text x="{x0 + w / 2}" y="{h - 8}" text-anchor="middle">{key} '
                   f'({xs[0]:g} … {xs[-1]:g}, log)</text>')
        out.append(f'<text x="{x0 + pad}" y="{pad - 8}">{name}: cost / first point '
                   '(1 … 64, log)</text>')
        for slope_ in (1, 2):
            xe = min(xs[-1], xs[0] * 64 ** (1 / slope_))
            (a, b), (c, d) = px(xs[0], 1), px(xe, (xe / xs[0]) ** slope_)
            out.append(f'<line x1="{a:.1f}" y1="{b:.1f}" x2="{c:.1f}" y2="{d:.1f}" '
                       'stroke="#ccc" stroke-width="1"/>')
        for stage, colour in COLOURS.items():
            sp = sorted((r for r in pts if r["stage"] == stage), key=lambda r: r[key])
            if len(sp) < 2:
                continue
            for field, dash in (("cpu_s", ""), ("peak_mb", ' stroke-dasharray="4 3"')):
                line = " ".join("%.1f,%.1f" % px(r[key], r[field] / sp[0][field]) for r in sp)
                out.append(f'<polyline points="{line}" fill="none" stroke="{colour}" '
                           f'stroke-width="1.5"{dash}/>')
    for k, (stage, colour) in enumerate(COLOURS.items()):
        out.append(f'<text x="{pad + 110 * k}" y="{h + 20}" fill="{colour}">{stage}</text>')
    out.append(f'<text x="{pad + 440}" y="{h + 20}">solid: CPU time, dashed: peak memory; '
               'grey: slopes 1 and 2</text></svg>')
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def read_csv(path):
    with open(path) as f:
        keys = f.readline().strip().split(",")
        rows = [dict(zip(keys, line.strip().split(","))) for line in f]
    for r in rows:
        for k in ("positions", "resolution", "threads"):
            r[k] = int(r[k])
        for k in ("photo_mp", "cpu_s", "wall_s", "peak_mb"):
            r[k] = float(r[k])
    return rows


def report(work, series, rows, throughput):
    """The growth exponents and the fit; stage_costs_fit.json."""
    print("\nGrowth exponents (log-log slope of CPU time and peak memory along each series)")
    print(f"{'stage':12s} {'series':10s} {'x':>22s} {'cpu ~ x^':>9s} {'mem ~ x^':>9s}")
    xkey = {"positions": "positions", "photo": "photo_mp", "slab": "resolution",
            "threads": "threads"}
    for stage in STAGES:
        for name in series:
            pts = [r for r in rows if r["series"] == name and r["stage"] == stage]
            if len(pts) < 2:
                continue
            xs = [r[xkey[name]] for r in pts]
            print(f"{stage:12s} {name:10s} {str(xs):>22s} "
                  f"{slope(xs, [r['cpu_s'] for r in pts]):9.2f} "
                  f"{slope(xs, [r['peak_mb'] for r in pts]):9.2f}")

    fit = {}
    print("\nFitted (coefficients >= 0): cpu_s = c0 + c1 M + c2 P M + c3 P R2;"
          "  peak_mb = m0 + m1 M min(T, P) + m2 R2 min(T, P) + m3 P R2"
          "\n(P positions, M photo MP, R2 = resolution^2 / 1e6, T threads)")
    for stage in STAGES:
        pts = [r for r in rows if r["stage"] == stage]
        c = fit_nonnegative([time_terms(r) for r in pts], [r["cpu_s"] for r in pts])
        m = fit_nonnegative([mem_terms(r) for r in pts], [r["peak_mb"] for r in pts])
        worst_c = max(r["cpu_s"] / max(sum(a * b for a, b in zip(c, time_terms(r))), 1e-3)
                      for r in pts)
        worst_m = max(r["peak_mb"] / max(sum(a * b for a, b in zip(m, mem_terms(r))), 1e-3)
                      for r in pts)
        fit[stage] = {"cpu_s": [round(x, 4) for x in c], "peak_mb": [round(x, 2) for x in m],
                      "worst_measured_over_fit": [round(worst_c, 2), round(worst_m, 2)]}
        print(f"{stage:12s} cpu_s = {c[0]:.3f} + {c[1]:.4f} M + {c[2]:.4f} P M + {c[3]:.3f} P R2 "
              f"(worst measured/fit {worst_c:.2f});\n{'':12s} peak_mb = {m[0]:.1f} + {m[1]:.1f} M "
              f"min(T,P) + {m[2]:.1f} R2 min(T,P) + {m[3]:.1f} P R2 (worst {worst_m:.2f})")
    plot(os.path.join(work, "stage_costs.svg"), rows)
    print(f"wrote {work}/stage_costs.svg")
    if throughput is None:
        return
    with open(os.path.join(work, "stage_costs_fit.json"), "w") as f:
        json.dump({"fit": fit, "throughput": throughput}, f, indent=1)
    print(f"\nwrote {work}/stage_costs.csv and stage_costs_fit.json")


if __name__ == "__main__":
    main()
