#!/usr/bin/python3
"""The 4 cm dam break of crosses with the tangential parameters recalibrated (thesis
§3.4.3 calibrated kt and gamma_t by trial and error; issue #4).

crosses_tangential_map, run on 2026-11-23 from a dense 300-cross packing, found the
Table 3.1 point (kt 3e2 N/m, gamma_t 1e3 1/s) on this model's boundary between a slow,
partial top-driven collapse and a standing column, and a substantial collapse only with
both about 3x lower (kt 1e2, gamma_t 3e2); from the looser packing of its run of
2026-11-24 every point collapses (see its notes), while on the pours of seeds 1-3
(crosses_tangential_packings) the Table 3.1 point stays and the point 3x lower collapses,
as on 2026-11-23: the premise holds on typical packings. This case
pours the 1300 crosses of cases/dem/dam-break-crosses.toml (4 cm gate, Table 3.1) once,
then follows the 3 s collapse twice from the same packing: with Table 3.1 and with
kt = 1e2 N/m, gamma_t = 3e2 1/s (both interactions).

Check (the tolerance of crosses_dam_break): the recalibrated run-out within 35 % of the
thesis' reference for a >= 4, the spheres of Lajeunesse et al. (2005), 1.9 a^(2/3); the
Table 3.1 continuation is reported next to it, and the mean speed against t / tau_c of
both is drawn with the thesis' Fig. 3.9 bands.

Then `sanguis calibrate` fits gamma_t at kt = 1e2 N/m (both interactions) to that
reference run-out from the same packing (runs stop once the pile is at rest, mean
speed below 1 mm/s after 1.5 s), and one more run at the fitted gamma_t checks it;
where the run-out turns before it reaches the target (a minimum above it), the
calibration reports its nearest run instead and no run is added.

Writes validation/dem/results/crosses_recalibrated.json and
docs/validation/figures/crosses_recalibrated.png. `--reuse`: analyse the runs on disk.
A call stopped on the way (the case takes hours) keeps its work: called again, it goes
on from the checkpoints its unfinished runs left, to the bits of one uninterrupted call.
Usage: /usr/bin/python3 validation/dem/crosses_recalibrated.py [--build build]
           [--threads T] [--reuse]
"""
import argparse
import csv
import os
import subprocess
import sys
import time

import matplotlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _outputs import (calibration_value_folder, continuation_command, read_summary,  # noqa: E402
                      regime_name, run_pour, uncounted_spans, wall_time, write_summary)
from crosses_dam_break import (CASE, RESULTS, ROOT, diagnostics,  # noqa: E402
                               draw_velocity_bands, lajeunesse, opening_time, velocity_curve)
from crosses_tangential_map import tangential_settings  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

RUNS = os.path.join(RESULTS, "runs", "crosses_calibration")
FIGURE = os.path.join(ROOT, "docs", "validation", "figures", "crosses_recalibrated.png")
OPENING_S = 5.0  # the case's gate removal; the pour is in and at rest by then
# run folder -> (label, kt [N/m], gamma_t [1/s]); None: the case's Table 3.1 values
RUNS_OF = {"table31": ("Table 3.1 (kt 3e2, γt 1e3)", None, None),
           "kt100_g300": ("recalibrated (kt 1e2, γt 3e2)", 1e2, 3e2)}
RECALIBRATED = "kt100_g300"
# The calibration: gamma_t at kt = 1e2 N/m against the reference run-out.
CALIBRATION = os.path.join(RUNS, "gamma_t")
CALIBRATED = os.path.join(RUNS, "calibrated")
CALIBRATION_KT = 1e2
CALIBRATION_VALUES = [1e3, 1.4e3, 2e3, 3e3]
# A collapsed pile is at rest well within 1.5 s (about 10 tau_c); stopping there
# saves half of each 3 s run.
AT_REST = ["--set", "stop.mean_velocity_below_m_s=1e-3",
           "--set", f"stop.check_after_s={OPENING_S + 1.5}"]


