#!/usr/bin/python3
"""Lid-driven cavity at Re = 100: centre-line velocity profiles.

Runs cases/flow/cavity-re100.toml (unit cube, lid y = 1 moving along x at
1 m/s, nu = 0.01 m2/s, to t = 15 s: steady) in variants written under
validation/flow/results/runs/:

* 2D: the cavity in the x-y plane, periodic in z (one block of 8 cells thick),
  at 32^2 and 64^2 cells (96^2 with --fine). Compared with Ghia, Ghia & Shin
  (1982), J. Comput. Phys. 48:387, Tables I and II (Re = 100, 129^2 multigrid
  vorticity-stream function solution): u on the vertical centre line x = 0.5,
  v on the horizontal one y = 0.5. Check: the largest difference at the Ghia
  points, relative to the lid velocity, below 2 % at 64^2.
* 3D: the cubic cavity at 16^3 and 32^3 (48^3 with --fine): u(y) on the line
  x = z = 0.5 and v(x) on y = z = 0.5, their extrema and the change under grid
  refinement. The published 3D tables (Ku, Hirsh & Taylor 1987; Albensoeder &
  Kuhlmann 2005) could not be retrieved here, so the 3D check is the grid
  convergence of the extrema; the 3D profiles are drawn beside the 2D ones
  (side walls slow the 3D vortex down).

The profiles are read from the last .vtu frame (our base64 binary format) and
averaged over the cells next to each centre line (the line runs along cell
faces for even cell counts: the average of the 2 x 2 neighbouring columns is
the bilinear interpolation there).

Writes validation/flow/results/cavity.json and .csv,
docs/validation/figures/flow_cavity_re100.png (profiles) and
flow_cavity_re100_slice.png (the 3D mid-plane). Exits 1 if a check fails.

Usage: /usr/bin/python3 validation/flow/cavity.py [--build build] [--fine] [--replot]
"""
import argparse
import json
import sys
from pathlib import Path

import numpy as np

from _cavity_common import centre_lines, last_frame, read_vtu, run, with_walls

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "validation" / "flow" / "results"
RUNS = RESULTS / "runs"
FIGURE = ROOT / "docs" / "validation" / "figures" / "flow_cavity_re100.png"
SLICE = ROOT / "docs" / "validation" / "figures" / "flow_cavity_re100_slice.png"

# Ghia, Ghia & Shin (1982), Re = 100: Table I (u on x = 0.5), Table II (v on y = 0.5).
GHIA_U = np.array([
    (1.0000, 1.00000), (0.9766, 0.84123), (0.9688, 0.78871), (0.9609, 0.73722),
    (0.9531, 0.68717), (0.8516, 0.23151), (0.7344, 0.00332), (0.6172, -0.13641),
    (0.5000, -0.20581), (0.4531, -0.21090), (0.2813, -0.15662), (0.1719, -0.10150),
    (0.1016, -0.06434), (0.0703, -0.04775), (0.0625, -0.04192), (0.0547, -0.03717),
    (0.0000, 0.00000)])
GHIA_V = np.array([
    (1.0000, 0.00000), (0.9688, -0.05906), (0.9609, -0.07391), (0.9531, -0.08864),
    (0.9453, -0.10313), (0.9063, -0.16914), (0.8594, -0.22445), (0.8047, -0.24533),
    (0.5000, 0.05454), (0.2344, 0.17527), (0.2266, 0.17507), (0.1563, 0.16077),
    (0.0938, 0.12317), (0.0781, 0.10890), (0.0703, 0.10091), (0.0625, 0.09233),
    (0.0000, 0.00000)])


def variant(case_text, n, two_d):
    """The case file text for n cells per side (2D: periodic in z, 8 cells thick)."""
    text = case_text.replace('name = "cavity-re100"', f'name = "cavity-{"2d" if two_d else "3d"}-{n}"')
    if two_d:
        text = text.replace("size_m = [1.0, 1.0, 1.0]", f"size_m = [1.0, 1.0, {8.0 / n!r}]")
        text = text.replace("cells = [32, 32, 32]", f"cells = [{n}, {n}, 8]")
        text = text.replace('z_min = { type = "wall" }', 'z_min = { type = "periodic" }')
        text = text.replace('z_max = { type = "wall" }', 'z_max = { type = "periodic" }')
    else:
        text = text.replace("cells = [32, 32, 32]", f"cells = [{n}, {n}, {n}]")
    text = text.replace("interval_s = 1.0", "interval_s = 5.0")
    return text


