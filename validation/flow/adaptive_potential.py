#!/usr/bin/python3
"""How many cells can the wavelet criterion save on a given flow? An a-priori bound.

The adaptive grid that the criterion (thesis eq. 4.11, src/flow/adapt_criterion.hpp)
settles on for a steady field is bounded by that field on the uniform finest
grid. Whatever the path, a settled grid has
no block coarser than the finest whose estimate exceeds zeta (it would be
refined), so the fewest cells it can have are those of the grid that takes,
top-down, every block allowed as a leaf. This script computes that grid from
the block estimates of the field restricted to each level (max over the
block's cells of |u - P(R(u))|, central slopes, one-sided at walls, periodic
where the flow is). The 2:1 balance between blocks is ignored (it only adds
cells) and a block's ghosts come from the same level (on a real composite grid
they come from its neighbours' levels): the count is an estimate of the lower
bound, and "uniform cells / adaptive cells" of the best ratio the criterion
can give at each zeta.

Fields (blocks of 8^3 cells, as in the flow cases):
  * the shielded Gaussian vortex of validation/flow/vortex_adaptive.py (exact
    field, 128^2 x 32 cells, periodic): a check of the estimate against the
    cells that the measured adaptive runs of that validation end with;
  * the Taylor-Green vortex u = sin x cos y cos z, v = -cos x sin y cos z,
    w = 0 on the periodic (2 pi)^3 box at 64^3 (exact field);
  * the steady Re = 1000 cubic lid-driven cavity at 64^3: the last frame of
    the uniform run of validation/flow/cavity_re1000.py (run it first:
    `validation/flow/cavity_re1000.py --sizes 64`, about 30 min on one core);
  * the steady Re = 100 cubic cavity at 64^3: the last frame (t = 15 s) of
    `sanguis run cases/flow/cavity-re100.toml --set "flow.grid.cells=[64, 64, 64]"
    --output validation/flow/results/runs/cavity-re100-64` (about 10 min on one core);
  * the same at 96^3: `... --set "flow.grid.cells=[96, 96, 96]" --set output.interval_s=5
    --output validation/flow/results/runs/cavity-re100-96` (16^3 blocks, chosen as the grid
    does not adapt; 18 min on one core beside other work), and at 128^3 (`cavity-re100-128`),
    to see how the bound grows as the grid refines; the cells of the adaptive runs of
    validation/flow/cavity_adaptive_3d.py, when its JSON is there, are set against the
    estimate with the same cap on the coarsening;
  * the steady Re = 100 2D cavity at 128^2 (a periodic slab 32 cells thick):
    the uniform run of validation/flow/cavity_adaptive.py (run it first).

Writes validation/flow/results/adaptive_potential.json and
docs/validation/figures/flow_adaptive_potential.png. A field whose run is not on disk keeps
its rows from the JSON of an earlier call (said so in the output).

Usage: /usr/bin/python3 validation/flow/adaptive_potential.py
"""
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _cavity_common import last_frame, read_vtu  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "validation" / "flow" / "results"
FIGURE = ROOT / "docs" / "validation" / "figures" / "flow_adaptive_potential.png"
B = 8  # cells per block edge
FRACTIONS = [float(f) for f in np.geomspace(1e-3, 1e-1, 13)]  # zeta / reference speed


