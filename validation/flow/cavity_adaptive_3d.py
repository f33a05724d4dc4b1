#!/usr/bin/python3
"""The 3D lid-driven cavity on an adaptive grid against its uniform finest grid (issue #7).

cases/flow/cavity-re100.toml (unit cube, Re = 100) with the finest grid 128^3,
run from rest to t = 15 L/U (steady: the kinetic energy of the uniform run
changes by 3e-4 of itself from t = 10 to 15) with `sanguis run`:
* adaptive: blocks of 8^3, the wavelet criterion of thesis eq. 4.11 on the
  velocity every 10 steps, zeta = 2e-2 U, cells down to two levels coarser
  (4h, h = 1/128);
* adaptive_2h: the same with zeta = 5e-2 U and cells at most one level coarser
  (2h). Added after the first run, which passed the cell and whole-grid checks
  but missed the centre-line one by 3 %, all of it from sampling the 4h cells
  on the line (below). The checks were not changed; the first run's verdict
  stays in the JSON (pass_of_the_run_fixed_first: false);
* uniform: the same case without [flow.adapt], 128^3 cells (16^3 blocks, the
  size a grid that does not adapt gets). This is the run that
  validation/flow/adaptive_potential.py reads (runs/cavity-re100-128); when it
  is on disk its t = 15 checkpoint is copied rather than run again (58 min on
  one thread).
All then continue from t = 15 to 15.5 at the same fixed step, 0.005 L/U (the
CFL step of the 128^3 grid is 0.0064): the velocity of the cells at the lid
corners depends on the last steps' length by several per cent (the approximate
projection, see validation/flow/cavity_adaptive.py), and the CFL runs' last
steps before t = 15 were shortened differently. The frames at t = 15.5 are
compared.

Why these zeta: validation/flow/adaptive_potential.py bounds the cells a
settled grid can have from the uniform field (blocks as coarse as the
criterion allows, any number of levels): 5.5x fewer at 1e-2 U, 8.7x at
2.2e-2 U. A settled grid holds more than the bound (a family merges only
below 2/3 of zeta; the vortex runs held up to 2x the bound), so 1e-2 U would
likely have left less than 5x; 2e-2 U was taken for the first run. For the
second, the bound capped at one coarser level and its centre lines were
computed from the uniform field first (what bound_grid_sampling now reports):
5.1x at 2e-2 U, 5.8x from 5e-2 U, lines 0.0011 U off with the uniform field
averaged onto that grid; 5e-2 U was taken for the cells. (Capped at two
levels, as the first run was, the bound is 8.5x at 2e-2 U, computed
afterwards.)

Checks for each adaptive run, fixed before the first (the 2D cavity's at 256^2,
which passed with 6x and 10x margins at zeta = 1e-2 U):
* cells: the adaptive grid at t = 15.5 has at least 5x fewer cells than the
  uniform finest grid (the issue's target);
* the same answer: on the two centre lines of the mid-plane z = 0.5 (u(y) on
  x = 0.5, v(x) on y = 0.5, at the uniform grid's cell centres, interpolated
  linearly between the centres of the cells touching the line) the adaptive
  velocity is within 5e-3 U of the uniform run's, and on the whole grid every
  adaptive cell is within 1e-2 U of the uniform run's mean over that cell.
Reported, not graded: the uniform run's own field averaged onto each adaptive
grid's cells and sampled on the lines the same way (what the cells alone do
to the line check), the same for the fewest-cells grids of the bound at
several zeta, the cells at the end, where the lines differ most, and the wall
time of each run to t = 15 (time to solution; all on one thread, see
--threads; the uniform run on disk wrote three frames of 486 MB in its time,
a uniform run made here writes none before t = 15).

Writes validation/flow/results/cavity_adaptive_3d.json (runs under
validation/flow/results/runs/cavity_adaptive_3d/) and
docs/validation/figures/flow_cavity_adaptive_3d.png. Exits 1 unless some
adaptive run passes every check. About 40 min on one core with the uniform
run on disk, 1 h 40 min without.

Usage: /usr/bin/python3 validation/flow/cavity_adaptive_3d.py [--build build] [--threads 1]
           [--replot]
"""
import argparse
import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "dem"))
import adaptive_potential  # noqa: E402
from _outputs import finished_segments  # noqa: E402  (run.log segments, both solvers write them)
from _cavity_common import (cell_boxes, draw_centre_lines, draw_plane_cut, last_frame, read_rows,  # noqa: E402
                            read_vtu, with_walls)

