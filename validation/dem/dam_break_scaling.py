#!/usr/bin/python3
"""Dam break of spheres: run-out against aspect ratio (Lajeunesse et al. 2005; thesis
§3.2.3, Fig. 3.7, app. B.1), several seeds per point.

cases/dem/dam-break-spheres.toml (glass beads R = 2 mm +- 10 %, mu_c = 0.5, mu_r = 0.05,
a 4 cm wide channel, a rough floor of glued beads) is run with the gate at L0 = 1.5, 2,
4, 4.1 and 6 cm (the column's particle count and height adapted through `--set`), two
seeds each, through `sanguis ensemble`; `sanguis analyze` measures L0, H0, L_inf (10 %
intensity, error bar 20 % / 1 %), H_inf, the centre-of-mass displacement and the mean
speed against time.

Reference: Lajeunesse, Monnier & Homsy, Phys. Fluids 17 (2005), quasi-2D channel on a
rough bottom: (L_inf - L0)/L0 = 1.2 a for a < 1.8 and 1.9 a^(2/3) for a > 2.8
(a = H0/L0), the scaling the thesis' sphere simulations reproduce; thesis Fig. 3.9a for
the mean speed of a column of spheres at a = 3.2.
Checks (tolerances fixed before running): every point within 35 % of the Lajeunesse
curve (linear branch below a = 2.3, power branch above); the log-log slope between the
two tallest columns within [0.45, 0.9] (2/3 expected); the mean coordination number of
the columns at the gate opening within 20 % of the thesis' 5.6 (§3.3.3); for the 4.1 cm
column (a = 3.2), the peak mean speed within 20 % of the thesis' 35-39 % of sqrt(g H0)
(the same ±20 % as for the other values read off the thesis), its time within
[0.5, 1.5] tau_c and the drop below 5 % within [3, 5] tau_c (thesis: at tau_c and 4 tau_c).

Writes validation/dem/results/dam_break_scaling.json and
docs/validation/figures/dam_break_{scaling,velocity}.png. `--quick`: one seed, two gate
positions.
Usage: /usr/bin/python3 validation/dem/dam_break_scaling.py [--build build] [--quick]
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import time

import matplotlib
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _outputs import (lajeunesse, read_arrays, read_pvd, read_summary, regime_name,  # noqa: E402
                      speed_landmarks)

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CASE = os.path.join(ROOT, "cases", "dem", "dam-break-spheres.toml")
RESULTS = os.path.join(ROOT, "validation", "dem", "results")
RUNS = os.path.join(RESULTS, "runs", "dam_break_scaling")
FIGURE = os.path.join(ROOT, "docs", "validation", "figures", "dam_break_scaling.png")

# gate position L0 [m] -> spheres in the column (keeps the insertion region feasible);
# the 4.1 cm column has the aspect ratio of Fig. 3.9 (a = 3.2, 3200 spheres there)
COLUMNS = [(0.015, 1500), (0.02, 1500), (0.04, 3000), (0.041, 3500), (0.06, 3000)]
FIG39_GATE = 0.041
VELOCITY_FIGURE = os.path.join(ROOT, "docs", "validation", "figures", "dam_break_velocity.png")
GATE_INDEX = 5  # [[obstacle]] number of the gate in the case


def overrides(l0, count):
    # Random insertion fills about 28 % of the region: make it tall enough.
    top = min(0.45, count * 3.4e-8 / (0.28 * l0 * 0.04))
    return [f"obstacle[{GATE_INDEX}].min_m=[{l0}, -0.01, 0.00401]",
            f"obstacle[{GATE_INDEX}].max_m=[{l0 + 0.005}, 0.05, 0.5]",
            f"particles[1].count={count}",
            f"particles[1].region_max_m=[{l0}, 0.04, {top:.4f}]",
            "domain.max_m=[0.40, 0.04, 0.5]",
            f"obstacle[{GATE_INDEX}].remove_at_s=0.6",
            "simulation.end_time_s=1.3",
            "output.interval_s=0.02"]


def velocity_curves(columns, seeds):
    """(t/tau_c, mean speed/sqrt(g H0)) of every run of the Fig. 3.9 column."""
    curves = []
    for l0, _ in columns:
        if l0 != FIG39_GATE:
            continue
        for k in range(seeds):
            path = os.path.join(RUNS, f"L0_{l0 * 100:g}cm", f"seed_{k + 1}", "analysis",
                                "velocity.csv")
            with open(path, newline="") as f:
                rows = list(csv.DictReader(f))
            curves.append(([float(r["time_over_tau_c"]) for r in rows],
                           [float(r["mean_speed_over_sqrt_gH0"]) for r in rows]))
    return curves


def velocity_checks(columns, seeds):
    """Fig. 3.9a: spheres at a = 3.2 peak at 35-39 % of sqrt(g H0) at t = tau_c and drop
    below 5 % at t = 4 tau_c. Tolerances fixed before running: the peak within 20 % of
    that range, its time within [0.5, 1.5] tau_c, the 5 % crossing within [3, 5] tau_c."""
    curves = velocity_curves(columns, seeds)
    if not curves:
        return []
    checks = []
    for k, (t, v) in enumerate(curves):
        peak, peak_t, below = speed_landmarks(t, v)
        checks += [
            {"quantity": f"Fig. 3.9 column, seed {k + 1}: peak mean speed / sqrt(g H0)",
             "measured": round(peak, 3), "thesis": "0.35-0.39",
             "tolerance": "[0.28, 0.468] (±20 %)", "pass": 0.28 <= peak <= 0.468},
            {"quantity": f"Fig. 3.9 column, seed {k + 1}: time of the peak / tau_c",
             "measured": round(peak_t, 2), "thesis": "1",
             "tolerance": "[0.5, 1.5]", "pass": 0.5 <= peak_t <= 1.5},
            {"quantity": f"Fig. 3.9 column, seed {k + 1}: speed below 5 % from t / tau_c",
             "measured": round(below, 2), "thesis": "≈ 4",
             "tolerance": "[3, 5]", "pass": 3.0 <= below <= 5.0}]
    fig, ax = plt.subplots(figsize=(6, 4.2))
    for k, (t, v) in enumerate(curves):
        ax.plot(t, v, label=f"sanguis, seed {k + 1}")
    ax.fill_between([0.9, 1.1], 0.35, 0.39, color="0.8", label="thesis: peak 35-39 % at τc")
    ax.axhline(0.05, color="k", lw=0.8, ls=":")
    ax.plot([4.0], [0.05], "kv", label="thesis: below 5 % at 4 τc")
    ax.set_xlim(0, 8)
    ax.set_xlabel(r"$t/\tau_c$, $\tau_c = \sqrt{H_0/g}$")
    ax.set_ylabel(r"mean speed / $\sqrt{g H_0}$")
    ax.set_title("Spheres, a = 3.2 (thesis Fig. 3.9a)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(VELOCITY_FIGURE, dpi=130)
    return checks


def contact_counts(run_dir, time_s):
    """Contacts of the frame nearest time_s: bead-bead (mobile), bead-glued bead, bead-wall,
    and the number of mobile beads."""
    frames = read_pvd(os.path.join(run_dir, "contacts.pvd"))
    _, path = min(frames, key=lambda f: abs(f[0] - time_s))
    particles = read_pvd(os.path.join(run_dir, "particles.pvd"))
    _, ppath = min(particles, key=lambda f: abs(f[0] - time_s))
    beads = read_arrays(ppath)
    glued_ids = set(beads["id"][beads["fixed"] != 0].astype(int).tolist())
    contacts = read_arrays(path)
    pair = np.isin(contacts["kind"], (0, 2))  # sphere pairs, body pairs (not walls)
    glued = np.array([int(a) in glued_ids or int(b) in glued_ids
                      for a, b in zip(contacts["first_id"], contacts["second_id"])], dtype=bool)
    return {"mobile": int((pair & ~glued).sum()), "glued": int((pair & glued).sum()),
            "walls": int((~pair).sum()), "beads": int((beads["fixed"] == 0).sum())}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--reuse", action="store_true",
                    help="analyse the runs already on disk (no new runs)")
    args = ap.parse_args()
    exe = os.path.join(ROOT, args.build, "app", "sanguis")
    columns = [COLUMNS[1], COLUMNS[3]] if args.quick else COLUMNS
    seeds = 1 if args.quick else 2
    t0 = time.time()
    points = []
    for l0, count in columns:
        out = os.path.join(RUNS, f"L0_{l0 * 100:g}cm")
        cmd = [exe, "ensemble", CASE, "--seeds", str(seeds), "--jobs", "2", "--output", out]
        for o in overrides(l0, count):
            cmd += ["--set", o]
        if not (args.reuse and os.path.exists(os.path.join(out, "ensemble.csv"))):
            print(" ".join(cmd), flush=True)
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        for k in range(seeds):
            s = read_summary(os.path.join(out, f"seed_{k + 1}"))
            s["gate_m"] = l0
            s["run_dir"] = os.path.join(out, f"seed_{k + 1}")
            points.append(s)
    elapsed = time.time() - t0
    if args.reuse:  # the wall-clock span of the runs on disk
        logs = [os.path.join(RUNS, d, f"seed_{k + 1}", "run.log") for d in os.listdir(RUNS)
                for k in range(seeds)]
        logs = [f for f in logs if os.path.exists(f)]
        first = min(os.path.getmtime(os.path.join(os.path.dirname(f), "obstacles.csv")) for f in logs)
        elapsed = max(os.path.getmtime(f) for f in logs) - first

    checks = []
    rows = []
    for p in points:
        a = p["aspect_ratio_H0_over_L0"]
        ref = lajeunesse(a)
        dev = p["runout_ratio"] / ref - 1.0
        rows.append([f"{p['gate_m'] * 100:g}", f"{p['L0_m'] * 100:.2f}", f"{p['H0_m'] * 100:.2f}",
                     f"{a:.2f}", f"{p['runout_ratio']:.2f}", f"{ref:.2f}", f"{100 * dev:+.0f} %",
                     f"{p['height_ratio_H0_over_Hinf']:.2f}", f"{p['com_displacement_x_over_L0']:.2f}",
                     regime_name(p)])
        checks.append({"quantity": f"(L∞−L0)/L0 at a = {a:.2f}", "measured": round(p["runout_ratio"], 3),
                       "thesis": f"{ref:.2f} (Lajeunesse)", "tolerance": "±35 %",
                       "pass": abs(dev) <= 0.35})
    # Slope between the two tallest columns, each the mean over its seeds.
    groups = {}
    for p in points:
        groups.setdefault(p["gate_m"], []).append(p)
    means = sorted(((sum(q["aspect_ratio_H0_over_L0"] for q in g) / len(g),
                     sum(q["runout_ratio"] for q in g) / len(g)) for g in groups.values()))
    if len(means) >= 2:
        (a1, r1), (a2, r2) = means[-2], means[-1]
        slope = math.log(r2 / r1) / math.log(a2 / a1)
        checks.append({"quantity": f"log-log slope between a = {a1:.2f} and {a2:.2f}",
                       "measured": round(slope, 3), "thesis": "2/3 (a > 3)",
                       "tolerance": "[0.45, 0.9]", "pass": 0.45 <= slope <= 0.9})
    # §3.3.3: a column of spheres has 2 x 41971 / 15000 = 5.6 contacts per particle.
    z = sum(p["pair_coordination"] for p in points) / len(points)
    checks.append({"quantity": "coordination number of the column (pairs, at the gate opening)",
                   "measured": round(z, 3), "thesis": "5.6 (§3.3.3, 15000 spheres)",
                   "tolerance": "±20 %", "pass": abs(z / 5.6 - 1.0) <= 0.2})

    # The thesis' "41,971 contacts" may count the walls too: the same formula on every
    # contact (bead-bead, bead-glued floor bead, bead-wall), reported, not graded.
    counts = [contact_counts(p["run_dir"], p["initial_time_s"]) for p in points]
    per_bead = sum((2 * c["mobile"] + c["glued"] + c["walls"]) / c["beads"] for c in counts)
    thesis_formula = sum(2 * (c["mobile"] + c["glued"] + c["walls"]) / c["beads"] for c in counts)
    # Glued beads touch neither each other nor the walls (no such contacts are formed
    # since 6988d1b and 124d8c3). The report of 2026-11-23 02:25 analysed runs made
    # before 124d8c3 and counted contacts of glued beads: 4.63; 5.36.
    # The boundary's share: beads against a wall, the glued floor or the gate lack
    # neighbours there (glued beads are not obstacles: beads on them count as touching
    # none); the bulk is the column less four mean radii on every side.
    n = len(points)
    wall_share = sum(p["particles_touching_obstacles_fraction"] for p in points) / n
    z_away = sum(p["pair_coordination_away_from_obstacles"] for p in points) / n
    bulk = [p for p in points if p["bulk_particles"] > 0]
    z_bulk = sum(p["bulk_pair_coordination"] for p in bulk) / max(len(bulk), 1)
    checks.append({"quantity": "beads touching a wall or the gate; pairs per bead of the others; "
                   f"pairs per bead of the bulk (mean of the {len(bulk)} runs that have one)",
                   "measured": f"{100 * wall_share:.0f} %; {z_away:.2f}; {z_bulk:.2f}",
                   "thesis": "5.6 (§3.3.3); frictional spheres compressed at mu = 0.3: about "
                   "4.5, rattlers left out (Agnolin & Roux 2007)",
                   "tolerance": "reported", "pass": None})
    checks.append({"quantity": "contacts per bead, contacts with walls and glued floor beads "
                   "included; 2 × (all contacts) / beads",
                   "measured": f"{per_bead / len(counts):.2f}; {thesis_formula / len(counts):.2f}",
                   "thesis": "5.6 = 2 × 41971 / 15000 (§3.3.3: which contacts, not stated)",
                   "tolerance": "not graded", "pass": None})

    checks += velocity_checks(columns, seeds)

    os.makedirs(os.path.dirname(FIGURE), exist_ok=True)
    fig, ax = plt.subplots(figsize=(6, 4.2))
    a_line = [0.3 * 1.05 ** k for k in range(80)]
    ax.loglog(a_line, [lajeunesse(a) for a in a_line], "k--", label="Lajeunesse et al. (2005)")
    for p in points:
        l0 = p["L0_m"]
        lo = (p["Linf_20pc_m"] - l0) / l0
        hi = (p["Linf_1pc_m"] - l0) / l0
        # max(0, .): the CSV values are rounded to 10 digits
        ax.errorbar([p["aspect_ratio_H0_over_L0"]], [p["runout_ratio"]],
                    yerr=[[max(0.0, p["runout_ratio"] - lo)], [max(0.0, hi - p["runout_ratio"])]],
                    fmt="o", color="tab:blue", capsize=3)
        ax.plot([p["aspect_ratio_H0_over_L0"]], [p["com_displacement_x_over_L0"]], "d", color="tab:orange")
    ax.plot([], [], "o", color="tab:blue", label="sanguis run-out (10 %; bars 20 % / 1 %)")
    ax.plot([], [], "d", color="tab:orange", label="sanguis centre-of-mass shift / L0")
    ax.set_xlabel(r"aspect ratio $a = H_0/L_0$")
    ax.set_ylabel(r"$(L_\infty - L_0)/L_0$")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(FIGURE, dpi=130)

    ok = all(c["pass"] for c in checks)
    summary = {
        "name": "dam_break_scaling",
        "title": "Dam break of spheres: run-out vs aspect ratio",
        "thesis": "§3.2.3, Fig. 3.7, app. B.1 (Lajeunesse et al. 2005)",
        "description": (
            "cases/dem/dam-break-spheres.toml with the gate at several positions (`--set`), "
            f"{seeds} seed(s) each through `sanguis ensemble`, measured by `sanguis analyze` "
            "(top-view intensity, 10 % threshold)."),
        "command": "/usr/bin/python3 validation/dem/dam_break_scaling.py --build BUILD"
                   + (" --quick" if args.quick else ""),
        "figures": ["docs/validation/figures/dam_break_scaling.png",
                    "docs/validation/figures/dam_break_velocity.png"],
        "checks": checks,
        "tables": [{"caption": "Per run.",
                    "header": ["gate [cm]", "L0 [cm]", "H0 [cm]", "a", "(L∞−L0)/L0", "Lajeunesse",
                               "deviation", "H0/H∞", "Δx_com/L0", "regime"],
                    "rows": rows}],
        "notes": [
            "The floor is rough: one square layer of glued beads (R = 2 mm, `fixed = true`), "
            "as the rough bottom of the experiments and of the Grains3D simulations of "
            "Girolami et al. (2012) that the thesis reproduces. On the smooth steel plane "
            "(mu = 0.45, mu_r = 0.05) used before, every run-out was 31-58 % above "
            "Lajeunesse's (commit 4a61097): the spheres rolled and slid on the floor.",
            "Heights are measured from z = 0, so H0 and H∞ include the glued layer "
            "(its tops at 4 mm, about 3 % of H0).",
            "The channel is 4 cm (about 10 diameters) wide; Lajeunesse's channel was "
            "quasi-2D as well. Both branches of the reference are used as published, "
            "joined at a = 2.3.",
            "Mean speed (Fig. 3.9a): the peak comes near tau_c as in the thesis, 15-20 % "
            "lower, and the column comes to rest about one tau_c sooner (5 % at about 2.8 "
            "tau_c against 4). Contact parameters close at most a third of that gap (Fig. "
            "3.9 column, 2026-11-24, frames every 0.17 tau_c; the same set-up with the "
            "case's parameters gives seed 1 above again, 2.76): without rolling friction "
            "(two seeds) peak 0.316 and 5 % crossing 2.96 and 2.97 tau_c; without rolling "
            "friction and with normal restitution 0.9 instead of 0.45 (one seed) 0.320 and "
            "3.17; without rolling friction and with mu_c 0.3 instead of 0.5 between beads "
            "(one seed) 0.318 and 3.17, between beads and with the walls (one seed) 0.334 "
            "and 3.17. The run-out of this column moves more: 3 % below Lajeunesse's "
            "without rolling friction (mean of the two seeds; 8-13 % below in the runs "
            "above), 16-19 % above it with mu_c 0.3 as well, 8 % below with restitution "
            "0.9. What makes the thesis' column flow longer (its floor, its contact "
            "parameters, or the reading of its figure) is not settled here.",
            "Coordination: the thesis' 5.6 is 2 x 41971 contacts / 15000 spheres (§3.3.3); "
            "the same formula gives 16.5 for its 12000 crosses, twice the 8.2 of its own "
            "Table B.1 for crosses, while 98939 / 12000 = 8.24 matches Table B.1. If the "
            "contact counts of §3.3.3 hold every contact twice, the spheres' value is 2.8. "
            "The check keeps the published 5.6.",
            f"Boundary: at the opening {100 * wall_share:.0f} % of the beads touch a wall or "
            f"the gate; the others have {z_away:.2f} touching neighbours, and the bulk (the "
            "column less four mean radii on every side, free surface and the layer on the "
            f"glued floor left out) {z_bulk:.2f}, against {z:.2f} for the whole column. A "
            "frictional packing poured under gravity is loose: Silbert et al. (2002) find the "
            "coordination falling from 6 as the friction grows, Agnolin & Roux (2007) about "
            "4.5 on the load-bearing contacts of spheres compressed at mu = 0.3, and these "
            "beads have mu = 0.5 and rolling friction. The thesis' 5.6 is above every one "
            "of these measures."],
        "run_time_s": round(elapsed, 1),
        "date": time.strftime("%Y-%m-%d %H:%M"),
        "quick": bool(args.quick),
        "pass": bool(ok),
    }
    os.makedirs(RESULTS, exist_ok=True)
    with open(os.path.join(RESULTS, "dam_break_scaling.json"), "w") as f:
        json.dump(summary, f, indent=1)
    print(f"{'PASS' if ok else 'FAIL'}: {len(points)} runs in {elapsed:.0f} s")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
