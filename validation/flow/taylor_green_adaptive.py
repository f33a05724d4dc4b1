#!/usr/bin/python3
"""The 3D Taylor-Green vortex on an adaptive grid against the uniform finest grid.

Runs build/validation/validate_taylor_green_adaptive (validation/flow/
taylor_green_adaptive_main.cpp): the classic Taylor-Green vortex
u = sin(kx) cos(ky) cos(kz), v = -cos(kx) sin(ky) cos(kz), w = 0 (k = 2 pi,
u0 = 1 m/s) in the periodic unit cube at Re = u0 / (k nu) = 100, from t = 0
through its dissipation peak to t = 1.5 s, with one fixed step (1/160 s, CFL
0.8 of 128^3) on uniform grids of 32^3, 64^3 and 128^3 cells and on a grid
between 32^3 and 128^3 set by the wavelet criterion (thesis eq. 4.11) on the
velocity, zeta = 1e-2 u0 (the threshold of the adaptive cavity), regrid
every 4 steps. The uniform 128^3 run is the reference.

The tolerances, fixed before the first run (2026-11-25; the cell-by-cell one is
the adaptive cavity's):
* at least 5x fewer cells than the uniform 128^3 grid (mean over the steps);
* every cell within 1e-2 u0 of the reference's mean over that cell (largest
  velocity component), at t = 0.75 s (near the dissipation peak) and 1.5 s;
* the kinetic energy within 0.5 % of the reference's at every recorded time
  (every 8 steps);
* the face velocity divergence-free to 1e-6 1/s.
The uniform 32^3 and 64^3 runs are measured against the same tolerances and
reported (not graded): they say how much of the answer a uniform grid with
as few cells keeps.

zeta = 1e-2 u0, the threshold fixed first, met the accuracy 6-9x over and
missed the cell count (1.5x). The threshold trades one for the other, so the
graded check, fixed on 2026-12-07 before these runs, is the sweep
zeta = 1e-2, 2e-2, 4e-2 u0 (the last two appended to the same reference with
the driver's --uniform no): the target is met if one threshold of the sweep
meets all four tolerances at once; every threshold's row is reported. The
sweep missed by 2.5 % (4.87x at 4e-2 u0, every accuracy tolerance met); the
next doubling, 8e-2 u0, was added afterwards and is reported only.

The same sweep with 4^3-cell blocks (the driver's --block-cells 4), added on
2026-12-07 21:47 after the 8^3 sweep missed and fixed before its runs: the
criterion refines and coarsens whole blocks, and with 8^3 blocks the 32^3 base
grid is 64 blocks, so a block is refined for its worst cell over 1/64 of the
box. 4^3 blocks refine in units 8x smaller. It is graded as a check of its own
(one of its thresholds meeting all four tolerances), beside the 8^3 sweep's,
which keeps its verdict: the script passes only if every graded check does.

The doubling sweep with 8^3 blocks again, bisected (fixed 2026-12-08 00:16, before its
runs, after the doubling sweep missed by 2.5 % in cells at 4e-2 u0 with every accuracy
tolerance met, and 8e-2 u0 missed the accuracy): zeta = 4e-2 u0 times 2^(1/8), 2^(2/8),
2^(3/8), i.e. 4.36e-2, 4.76e-2 and 5.19e-2 u0, against the same reference and
tolerances. It is graded as a check of its own, a threshold meeting all four tolerances;
the two sweeps above keep their verdicts, and the script passes only if every graded
check does.

Writes validation/flow/results/taylor_green_adaptive.json (the driver's CSVs
and the reference snapshots under results/runs/taylor_green/) and
docs/validation/figures/flow_taylor_green_adaptive.png. Exits 1 if a check
fails. About 20 min on 2 cores (the 128^3 reference most of it), about 5 min for the
bisection, and about 33 min
more for the sweep with 4^3 blocks.

Usage: /usr/bin/python3 validation/flow/taylor_green_adaptive.py [--build build] [--threads T]
           [--replot]
"""
import argparse
import itertools
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _cavity_common import read_text_rows as read_rows  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "validation" / "flow" / "results"
RUNS = RESULTS / "runs" / "taylor_green"
FIGURE = ROOT / "docs" / "validation" / "figures" / "flow_taylor_green_adaptive.png"
REFERENCE = "uniform 128^3"
CHECKED = "adaptive zeta 0.01"
SWEEP = (0.01, 0.02, 0.04)  # u0; fixed 2026-12-07 before the 0.02 and 0.04 runs
# Added after the sweep missed by 2.5 % (4.87x at 0.04): the next doubling, reported
# only, so that the figure shows where the trade-off crosses the tolerances.
AFTER_SWEEP = (0.08,)
# The sweep again with 4^3-cell blocks; fixed 2026-12-07 21:47, before its runs.
BLOCKS4_SWEEP = (0.01, 0.02, 0.04)
BLOCKS4 = " (4^3 blocks)"
# The 8^3 sweep bisected between 4e-2 and 8e-2 u0 in steps of 2^(1/8); fixed 2026-12-08
# 00:16, before its runs.
BISECTION = (0.0436, 0.0476, 0.0519)
CELL_TOLERANCE = 1e-2  # u0
ENERGY_TOLERANCE = 5e-3  # relative


