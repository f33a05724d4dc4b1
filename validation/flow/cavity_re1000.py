#!/usr/bin/python3
"""Lid-driven cubic cavity at Re = 1000 against Albensoeder & Kuhlmann (2005).

Runs cases/flow/cavity-re1000.toml (unit cube, lid y = 1 moving along x at
1 m/s, nu = 1e-3 m2/s, to t = 60 s: steady) at 32^3, 48^3 and 64^3 cells
(--sizes to change) under validation/flow/results/runs/, then compares the
centre-line profiles with the reference:

* S. Albensoeder, H. C. Kuhlmann, "Accurate three-dimensional lid-driven
  cavity flow", J. Comput. Phys. 206 (2005) 536-558, Tables 5 and 6
  (Chebyshev collocation, 96 x 96 x 64 modes): the lid-parallel velocity on
  the vertical centre line and the vertical velocity on the horizontal one,
  at Ghia's 17 points. Values as redistributed (5 digits, already divided by
  Re) in tum-pbs/PICT tests/validations.py, mapped to our axes: their lid is
  the plane x = -1/2 moving along +y, ours the plane y = 1 moving along +x,
  so our u(y) = their v at x_AK = 1/2 - y, and our v(x) = -(their u) at
  y_AK = x - 1/2.
* The extrema to 7 digits and their positions, as quoted from A&K in
  Ben Beya & Lili, C. R. Mecanique 336 (2008) 863-872, Table 1, with that
  paper's own 64^3 finite-volume result for context.

Checks, fixed before the runs (64^3 is the finest grid here; second-order
finite-volume codes at 64^3 are 1-5 % off the spectral extrema in the
literature: Ben Beya & Lili 64^3 1.2 %, Lo et al. 101^3 4.7 %):
  1. each of u_min, v_max, v_min within 5 % of A&K at the finest grid;
  2. their positions within one cell (1/64) of A&K's;
  3. the largest difference at A&K's 30 interior table points below 0.03 U;
  4. the extremum errors shrink monotonically from grid to grid.

The extrema are taken from a parabola through the three cell values around
the discrete extremum. Steadiness is shown by the relative change of the
kinetic energy over the last output interval.

Writes validation/flow/results/cavity_re1000.json and .csv and
docs/validation/figures/flow_cavity_re1000.png. Exits 1 if a check fails.

Usage: /usr/bin/python3 validation/flow/cavity_re1000.py [--build build]
       [--sizes 32 48 64] [--replot | --reuse]    (64^3 is about 40 min on one core)
"""
import argparse
import csv
import json
import sys
from pathlib import Path

import numpy as np

from _cavity_common import centre_lines, last_frame, read_vtu, run, with_walls

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "validation" / "flow" / "results"
RUNS = RESULTS / "runs"
FIGURE = ROOT / "docs" / "validation" / "figures" / "flow_cavity_re1000.png"

# A&K Table 5: their v on the line through the cube centre normal to the lid,
# at x_AK (lid at -0.5); A&K Table 6: their u (normal to the lid, positive into
# the cavity) along the lid's direction of motion, at y_AK.
AK_T5_X = np.array([0.5000, 0.4453, 0.4375, 0.4297, 0.3984, 0.3281, 0.2187, 0.0469, 0.0000,
                    -0.1172, -0.2344, -0.3516, -0.4531, -0.4609, -0.4688, -0.4766, -0.5000])
AK_T5_V = np.array([0.00000, -0.20623, -0.22283, -0.23696, -0.27293, -0.25160, -0.10999, -0.00612,
                    0.00802, 0.03905, 0.07334, 0.12183, 0.33171, 0.39821, 0.48443, 0.58964, 1.00000])
AK_T6_Y = np.array([-0.5000, -0.4375, -0.4297, -0.4219, -0.4062, -0.3437, -0.2734, -0.2656, 0.0000,
                    0.3047, 0.3594, 0.4063, 0.4453, 0.4531, 0.4609, 0.4688, 0.5000])
AK_T6_U = np.array([0.00000, -0.21738, -0.22746, -0.23503, -0.24407, -0.22924, -0.17580, -0.16987,
                    -0.03674, 0.15223, 0.31117, 0.43423, 0.33511, 0.29032, 0.24095, 0.18864, 0.00000])
