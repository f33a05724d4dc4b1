#!/usr/bin/python3
"""Repose angle against friction, and `sanguis calibrate` recovering mu_c (issue #4).

cases/dem/heap-repose.toml pours 2000 glass beads (R = 1.5 mm, §2.4 procedure,
en = 0.45, et = 0.3, mu_r = 0.1) through a 16 mm opening onto a rough floor; the
conical heap's angle is `repose_angle_deg` of `sanguis analyze` (surface envelope
around the apex fitted between 20 % and 80 % of the height).

1. "Truth": two runs (seeds 100, 101) with mu_c = TRUE_MU give the target angle and
   its spread.
2. `sanguis calibrate` sweeps mu_c over VALUES with two seeds each (in parallel),
   fits the angle around the target and reports mu_c with its uncertainty.

Checks: the estimate is within 2 sigma of TRUE_MU and sigma < 0.1 (the fit is
informative); the angle grows with mu_c (thesis Fig. 2.7 trend: grows, then
saturates); the angle at mu_c = 0.5 is reported next to the thesis' ~36 degrees
(hopper heap of 1 mm beads, mu_r 0.45 on walls: a different set-up, not graded).

Writes validation/dem/results/calibrate_friction.json, docs/validation/figures/
calibrate_friction.png. Run time: 12 runs of ~40 s on one core each, two at a time.

Usage: /usr/bin/python3 validation/dem/calibrate_friction.py [--build build] [--quick]
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import time

import matplotlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _outputs import calibration_value_folder, read_summary  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CASE = os.path.join(ROOT, "cases", "dem", "heap-repose.toml")
RESULTS = os.path.join(ROOT, "validation", "dem", "results")
RUNS = os.path.join(RESULTS, "runs", "calibrate_friction")
FIGURE = os.path.join(ROOT, "docs", "validation", "figures", "calibrate_friction.png")
TRUE_MU = 0.1
VALUES = [0.05, 0.1, 0.15, 0.3, 0.5]
QUICK_VALUES = [0.05, 0.15]
PARAMETER = "interaction[0].friction"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--quick", action="store_true", help="two values, for a smoke test")
    args = ap.parse_args()
    exe = os.path.join(ROOT, args.build, "app", "sanguis")
    values = QUICK_VALUES if args.quick else VALUES
    t0 = time.time()

    truth = []
    for seed in (100, 101):
        out = os.path.join(RUNS, f"truth_seed_{seed}")
        subprocess.run([exe, "run", CASE, "--output", out, "--quiet", "--threads", "1",
                        "--seed", str(seed), "--set", f"{PARAMETER}={TRUE_MU}"],
                       check=True, stdout=subprocess.DEVNULL)
        subprocess.run([exe, "analyze", out], check=True, stdout=subprocess.DEVNULL)
        truth.append(read_summary(out)["repose_angle_deg"])
    target = sum(truth) / len(truth)
    target_std = abs(truth[0] - truth[1]) / 2.0  # std of the mean of two
    print(f"target: repose angle {target:.2f} +- {target_std:.2f} deg at mu_c = {TRUE_MU}")

    calib = os.path.join(RUNS, "calibrate")
    subprocess.run([exe, "calibrate", CASE, "--parameter", PARAMETER,
                    "--values", ",".join(str(v) for v in values), "--measure", "repose_angle_deg",
                    "--target", f"{target:.10g}", "--target-std", f"{target_std:.10g}",
                    "--seeds", "2", "--jobs", "2", "--output", calib], check=True)
    with open(os.path.join(calib, "calibration_result.csv"), newline="") as f:
        result = {k: v for k, v in next(csv.DictReader(f)).items()}
    estimate, sigma = float(result["estimate"]), float(result["estimate_std"])
    sweep = []
    with open(os.path.join(calib, "calibration.csv"), newline="") as f:
        for r in csv.DictReader(f):
            sweep.append((float(r["value"]), float(r["repose_angle_deg_mean"]),
                          float(r["repose_angle_deg_std"])))
    seeds = {}
    for v in values:
        for seed in (1, 2):
            d = os.path.join(calibration_value_folder(calib, v), f"seed_{seed}")
            seeds.setdefault(v, []).append(read_summary(d)["repose_angle_deg"])
    elapsed = time.time() - t0

    checks = []

    def check(quantity, measured, reference, tolerance, ok):
        checks.append({"quantity": quantity, "measured": measured, "thesis": reference,
                       "tolerance": tolerance, "pass": ok})

    check("recovered mu_c", f"{estimate:.3f} ± {sigma:.3f}", f"{TRUE_MU} (known)", "within 2 σ",
          abs(estimate - TRUE_MU) <= 2 * sigma)
    check("uncertainty of mu_c", round(sigma, 4), "—", "< 0.1", sigma < 0.1)
    means = [m for _, m, _ in sweep]
    check("repose angle grows with mu_c", f"{means[0]:.1f}° → {max(means):.1f}°",
          "grows then saturates (Fig. 2.7)", "last-first > 5°", max(means) - means[0] > 5.0)
    at_half = [m for v, m, _ in sweep if abs(v - 0.5) < 1e-9]
    if at_half:
        check("repose angle at mu_c = 0.5", f"{at_half[0]:.1f}°", "≈ 36° (hopper heap)",
              "not graded", None)

    os.makedirs(os.path.dirname(FIGURE), exist_ok=True)
    fig, ax = plt.subplots(figsize=(6, 4))
    for v, angles in seeds.items():
        ax.plot([v] * len(angles), angles, "o", color="0.6", ms=4)
    ax.errorbar([v for v, _, _ in sweep], means, yerr=[s for _, _, s in sweep], fmt="k-s",
                capsize=3, label="sanguis, mean ± std of 2 seeds")
    ax.axhline(target, color="tab:blue", ls="--", label=f"target {target:.1f}° (mu_c = {TRUE_MU})")
    ax.axvspan(estimate - sigma, estimate + sigma, color="tab:red", alpha=0.2)
    ax.axvline(estimate, color="tab:red", label=f"calibrated mu_c = {estimate:.3f} ± {sigma:.3f}")
    ax.plot([0.5], [36.0], "r*", ms=12, label="thesis Fig. 2.7 at 0.5 (hopper)")
    ax.set_xlabel(r"friction coefficient $\mu_c$")
    ax.set_ylabel("repose angle [deg]")
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    fig.savefig(FIGURE, dpi=130)

    ok = all(c["pass"] for c in checks if c["pass"] is not None)
    summary = {
        "name": "calibrate_friction",
        "title": "Repose angle vs friction and calibration of mu_c",
        "thesis": "§2.6.3, Fig. 2.7; §3.4.3 (calibration)",
        "description": (
            "2000 glass beads (R = 1.5 mm) poured onto a rough floor (cases/dem/heap-repose.toml); "
            "repose angle from `sanguis analyze`. Two runs with a known mu_c give a target angle; "
            "`sanguis calibrate` sweeps mu_c (two seeds per value, in parallel), fits the angle "
            "near the target by weighted least squares and propagates the scatter into an "
            "uncertainty on mu_c."),
        "command": "/usr/bin/python3 validation/dem/calibrate_friction.py --build BUILD"
                   + (" --quick" if args.quick else ""),
        "figures": ["docs/validation/figures/calibrate_friction.png"],
        "checks": checks,
        "tables": [{"caption": "Repose angle per mu_c (seeds 1 and 2).",
                    "header": ["mu_c", "mean [deg]", "std [deg]", "runs [deg]"],
                    "rows": [[v, f"{m:.2f}", f"{s:.2f}",
                              ", ".join(f"{a:.1f}" for a in seeds[v])] for v, m, s in sweep]}],
        "notes": [f"target from seeds 100 and 101: {truth[0]:.2f}° and {truth[1]:.2f}°"],
        "run_time_s": round(elapsed, 1),
        "date": time.strftime("%Y-%m-%d %H:%M"),
        "quick": bool(args.quick),
        "pass": bool(ok),
    }
    os.makedirs(RESULTS, exist_ok=True)
    with open(os.path.join(RESULTS, "calibrate_friction.json"), "w") as f:
        json.dump(summary, f, indent=1)
    print(f"{'PASS' if ok else 'FAIL'}: mu_c = {estimate:.3f} +- {sigma:.3f} (true {TRUE_MU}), "
          f"{elapsed:.0f} s")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