def kinetic_energy_error(reference, run):
    """Largest relative difference of the kinetic energy (column 1 of the history rows,
    recorded at the same times in both runs)."""
    return float(np.max(np.abs(run[:, 1] / reference[:, 1] - 1.0)))


def sweep_checks(name, run, reference_cells, energy_error):
    """(name, value, tolerance, pass) of one adaptive run against the four tolerances:
    `run` its row of the driver's CSV, `reference_cells` the uniform 128^3 grid's cells,
    `energy_error` its kinetic_energy_error."""
    r = reference_cells / run["cells_mean"]
    return [
        (f"{name}: cells, uniform 128^3 / adaptive (mean over the steps)", r, ">= 5", r >= 5.0),
        (f"{name}: every cell against the reference's mean over it, t = 0.75 s (u0)",
         run["max_mid"], f"<= {CELL_TOLERANCE:g}", run["max_mid"] <= CELL_TOLERANCE),
        (f"{name}: every cell against the reference's mean over it, t = 1.5 s (u0)",
         run["max_end"], f"<= {CELL_TOLERANCE:g}", run["max_end"] <= CELL_TOLERANCE),
        (f"{name}: kinetic energy against the reference, every 8 steps (relative)",
         energy_error, f"<= {ENERGY_TOLERANCE:g}", energy_error <= ENERGY_TOLERANCE),
        (f"{name}: max |div uf| over the steps (1/s)", run["max_divergence"], "< 1e-6",
         run["max_divergence"] < 1e-6),
    ]


def on_disk(runs, thresholds, suffix=""):
    """The names of a sweep's runs found in the driver's CSV (`runs`, by name), in the
    order of `thresholds`; `suffix` marks the 4^3-block runs."""
    return [f"adaptive zeta {z:g}{suffix}" for z in thresholds
            if f"adaptive zeta {z:g}{suffix}" in runs]


def graded_sweep(thresholds, names, rows, blocks=""):
    """The graded check of one sweep: a threshold meeting all four tolerances at once
    (`rows`: each run's sweep_checks, `names` the runs of the sweep found on disk); a
    run missing from the disk fails it ("not run"), as a missed one does. Returns the
    runs meeting every tolerance and the check (name, value, tolerance, pass)."""
    meeting = [name for name in names if all(c[3] for c in rows[name])]
    missing = len(thresholds) - len(names)
    check = (f"thresholds of the sweep zeta = {', '.join(f'{z:g}' for z in thresholds)} u0 "
             f"{blocks}meeting all four tolerances at once", len(meeting),
             ">= 1 (" + (", ".join(meeting) if meeting else "none") + ")"
             + (f"; {missing} not run" if missing else ""),
             len(meeting) >= 1 and missing == 0)
    return meeting, check