# In our axes: u(y) on x = z = 1/2 and v(x) on y = z = 1/2.
REF_U = np.column_stack((0.5 - AK_T5_X, AK_T5_V))
REF_V = np.column_stack((AK_T6_Y + 0.5, -AK_T6_U))
# Extrema (value, position along the line) from A&K via Ben Beya & Lili Table 1.
REF_EXTREMA = {"u_min": (-0.2803833, 0.12419), "v_max": (0.2466511, 0.10913),
               "v_min": (-0.4350186, 0.90957)}
BEN_BEYA_64 = {"u_min": (-0.2769995, 0.1227), "v_max": (0.2438928, 0.1084),
               "v_min": (-0.4295692, 0.9041)}
TOLERANCE_EXTREMUM = 0.05
TOLERANCE_PROFILE = 0.03


def variant(case_text, n):
    text = case_text.replace('name = "cavity-re1000"', f'name = "cavity-re1000-{n}"')
    return text.replace("cells = [64, 64, 64]", f"cells = [{n}, {n}, {n}]")


def parabolic_extremum(coord, value, index):
    """Vertex of the parabola through the three values around `index`."""
    i = min(max(index, 1), len(value) - 2)
    a, b, c = np.polyfit(coord[i - 1:i + 2], value[i - 1:i + 2], 2)
    if a == 0.0:
        return float(value[index]), float(coord[index])
    x0 = -b / (2 * a)
    return float(c - b * b / (4 * a)), float(x0)


def kinetic_energy_change(name):
    """Relative change of the kinetic energy over the last output interval, and t_end."""
    with open(RUNS / name / "diagnostics.csv") as f:
        rows = list(csv.DictReader(f))
    e1, e0 = float(rows[-1]["kinetic_energy_J"]), float(rows[-2]["kinetic_energy_J"])
    return abs(e1 - e0) / e1, float(rows[-1]["time_s"])


def logged_seconds(name):
    """Wall time from the run log's "done: ... in 32m37s" line (runs started by hand)."""
    import re
    log = RUNS / name / "run.log"
    if not log.exists():
        return None
    m = re.search(r"done: .* in ((?:\d+h)?(?:\d+m)?(?:\d+s)?) ", log.read_text())
    if not m:
        return None
    parts = dict((unit, int(value)) for value, unit in re.findall(r"(\d+)([hms])", m.group(1)))
    return 3600 * parts.get("h", 0) + 60 * parts.get("m", 0) + parts.get("s", 0)


def measure(n, seconds):
    name = f"cavity-re1000-{n}"
    centres, arrays = read_vtu(last_frame(RUNS, name))
    (y, u), (x, v) = centre_lines(centres, arrays["velocity"], False)
    yy, uu = with_walls(y, u, 1.0)
    xx, vv = with_walls(x, v, 0.0)
    extrema = {"u_min": parabolic_extremum(y, u, int(np.argmin(u))),
               "v_max": parabolic_extremum(x, v, int(np.argmax(v))),
               "v_min": parabolic_extremum(x, v, int(np.argmin(v)))}
    interior_u = REF_U[1:-1]
    interior_v = REF_V[1:-1]
    du = np.abs(np.interp(interior_u[:, 0], yy, uu) - interior_u[:, 1])
    dv = np.abs(np.interp(interior_v[:, 0], xx, vv) - interior_v[:, 1])
    change, t_end = kinetic_energy_change(name)
    if seconds is None:
        seconds = logged_seconds(name)
    entry = {"cells_per_side": n, "t_end_s": t_end, "kinetic_energy_change_last_interval": change,
             "wall_seconds": seconds, "y": y.tolist(), "u": u.tolist(), "x": x.tolist(), "v": v.tolist(),
             "max_diff_u_vs_ak": float(du.max()), "max_diff_v_vs_ak": float(dv.max()),
             "rms_diff_vs_ak": float(np.sqrt(np.mean(np.concatenate((du, dv)) ** 2)))}
    for key, (value, position) in extrema.items():
        ref_value, ref_position = REF_EXTREMA[key]
        entry[key] = value
        entry[f"{key}_at"] = position
        entry[f"{key}_rel_error"] = (value - ref_value) / abs(ref_value)
    return entry