ROOT = Path(__file__).resolve().parents[2]
CASE = ROOT / "cases" / "flow" / "cavity-re100.toml"
RESULTS = ROOT / "validation" / "flow" / "results"
RUNS = RESULTS / "runs" / "cavity_adaptive_3d"
UNIFORM_ON_DISK = RESULTS / "runs" / "cavity-re100-128"
SUMMARY = RESULTS / "cavity_adaptive_3d.json"
FIGURE = ROOT / "docs" / "validation" / "figures" / "flow_cavity_adaptive_3d.png"
N = 128
END = 15.0
SETTLE_END = 15.5
FIXED_STEP = 0.005
# The adaptive runs: zeta of eq. 4.11 over the lid speed U = 1 m/s, and how many
# levels coarser than the finest the cells may become.
ADAPTIVE = {"adaptive": {"zeta": 2e-2, "coarsen_levels": 2,
                         "chosen": "fixed before any run, with the checks"},
            "adaptive_2h": {"zeta": 5e-2, "coarsen_levels": 1,
                            "chosen": "added after 'adaptive' failed the centre-line check; checks unchanged"}}
CELL_RATIO = 5.0
LINE_TOLERANCE = 5e-3
FIELD_TOLERANCE = 1e-2
CENTRES = (np.arange(N) + 0.5) / N  # where the centre lines are compared: the uniform cells'


def case_text(name):
    """cavity-re100.toml at 128^3, with the [flow.adapt] of an ADAPTIVE run or without."""
    text = CASE.read_text()
    old = "cells = [32, 32, 32]"
    if old not in text:
        raise SystemExit(f"{CASE}: expected '{old}' (the case changed; update this script)")
    adaptive = ADAPTIVE.get(name)
    text = text.replace(old, f"cells = [{N}, {N}, {N}]" + ("\nblock_cells = 8" if adaptive else ""))
    if adaptive:
        text += ("\n[flow.adapt]\n"
                 f"velocity_threshold_m_s = {adaptive['zeta']!r}\n"
                 f"refine_levels = 0\ncoarsen_levels = {adaptive['coarsen_levels']}\nevery_steps = 10\n")
    return text


def sanguis(exe, case, out, threads, *extra):
    cmd = [str(exe), "run", str(case), "-o", str(out), "--quiet",
           "--set", f"simulation.threads={threads}", *extra]
    print(" ".join(cmd), flush=True)
    start = time.time()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return time.time() - start


def reached(out, t):
    """Whether a run's diagnostics reach time t."""
    path = out / "diagnostics.csv"
    return path.exists() and read_rows(path)[-1]["time_s"] >= t - 1e-9


