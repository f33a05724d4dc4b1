#!/usr/bin/python3
"""Flow past a cube in a channel at Re = 100 on a grid that follows the wake (issue #7).

Runs cases/flow/obstacle-wake.toml twice with `sanguis run`: as written (adaptive:
8 cells per D at the finest, blocks near the cube kept finest, the wavelet
criterion of thesis eq. 4.11 on the velocity with zeta = 0.05 m/s every 10 steps,
coarsening down to 2 cells per D), and on its uniform finest grid (the same case
without [flow.adapt], 128 x 64 x 64 cells). Both start from rest with the parabolic
inflow switched on at t = 0 and run to t = 20 s (20 D/U).

Checks, fixed before the validation runs (a trial adaptive run had shown about 3x
fewer cells at the end and the drag still drifting slowly at t = 20 s):
* drag: the force of the fluid on the cube along x at t = 20 s, and its mean over
  t = 15-20 s, within 3 % of the uniform finest run's;
* the grid follows the wake: in the wake behind the cube (x = 4.5-8, |y - 4| and
  |z - 4| < 0.5, at t = 20 s) at least 90 % of the volume is at the finest level;
* the face velocity stays divergence-free: max |div uf| below 1e-3 1/s (the
  projection tolerance is 1e-6 relative) in both runs.
Reported: cells at the end and on average, wall time of both runs (time to
solution at equal accuracy), the regrid share.

Writes validation/flow/results/obstacle_wake.json (runs under
validation/flow/results/runs/obstacle_wake/) and
docs/validation/figures/flow_obstacle_wake.png. About 20 min on 2 cores.
Exits 1 if a check fails.

Usage: /usr/bin/python3 validation/flow/obstacle_wake.py [--build build] [--threads T] [--replot]
"""
import argparse
import json
import re
import subprocess
import sys
import time
from pathlib import Path

import matplotlib
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _cavity_common import cell_boxes, draw_speed_and_blocks, read_rows, read_vtu  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
CASE = ROOT / "cases" / "flow" / "obstacle-wake.toml"
RESULTS = ROOT / "validation" / "flow" / "results"
RUNS = RESULTS / "runs" / "obstacle_wake"
FIGURE = ROOT / "docs" / "validation" / "figures" / "flow_obstacle_wake.png"
END = 20.0
DRAG_TOLERANCE = 0.03
WAKE_FINEST = 0.90
DIVERGENCE_LIMIT = 1e-3


def set_end(end):
    global END
    END = end


def sanguis_run(exe, case, out, threads, extra=()):
    cmd = [str(exe), "run", str(case), "-o", str(out), "--quiet",
           "--set", f"simulation.threads={threads}", "--set", "output.interval_s=0.5", *extra]
    print(" ".join(cmd), flush=True)
    start = time.time()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return time.time() - start


def run_both(exe, threads):
    """The adaptive case as written (to 19.5 s without frames, then to 20 s with
    the last frame), and the same case without [flow.adapt]."""
    RUNS.mkdir(parents=True, exist_ok=True)
    seconds = {}
    adaptive = RUNS / "adaptive"
    seconds["adaptive"] = sanguis_run(
        exe, CASE, adaptive, threads,
        ["--set", f"simulation.end_time_s={max(END - 0.5, END / 2)}", "--set", "output.vtk=false"])
    seconds["adaptive"] += sanguis_run(
        exe, CASE, adaptive, threads,
        ["--restart", "--set", f"simulation.end_time_s={END}", "--set", "output.vtk=true"])
    # The same case without [flow.adapt] (and any sub-table of it).
    kept, inside = [], False
    for line in CASE.read_text().splitlines(keepends=True):
        header = re.match(r"\s*\[\[?\s*([\w.]+)\s*\]\]?", line)
        if header:
            inside = header.group(1) == "flow.adapt" or header.group(1).startswith("flow.adapt.")
        if not inside:
            kept.append(line)
    uniform_text = "".join(kept)
    uniform_case = RUNS / "obstacle-wake-uniform.toml"
    uniform_case.write_text(uniform_text)
    seconds["uniform"] = sanguis_run(
        exe, uniform_case, RUNS / "uniform", threads,
        ["--set", f"simulation.end_time_s={END}", "--set", "output.vtk=false"])
    (RUNS / "wall_seconds.json").write_text(json.dumps(seconds))
    return seconds