def extrapolated_extrema(results, sizes):
    """Richardson estimate of each extremum's grid limit (not a check): the
    observed order p from the three finest grids (u = u* + C h^p solved
    exactly), and the order-2 estimate from the two finest. Empty with fewer
    than three grids or a sequence that is not monotone."""
    if len(sizes) < 3:
        return {}
    out = {}
    n1, n2, n3 = sizes[-3:]
    for key in REF_EXTREMA:
        u1, u2, u3 = (results[str(n)][key] for n in (n1, n2, n3))
        d12, d23 = u2 - u1, u3 - u2
        if d12 * d23 <= 0.0:
            continue
        # d12 / d23 = (h1^p - h2^p) / (h2^p - h3^p) with h = 1/n: solve for p by bisection.
        ratio = d12 / d23

        def f(p):
            return (n1 ** -p - n2 ** -p) / (n2 ** -p - n3 ** -p) - ratio
        lo, hi = 0.1, 8.0
        if f(lo) * f(hi) > 0.0:
            continue
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if f(lo) * f(mid) > 0.0 else (lo, mid)
        p = 0.5 * (lo + hi)
        limit = u3 + d23 * n3 ** -p / (n2 ** -p - n3 ** -p)
        r = (n3 / n2) ** 2
        limit2 = (r * u3 - u2) / (r - 1.0)
        ref = REF_EXTREMA[key][0]
        out[key] = {"grids": [n1, n2, n3], "order": p, "limit": limit,
                    "rel_to_ak": (limit - ref) / abs(ref), "limit_order2": limit2,
                    "rel_to_ak_order2": (limit2 - ref) / abs(ref)}
    return out