def run_to_end(exe, name, threads):
    """Runs one case to END (frames every 5 s), or reuses the run on disk;
    returns the wall seconds to END (from the log when reused)."""
    RUNS.mkdir(parents=True, exist_ok=True)
    case = RUNS / f"{name}.toml"
    case.write_text(case_text(name))
    out = RUNS / name
    if reached(out, END):
        check_settings(name, out)
        return run_seconds(name)["seconds_to_end"]
    if name == "uniform" and reached(UNIFORM_ON_DISK, END) and not out.exists():
        out.mkdir()
        for f in ("checkpoint.bin", "diagnostics.csv", "run.log"):
            shutil.copy2(UNIFORM_ON_DISK / f, out / f)
        seconds = log_seconds(out / "run.log")
        print(f"uniform: the t = {END:g} checkpoint of {UNIFORM_ON_DISK.relative_to(ROOT)} copied "
              f"({seconds:.0f} s to t = {END:g} there)", flush=True)
    else:
        restart = ["--restart"] if (out / "checkpoint.bin").exists() else []
        # No frames of the uniform run before the last one (600 MB each at 128^3).
        frames = ["--set", "output.vtk=false"] if name == "uniform" else []
        seconds = sanguis(exe, case, out, threads, "--set", "output.interval_s=5", *frames, *restart)
        if restart:  # time of a resumed run: the log's total
            seconds = log_seconds(out / "run.log")
    seconds_path(name).write_text(json.dumps({"seconds_to_end": seconds, "threads": threads}))
    return seconds


def check_settings(name, out):
    """Stops when an adaptive run on disk was made with other [flow.adapt] settings than
    ADAPTIVE gives it (run.log's 'adaptive grid:' line), rather than label it wrongly."""
    adaptive = ADAPTIVE.get(name)
    if not adaptive:
        return
    expected = (f"threshold {adaptive['zeta']:g} m/s",
                f"{2 ** adaptive['coarsen_levels']}x coarser")
    line = next((l for l in (out / "run.log").read_text().splitlines() if l.startswith("adaptive grid:")), "")
    if not all(e in line for e in expected):
        raise SystemExit(f"{out}: made with other [flow.adapt] settings ({line!r}); remove the folder to rerun it")


def seconds_path(name):
    return RUNS / f"{name}_seconds.json"


def run_seconds(name):
    """The wall seconds to END and the threads of a run, as run_to_end recorded them;
    from its run.log (threads unknown) when that record is missing."""
    path = seconds_path(name)
    if path.exists():
        return json.loads(path.read_text())
    return {"seconds_to_end": log_seconds(RUNS / name / "run.log", END), "threads": None}


def log_seconds(path, until=float("inf")):
    """Wall seconds of a run from its run.log (the file at `path`): its segments
    that ended by time `until`, summed over restarts (_outputs.finished_segments)."""
    return sum(seconds for end, seconds in finished_segments(str(path.parent)) if end <= until + 1e-9)


def settle(exe, name, threads):
    """From END to SETTLE_END at the fixed step, with a frame at the end."""
    out = RUNS / name
    if reached(out, SETTLE_END):
        return
    sanguis(exe, RUNS / f"{name}.toml", out, threads, "--restart",
            "--set", f"simulation.end_time_s={SETTLE_END!r}",
            "--set", f"flow.time.max_time_step_s={FIXED_STEP!r}",
            "--set", f"output.interval_s={SETTLE_END - END!r}")


def final_frame(name):
    return read_vtu(last_frame(RUNS, name))[1]


def line_profile(arrays, along, across, component, at):
    """Velocity component on the line {x_across = 0.5, z = 0.5} of the mid-plane
    as a function of x_along, at the points `at`: in each of the four quadrants
    around the line, the cells touching it, interpolated linearly between their
    centres (wall values at the ends); the four quadrants averaged (on a uniform
    grid: the mean of the four cells around the line)."""
    lo, hi = cell_boxes(arrays)
    centre = 0.5 * (lo + hi)
    eps = 1e-9
    lid = 1.0 if (along == 1 and component == 0) else 0.0  # u = U at the lid y = 1
    quadrants = []
    for side_a in (np.abs(hi[:, across] - 0.5) < eps, np.abs(lo[:, across] - 0.5) < eps):
        for side_z in (np.abs(hi[:, 2] - 0.5) < eps, np.abs(lo[:, 2] - 0.5) < eps):
            touching = side_a & side_z
            keys = np.round(centre[touching, along], 12)
            order = np.argsort(keys)
            xs, ys = with_walls(keys[order], arrays["velocity"][touching, component][order], lid)
            quadrants.append(np.interp(at, xs, ys))
    return np.mean(quadrants, axis=0)