def calibrate(exe, target):
    """`sanguis calibrate` of gamma_t (kt fixed) against the run-out `target`; runs
    already done with the same command are reused. Returns (table rows, result)."""
    keys = ",".join(f"interaction[{i}].tangential_damping_rate_1_s" for i in (0, 1))
    fixed = []
    for i in (0, 1):
        fixed += ["--set", f"interaction[{i}].tangential_stiffness_N_m={CALIBRATION_KT:.0e}"
                  .replace("e+0", "e")]  # "1e2": the text the runs were recorded with
    # The case by its path from the repository root, as the runs record it (--reuse).
    subprocess.run([exe, "calibrate", os.path.relpath(CASE, ROOT), "--from",
                    os.path.join(RUNS, "pour"),
                    "--parameter", keys, "--values", ",".join(f"{v:g}" for v in CALIBRATION_VALUES),
                    "--measure", "runout_ratio", "--target", f"{target:.6g}",
                    "--jobs", str(len(CALIBRATION_VALUES)), "--reuse", "-o", CALIBRATION]
                   + fixed + AT_REST, check=True, cwd=ROOT)
    return read_csv(os.path.join(CALIBRATION, "calibration.csv")), \
        read_csv(os.path.join(CALIBRATION, "calibration_result.csv"))[0]


def value_folder(value):
    return calibration_value_folder(CALIBRATION, value)


def read_csv(path):
    with open(path, newline="") as f:
        return [{k: (float(v) if k not in ("parameter", "measure") else v) for k, v in r.items()}
                for r in csv.DictReader(f)]


def run_row(label, s, wall_s):
    """One row of the per-run table from a run's summary."""
    a = s["aspect_ratio_H0_over_L0"]
    return [label, f"{100 * s['L0_m']:.1f}", f"{100 * s['H0_m']:.1f}", f"{a:.2f}",
            f"{s['runout_ratio']:.2f}", f"{lajeunesse(a):.2f}",
            f"{s['height_ratio_H0_over_Hinf']:.2f}", f"{s['peak_mean_speed_over_sqrt_gH0']:.3f}",
            f"{s['peak_time_over_tau_c']:.1f}", regime_name(s),
            f"{wall_s / 3600:.2f}"]


def run_calibrated(exe, gamma):
    """The collapse from the packing at the fitted gamma_t (kt = CALIBRATION_KT); one
    stopped on the way goes on from its checkpoint."""
    cmd = continuation_command(
        [exe, "run", CASE, "--output", CALIBRATED, "--restart", "--quiet", "--threads", "2"]
        + tangential_settings(CALIBRATION_KT, gamma) + AT_REST, CALIBRATED,
        os.path.join(RUNS, "pour"), OPENING_S)
    if cmd:
        subprocess.run(cmd, check=True)
    with open(os.path.join(CALIBRATED, "gamma_t.txt"), "w") as f:
        f.write(f"{gamma:g}\n")