def draw(results, sizes):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax_u, ax_v, ax_e) = plt.subplots(1, 3, figsize=(15, 4.6))
    ax_u.plot(REF_U[:, 1], REF_U[:, 0], "ko", mfc="none", label="Albensoeder & Kuhlmann 2005")
    ax_v.plot(REF_V[:, 0], REF_V[:, 1], "ko", mfc="none", label="Albensoeder & Kuhlmann 2005")
    for n in sizes:
        e = results[str(n)]
        yy, uu = with_walls(np.array(e["y"]), np.array(e["u"]), 1.0)
        xx, vv = with_walls(np.array(e["x"]), np.array(e["v"]), 0.0)
        ax_u.plot(uu, yy, "-", label=f"sanguis {n}$^3$")
        ax_v.plot(xx, vv, "-", label=f"sanguis {n}$^3$")
    ax_u.set_xlabel("u / U on x = z = 0.5")
    ax_u.set_ylabel("y / L")
    ax_v.set_xlabel("x / L")
    ax_v.set_ylabel("v / U on y = z = 0.5")
    h = np.array([1.0 / n for n in sizes])
    for key, marker in (("u_min", "o-"), ("v_max", "s-"), ("v_min", "^-")):
        err = np.array([abs(results[str(n)][f"{key}_rel_error"]) for n in sizes])
        ax_e.loglog(h, err, marker, label=key)
        bb_value = BEN_BEYA_64[key][0]
        ax_e.loglog([1 / 64], [abs(bb_value - REF_EXTREMA[key][0]) / abs(REF_EXTREMA[key][0])],
                    marker[0], mfc="none", color="gray")
    ax_e.loglog(h, 0.5 * (h / h[-1]) ** 2 * abs(results[str(sizes[-1])]["u_min_rel_error"]), "k:",
                label="slope 2")
    ax_e.axhline(TOLERANCE_EXTREMUM, color="r", lw=0.8, ls="--", label="tolerance 5 %")
    ax_e.set_xlabel("cell size h / L")
    ax_e.set_ylabel("|extremum - A&K| / |A&K|")
    ax_e.set_title("grey: Ben Beya & Lili 2008, 64$^3$ FV", fontsize=9)
    for ax in (ax_u, ax_v, ax_e):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Lid-driven cubic cavity, Re = 1000, t = 60 L/U")
    fig.tight_layout()
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURE, dpi=120)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--sizes", type=int, nargs="+", default=[32, 48, 64])
    parser.add_argument("--replot", action="store_true", help="use the runs on disk")
    parser.add_argument("--reuse", action="store_true", help="run only the grids not finished on disk")
    args = parser.parse_args()
    sizes = sorted(args.sizes)
    end_time = 60.0
    sanguis = (ROOT / args.build / "app" / "sanguis").resolve()
    case_text = (ROOT / "cases" / "flow" / "cavity-re1000.toml").read_text()
    previous = {}
    if (RESULTS / "cavity_re1000.json").exists():
        previous = json.loads((RESULTS / "cavity_re1000.json").read_text()).get("grids", {})

    results = {}
    for n in sizes:
        seconds = previous.get(str(n), {}).get("wall_seconds")
        finished = (RUNS / f"cavity-re1000-{n}" / "diagnostics.csv").exists() and \
            kinetic_energy_change(f"cavity-re1000-{n}")[1] >= end_time - 1e-6
        if not args.replot and not (args.reuse and finished):
            seconds = run(sanguis, RUNS, f"cavity-re1000-{n}", variant(case_text, n))
            print(f"cavity-re1000-{n}: {seconds:.1f} s", flush=True)
        results[str(n)] = measure(n, seconds)

    finest = results[str(sizes[-1])]
    checks = []
    for key in REF_EXTREMA:
        err = finest[f"{key}_rel_error"]
        checks.append((f"{sizes[-1]}^3: {key} = {finest[key]:.4f} within 5 % of A&K {REF_EXTREMA[key][0]:.4f} "
                       f"({100 * err:+.2f} %)", abs(err) <= TOLERANCE_EXTREMUM))
        shift = finest[f"{key}_at"] - REF_EXTREMA[key][1]
        checks.append((f"{sizes[-1]}^3: {key} at {finest[f'{key}_at']:.4f}, within one cell of A&K's "
                       f"{REF_EXTREMA[key][1]:.4f} ({shift:+.4f})", abs(shift) <= 1.0 / sizes[-1]))
        errors = [abs(results[str(n)][f"{key}_rel_error"]) for n in sizes]
        checks.append((f"{key} error shrinks with the grid: " + ", ".join(f"{100 * e:.2f} %" for e in errors),
                       all(b < a for a, b in zip(errors, errors[1:]))))
    worst = max(finest["max_diff_u_vs_ak"], finest["max_diff_v_vs_ak"])
    checks.append((f"{sizes[-1]}^3: largest difference at A&K's table points {worst:.4f} U < 0.03 U",
                   worst < TOLERANCE_PROFILE))

    out = {"reference": "Albensoeder & Kuhlmann, J. Comput. Phys. 206 (2005) 536, Tables 5-6",
           "grids": results, "checks": [{"check": c, "passed": bool(p)} for c, p in checks],
           "extrapolated": extrapolated_extrema(results, sizes)}
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "cavity_re1000.json").write_text(json.dumps(out, indent=1))
    with open(RESULTS / "cavity_re1000.csv", "w") as f:
        keys = ["cells_per_side", "u_min", "u_min_at", "u_min_rel_error", "v_max", "v_max_at", "v_max_rel_error",
                "v_min", "v_min_at", "v_min_rel_error", "max_diff_u_vs_ak", "max_diff_v_vs_ak", "rms_diff_vs_ak",
                "kinetic_energy_change_last_interval", "t_end_s", "wall_seconds"]
        f.write(",".join(keys) + "\n")
        for n in sizes:
            f.write(",".join(str(results[str(n)][k]) for k in keys) + "\n")
    draw(results, sizes)

    ok = True
    for c, p in checks:
        print(("PASS " if p else "FAIL ") + c)
        ok = ok and p
    for key, e in out["extrapolated"].items():
        print(f"{key}: grid limit from the three finest grids {e['limit']:.5f} (observed order "
              f"{e['order']:.2f}; {100 * e['rel_to_ak']:+.2f} % from A&K), with order 2 from the two "
              f"finest {e['limit_order2']:.5f} ({100 * e['rel_to_ak_order2']:+.2f} %) [not a check]")
    for n in sizes:
        e = results[str(n)]
        print(f"{n}^3: u_min {e['u_min']:.4f}@{e['u_min_at']:.4f}  v_max {e['v_max']:.4f}@{e['v_max_at']:.4f}  "
              f"v_min {e['v_min']:.4f}@{e['v_min_at']:.4f}  max|diff| u {e['max_diff_u_vs_ak']:.4f} "
              f"v {e['max_diff_v_vs_ak']:.4f}  dE/E last 5 s {e['kinetic_energy_change_last_interval']:.1e}  "
              f"wall {e['wall_seconds']}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