def uniform_array(arrays):
    """The uniform run's velocity as an N^3 x 3 array indexed by cell."""
    lo, _ = cell_boxes(arrays)
    index = np.rint(lo * N).astype(int)
    grid = np.zeros((N, N, N, 3))
    grid[index[:, 0], index[:, 1], index[:, 2]] = arrays["velocity"]
    return grid


def cell_means(grid, arrays):
    """The uniform run's velocity averaged over each cell of another grid (its
    cells nest in those cells): block averages of the N^3 array by the cell's
    width, looked up at the cell's index."""
    lo, hi = cell_boxes(arrays)
    width = np.rint((hi[:, 0] - lo[:, 0]) * N).astype(int)
    means = np.empty((len(lo), 3))
    for w in np.unique(width):
        m = N // w
        averaged = grid.reshape(m, w, m, w, m, w, 3).mean(axis=(1, 3, 5))
        sel = width == w
        i = np.rint(lo[sel] * N).astype(int) // w
        means[sel] = averaged[i[:, 0], i[:, 1], i[:, 2]]
    return means


def boxes_frame(lo, hi, grid):
    """Arrays of a frame whose cells are the boxes (lo, hi), with the uniform
    run's means over them as velocity (what line_profile and cell_means read)."""
    n = len(lo)
    low, high = np.arange(n)[:, None], np.arange(n, 2 * n)[:, None]
    connectivity = np.concatenate([np.tile(low, 4), np.tile(high, 4)], axis=1).ravel()
    arrays = {"Points": np.concatenate([lo, hi]), "connectivity": connectivity}
    arrays["velocity"] = cell_means(grid, arrays)
    return arrays


def centre_lines(arrays):
    """u(y) on x = z = 0.5 and v(x) on y = z = 0.5 at CENTRES."""
    return {"u": line_profile(arrays, 1, 0, 0, CENTRES), "v": line_profile(arrays, 0, 1, 1, CENTRES)}


def line_difference(lines, reference):
    """Largest difference between two sets of centre lines."""
    return float(max(np.abs(lines[c] - reference[c]).max() for c in ("u", "v")))


def block_estimates(grid):
    """adaptive_potential's block estimates of the uniform field, every level (finest first)."""
    return adaptive_potential.level_estimates([grid[..., d] for d in range(3)], (False, False, False))