def run_all(exe, threads):
    pour = os.path.join(RUNS, "pour")
    run_pour([exe, "run", CASE, "--output", pour, "--quiet", "--threads", str(threads)], pour,
             OPENING_S)
    running = []
    for name, (_, kt, gamma) in RUNS_OF.items():
        out = os.path.join(RUNS, name)
        extra = [] if kt is None else tangential_settings(kt, gamma)
        cmd = continuation_command([exe, "run", CASE, "--output", out, "--restart", "--quiet",
                                    "--threads", "1"] + extra, out, pour, OPENING_S)
        if cmd:  # a continuation stopped on the way goes on from its checkpoint
            running.append(subprocess.Popen(cmd))  # one core each
    for proc in running:
        if proc.wait() != 0:
            sys.exit("a continuation failed")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--threads", type=int, default=2, help="threads of the pour")
    ap.add_argument("--reuse", action="store_true", help="analyse the runs already on disk")
    ap.add_argument("--quick", action="store_true", help="same as the default")
    args = ap.parse_args()
    exe = os.path.join(ROOT, args.build, "app", "sanguis")
    t0 = time.time()
    if not args.reuse:
        run_all(exe, args.threads)
    results = {}
    for name in RUNS_OF:
        out = os.path.join(RUNS, name)
        subprocess.run([exe, "analyze", out], check=True, stdout=subprocess.DEVNULL)
        results[name] = read_summary(out)

    rec = results[RECALIBRATED]
    a = rec["aspect_ratio_H0_over_L0"]
    ref = lajeunesse(a)
    table, fit = calibrate(exe, ref)
    turns = fit.get("turns", 0.0) == 1.0
    extrapolated = None  # (gamma, summary) of a run at a line's extrapolation past the turn
    if turns:
        # The run-out turns before the target: the calibration's own run nearest it is
        # the answer (a line through a turn means nothing); no run of its own.
        gamma = fit["estimate"]
        cal_dir = os.path.join(value_folder(gamma), "seed_1")
        done = os.path.join(CALIBRATED, "gamma_t.txt")
        if os.path.exists(done):
            subprocess.run([exe, "analyze", CALIBRATED], check=True, stdout=subprocess.DEVNULL)
            extrapolated = (float(open(done).read()), read_summary(CALIBRATED))
    else:
        gamma = float(f"{fit['estimate']:.3g}")
        run_calibrated(exe, gamma)
        cal_dir = CALIBRATED
    subprocess.run([exe, "analyze", cal_dir], check=True, stdout=subprocess.DEVNULL)
    cal = read_summary(cal_dir)
    what = "nearest the target over the calibration" if turns else "at the calibrated"
    cal_label = f"{'nearest' if turns else 'calibrated'} (kt 1e2, γt {gamma:g})"
    checks = [{"quantity": f"(L∞−L0)/L0 {what} γt = {gamma:g} 1/s (kt 1e2), "
                           f"a = {cal['aspect_ratio_H0_over_L0']:.2f}",
               "measured": round(cal["runout_ratio"], 3),
               "thesis": f"{ref:.2f} (Lajeunesse, a ≳ 4, §3.3)", "tolerance": "±35 %",
               "pass": abs(cal["runout_ratio"] / ref - 1) <= 0.35},
              {"quantity": "calibration of γt at kt 1e2: target bracketed by the runs",
               "measured": (f"no crossing: nearest {cal['runout_ratio']:.2f} at γt {gamma:g}, "
                            "moving away on both sides" if turns else
                            f"γt = {fit['estimate']:.3g} ± {fit['estimate_std']:.2g} 1/s"),
               "thesis": "kt 3e2, γt 1e3 (Table 3.1, Grains3D)", "tolerance": "bracketed",
               "pass": fit["bracketed"] == 1.0},
              {"quantity": f"(L∞−L0)/L0, kt 1e2, γt 3e2, a = {a:.2f}",
               "measured": round(rec["runout_ratio"], 3),
               "thesis": f"{ref:.2f}", "tolerance": "reported", "pass": None}]
    base = results["table31"]
    checks.append({"quantity": f"(L∞−L0)/L0, Table 3.1, same packing, a = "
                               f"{base['aspect_ratio_H0_over_L0']:.2f}",
                   "measured": round(base["runout_ratio"], 3),
                   "thesis": f"{lajeunesse(base['aspect_ratio_H0_over_L0']):.2f}",
                   "tolerance": "reported", "pass": None})
    pour = os.path.join(RUNS, "pour")
    before = diagnostics(pour)[-1]
    checks.append({"quantity": "sanity: mean speed at the opening [m/s]",
                   "measured": f"{before['mean_velocity_m_s']:.2g}", "thesis": "—",
                   "tolerance": "< 1e-3", "pass": before["mean_velocity_m_s"] < 1e-3})
    rows = []
    for name, (label, _, _) in RUNS_OF.items():
        out = os.path.join(RUNS, name)
        rows.append(run_row(label, results[name], wall_time(out, opening_time(out))))
    rows.append(run_row(cal_label, cal, wall_time(cal_dir, OPENING_S)))
    if extrapolated:
        rows.append(run_row(f"kt 1e2, γt {extrapolated[0]:g} (a line extrapolated past the turn)",
                            extrapolated[1], wall_time(CALIBRATED, OPENING_S)))
    cal_rows = [[f"{r['value']:g}", f"{r['runout_ratio_mean']:.2f}"] for r in table]
    closest = min(table, key=lambda r: abs(r["runout_ratio_mean"] - ref)) if table else None

    os.makedirs(os.path.dirname(FIGURE), exist_ok=True)
    fig, (a1, a2, a3) = plt.subplots(1, 3, figsize=(15, 4.2))
    a_line = [0.3 * 1.05 ** k for k in range(70)]
    a1.loglog(a_line, [lajeunesse(x) for x in a_line], "k--", label="Lajeunesse et al. (spheres)")
    for name, (label, _, _) in RUNS_OF.items():
        s = results[name]
        l0, r = s["L0_m"], s["runout_ratio"]
        lo, hi = (s["Linf_20pc_m"] - l0) / l0, (s["Linf_1pc_m"] - l0) / l0
        a1.errorbar([s["aspect_ratio_H0_over_L0"]], [r],
                    yerr=[[max(0.0, r - lo)], [max(0.0, hi - r)]], fmt="o", capsize=3, label=label)
        t, v = velocity_curve(os.path.join(RUNS, name))
        a2.plot(t, v, label=label)
    a1.plot([cal["aspect_ratio_H0_over_L0"]], [cal["runout_ratio"]], "s", label=cal_label)
    t, v = velocity_curve(cal_dir)
    a2.plot(t, v, label=cal_label)
    # The calibration: run-out against gamma_t at kt = 1e2.
    a3.axhspan(0.65 * ref, 1.35 * ref, color="0.9", label="Lajeunesse ±35 %")
    a3.axhline(ref, color="k", ls="--", lw=0.8)
    a3.semilogx([r["value"] for r in table], [r["runout_ratio_mean"] for r in table], "o-",
                label="sanguis calibrate runs")
    a3.semilogx([3e2], [rec["runout_ratio"]], "^", label="kt 1e2, γt 3e2 (3 s run)")
    if turns:
        a3.plot([gamma], [cal["runout_ratio"]], "s", mfc="none", ms=10,
                label=f"nearest the target: γt {gamma:g}")
        if extrapolated:
            a3.semilogx([extrapolated[0]], [extrapolated[1]["runout_ratio"]], "x", ms=8,
                        label=f"γt {extrapolated[0]:g}: a line extrapolated past the turn")
    else:
        a3.errorbar([gamma], [cal["runout_ratio"]],
                    xerr=[[fit["estimate_std"]], [fit["estimate_std"]]], fmt="s", capsize=3,
                    label=f"fit {fit['estimate']:.3g} ± {fit['estimate_std']:.2g}: run")
    a3.set_xlabel(r"$\gamma_t$ [1/s] (kt = 1e2 N/m)")
    a3.set_ylabel(r"$(L_\infty - L_0)/L_0$")
    a3.legend(fontsize=8)
    a1.set_xlabel(r"$a = H_0/L_0$")
    a1.set_ylabel(r"$(L_\infty - L_0)/L_0$")
    a1.legend(fontsize=8)
    draw_velocity_bands(a2)
    fig.tight_layout()
    fig.savefig(FIGURE, dpi=130)

    elapsed = time.time() - t0
    if args.reuse:
        # the two continuations ran side by side, one thread each: count the longer
        elapsed = wall_time(pour) + max(wall_time(os.path.join(RUNS, n), OPENING_S)
                                        for n in RUNS_OF)
        if not turns or extrapolated:
            elapsed += wall_time(CALIBRATED, OPENING_S)
        # the runs of the calibration ran side by side: count the longest
        elapsed += max(wall_time(os.path.join(value_folder(r["value"]), "seed_1"),
                                 OPENING_S) for r in table)
    ok = all(c["pass"] for c in checks if c["pass"] is not None)
    uncounted = [f"{name} {a:g}-{b:g} s" for name in ["pour", *RUNS_OF, "calibrated"]
                 for a, b in uncounted_spans(os.path.join(RUNS, name))]
    summary = {
        "name": "crosses_recalibrated",
        "title": "Dam break of crosses with kt and γt recalibrated",
        "thesis": "§3.4.3 (calibration of kt, γt), Fig. 3.7, 3.9",
        "description": (
            "The 4 cm gate of cases/dem/dam-break-crosses.toml (1300 crosses, Table 3.1) "
            "poured once; the 3 s collapse followed from the same packing with Table 3.1 "
            "and with kt = 1e2 N/m, γt = 3e2 1/s, where the tangential map of this model "
            "first shows a substantial collapse; then `sanguis calibrate` fits γt at kt = "
            "1e2 N/m to the reference run-out from the same packing, and a run at the "
            "fitted value checks it."),
        "command": "/usr/bin/python3 validation/dem/crosses_recalibrated.py --build BUILD",
        "figures": ["docs/validation/figures/crosses_recalibrated.png"],
        "checks": checks,
        "tables": [{"caption": "Per run (`sanguis analyze`).",
                    "header": ["tangential parameters", "L0 [cm]", "H0 [cm]", "a", "(L∞−L0)/L0",
                               "Lajeunesse", "H0/H∞", "peak v/√(gH0)", "peak t/τc", "regime",
                               "collapse wall time, 1 thread [h]"],
                    "rows": rows},
                   {"caption": "`sanguis calibrate`: γt at kt = 1e2 N/m (both interactions), "
                               "one run per value from the packing, stopped at rest.",
                    "header": ["γt [1/s]", "(L∞−L0)/L0"], "rows": cal_rows}],
        "notes": [f"From one packing the run-out goes from {base['runout_ratio']:.2f} (Table 3.1, "
                  f"peak mean speed {base['peak_mean_speed_over_sqrt_gH0']:.3f} sqrt(g H0)) to "
                  f"{rec['runout_ratio']:.2f} (kt and γt 3x lower, peak "
                  f"{rec['peak_mean_speed_over_sqrt_gH0']:.3f} sqrt(g H0)) against the "
                  f"reference {ref:.2f}: the thesis' 'narrow region' of physical behaviour "
                  "(§3.4.3) lies between the two points for this model, and a factor of 3 in "
                  "the tangential parameters moves the run-out by an order of magnitude.",
                  "The thesis calibrated kt and γt by trial and error against its experiments "
                  "(§3.4.3) and found its physical band at kt 3e2, γt 1e3. On this model, at "
                  "kt 1e2 the run-out against γt is "
                  + ", ".join(f"{r['runout_ratio_mean']:.2f} at {r['value']:g}" for r in table)
                  + " 1/s"
                  + (f", and {extrapolated[1]['runout_ratio']:.2f} at {extrapolated[0]:g}. "
                     if extrapolated else ". ")
                  + (f"The closest run ({closest['value']:g} 1/s) is "
                     f"{100 * (closest['runout_ratio_mean'] / ref - 1):+.1f} % from the target. "
                     if closest else "")
                  + ("The fit brackets the target. " if fit["bracketed"] == 1.0 else
                     "The run-out turns before it reaches the target, nearest it at "
                     f"{gamma:g} 1/s and moving away on both sides: γt alone at kt 1e2 does not "
                     "bring this packing to the reference. " if turns else
                     "The target lies beyond the runs: the fitted line extrapolates. ")
                  + "The steep change is in kt (Table 3.1, kt 3e2: "
                  f"{base['runout_ratio']:.2f}). What shifts the band is not "
                  "known; candidates are the contact details that differ from Grains3D "
                  "(rounded crusts around shrunk cores where Grains3D keeps sharp boxes and "
                  "maps the shrunk shapes' closest points back, app. A.2.3) and the packing "
                  "(touching neighbours 6.8-7.5 per cross here against 8.2 in Table B.1). "
                  + ("`sanguis calibrate` finds no crossing and reports the nearest value, "
                     f"γt = {gamma:g} 1/s ({cal['runout_ratio']:.2f}). " if turns else
                     f"`sanguis calibrate` fitted γt at kt = 1e2 N/m: {fit['estimate']:.3g} "
                     f"± {fit['estimate_std']:.2g} 1/s (a straight line through the runs; "
                     f"slope {fit['slope']:.3g} per 1/s); the run at "
                     f"γt = {gamma:g} gives {cal['runout_ratio']:.2f}. ")
                  + "This fits one number "
                  "(the 4 cm gate's run-out), so it is a calibration, not a validation: the "
                  "other gates of Fig. 3.7 with these parameters are the test "
                  "(crosses_calibrated_gates: the 8 cm gate).",
                  "Wall times: the pour on 2 threads; the two 3 s collapses side by side, one "
                  "thread each; the calibration's runs side by side, one thread each; the run "
                  "at the fit on 2 threads; all on the 2-core VM, with other jobs for part of "
                  "the time."
                  + (" Not counted in the run time: the simulated spans "
                     + ", ".join(uncounted) + ", run by calls stopped before run.log "
                     "recorded checkpoints (their restarts began from later checkpoints)."
                     if uncounted else "")],
    }
    write_summary(summary, RESULTS, elapsed, args.quick, ok)
    print(f"{'PASS' if ok else 'FAIL'}: {elapsed / 3600:.2f} h")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
