#!/usr/bin/python3
"""Dam break of crosses with and without contact memory (thesis §3.4.2, Fig. 3.16).

cases/dem/dam-break-crosses-memory.toml pours 300 crosses (Table 3.1) behind a gate
and lets them settle until the gate is removed (t = 3.0 s, the case's remove_at_s).
The pour runs once; its final checkpoint is copied twice and continued for 0.8 s: as
is (tangential memory, eq. 2.6) and with memory = false on both interactions
(dashpot with Coulomb limit: no tangential spring). The same initial microstructure,
as in the thesis.

The thesis' observation: without memory "the granular column slowly deforms and
overpacks at the bottom of the pile, while it should remain static in that region";
with memory the base stays and particles fall off the top.
Checks (fixed before running): the particles of the back half of the base (x < L0/2,
z < H0/4 at the gate opening) move on average at least 5 times less with memory than
without after 0.8 s; without memory they move more than 1 mm (they creep).
Also: the coordination number at the opening against §3.3.3 (16.5 contact points
per cross) and Table B.1 (8.2 neighbours), each within 20 %; H_inf, L_inf and the
regime of both runs (`sanguis analyze`); and, as a sanity check, the column at rest
when the gate opens (mean speed below 1e-3 m/s, added 2026-11-25).

Writes validation/dem/results/crosses_memory.json and
docs/validation/figures/crosses_memory.png. Run time: pour ~5-10 min, then the two
continuations side by side ~5-10 min (2 cores).
Usage: /usr/bin/python3 validation/dem/crosses_memory.py [--build build] [--rerun-pour]
"""
import argparse
import json
import os
import subprocess
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _outputs import (continuation_command, gate_removal_time, read_arrays,  # noqa: E402
                      read_pvd, read_summary, regime_name, run_pour, wall_time)
from crosses_dam_break import diagnostics  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CASE = os.path.join(ROOT, "cases", "dem", "dam-break-crosses-memory.toml")
RESULTS = os.path.join(ROOT, "validation", "dem", "results")
RUNS = os.path.join(RESULTS, "runs", "crosses_memory")
FIGURE = os.path.join(ROOT, "docs", "validation", "figures", "crosses_memory.png")
GATE_TIME = gate_removal_time(CASE)
NO_MEMORY = ["--set", "interaction[0].memory=false", "--set", "interaction[1].memory=false"]


def frames(run):
    return read_pvd(os.path.join(run, "particles.pvd"))


def positions_by_id(path):
    a = read_arrays(path)
    order = np.argsort(a["id"])
    return a["id"][order], a["Points"][order]


