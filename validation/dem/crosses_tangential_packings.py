#!/usr/bin/python3
"""The Table 3.1 point of the tangential map on several packings (thesis §3.4.3, Fig. 3.17).

crosses_tangential_map classifies every (kt, gamma_t) on one settled 300-cross column,
the pour of the case's own seed; that pour can be an outlier (on 2026-11-24, when the
gate still opened at 2.4 s on a column settling, the seed-5 pour stood at H0 20.9 cm
and every point of the map collapsed). This case pours
the same column with seeds 1, 2 and 3 (cases/dem/dam-break-crosses-memory.toml to the
gate's opening, Table 3.1 parameters, one thread, two pours at a time) and continues
each with two tangential settings, classified as in crosses_tangential_map:
  the Table 3.1 point, kt = 3e2 N/m, gamma_t = 1e3 1/s (the thesis: region 2, a
  top-driven collapse, as in the experiments);
  both three times lower, kt = 1e2 N/m, gamma_t = 3e2 1/s (where the map of
  2026-11-23 found this model's substantial collapse).
Check: the Table 3.1 point is top-driven (region 2) on every packing. Reported: the
lower point's region and each packing's height and touching neighbours per cross.

Writes validation/dem/results/crosses_tangential_packings.json and
docs/validation/figures/crosses_tangential_packings.png.
Usage: /usr/bin/python3 validation/dem/crosses_tangential_packings.py [--build build]
       [--rerun-pours] [--reuse]
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

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _outputs import (pour_command, read_summary, span, two_at_a_time_span,  # noqa: E402
                      wall_time, write_summary)
from crosses_tangential_map import (CASE, GATE_TIME, RESULTS, ROOT,  # noqa: E402
                                    TABLE_31, classify, settings, sphere_reference)

RUNS = os.path.join(RESULTS, "runs", "crosses_tangential_packings")
FIGURE = os.path.join(ROOT, "docs", "validation", "figures", "crosses_tangential_packings.png")
SEEDS = [1, 2, 3]
LOWER = (1e2, 3e2)


def run_two_at_a_time(jobs):
    """Runs the (command, folder) jobs two at a time; stops on the first failure."""
    running = []
    while jobs or running:
        while jobs and len(running) < 2:
            cmd, d = jobs.pop(0)
            print(f"started {os.path.relpath(d, RUNS)}", flush=True)
            running.append((subprocess.Popen(cmd, stdout=subprocess.DEVNULL), d))
        proc, d = running.pop(0)
        if proc.wait() != 0:
            sys.exit(f"run failed: {d}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--rerun-pours", action="store_true")
    ap.add_argument("--quick", action="store_true", help="same as the full run")
    ap.add_argument("--reuse", action="store_true", help="classify the runs on disk")
    args = ap.parse_args()
    exe = os.path.join(ROOT, args.build, "app", "sanguis")
    t0 = time.time()
    pours = {seed: os.path.join(RUNS, f"pour_seed_{seed}") for seed in SEEDS}
    reused = []  # wall times of pours kept from an earlier call: they count in the run time
    jobs = []
    for seed, d in pours.items():
        if args.reuse:
            continue
        cmd = pour_command([exe, "run", CASE, "--output", d, "--quiet", "--threads", "1",
                            "--seed", str(seed)], d, GATE_TIME, args.rerun_pours)
        if cmd:
            jobs.append((cmd, d))
        else:
            reused.append(wall_time(d))
    run_two_at_a_time(jobs)
    packing = {}
    for seed, d in pours.items():
        subprocess.run([exe, "analyze", d], check=True, stdout=subprocess.DEVNULL)
        packing[seed] = read_summary(d)

    jobs = []
    points = [TABLE_31, LOWER]
    for seed, pour in pours.items():
        for kt, g in points:
            d = os.path.join(RUNS, f"seed_{seed}_kt_{kt:g}_gamma_{g:g}")
            if args.reuse:
                continue
            shutil.rmtree(d, ignore_errors=True)
            shutil.copytree(pour, d)
            jobs.append(([exe, "run", CASE, "--output", d, "--restart", "--quiet", "--threads",
                          "1"] + settings(kt, g), d))
    run_two_at_a_time(jobs)
    base_reference = sphere_reference(exe)["bottom_move_mm"]
    results = {}
    for seed in SEEDS:
        for kt, g in points:
            d = os.path.join(RUNS, f"seed_{seed}_kt_{kt:g}_gamma_{g:g}")
            subprocess.run([exe, "analyze", d], check=True, stdout=subprocess.DEVNULL)
            results[(seed, kt, g)] = classify(d, base_reference)
    elapsed = time.time() - t0 + two_at_a_time_span(reused)
    previous = os.path.join(RESULTS, "crosses_tangential_packings.json")
    if args.reuse and os.path.exists(previous):  # keep the time the runs took
        with open(previous) as f:
            elapsed = json.load(f).get("run_time_s", elapsed)

    os.makedirs(os.path.dirname(FIGURE), exist_ok=True)
    fig, ax = plt.subplots(figsize=(6.0, 3.8))
    width = 0.38
    for k, ((kt, g), colour) in enumerate(zip(points, ["tab:blue", "tab:green"])):
        losses = [results[(seed, kt, g)]["height_loss"] for seed in SEEDS]
        ax.bar([i + (k - 0.5) * width for i in range(len(SEEDS))], losses, width, color=colour,
               label=f"kt {kt:g} N/m, γt {g:g} 1/s" + (" (Table 3.1)" if (kt, g) == TABLE_31
                                                       else ""))
    ax.axhline(0.05, color="k", lw=0.8, ls=":", label="5 %: below it, region 3 (stable)")
    ax.set_xticks(range(len(SEEDS)), [f"seed {seed}" for seed in SEEDS])
    ax.set_ylabel("height lost / $H_0$ within 0.5 s")
    ax.set_title("300 crosses, three pours (thesis: Table 3.1 is top-driven, region 2)",
                 fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(FIGURE, dpi=130)

    max_collapse_base = max((r["bottom_move_mm"] for r in results.values() if r["region"] != 3),
                            default=0.0)
    table31 = [results[(seed, *TABLE_31)]["region"] for seed in SEEDS]
    lower = [results[(seed, *LOWER)]["region"] for seed in SEEDS]
    checks = [
        {"quantity": "Table 3.1 point (kt 3e2, γt 1e3): region on the packings of seeds 1, 2, 3",
         "measured": ", ".join(map(str, table31)),
         "thesis": "region 2 (top-driven, as the experiments)", "tolerance": "2 on every packing",
         "pass": all(r == 2 for r in table31)},
        {"quantity": "kt 1e2, γt 3e2: region on the same packings", "measured":
         ", ".join(map(str, lower)), "thesis": "—", "tolerance": "reported", "pass": None},
    ]
    rows = []
    for seed in SEEDS:
        p = packing[seed]
        for kt, g in points:
            r = results[(seed, kt, g)]
            rows.append([seed, f"{100 * p['H0_m']:.1f}", f"{p['pair_coordination']:.2f}",
                         f"{kt:g}", f"{g:g}", r["region"], r["regime"], f"{r['top_move_mm']:.2f}",
                         f"{r['bottom_move_mm']:.2f}", f"{r['height_loss']:.3f}",
                         f"{r['runout_ratio']:.2f}"])
    ok = all(c["pass"] for c in checks if c["pass"] is not None)
    summary = {
        "name": "crosses_tangential_packings",
        "title": "Cross column: the Table 3.1 point on three packings",
        "thesis": "§3.4.3, Fig. 3.17",
        "description": (
            "The 300-cross column of the memory case poured with seeds 1, 2 and 3 and "
            "continued from the gate's opening with the Table 3.1 tangential parameters and "
            "with both three times lower (both interactions); regions as in "
            "crosses_tangential_map (3 stable: the highest particle lost less than 5 % of H0)."),
        "command": "/usr/bin/python3 validation/dem/crosses_tangential_packings.py --build BUILD",
        "figures": ["docs/validation/figures/crosses_tangential_packings.png"],
        "checks": checks,
        "tables": [{"caption": "Per run (packing at the opening: H0 and touching neighbours "
                               "per cross).",
                    "header": ["seed", "H0 [cm]", "neighbours", "kt [N/m]", "γt [1/s]",
                               "region", "regime", "top moved [mm]", "bottom moved [mm]",
                               "height loss / H0", "(L∞−L0)/L0"],
                    "rows": rows}],
        "notes": ["Why this case: crosses_tangential_map uses one pour, and its reading changes "
                  "with that pour (see its notes). Here three other pours of the same case "
                  "decide the Table 3.1 point.",
                  # The runs of 2026-11-24 (pours to 2.4 s), quoted from this file's JSON then.
                  "Since 2026-11-25 the pours run to the gate's opening at t = 3.0 s, when the "
                  "column is at rest (before: 2.4 s, with the case's own seed still "
                  "settling). For these three seeds it changed little: with the opening at "
                  "2.4 s they stood at H0 17.8-18.2 cm with 6.35-6.66 neighbours, the Table "
                  "3.1 point lost 1.7-3.8 % (region 3) and the lower point 27-55 % (region 2); "
                  "opened at 3.0 s, with one contact point per element pair (2026-11-25), "
                  "17.8-18.1 cm, 6.35-6.65, 1.2-3.1 % and 35-59 %. On the case's own seed, "
                  "settled, the Table 3.1 point collapsed then (23 %, crosses_tangential_map): "
                  "the point sat on the border of regions 2 and 3.",
                  "With the contact patches of flat faces (docs/theory/dem.md, from "
                  "2026-12-02 evening) the pours stand at H0 "
                  f"{span([100 * packing[s]['H0_m'] for s in SEEDS], '.1f')} cm with "
                  f"{span([packing[s]['pair_coordination'] for s in SEEDS], '.2f')} "
                  "neighbours per cross; the Table 3.1 point loses "
                  f"{span([100 * results[(s, *TABLE_31)]['height_loss'] for s in SEEDS], '.1f')} "
                  "% of H0 and the lower point "
                  f"{span([100 * results[(s, *LOWER)]['height_loss'] for s in SEEDS], '.0f')} %.",
                  # The collapses of 2026-12-05 23:16-23:26 UTC; the pours are older.
                  "The collapses were rerun on 2026-12-05 evening with the torsional spring "
                  "of the patches spread over them (docs/theory/dem.md, \"The torsional spring "
                  "until 2026-12-05 evening\"), from the pours made before (their twist "
                  "moments start at zero at the opening). With the corners' spring the Table "
                  "3.1 point lost 1.0-4.4 % of H0 and the lower point 26-61 %, the same "
                  "regions. With the spread spring, on those pours (AMD EPYC VM), the Table "
                  "3.1 point lost 1.1-3.4 % on every pour (region 3) and the lower point "
                  "26-55 % (region 2).",
                  "Rerun on 2026-12-06 on an Intel Xeon VM, pours included: a build for "
                  "another processor rounds otherwise (-march=native), so the same seeds give "
                  "other packings. On them the Table 3.1 point collapses top-driven on "
                  f"{table31.count(2)} pour(s) of {len(table31)}. With the contact patches it "
                  "stood on the three earlier pours (2026-12-05) and on the pours of "
                  "crosses_tangential_map (2026-12-02 and 12-06), so it sits on the border of "
                  "regions 2 and 3, on the standing side more often than not. "
                  "Regions since 2026-12-06 by the rule of crosses_tangential_map that "
                  "measures the base against a column of spheres: the collapses here move "
                  f"their base at most {max_collapse_base:.1f} mm in one τc, against the "
                  f"spheres' {base_reference:.1f} mm."],
    }
    write_summary(summary, RESULTS, elapsed, args.quick, ok)
    print(f"{'PASS' if ok else 'FAIL'}: Table 3.1 regions {table31}, lower point {lower}, "
          f"{elapsed:.0f} s")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