def regrid_share(run):
    text = (run / "run.log").read_text()
    shares = [float(m) for m in re.findall(r"regridding ([\d.]+) %", text)]
    return shares


def drag_stats(rows):
    t = np.array([r["time_s"] for r in rows])
    f = np.array([r["solid_force_x_N"] for r in rows])
    late = (t >= 0.75 * END - 1e-9) & (t <= END + 1e-9)
    return float(f[np.argmin(np.abs(t - END))]), float(f[late].mean())


def slice_cells(arrays, z):
    """The cells the plane at height z cuts: lower and upper corners, level, speed, block."""
    lo, hi = cell_boxes(arrays)
    cut = (lo[:, 2] <= z) & (hi[:, 2] > z)
    speed = np.linalg.norm(arrays["velocity"], axis=1)
    return lo[cut], hi[cut], arrays["level"][cut], speed[cut], arrays["block"][cut]


def wake_finest_fraction(arrays):
    lo, hi = cell_boxes(arrays)
    centre = 0.5 * (lo + hi)
    volume = np.prod(hi - lo, axis=1)
    wake = ((centre[:, 0] > 4.5) & (centre[:, 0] < 8.0) & (np.abs(centre[:, 1] - 4.0) < 0.5)
            & (np.abs(centre[:, 2] - 4.0) < 0.5))
    finest = arrays["level"] == arrays["level"].max()
    return float(volume[wake & finest].sum() / volume[wake].sum())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--replot", action="store_true", help="analyse the runs on disk")
    ap.add_argument("--end-time", type=float, default=END,
                    help="shorter runs for a smoke test (the checks are stated for 20 s)")
    args = ap.parse_args()
    set_end(args.end_time)
    exe = ROOT / args.build / "app" / "sanguis"
    if args.replot:
        seconds = json.loads((RUNS / "wall_seconds.json").read_text())
    else:
        seconds = run_both(exe, args.threads)

    adaptive = read_rows(RUNS / "adaptive" / "diagnostics.csv")
    uniform = read_rows(RUNS / "uniform" / "diagnostics.csv")
    drag_a, mean_a = drag_stats(adaptive)
    drag_u, mean_u = drag_stats(uniform)
    frames = sorted((RUNS / "adaptive" / "flow").glob("flow_*.vtu"))
    _, arrays = read_vtu(frames[-1])
    wake = wake_finest_fraction(arrays)
    cells_uniform = uniform[-1]["cells"]
    cells_end = adaptive[-1]["cells"]
    cells_mean = float(np.mean([r["cells"] for r in adaptive[1:]]))
    div_a = max(r["max_divergence_1_s"] for r in adaptive)
    div_u = max(r["max_divergence_1_s"] for r in uniform)

    checks = [
        {"quantity": f"drag F_x at t = {END:g} s [N]", "measured": round(drag_a, 5),
         "reference": round(drag_u, 5), "tolerance": f"±{DRAG_TOLERANCE:.0%}",
         "pass": abs(drag_a / drag_u - 1) <= DRAG_TOLERANCE},
        {"quantity": f"mean drag F_x over t = {0.75 * END:g}-{END:g} s [N]",
         "measured": round(mean_a, 5),
         "reference": round(mean_u, 5), "tolerance": f"±{DRAG_TOLERANCE:.0%}",
         "pass": abs(mean_a / mean_u - 1) <= DRAG_TOLERANCE},
        {"quantity": "volume of the wake (x 4.5-8, |y-4|, |z-4| < 0.5) at the finest level",
         "measured": round(wake, 4), "reference": "—", "tolerance": f">= {WAKE_FINEST:.0%}",
         "pass": wake >= WAKE_FINEST},
        {"quantity": "max |div uf| over the run [1/s], adaptive; uniform",
         "measured": f"{div_a:.2e}; {div_u:.2e}", "reference": "—",
         "tolerance": f"< {DIVERGENCE_LIMIT:g}",
         "pass": div_a < DIVERGENCE_LIMIT and div_u < DIVERGENCE_LIMIT},
    ]
    ok = all(c["pass"] for c in checks)
    summary = {
        "case": str(CASE.relative_to(ROOT)), "end_time_s": END, "checks": checks,
        "cells_uniform": int(cells_uniform), "cells_adaptive_end": int(cells_end),
        "cells_adaptive_mean": round(cells_mean), "cell_ratio_end": round(cells_uniform / cells_end, 2),
        "cell_ratio_mean": round(cells_uniform / cells_mean, 2),
        "wall_seconds": {k: round(v, 1) for k, v in seconds.items()},
        "regrid_share_percent": regrid_share(RUNS / "adaptive"),
        "drag_relative_difference_end": round(drag_a / drag_u - 1, 5),
        "drag_relative_difference_mean": round(mean_a / mean_u - 1, 5),
    }
    for c in checks:
        print(f"{'PASS' if c['pass'] else 'FAIL'}  {c['quantity']}: {c['measured']} "
              f"(reference {c['reference']}, {c['tolerance']})")
    print(f"cells: uniform {int(cells_uniform)}, adaptive {int(cells_end)} at the end "
          f"({cells_uniform / cells_end:.2f}x fewer), {cells_mean:.0f} on average "
          f"({cells_uniform / cells_mean:.2f}x); wall time adaptive {seconds['adaptive']:.0f} s, "
          f"uniform {seconds['uniform']:.0f} s")

    fig = plt.figure(figsize=(13, 7.5))
    lo, hi, level, speed, block = slice_cells(arrays, 4.0 + 1.0 / 32)
    ax1 = fig.add_subplot(2, 2, (1, 2))
    draw_speed_and_blocks(fig, ax1, lo, hi, speed, block, "|u| [m/s]", 0.025, 0.4)
    ax1.add_patch(plt.Rectangle((3.5, 3.5), 1.0, 1.0, color="k"))
    ax1.set_xlim(0, 16)
    ax1.set_ylim(0, 8)
    ax1.set_aspect("equal")
    ax1.set_anchor("C")
    ax1.set_xlabel("x [m]")
    ax1.set_ylabel("y [m]")
    ax1.set_title(f"adaptive run at t = {END:g} s, mid-plane z = 4: speed and blocks "
                  f"(8 cells each; levels {int(level.min())}-{int(level.max())})")

    ax2 = fig.add_subplot(2, 2, 3)
    for rows, label in ((uniform, f"uniform finest ({int(cells_uniform)} cells)"),
                        (adaptive, "adaptive")):
        ax2.plot([r["time_s"] for r in rows[1:]], [r["solid_force_x_N"] for r in rows[1:]],
                 label=label)
    ax2.set_xlabel("t [s]  (D/U = 1 s)")
    ax2.set_ylabel("drag F_x [N]")
    ax2.set_ylim(0, None)
    ax2.legend()
    ax2.set_title(f"drag: {100 * (drag_a / drag_u - 1):+.2f} % at t = {END:g} s, "
                  f"{100 * (mean_a / mean_u - 1):+.2f} % over {0.75 * END:g}-{END:g} s")
    ax3 = fig.add_subplot(2, 2, 4)
    ax3.plot([r["time_s"] for r in adaptive], [r["cells"] for r in adaptive], label="adaptive")
    ax3.axhline(cells_uniform, color="k", ls="--", label="uniform finest")
    ax3.set_xlabel("t [s]")
    ax3.set_ylabel("cells")
    ax3.set_ylim(0, 1.1 * cells_uniform)
    ax3.legend()
    ax3.set_title(f"cells: {cells_uniform / cells_mean:.1f}x fewer on average; wall time "
                  f"{seconds['adaptive']:.0f} s vs {seconds['uniform']:.0f} s")
    fig.tight_layout()
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURE, dpi=110)
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "obstacle_wake.json").write_text(json.dumps(summary, indent=1))
    print(f"{'PASS' if ok else 'FAIL'}; figure {FIGURE.relative_to(ROOT)}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