def base_creep(run, base_ids):
    """Mean displacement of the base particles from the gate opening, per frame."""
    series = []
    ref = None
    for t, path in frames(run):
        if t < GATE_TIME - 1e-9:
            continue
        ids, x = positions_by_id(path)
        sel = np.isin(ids, base_ids)
        if ref is None:
            ref = x[sel]
        series.append((t - GATE_TIME, float(np.mean(np.linalg.norm(x[sel] - ref, axis=1))),
                       float(np.max(x[:, 2]))))
    return series


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--rerun-pour", action="store_true")
    ap.add_argument("--quick", action="store_true", help="same as the full run (no smaller variant)")
    args = ap.parse_args()
    exe = os.path.join(ROOT, args.build, "app", "sanguis")
    pour = os.path.join(RUNS, "pour")
    run_pour([exe, "run", CASE, "--output", pour, "--quiet", "--threads", "1"], pour, GATE_TIME,
             args.rerun_pour)
    runs = {"memory": os.path.join(RUNS, "memory"), "no memory": os.path.join(RUNS, "no_memory")}
    procs = []
    for name, d in runs.items():
        # A continuation stopped on the way goes on from its checkpoint.
        cmd = continuation_command(
            [exe, "run", CASE, "--output", d, "--restart", "--quiet", "--threads", "1"]
            + (NO_MEMORY if name == "no memory" else []), d, pour, GATE_TIME)
        if cmd:
            procs.append(subprocess.Popen(cmd, stdout=subprocess.DEVNULL))
    for p in procs:
        if p.wait() != 0:
            sys.exit("a continuation failed")
    for d in runs.values():
        subprocess.run([exe, "analyze", d, "--plot"], check=True, stdout=subprocess.DEVNULL)
    # The work kept in the folders, whichever calls did it (run.log): the pour, then the
    # two continuations side by side.
    elapsed = wall_time(pour) + max(wall_time(d, GATE_TIME) for d in runs.values())

    s0 = read_summary(runs["memory"])
    gate_frame = [p for t, p in frames(pour) if abs(t - GATE_TIME) < 1e-6 or t <= GATE_TIME][-1]
    ids, x = positions_by_id(gate_frame)
    l0, h0 = s0["L0_m"], s0["H0_m"]
    base = ids[(x[:, 0] < 0.5 * l0) & (x[:, 2] < 0.25 * h0)]
    creep = {name: base_creep(d, base) for name, d in runs.items()}
    final = {name: c[-1][1] for name, c in creep.items()}
    ratio = final["no memory"] / max(final["memory"], 1e-12)

    checks = [
        {"quantity": "base displacement after 0.8 s, no memory / memory", "measured": round(ratio, 2),
         "thesis": "base static with memory, creeps without (Fig. 3.16)", "tolerance": "≥ 5",
         "pass": ratio >= 5.0},
        {"quantity": "base displacement without memory [mm]", "measured": round(1e3 * final["no memory"], 3),
         "thesis": "creeps", "tolerance": "> 1 mm", "pass": final["no memory"] > 1e-3},
        {"quantity": "base displacement with memory [mm]", "measured": round(1e3 * final["memory"], 4),
         "thesis": "static", "tolerance": "reported", "pass": None},
    ]
    # §3.3.3: 2 x 98939 / 12000 = 16.5 contacts per cross; Table B.1: 8.2 (pairs).
    zp, zc = s0["pair_coordination"], s0["contact_point_coordination"]
    checks += [
        {"quantity": "coordination, contact points per cross (gate opening)", "measured": round(zc, 3),
         "thesis": "16.5 (§3.3.3, 12000 crosses)", "tolerance": "±20 %", "pass": abs(zc / 16.5 - 1) <= 0.2},
        {"quantity": "coordination, touching neighbours per cross", "measured": round(zp, 3),
         "thesis": "8.2 (Table B.1)", "tolerance": "±20 %", "pass": abs(zp / 8.2 - 1) <= 0.2},
    ]
    # How much of the column is boundary: a cross against a wall, the floor or the gate
    # has the wall where it would have neighbours (the bulk of `sanguis analyze`, four
    # mean bounding radii in from every side, is empty in a column 3.9 cm long).
    wall_share = s0["particles_touching_obstacles_fraction"]
    zp_away = s0["pair_coordination_away_from_obstacles"]
    checks.append({"quantity": "crosses touching a wall, the floor or the gate; touching neighbours "
                   "per cross of the others (gate opening)",
                   "measured": f"{100 * wall_share:.0f} %; {zp_away:.3f}",
                   "thesis": "8.2 (Table B.1)", "tolerance": "reported", "pass": None})
    at_opening = diagnostics(pour)[-1]
    checks.append({"quantity": "sanity: mean speed at the opening [m/s]",
                   "measured": f"{at_opening['mean_velocity_m_s']:.2g}", "thesis": "—",
                   "tolerance": "< 1e-3", "pass": at_opening["mean_velocity_m_s"] < 1e-3})
    rows = []
    for name, d in runs.items():
        s = read_summary(d)
        rows.append([name, f"{100 * s['L0_m']:.1f}", f"{100 * s['H0_m']:.1f}", f"{100 * s['Linf_m']:.1f}",
                     f"{100 * s['Hinf_m']:.1f}", regime_name(s),
                     f"{1e3 * final[name]:.3g}"])

    os.makedirs(os.path.dirname(FIGURE), exist_ok=True)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 3.8))
    for name, c in creep.items():
        t = [r[0] for r in c]
        a1.semilogy(t, [max(r[1], 1e-9) * 1e3 for r in c], label=name)
        a2.plot(t, [r[2] * 100 for r in c], label=name)
    a1.set_xlabel("time after the gate opens [s]")
    a1.set_ylabel(f"mean displacement of {len(base)} base particles [mm]")
    a2.set_xlabel("time after the gate opens [s]")
    a2.set_ylabel("highest particle centre [cm]")
    a1.legend()
    a2.legend()
    fig.tight_layout()
    fig.savefig(FIGURE, dpi=130)

    ok = all(c["pass"] for c in checks if c["pass"] is not None)
    out = {
        "name": "crosses_memory",
        "title": "Crosses with and without contact memory",
        "thesis": "§3.4.2, Fig. 3.16",
        "description": (
            "300 crosses (Table 3.1) poured behind a gate (cases/dem/dam-break-crosses-memory.toml); "
            "the settled packing is continued twice from one checkpoint after the gate opens: "
            "with the tangential spring (memory) and without (memory = false). Base particles: "
            "back half of the column, lowest quarter, at the opening."),
        "command": "/usr/bin/python3 validation/dem/crosses_memory.py --build BUILD",
        "figures": ["docs/validation/figures/crosses_memory.png"],
        "checks": checks,
        "tables": [{"caption": "Both continuations (`sanguis analyze`).",
                    "header": ["run", "L0 [cm]", "H0 [cm]", "L∞ [cm]", "H∞ [cm]", "regime",
                               "base displacement [mm]"], "rows": rows}],
        "notes": [f"{len(base)} base particles",
                  # Measured 2026-11-25: the pour of the case continued to t = 4 s with
                  # the gate in place (diagnostics every 0.05 s), and this script's runs
                  # with the opening at 2.4 s (2026-11-22/24) and at 3.0 s.
                  "The gate opens at t = 3.0 s on a column at rest. Until 2026-11-25 it "
                  "opened at 2.4 s, when the pour's last crosses were still landing (mean "
                  "speed about 0.1 m/s at 2.3 s; at rest, below 1e-5 m/s, from about 2.6 s): "
                  "the heights and coordination taken then (H0 17.6-20.9 cm and 4.9-6.7 "
                  "touching neighbours per cross over seeds and builds) could be those of a "
                  "column still settling: the case's seed was (H0 20.9 cm, 4.94 neighbours, "
                  "and the memory check passed only just, 5.09), seeds 1-3 changed little "
                  "(crosses_tangential_packings). At "
                  "rest, with one contact point per element pair (run of 2026-12-02 12:03, "
                  "commit f4aaf9e), the case's seed gave H0 17.9 cm, 6.31 touching "
                  "neighbours and 8.03 contact points per cross, and the ratio 8.9. With the "
                  "contact patches of flat faces (docs/theory/dem.md, from 2026-12-02 "
                  "evening) it gave H0 17.8 cm, 6.23 touching neighbours and 8.03 contact "
                  "points per cross, and the ratio 11 (2026-12-02 18:07, commit 826b1db); "
                  "with their torsional spring spread over the patch (\"The torsional spring "
                  "until 2026-12-05 evening\"), pour and continuations rerun, "
                  f"H0 {100 * h0:.1f} cm, {zp:.2f} touching neighbours and "
                  f"{zc:.2f} contact points per cross, and the ratio {ratio:.2g}.",
                  "Coordination: this column of 300 crosses is 3.9 cm long, one and a half "
                  "cross lengths: many crosses touch the back wall, the gate, a side wall "
                  f"or the floor ({100 * wall_share:.0f} % at the opening), and a cross has "
                  "the wall where it would have neighbours; the crosses that touch none "
                  f"have {zp_away:.2f} touching neighbours, against {zp:.2f} for the whole "
                  "column and Table B.1's 8.2 (its columns are larger; crosses_dam_break: "
                  "7.55 for 7000 crosses). The 16.5 of §3.3.3 is 2 x 98939 / 12000; "
                  "98939 / 12000 = 8.24 matches Table B.1, so §3.3.3 may count every "
                  f"contact twice, and {zc:.2f} contact points per cross would then be "
                  f"{100 * abs(zc / 8.24 - 1):.0f} % from its 8.24. The checks keep the published "
                  "numbers on the whole column."],
        "run_time_s": round(elapsed, 1),
        "date": time.strftime("%Y-%m-%d %H:%M"),
        "quick": False,
        "pass": bool(ok),
    }
    with open(os.path.join(RESULTS, "crosses_memory.json"), "w") as f:
        json.dump(out, f, indent=1)
    print(f"{'PASS' if ok else 'FAIL'}: base displacement ratio {ratio:.3g} ({elapsed:.0f} s)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
