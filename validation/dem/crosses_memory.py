#!/usr/bin/python3
"""Dam break of crosses with and without contact memory (thesis §3.4.2, Fig. 3.16).

cases/dem/dam-break-crosses-memory.toml pours 300 crosses (Table 3.1) behind a gate
and lets them settle until the gate is removed at t = 2.4 s. The pour runs once; its
final checkpoint is copied twice and continued for 0.8 s: as is (tangential memory,
eq. 2.6) and with memory = false on both interactions (dashpot with Coulomb limit:
no tangential spring). The same initial microstructure, as in the thesis.

The thesis' observation: without memory "the granular column slowly deforms and
overpacks at the bottom of the pile, while it should remain static in that region";
with memory the base stays and particles fall off the top.
Checks (fixed before running): the particles of the back half of the base (x < L0/2,
z < H0/4 at the gate opening) move on average at least 5 times less with memory than
without after 0.8 s; without memory they move more than 1 mm (they creep).
Also: the coordination number at the opening against §3.3.3 (16.5 contact points
per cross) and Table B.1 (8.2 neighbours), each within 20 %; H_inf, L_inf and the
regime of both runs (`sanguis analyze`).

Writes validation/dem/results/crosses_memory.json and
docs/validation/figures/crosses_memory.png. Run time: pour ~5-10 min, then the two
continuations side by side ~5-10 min (2 cores).
Usage: /usr/bin/python3 validation/dem/crosses_memory.py [--build build] [--rerun-pour]
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _outputs import read_arrays, read_pvd, read_summary, regime_name, wall_time  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CASE = os.path.join(ROOT, "cases", "dem", "dam-break-crosses-memory.toml")
RESULTS = os.path.join(ROOT, "validation", "dem", "results")
RUNS = os.path.join(RESULTS, "runs", "crosses_memory")
FIGURE = os.path.join(ROOT, "docs", "validation", "figures", "crosses_memory.png")
GATE_TIME = 2.4
END_TIME = 3.2
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
    t0 = time.time()
    pour = os.path.join(RUNS, "pour")
    reused_pour_s = 0.0  # a pour kept from an earlier call still counts in the run time
    if args.rerun_pour or not os.path.exists(os.path.join(pour, "checkpoint.bin")):
        subprocess.run([exe, "run", CASE, "--output", pour, "--quiet", "--threads", "1",
                        "--set", f"simulation.end_time_s={GATE_TIME}"], check=True)
    else:
        reused_pour_s = wall_time(pour)
    runs = {"memory": os.path.join(RUNS, "memory"), "no memory": os.path.join(RUNS, "no_memory")}
    procs = []
    for name, d in runs.items():
        shutil.rmtree(d, ignore_errors=True)
        shutil.copytree(pour, d)
        cmd = [exe, "run", CASE, "--output", d, "--restart", "--quiet", "--threads", "1"]
        procs.append(subprocess.Popen(cmd + (NO_MEMORY if name == "no memory" else []),
                                      stdout=subprocess.DEVNULL))
    for p in procs:
        if p.wait() != 0:
            sys.exit("a continuation failed")
    for d in runs.values():
        subprocess.run([exe, "analyze", d, "--plot"], check=True, stdout=subprocess.DEVNULL)
    elapsed = time.time() - t0 + reused_pour_s

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
                  # Measured 2026-11-24 with pours of the same case to t = 2.4 s (`--seed`,
                  # `--set simulation.storage_sort_steps=0`), analysed at their last frame.
                  "The packing depends on the pour's realisation, and this one is loose: the "
                  "run of 2026-11-24 (seed 5, the case's, current build) settled to H0 = 20.9 cm "
                  "with 4.94 touching neighbours per cross; seeds 1-3 of the same build settle "
                  "to 17.6-18.2 cm and 6.2-6.7 (with the storage sort or without, no systematic "
                  "difference), seed 5 without the sort to 18.0 cm and 5.37, and the run of "
                  "2026-11-22 (an earlier build) to 17.9 cm and 6.18. On this loose packing the "
                  "column collapses with memory too (L∞ 25.7 cm, where the 2026-11-22 packing "
                  "stood: 7.5 cm), but its base still holds: the memory check passes (5.09, "
                  "6.15 before), only just. A single 300-cross column decides neither check; "
                  "several packings per setting would (not run here)."],
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