def restrict(u):
    """8-cell means onto a grid twice as coarse (R of eq. 4.11)."""
    m = [s // 2 for s in u.shape]
    return u.reshape(m[0], 2, m[1], 2, m[2], 2).mean(axis=(1, 3, 5))


def cell_estimate(u, periodic):
    """|u - P(R(u))| per cell: P the linear prolongation with central slopes,
    one-sided at non-periodic domain faces."""
    coarse = restrict(u)
    up = np.repeat(np.repeat(np.repeat(coarse, 2, 0), 2, 1), 2, 2)
    for d in range(3):
        c = np.moveaxis(coarse, d, 0)
        if periodic[d]:
            slope = 0.5 * (np.roll(c, -1, 0) - np.roll(c, 1, 0))
        else:
            slope = np.empty_like(c)
            slope[1:-1] = 0.5 * (c[2:] - c[:-2])
            slope[0], slope[-1] = c[1] - c[0], c[-1] - c[-2]
        slope = np.repeat(np.repeat(np.repeat(np.moveaxis(slope, 0, d), 2, 0), 2, 1), 2, 2)
        sign = np.where(np.arange(u.shape[d]) % 2 == 1, 0.25, -0.25)
        shape = [1, 1, 1]
        shape[d] = u.shape[d]
        up += slope * sign.reshape(shape)
    return np.abs(u - up)


def block_max(e):
    m = [s // B for s in e.shape]
    return e.reshape(m[0], B, m[1], B, m[2], B).max(axis=(1, 3, 5))


def level_estimates(components, periodic):
    """Block estimates (max over components) at the finest grid and every
    coarser one that still holds whole blocks of B^3 cells."""
    levels = []
    fields = list(components)
    while all(s % B == 0 for s in fields[0].shape):
        levels.append(np.max([block_max(cell_estimate(f, periodic)) for f in fields], axis=0))
        if any(s % 2 for s in fields[0].shape):
            break
        fields = [restrict(f) for f in fields]
    return levels  # levels[0]: finest blocks


def fewest_leaves(levels, zeta):
    """The leaf blocks of the grid with the fewest cells the criterion can settle on:
    every block coarser than the finest must have an estimate <= zeta (else it is
    refined), so taking, top-down, every block whose estimate allows it as a leaf
    gives the minimum. Returns one boolean array per level (finest first): which
    blocks of that level are leaves."""
    top = len(levels) - 1
    leaves = [None] * len(levels)
    # open[k]: blocks of level k not covered by a coarser leaf.
    open_blocks = np.ones_like(levels[top], dtype=bool)
    for k in range(top, -1, -1):
        leaves[k] = open_blocks if k == 0 else open_blocks & (levels[k] <= zeta)
        if k > 0:
            rest = open_blocks & ~leaves[k]
            open_blocks = np.repeat(np.repeat(np.repeat(rest, 2, 0), 2, 1), 2, 2)
    return leaves


def fewest_cells(levels, zeta):
    """The cells of fewest_leaves' grid and its leaf blocks per level (finest first)."""
    counts = [int(leaf.sum()) for leaf in fewest_leaves(levels, zeta)]
    return sum(counts) * B ** 3, counts


def vortex_field():
    """Exact velocity of vortex_adaptive_main.cpp at t = 0 on 128 x 128 x 32 cells:
    u = U - r_y g, v = r_x g, g = A / sigma^2 exp(-r^2 / 2 sigma^2), A = swirl sigma e^(1/2)."""
    n, nz = 128, 32
    sigma, swirl = 0.05, 0.5
    x = (np.arange(n) + 0.5) / n
    X, Y = np.meshgrid(x, x, indexing="ij")
    rx, ry = X - 0.5, Y - 0.5
    g = swirl * sigma * np.exp(0.5) / sigma ** 2 * np.exp(-(rx * rx + ry * ry) / (2 * sigma ** 2))
    u = np.repeat((1.0 - ry * g)[:, :, None], nz, axis=2)
    v = np.repeat((rx * g)[:, :, None], nz, axis=2)
    return [u, v, np.zeros_like(u)], (True, True, True), 1.0 / n, 0.5


def taylor_green_field():
    n = 64
    x = (np.arange(n) + 0.5) * 2 * np.pi / n
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    u = np.sin(X) * np.cos(Y) * np.cos(Z)
    v = -np.cos(X) * np.sin(Y) * np.cos(Z)
    return [u, v, np.zeros_like(u)], (True, True, True), 2 * np.pi / n, 1.0


def cavity_field(name="cavity-re1000-64", n=64):
    """A steady uniform n^3 cubic cavity run (lid speed 1) of RESULTS/runs, if on disk."""
    runs = RESULTS / "runs"
    if not (runs / name / "flow").exists():
        return None
    return uniform_velocity(runs, name, n, (n, n, n)), (False, False, False), 1.0 / n, 1.0


def uniform_velocity(runs, name, n, shape):
    """The three velocity components of the last frame of a uniform run with n
    cells per unit length, as arrays of `shape` cells."""
    centres, arrays = read_vtu(last_frame(runs, name))
    index = np.floor(centres * n).astype(int)
    fields = []
    for d in range(3):
        f = np.zeros(shape)
        f[index[:, 0], index[:, 1], index[:, 2]] = arrays["velocity"][:, d]
        fields.append(f)
    return fields


def cavity_2d_field():
    """The steady 2D Re = 100 cavity, 128^2 x 32 cells (periodic slab): the last
    frame of the uniform run of validation/flow/cavity_adaptive.py."""
    runs = RESULTS / "runs" / "cavity_adaptive"
    if not (runs / "uniform" / "flow").exists():
        return None
    return uniform_velocity(runs, "uniform", 128, (128, 128, 32)), (False, False, True), 1.0 / 128, 1.0


def main():
    earlier_path = RESULTS / "adaptive_potential.json"
    earlier = json.loads(earlier_path.read_text()) if earlier_path.exists() else {}
    results = {}
    cases = {"vortex (128^2 x 32)": vortex_field(), "Taylor-Green (64^3)": taylor_green_field()}
    cavity_2d = cavity_2d_field()
    for name, field, how in (
            ("cavity Re 1000 (64^3)", cavity_field(), "validation/flow/cavity_re1000.py --sizes 64"),
            ("cavity Re 100 (64^3)", cavity_field("cavity-re100-64"), "see this script's docstring"),
            ("cavity Re 100 (96^3)", cavity_field("cavity-re100-96", 96), "see this script's docstring"),
            ("cavity Re 100 (128^3)", cavity_field("cavity-re100-128", 128), "see this script's docstring"),
            ("2D cavity Re 100 (128^2 x 32)", cavity_2d, "validation/flow/cavity_adaptive.py")):
        if field is not None:
            cases[name] = field
        elif name in earlier:
            results[name] = earlier[name]
            print(f"{name}: its uniform run is not on disk ({how}); rows kept from the earlier JSON")
        else:
            print(f"{name}: its uniform run is not on disk ({how}); skipped")
    levels_of = {}
    for name, (components, periodic, h, speed) in cases.items():
        levels = levels_of[name] = level_estimates(components, periodic)
        uniform = components[0].size
        rows = []
        for fraction in FRACTIONS:
            zeta = fraction * speed
            cells, counts = fewest_cells(levels, zeta)
            rows.append({"zeta_over_speed": fraction, "zeta": zeta, "cells": cells,
                         "ratio": uniform / cells, "blocks_per_level_finest_first": counts})
            print(f"{name:24s} zeta = {fraction:7.1e} x {speed:g} m/s: {cells:8d} cells, "
                  f"{uniform / cells:5.2f}x fewer than {uniform}")
        results[name] = {"uniform_cells": uniform, "reference_speed": speed, "rows": rows}
    # The measured adaptive vortex runs (cells at the end of the crossing) against the estimate.
    measured = []
    vortex_json = RESULTS / "vortex_adaptive.json"
    if vortex_json.exists():
        vortex = results["vortex (128^2 x 32)"]
        levels = level_estimates(*vortex_field()[:2])
        for run in json.loads(vortex_json.read_text())["runs"].values():
            if run["zeta"] > 0:
                estimate, _ = fewest_cells(levels, run["zeta"])
                measured.append({"zeta": run["zeta"], "cells_end": run["cells_end"], "estimate": estimate,
                                 "ratio_end": vortex["uniform_cells"] / run["cells_end"]})
                print(f"vortex, measured at zeta = {run['zeta']:g} m/s: {run['cells_end']:.0f} cells at the end "
                      f"against the estimate {estimate} ({run['cells_end'] / estimate - 1:+.0%})")
        vortex["measured"] = measured
    # The measured adaptive 2D cavity runs (cells at t = 15) against the estimate.
    cavity_json = RESULTS / "cavity_adaptive.json"
    if cavity_2d is not None and cavity_json.exists():
        adaptive = json.loads(cavity_json.read_text())
        levels = level_estimates(*cavity_2d[:2])
        estimate, _ = fewest_cells(levels, adaptive["zeta_over_U"])
        run = adaptive["runs"]["adaptive"]
        results["2D cavity Re 100 (128^2 x 32)"]["measured"] = {
            "zeta": adaptive["zeta_over_U"], "cells_end": run["cells_end"], "estimate": estimate}
        print(f"2D cavity, measured at zeta = {adaptive['zeta_over_U']:g} U: {run['cells_end']} cells at "
              f"t = 15 against the estimate {estimate} ({run['cells_end'] / estimate - 1:+.0%})")
    # The measured adaptive 3D cavity runs (cells at t = 15.5) against the estimate with the
    # same cap on the coarsening (validation/flow/cavity_adaptive_3d.py).
    cavity_3d = "cavity Re 100 (128^3)"
    cavity_3d_json = RESULTS / "cavity_adaptive_3d.json"
    if cavity_3d in levels_of and cavity_3d_json.exists():
        uniform = results[cavity_3d]["uniform_cells"]
        results[cavity_3d]["measured"] = []
        for run_name, run in json.loads(cavity_3d_json.read_text())["runs"].items():
            estimate, _ = fewest_cells(levels_of[cavity_3d][:run["coarsen_levels"] + 1], run["zeta"])
            results[cavity_3d]["measured"].append(
                {"run": run_name, "zeta": run["zeta"], "coarsen_levels": run["coarsen_levels"],
                 "cells_end": run["cells_end"], "estimate": estimate, "ratio_end": uniform / run["cells_end"]})
            print(f"3D cavity 128^3, {run_name}, measured at zeta = {run['zeta']:g} U, at most "
                  f"{run['coarsen_levels']} level(s) coarser: {run['cells_end']} cells against the estimate "
                  f"{estimate} ({run['cells_end'] / estimate - 1:+.0%})")
    order = ["vortex (128^2 x 32)", "Taylor-Green (64^3)", "cavity Re 1000 (64^3)",
             "cavity Re 100 (64^3)", "cavity Re 100 (96^3)", "cavity Re 100 (128^3)",
             "2D cavity Re 100 (128^2 x 32)"]
    results = {name: results[name] for name in sorted(results, key=order.index)}
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "adaptive_potential.json").write_text(json.dumps(results, indent=1))

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for name, r in results.items():
        ax.semilogx([row["zeta_over_speed"] for row in r["rows"]], [row["ratio"] for row in r["rows"]],
                    "o-", label=name)
    if measured:
        ax.semilogx([m["zeta"] / 0.5 for m in measured], [m["ratio_end"] for m in measured], "k*", ms=9,
                    label="vortex, measured adaptive runs (end)")
    for m in results.get("cavity Re 100 (128^3)", {}).get("measured", []):
        ax.semilogx([m["zeta"]], [m["ratio_end"]], "k^" if m["coarsen_levels"] > 1 else "kv", ms=8,
                    label=f"3D cavity 128$^3$, measured ({m['run']}, at most {2 ** m['coarsen_levels']} h)")
    ax.axhline(5.0, color="r", ls="--", lw=0.8, label="5x fewer (issue #7)")
    ax.set_xlabel(r"$\zeta$ / reference speed")
    ax.set_ylabel("uniform cells / fewest settled cells (estimate)")
    ax.set_yscale("log")
    ax.set_title("What the wavelet criterion can save, blocks of 8$^3$", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURE, dpi=120)
    print(f"wrote {FIGURE.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