def bound_grid_sampling(grid, profiles, coarsen_levels, zetas, levels=None):
    """For the fewest-cells grid the criterion can settle on at each zeta
    (adaptive_potential.fewest_leaves, at most `coarsen_levels` coarser): its cells
    and how far the uniform field averaged onto it, sampled on the centre lines,
    lies from the uniform lines. What the centre-line check measures of the cells
    alone, whatever the solution on them. `levels`: block_estimates(grid), when
    already at hand."""
    B = adaptive_potential.B
    levels = (block_estimates(grid) if levels is None else levels)[:coarsen_levels + 1]
    corner = np.stack(np.meshgrid(*[np.arange(B)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    rows = []
    for zeta in zetas:
        lo, hi = [], []
        for k, leaf in enumerate(adaptive_potential.fewest_leaves(levels, zeta)):
            w = 2 ** k
            for block in np.argwhere(leaf):
                cells = (block * B + corner) * w
                lo.append(cells / N)
                hi.append((cells + w) / N)
        arrays = boxes_frame(np.concatenate(lo), np.concatenate(hi), grid)
        cells = len(arrays["velocity"])
        difference = line_difference(centre_lines(arrays), profiles)
        rows.append({"coarsen_levels": coarsen_levels, "zeta_over_U": zeta, "cells": cells,
                     "cell_ratio": round(N ** 3 / cells, 2),
                     "centre_line_difference_of_the_averaged_uniform_field": round(difference, 5)})
        print(f"  bound grid, {coarsen_levels} level(s) coarser at most, zeta = {zeta:g} U: "
              f"{N ** 3 / cells:.2f}x fewer cells, lines of the averaged uniform field {difference:.5f} U", flush=True)
    return rows


def draw_plane(fig, ax, arrays, values, label, title):
    """The cells cut by the plane z = 0.5 + h/2 (h: the finest cell) coloured by
    `values` (one per cell), with the blocks outlined."""
    draw_plane_cut(fig, ax, arrays, values, 0.5 + 0.5 / N, label, title, 0.4)


def draw(frames, profiles, averaged, rows, diffs, cells_uniform):
    """The figure; averaged[name]: the uniform run's centre lines through the cells of run name."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(20, 9))
    for k, name in enumerate(ADAPTIVE):
        arrays, setup = frames[name], ADAPTIVE[name]
        draw_plane(fig, fig.add_subplot(2, 4, 1 + k), arrays, np.linalg.norm(arrays["velocity"], axis=1), "|u| / U",
                   f"{name} (zeta {setup['zeta']:g} U, at most {2 ** setup['coarsen_levels']} h), mid-plane z = 0.5:\n"
                   f"{rows[name][-1]['cells']:.0f} cells, t = {SETTLE_END:g} L/U")
        draw_plane(fig, fig.add_subplot(2, 4, 5 + k), arrays, diffs[name],
                   f"|u - mean of uniform {N}$^3$ over the cell| / U", f"{name} against the uniform run, mid-plane")
    ax = fig.add_subplot(2, 4, 3)
    draw_centre_lines(ax, profiles, CENTRES, zip(("uniform", *ADAPTIVE), ("-", "--", ":")),
                      "centre lines of the mid-plane, Re = 100", " on x = z = 0.5", " on y = z = 0.5")
    ax = fig.add_subplot(2, 4, 7)
    for name, colour in zip(ADAPTIVE, ("C0", "C1")):
        for c, line, style in (("u", "x", "-"), ("v", "y", "--")):
            ax.semilogy(CENTRES, np.abs(profiles[name][c] - profiles["uniform"][c]) + 1e-7, style, color=colour,
                        lw=1, label=f"{name}: |Δ{c}| on {line} = z = 0.5")
            ax.semilogy(CENTRES, np.abs(averaged[name][c] - profiles["uniform"][c]) + 1e-7, ":", color=colour,
                        lw=1.5, label=f"uniform averaged onto the cells of {name}: |Δu|, |Δv|" if c == "v" else None)
    ax.axhline(LINE_TOLERANCE, color="r", ls="--", lw=0.8, label="tolerance")
    ax.set_xlabel("position along the line / L")
    ax.set_ylabel(f"difference from uniform {N}$^3$ / U")
    ax.set_ylim(1e-6, 2e-2)
    ax.legend(fontsize=5)
    ax.set_title("centre lines against the uniform finest run", fontsize=9)
    ax = fig.add_subplot(2, 4, 8)
    for name, colour in zip(ADAPTIVE, ("C0", "C1")):
        lo, hi = cell_boxes(frames[name])
        centre = 0.5 * (lo + hi)
        # Distance from the nearer of the lid's two singular edges (x = 0 or 1, y = 1).
        r = np.minimum(np.hypot(centre[:, 0], 1 - centre[:, 1]), np.hypot(1 - centre[:, 0], 1 - centre[:, 1]))
        ax.loglog(r, diffs[name] + 1e-7, ".", ms=1, alpha=0.2, color=colour, label=name)
    ax.axhline(FIELD_TOLERANCE, color="r", ls="--", lw=0.8, label="tolerance")
    ax.set_xlabel("distance of the cell from the nearer lid edge / L")
    ax.set_ylabel(f"|u - mean of uniform {N}$^3$ over the cell| / U")
    ax.legend(fontsize=6, markerscale=8)
    ax.set_title("every cell against the uniform finest run", fontsize=9)
    ax = fig.add_subplot(2, 4, 4)
    for name in ADAPTIVE:
        ax.plot([r["time_s"] for r in rows[name]], [r["cells"] for r in rows[name]], "o-", ms=3, label=name)
    ax.axhline(cells_uniform, color="k", ls="--", label=f"uniform {N}$^3$")
    ax.axhline(cells_uniform / CELL_RATIO, color="r", ls=":", label="5x fewer")
    ax.set_xlabel("t / (L/U)")
    ax.set_ylabel("cells")
    ax.set_yscale("log")
    ax.legend(fontsize=7)
    ax.set_title("cells (regrid every 10 steps)", fontsize=9)
    fig.tight_layout()
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURE, dpi=100)
    print(f"wrote {FIGURE.relative_to(ROOT)}")


def evaluate(name, arrays, rows, grid, profiles, cells_uniform, seconds):
    """The checks of one adaptive run against the uniform one. Returns its summary
    entry, the difference of each cell from the uniform means, and the uniform
    run's centre lines through this run's cells (its field averaged onto them,
    sampled the same way: what the cells alone do to the line check)."""
    line_diff = line_difference(profiles[name], profiles["uniform"])
    means = cell_means(grid, arrays)
    diff = np.abs(arrays["velocity"] - means).max(axis=1)
    field_diff = float(diff.max())
    averaged = centre_lines(dict(arrays, velocity=means))
    seen_through = line_difference(averaged, profiles["uniform"])
    cells_end = int(rows[-1]["cells"])
    checks = [
        {"quantity": f"uniform finest cells / adaptive cells at t = {SETTLE_END:g}",
         "measured": round(cells_uniform / cells_end, 2), "reference": f"{cells_uniform} / {cells_end}",
         "tolerance": f">= {CELL_RATIO:g}", "pass": bool(cells_uniform / cells_end >= CELL_RATIO)},
        {"quantity": "mid-plane centre lines: max |u_adaptive - u_uniform| (u on x = z = 0.5, v on y = z = 0.5) / U",
         "measured": round(line_diff, 5), "reference": f"uniform {N}^3",
         "tolerance": f"<= {LINE_TOLERANCE:g}", "pass": bool(line_diff <= LINE_TOLERANCE)},
        {"quantity": "whole grid: max over adaptive cells |u - mean of the uniform run over the cell| / U",
         "measured": round(field_diff, 5), "reference": f"uniform {N}^3",
         "tolerance": f"<= {FIELD_TOLERANCE:g}", "pass": bool(field_diff <= FIELD_TOLERANCE)},
    ]
    worst = int(np.argmax(diff))
    lo, hi = cell_boxes(arrays)
    level = arrays["level"]
    entry = {
        **ADAPTIVE[name], "cells_end": cells_end, "cell_ratio_end": round(cells_uniform / cells_end, 2),
        "cells_per_level": {int(k): int((level == k).sum()) for k in np.unique(level)},
        "wall_seconds_to_end": round(seconds["seconds_to_end"], 1), "threads": seconds["threads"],
        "max_divergence_1_s": rows[-1]["max_divergence_1_s"], "kinetic_energy_J": rows[-1]["kinetic_energy_J"],
        "worst_cell": {"min_m": [round(float(x), 5) for x in lo[worst]],
                       "max_m": [round(float(x), 5) for x in hi[worst]], "difference": round(field_diff, 5)},
        "cells_beyond_half_the_field_tolerance": int((diff > 0.5 * FIELD_TOLERANCE).sum()),
        "centre_line_difference_of_the_uniform_field_averaged_onto_these_cells": round(seen_through, 5),
        "where_the_centre_lines_differ_most": where_lines_differ(profiles[name], profiles["uniform"]),
        "checks": checks, "pass": all(c["pass"] for c in checks)}
    print(f"{name} (zeta {entry['zeta']:g} U, at most {entry['coarsen_levels']} level(s) coarser; "
          f"{entry['chosen']}): {cells_end} cells at t = {SETTLE_END:g} ({cells_uniform / cells_end:.2f}x fewer than "
          f"{cells_uniform}); wall time to t = {END:g}: {seconds['seconds_to_end']:.0f} s")
    for c in checks:
        print(f"  {'PASS' if c['pass'] else 'FAIL'}  {c['quantity']}: {c['measured']} "
              f"(reference {c['reference']}, {c['tolerance']})")
    print(f"  the uniform run's field averaged onto these cells, sampled the same way: {seen_through:.5f} U "
          "from its own centre lines (reported, not graded)")
    return entry, diff, averaged


def where_lines_differ(lines, reference):
    """The line and the position along it where two sets of centre lines differ most."""
    c = max(("u", "v"), key=lambda c: np.abs(lines[c] - reference[c]).max())
    at = float(CENTRES[int(np.argmax(np.abs(lines[c] - reference[c])))])
    return f"{c} at {'y' if c == 'u' else 'x'} = {at:.3f}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--threads", type=int, default=1,
                    help="threads of the runs to t = 15 (1: as the uniform run on disk was made)")
    ap.add_argument("--replot", action="store_true", help="analyse the runs on disk")
    args = ap.parse_args()
    exe = (ROOT / args.build / "app" / "sanguis").resolve()
    names = ("uniform", *ADAPTIVE)
    if not args.replot:
        for name in names:
            run_to_end(exe, name, args.threads)
        for name in names:
            settle(exe, name, args.threads)
    seconds = {name: run_seconds(name) for name in names}

    rows = {name: read_rows(RUNS / name / "diagnostics.csv") for name in names}
    frames = {name: final_frame(name) for name in names}
    profiles = {name: centre_lines(a) for name, a in frames.items()}
    grid = uniform_array(frames["uniform"])
    cells_uniform = int(rows["uniform"][-1]["cells"])
    summary = {
        "case": str(CASE.relative_to(ROOT)), "finest": f"{N}^3", "end_time_s": END, "compared_at_s": SETTLE_END,
        "fixed_step_from_end": FIXED_STEP, "cells_uniform": cells_uniform,
        "uniform": {"wall_seconds_to_end": round(seconds["uniform"]["seconds_to_end"], 1),
                    "threads": seconds["uniform"]["threads"],
                    "max_divergence_1_s": rows["uniform"][-1]["max_divergence_1_s"],
                    "kinetic_energy_J": rows["uniform"][-1]["kinetic_energy_J"]},
        "runs": {}}
    diffs, averaged = {}, {}
    for name in ADAPTIVE:
        summary["runs"][name], diffs[name], averaged[name] = evaluate(
            name, frames[name], rows[name], grid, profiles, cells_uniform, seconds[name])
    print(f"uniform: wall time to t = {END:g}: {seconds['uniform']['seconds_to_end']:.0f} s")
    print("the cells alone, whatever the solution on them (reported, not graded):", flush=True)
    levels = block_estimates(grid)
    summary["bound_grids"] = [row for cap in (2, 1) for row in bound_grid_sampling(
        grid, profiles["uniform"], cap, (5e-3, 1e-2, 1.5e-2, 2e-2, 5e-2), levels)]
    # The run fixed before any was made decides alone whether the checks as first
    # set were met; the script passes when some run meets every check.
    first = next(iter(ADAPTIVE))
    summary["pass_of_the_run_fixed_first"] = summary["runs"][first]["pass"]
    summary["pass"] = any(run["pass"] for run in summary["runs"].values())
    SUMMARY.write_text(json.dumps(summary, indent=1) + "\n")
    print(f"wrote {SUMMARY.relative_to(ROOT)}")
    print(f"{'PASS' if summary['pass'] else 'FAIL'} (some adaptive run passes every check); the run fixed first, "
          f"{first}: {'PASS' if summary['pass_of_the_run_fixed_first'] else 'FAIL'}")
    draw(frames, profiles, averaged, rows, diffs, cells_uniform)
    return 0 if summary["pass"] else 1


if __name__ == "__main__":
    sys.exit(main())