def script_passes(checks):
    """Every graded check passes; a check whose pass is None is reported, not graded."""
    return all(c[3] for c in checks if c[3] is not None)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=str(ROOT / "build"))
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--replot", action="store_true", help="check and plot existing results")
    args = ap.parse_args()
    started = time.time()
    if not args.replot:
        exe = Path(args.build) / "validation" / "validate_taylor_green_adaptive"
        subprocess.run([str(exe), str(RUNS), "--threads", str(args.threads),
                        "--zeta", str(SWEEP[0])], check=True)
        for zeta in SWEEP[1:] + AFTER_SWEEP:  # against the snapshots of the reference just run
            subprocess.run([str(exe), str(RUNS), "--threads", str(args.threads),
                            "--zeta", str(zeta), "--uniform", "no"], check=True)
        for zeta in BISECTION:
            subprocess.run([str(exe), str(RUNS), "--threads", str(args.threads),
                            "--zeta", str(zeta), "--uniform", "no"], check=True)
        for zeta in BLOCKS4_SWEEP:
            subprocess.run([str(exe), str(RUNS), "--threads", str(args.threads),
                            "--zeta", str(zeta), "--uniform", "no", "--block-cells", "4"],
                           check=True)
    runs = {r["run"]: {k: (v if k == "run" else float(v)) for k, v in r.items()}
            for r in read_rows(RUNS / "taylor_green_adaptive.csv")}
    history = {}
    for r in read_rows(RUNS / "taylor_green_history.csv"):
        history.setdefault(r["run"], []).append(
            (float(r["time"]), float(r["kinetic_energy"]), float(r["cells"])))
    history = {name: np.array(rows) for name, rows in history.items()}
    slices = {}
    for r in read_rows(RUNS / "taylor_green_slice.csv"):
        slices.setdefault(r["run"], []).append(
            (float(r["x"]), float(r["y"]), float(r["h"]), float(r["difference"])))

    def energy_error(name):
        return kinetic_energy_error(history[REFERENCE], history[name])

    fine = runs[REFERENCE]

    swept, after = on_disk(runs, SWEEP), on_disk(runs, AFTER_SWEEP)
    blocks4, bisected = on_disk(runs, BLOCKS4_SWEEP, BLOCKS4), on_disk(runs, BISECTION)
    rows = {name: sweep_checks(name, runs[name], fine["cells_mean"], energy_error(name))
            for name in swept + after + bisected + blocks4}

    meeting, check8 = graded_sweep(SWEEP, swept, rows)
    meeting4, check4 = graded_sweep(BLOCKS4_SWEEP, blocks4, rows, "with 4^3 blocks ")
    meeting_bisected, check_bisected = graded_sweep(BISECTION, bisected, rows, "(the bisection) ")
    checks = [check8, check4, check_bisected]
    # Each threshold's rows, with their verdicts, shown but not graded one by one.
    for name in swept + after + bisected + blocks4:
        checks += [(n, v, t + ", reported", None, p) for n, v, t, p in rows[name]]
        checks.append((f"{name}: cells (largest grid of the run)",
                       fine["cells_mean"] / runs[name]["cells_max"], "reported", None))
    for name in ("uniform 64^3", "uniform 32^3"):
        r = runs[name]
        checks += [
            (f"{name}: cells ratio", fine["cells_mean"] / r["cells_mean"], "reported", None),
            (f"{name}: every cell, t = 0.75 s / 1.5 s (u0)", max(r["max_mid"], r["max_end"]),
             "reported", None),
            (f"{name}: kinetic energy (relative)", energy_error(name), "reported", None),
        ]
    ok = script_passes(checks)
    for name, value, tol, passed, *met in checks:
        if passed is not None:
            verdict = "PASS" if passed else "FAIL"
        else:
            verdict = "REPORTED" + ("" if not met else (" (met)" if met[0] else " (not met)"))
        print(f"{verdict}: {name} = {value:.4g} ({tol})")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm
    fig, axes = plt.subplots(1, 4, figsize=(17, 5.2))
    styles = {"uniform 32^3": ":", "uniform 64^3": "--", REFERENCE: "-"}
    # One marker per run (cycled, so that a run added later is still drawn).
    markers = dict(zip(swept + after + bisected, itertools.cycle("o^sdPXh")))
    markers.update(zip(blocks4, itertools.cycle("v<>")))
    styles.update({name: m + ("-." if name in blocks4 else "") for name, m in markers.items()})

    def label_of(name, prefix="adaptive, zeta = "):
        if not name.startswith("adaptive zeta "):
            return name.replace("^3", "$^3$")
        zeta = name.removeprefix("adaptive zeta ").removesuffix(BLOCKS4)
        return (f"{prefix}{zeta} u0" + (", 4$^3$ blocks" if name in blocks4 else "")
                + (" (after the sweep)" if name in after else "")
                + (" (bisection)" if name in bisected else ""))

    for name, style in styles.items():
        h = history[name]
        label = label_of(name)
        axes[0].plot(h[:, 0], h[:, 1], style, ms=3, label=label)
        # Dissipation rate -dE/dt, centred differences between records.
        t_mid = 0.5 * (h[1:, 0] + h[:-1, 0])
        axes[1].plot(t_mid, -np.diff(h[:, 1]) / np.diff(h[:, 0]), style, ms=3, label=label)
    axes[0].set_xlabel("t (s)")
    axes[0].set_ylabel("kinetic energy per unit mass (m$^2$/s$^2$)")
    axes[0].set_title("Taylor-Green, Re = 100")
    axes[0].legend(fontsize=7)
    axes[1].set_xlabel("t (s)")
    axes[1].set_ylabel("dissipation rate -dE/dt (m$^2$/s$^3$)")
    axes[1].set_title("dissipation")
    for name, marker in markers.items():
        h = history[name]
        axes[2].plot(h[:, 0], h[:, 2], marker + ("-." if name in blocks4 else "-"), ms=3,
                     label=label_of(name, "zeta = "))
    for name, style in (("uniform 128^3", "-"), ("uniform 64^3", "--")):
        axes[2].axhline(runs[name]["cells_mean"], ls=style, color="k", lw=0.8,
                        label=name.replace("^3", "$^3$"))
    axes[2].axhline(fine["cells_mean"] / 5, ls=":", color="C2", lw=1.0,
                    label="5x fewer than 128$^3$")
    axes[2].set_yscale("log")
    axes[2].set_xlabel("t (s)")
    axes[2].set_ylabel("cells")
    axes[2].set_title("grid: " + ", ".join(
        f"{fine['cells_mean'] / runs[n]['cells_mean']:.3g}x"
        for n in swept + after + bisected + blocks4)
        + " fewer cells", fontsize=9)
    # Below the panel: above it the legend would hide the curves.
    axes[2].legend(fontsize=7, ncol=2, loc="upper center", bbox_to_anchor=(0.5, -0.16))
    # The layer at z = 0 at t = 1.5 s of the coarsest run that meets the accuracy
    # tolerances (else the first threshold's): |difference| per cell, cell outlines.
    accurate = [n for n in swept + bisected if all(c[3] for c in rows[n][1:])]
    shown_run = accurate[-1] if accurate else CHECKED
    n = 128
    image = np.zeros((n, n))
    size = np.zeros((n, n))
    for x, y, hc, d in slices.get(shown_run, []):
        i0, j0, r = int(round(x * n)), int(round(y * n)), int(round(hc * n))
        image[j0:j0 + r, i0:i0 + r] = d
        size[j0:j0 + r, i0:i0 + r] = r
    shown = axes[3].imshow(np.maximum(image, 1e-6), origin="lower", extent=(0, 1, 0, 1),
                           norm=LogNorm(vmin=1e-5, vmax=CELL_TOLERANCE), cmap="viridis")
    centres = (np.arange(n) + 0.5) / n
    if len(np.unique(size)) > 1:  # a layer of one level has no level change to outline
        axes[3].contour(centres, centres, size, levels=[1.5, 3], colors="w", linewidths=0.8)
    fig.colorbar(shown, ax=axes[3], label="|u - reference mean| (u0)")
    axes[3].set_xlabel("x (m)")
    axes[3].set_ylabel("y (m)")
    axes[3].set_title(f"{shown_run.replace('adaptive zeta ', 'zeta = ')} u0, z = 0, t = 1.5 s\n"
                      "(white: level changes)", fontsize=9)
    fig.tight_layout()
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURE, dpi=110)

    summary = {
        "runs": runs,
        "kinetic_energy_error": {name: energy_error(name) for name in history if name != REFERENCE},
        "checks": [{"name": c[0], "value": c[1], "tolerance": c[2], "pass": c[3],
                    **({"met": c[4]} if len(c) > 4 else {})} for c in checks],
        "sweep_meeting_every_tolerance": meeting,
        "sweep_with_4_cell_blocks_meeting_every_tolerance": meeting4,
        "bisection_meeting_every_tolerance": meeting_bisected,
        "after_the_sweep_meeting_every_tolerance": [
            n for n in after if all(c[3] for c in rows[n])],
        "pass": ok,
        "script_seconds": round(time.time() - started, 1),
        "date": time.strftime("%Y-%m-%d %H:%M"),
    }
    (RESULTS / "taylor_green_adaptive.json").write_text(json.dumps(summary, indent=1))
    print(f"{'PASS' if ok else 'FAIL'}; figure {FIGURE.relative_to(ROOT)}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