def ghia_differences(y, u, x, v):
    """Largest |u - u_Ghia| on x = 0.5 and |v - v_Ghia| on y = 0.5 (lid speed 1), the
    profiles interpolated linearly to Ghia's points, the walls' values added."""
    yy, uu = with_walls(y, u, 1.0)
    xx, vv = with_walls(x, v, 0.0)
    du = np.abs(np.interp(GHIA_U[:, 0], yy, uu) - GHIA_U[:, 1])
    dv = np.abs(np.interp(GHIA_V[:, 0], xx, vv) - GHIA_V[:, 1])
    return float(du.max()), float(dv.max())


def draw_slice(name):
    """The mid-plane z = 0.5 of a 3D run: speed and in-plane streamlines (PNG)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    centres, arrays = read_vtu(last_frame(RUNS, name))
    h = np.min(np.diff(np.unique(np.round(centres[:, 0], 12))))
    n = int(round(1.0 / h))
    mask = np.abs(centres[:, 2] - 0.5) < 0.6 * h  # the two cell layers beside z = 0.5
    ix = np.floor(centres[mask, 0] / h).astype(int)
    iy = np.floor(centres[mask, 1] / h).astype(int)
    u = np.zeros((n, n)); v = np.zeros((n, n)); vort = np.zeros((n, n)); count = np.zeros((n, n))
    np.add.at(u, (iy, ix), arrays["velocity"][mask, 0])
    np.add.at(v, (iy, ix), arrays["velocity"][mask, 1])
    np.add.at(vort, (iy, ix), arrays["vorticity_magnitude"][mask])
    np.add.at(count, (iy, ix), 1.0)
    u /= count; v /= count; vort /= count
    x = (np.arange(n) + 0.5) * h
    fig, ax = plt.subplots(figsize=(5.5, 5))
    speed = np.hypot(u, v)
    im = ax.pcolormesh(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1), speed, cmap="viridis", shading="flat")
    ax.streamplot(x, x, u, v, color="w", density=1.2, linewidth=0.6, arrowsize=0.6)
    fig.colorbar(im, ax=ax, label="|(u, v)| / U")
    ax.set_aspect("equal")
    ax.set_xlabel("x / L")
    ax.set_ylabel("y / L")
    ax.set_title(f"Re = 100, {n}$^3$, plane z = 0.5, t = 15 L/U")
    fig.tight_layout()
    fig.savefig(SLICE, dpi=120)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--fine", action="store_true", help="also 96^2 and 48^3")
    parser.add_argument("--replot", action="store_true", help="use the runs on disk")
    args = parser.parse_args()
    sanguis = (ROOT / args.build / "app" / "sanguis").resolve()
    case_text = (ROOT / "cases" / "flow" / "cavity-re100.toml").read_text()
    sizes_2d = [32, 64] + ([96] if args.fine else [])
    sizes_3d = [16, 32] + ([48] if args.fine else [])

    results = {"2d": {}, "3d": {}}
    previous = {}
    if args.replot and (RESULTS / "cavity.json").exists():
        previous = json.loads((RESULTS / "cavity.json").read_text())  # keeps the run times
    for two_d, sizes in ((True, sizes_2d), (False, sizes_3d)):
        for n in sizes:
            name = f"cavity-{'2d' if two_d else '3d'}-{n}"
            seconds = None
            if not args.replot:
                seconds = run(sanguis, RUNS, name, variant(case_text, n, two_d))
                print(f"{name}: {seconds:.1f} s", flush=True)
            if seconds is None:
                seconds = previous.get("2d" if two_d else "3d", {}).get(str(n), {}).get("wall_seconds")
            centres, arrays = read_vtu(last_frame(RUNS, name))
            (y, u), (x, v) = centre_lines(centres, arrays["velocity"], two_d)
            entry = {"y": y.tolist(), "u": u.tolist(), "x": x.tolist(), "v": v.tolist(),
                     "u_min": float(u.min()), "y_at_u_min": float(y[np.argmin(u)]),
                     "v_max": float(v.max()), "x_at_v_max": float(x[np.argmax(v)]),
                     "v_min": float(v.min()), "x_at_v_min": float(x[np.argmin(v)]),
                     "wall_seconds": seconds}
            if two_d:
                entry["max_diff_u_vs_ghia"], entry["max_diff_v_vs_ghia"] = ghia_differences(y, u, x, v)
            results["2d" if two_d else "3d"][str(n)] = entry

    checks = []
    fine2d = results["2d"][str(sizes_2d[-1] if not args.fine else 64)]
    checks.append(("2D 64^2: max |u - u_Ghia| < 0.02", fine2d["max_diff_u_vs_ghia"] < 0.02))
    checks.append(("2D 64^2: max |v - v_Ghia| < 0.02", fine2d["max_diff_v_vs_ghia"] < 0.02))
    e3 = [results["3d"][str(n)]["u_min"] for n in sizes_3d]
    checks.append(("3D: u_min changes by < 10 % of itself from the second-finest to the finest grid",
                   abs(e3[-1] - e3[-2]) < 0.1 * abs(e3[-1])))
    results["checks"] = [{"check": c, "passed": bool(p)} for c, p in checks]

    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "cavity.json").write_text(json.dumps(results, indent=1))
    with open(RESULTS / "cavity.csv", "w") as f:
        f.write("case,cells_per_side,u_min,y_at_u_min,v_max,x_at_v_max,v_min,x_at_v_min,max_diff_u_vs_ghia,max_diff_v_vs_ghia,wall_seconds\n")
        for dim in ("2d", "3d"):
            for n, e in results[dim].items():
                f.write(f"{dim},{n},{e['u_min']:.6f},{e['y_at_u_min']:.6f},{e['v_max']:.6f},{e['x_at_v_max']:.6f},"
                        f"{e['v_min']:.6f},{e['x_at_v_min']:.6f},{e.get('max_diff_u_vs_ghia', float('nan')):.6f},"
                        f"{e.get('max_diff_v_vs_ghia', float('nan')):.6f},{e['wall_seconds'] or float('nan'):.1f}\n")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax_u, ax_v) = plt.subplots(1, 2, figsize=(10, 4.5))
    ax_u.plot(GHIA_U[:, 1], GHIA_U[:, 0], "ko", mfc="none", label="Ghia et al. 1982 (2D)")
    ax_v.plot(GHIA_V[:, 0], GHIA_V[:, 1], "ko", mfc="none", label="Ghia et al. 1982 (2D)")
    for dim, style in (("2d", "-"), ("3d", "--")):
        for n, e in results[dim].items():
            label = f"sanguis {dim.upper()} {n}" + ("$^2$" if dim == "2d" else "$^3$")
            yy, uu = with_walls(np.array(e["y"]), np.array(e["u"]), 1.0)
            xx, vv = with_walls(np.array(e["x"]), np.array(e["v"]), 0.0)
            ax_u.plot(uu, yy, style, label=label)
            ax_v.plot(xx, vv, style, label=label)
    ax_u.set_xlabel("u / U on x = 0.5 (z = 0.5)")
    ax_u.set_ylabel("y / L")
    ax_v.set_xlabel("x / L")
    ax_v.set_ylabel("v / U on y = 0.5 (z = 0.5)")
    for ax in (ax_u, ax_v):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Lid-driven cavity, Re = 100, t = 15 L/U")
    fig.tight_layout()
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURE, dpi=120)

    draw_slice(f"cavity-3d-{sizes_3d[-1]}")

    ok = True
    for c, p in checks:
        print(("PASS " if p else "FAIL ") + c)
        ok = ok and p
    print(json.dumps({dim: {n: {k: v for k, v in e.items() if k not in ("x", "y", "u", "v")}
                            for n, e in results[dim].items()} for dim in ("2d", "3d")}, indent=1))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
