#!/usr/bin/python3
"""The gate effect on a column of crosses (thesis §3.2.1, §3.3.1, Fig. 3.3; issue #4, case 5).

Every other dam break of crosses here removes the gate at once, as the thesis' simulations
of Fig. 3.7-3.9 do. Its experiments lift a PVC gate with a pneumatic cylinder at an almost
constant 43 +- 3 m/s^2 to about 3 m/s (reached in 0.07 s, §3.2.1), and for the snapshots
of Fig. 3.3-3.4 alone its simulations include that "gate effect": the crosses touching the
gate feel its friction as it slides up at a finite speed. Fig. 3.3 is the top-driven
collapse, "by far the most common avalanching mechanism of our cross-shaped particles ...
observed for all aspect ratios" (§3.3.1).

Here the 300-cross column of cases/dem/dam-break-crosses-memory.toml (Table 3.1, gate at
4 cm) is poured with seeds 1, 2 and 3 (`--seeds`: more; the pours of
crosses_tangential_packings, shared with it: a pour on disk is reused) and each packing
is opened twice from the same checkpoint at t = 3.0 s, to the case's end 0.8 s later:
  at once   the gate vanishes (the case as it is);
  lifted    the gate slides up from t = 3.0 s at 43 m/s^2 to 3 m/s (the case file's
            `translation` ramp), with the particle-wall friction of Table 3.1 (0.62), and
            is removed 0.2 s later, once its lower edge has passed the domain's top.
Each run is classified as in crosses_tangential_map (region 3: stable, not collapsed by
`sanguis analyze` or the top lost less than 5 % of H0; region 1: base-driven, the bottom
quarter moved in one tau_c at least half as far as the same column of spheres' does,
cases/dem/dam-break-sphere-column.toml; region 2: a top-driven collapse, the others).
Until 2026-12-06 region 2 was told from region 1 by the top quarter moving more than the
bottom one (crosses_tangential_map changed its rule then); that measure is reported.

Check (fixed before the runs): with the gate lifted, the Table 3.1 column is in region 2
by that test on at least two of the three packings (the thesis' "most common" mechanism,
the top-driven collapse, shown with the gate effect). Reported: both openings' regions,
the height lost against the 5 % line, run-out (L_inf - L0)/L0, H0/H_inf, the centre of
mass, the crosses past the gate, the motion of the top and bottom quarters, the lift of
the column and its settling, the peak mean speed, and how much the lifted gate changes
them (the thesis compares its gate-free runs with gated experiments in Fig. 3.7-3.8, so
it takes that change to be small).
`--quick`: seed 1 only (same check on one packing). `--seeds`: other packings too (pours
shared with crosses_tangential_packings the same way); the check above stays on seeds 1-3,
where it was fixed, and the region on any further seed is reported next to it (seeds 4-6
were added on 2026-12-05, after seeds 1-3 passed on margins of tenths of a millimetre).

Writes validation/dem/results/crosses_gate_effect.json and
docs/validation/figures/crosses_gate_effect.png.
Usage: /usr/bin/python3 validation/dem/crosses_gate_effect.py [--build build] [--quick]
           [--seeds 1 2 3 ...] [--reuse]
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import time
import tomllib

import matplotlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _outputs import (continuation_command, pour_command, read_pvd, read_summary,  # noqa: E402
                      run_two_at_a_time, span, two_at_a_time_span, wall_time, write_summary)
from crosses_dam_break import diagnostics, velocity_curve  # noqa: E402
from crosses_tangential_map import (BASE_DRIVEN_SHARE, CASE, GATE_TIME, RESULTS,  # noqa: E402
                                    ROOT, by_id, classify, sphere_reference)
from crosses_tangential_packings import RUNS as POURS  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

# The packings the check was fixed on (crosses_tangential_packings pours more since
# 2026-12-06; its pours of these seeds are shared).
SEEDS = [1, 2, 3]

RUNS = os.path.join(RESULTS, "runs", "crosses_gate_effect")
FIGURE = os.path.join(ROOT, "docs", "validation", "figures", "crosses_gate_effect.png")
with open(CASE, "rb") as _f:
    _CASE = tomllib.load(_f)
# [[obstacle]] number of the gate in the case (the obstacle gate_removal_time reads)
GATE_INDEX = next(k for k, o in enumerate(_CASE["obstacle"]) if o.get("name") == "gate")
END_S = float(_CASE["simulation"]["end_time_s"])  # the case's end time [s]
DOMAIN_TOP = float(_CASE["domain"]["max_m"][2])   # m, the top of the case's domain
GATE_FACE_X = float(_CASE["obstacle"][GATE_INDEX]["max_m"][0])  # m, its face to the channel
LIFT_ACCELERATION = 43.0  # m/s^2, §3.2.1
LIFT_SPEED = 3.0          # m/s, §3.2.1
REMOVE_AFTER_S = 0.2      # the gate goes once its lower edge (z = 0 before the lift) is
                          # above DOMAIN_TOP
OPENINGS = ("at once", "lifted")


def lift_distance(t):
    """How far the gate has risen t seconds after the lift starts (ramp, then constant)."""
    ramp = LIFT_SPEED / LIFT_ACCELERATION
    if t <= ramp:
        return 0.5 * LIFT_ACCELERATION * t * t
    return 0.5 * LIFT_SPEED * ramp + LIFT_SPEED * (t - ramp)


def opening_settings(opening):
    """The `sanguis run` overrides of an opening (none: the case removes the gate at once)."""
    if opening == "at once":
        return []
    motion = (f"{{ direction = [0.0, 0.0, 1.0], law = \"ramp\", speed_m_s = {LIFT_SPEED}, "
              f"acceleration_m_s2 = {LIFT_ACCELERATION}, start_s = {GATE_TIME} }}")
    return ["--set", f"obstacle[{GATE_INDEX}].translation={motion}",
            "--set", f"obstacle[{GATE_INDEX}].remove_at_s={GATE_TIME + REMOVE_AFTER_S}"]


def folder(seed, opening):
    return os.path.join(RUNS, f"seed_{seed}_" + opening.replace(" ", "_"))


def column_motion(run, lift_s=0.05, rise_m=0.005):
    """How the crosses moved from the opening: within lift_s (the lift) and twice that,
    the median rise, the crosses risen more than rise_m and the largest rise [m]; at the
    end, the median change of height (negative: the column settled) and the crosses past
    the gate's face."""
    frames = read_pvd(os.path.join(run, "particles.pvd"))

    def positions(t):
        time_s, path = [(ts, p) for ts, p in frames if ts <= t + 1e-9][-1]
        assert abs(time_s - t) < 1e-6, f"{run}: no frame at t = {t} s"
        return by_id(path)[1]

    x0 = positions(GATE_TIME)
    rise = positions(GATE_TIME + lift_s)[:, 2] - x0[:, 2]
    later = positions(GATE_TIME + 2 * lift_s)[:, 2] - x0[:, 2]
    end = by_id(frames[-1][1])[1]
    return {"median_rise_m": float(np.median(rise)), "risen": int((rise > rise_m).sum()),
            "largest_rise_m": float(rise.max()), "largest_rise_later_m": float(later.max()),
            "median_settling_m": float(np.median(end[:, 2] - x0[:, 2])),
            "past_gate": int((end[:, 0] > GATE_FACE_X).sum())}


def across(results, seeds, opening, key, scale=1.0):
    """The value `key` of each seed's run with this opening, times scale."""
    return [scale * results[(seed, opening)][key] for seed in seeds]


def near_the_line(results, seeds, line=0.05, within=0.005):
    """The runs whose height loss lies within `within` of the region test's line, each
    with its margin in points of H0 and in mm, and on which side."""
    parts = []
    for seed in seeds:
        for opening in OPENINGS:
            r = results[(seed, opening)]
            margin = r["height_loss"] - line
            if abs(margin) < within:
                parts.append(f"seed {seed} {opening} is {100 * abs(margin):.2f} points "
                             f"({10 * abs(margin) * r['H0_cm']:.2f} mm) "
                             + ("above" if margin >= 0 else "below"))
    return ", ".join(parts)


def peak_sentence(results, seeds, first_frame=0.5):
    """Where the lifted runs' mean speed peaks: at the first output frame after the
    opening (t / tau_c below first_frame: the column lifted and falling back) or later."""
    early = [x for x in seeds if results[(x, "lifted")]["peak_t"] < first_frame]
    late = [x for x in seeds if x not in early]
    parts = []
    if early:
        parts.append("at the first output frame after the opening (0.05 s, "
                     f"{results[(early[0], 'lifted')]['peak_t']:.2f} τc) on seeds "
                     + ", ".join(map(str, early)) + ": the column lifted and falling back")
    if late:
        parts.append("later on seeds " + ", ".join(map(str, late)) + ", at "
                     + ", ".join(f"{results[(x, 'lifted')]['peak_t']:.1f}" for x in late)
                     + " τc, in the collapse")
    return "The lifted runs' mean speed peaks " + "; ".join(parts) + "."


def lift_changes(results, seeds, key):
    """Per packing, the lifted run's `key` less the one opened at once."""
    return [results[(x, "lifted")][key] - results[(x, "at once")][key] for x in seeds]


def more_when_lifted(results, seeds, key):
    """On how many packings the lifted run's `key` exceeds the one opened at once."""
    return sum(d > 0 for d in lift_changes(results, seeds, key))


def run_time(pours, openings):
    """Wall-clock seconds of the phases reused from an earlier call: the pours two at a
    time, then (once every pour is done) the openings two at a time."""
    return two_at_a_time_span(pours) + two_at_a_time_span(openings)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--quick", action="store_true", help="seed 1 only")
    ap.add_argument("--seeds", type=int, nargs="+", default=SEEDS,
                    help="packings (the check is on those of 1, 2, 3 among them)")
    ap.add_argument("--reuse", action="store_true", help="analyse the runs on disk")
    args = ap.parse_args()
    assert lift_distance(REMOVE_AFTER_S) > DOMAIN_TOP, "the gate would vanish inside the domain"
    exe = os.path.join(ROOT, args.build, "app", "sanguis")
    seeds = SEEDS[:1] if args.quick else sorted(set(args.seeds))
    checked = [seed for seed in seeds if seed in SEEDS]  # where the check was fixed
    if not checked:
        sys.exit(f"--seeds: the check is on seeds {SEEDS}; give at least one of them")
    t0 = time.time()

    pours = {seed: os.path.join(POURS, f"pour_seed_{seed}") for seed in seeds}
    jobs, reused_pours, reused_openings = [], [], []
    for seed, d in pours.items():
        cmd = pour_command([exe, "run", CASE, "--output", d, "--quiet", "--threads", "1",
                            "--seed", str(seed)], d, GATE_TIME)
        if cmd and not args.reuse:
            jobs.append((cmd, d))
        elif not cmd:
            reused_pours.append(wall_time(d))
    run_two_at_a_time(jobs, POURS)

    jobs = []
    for seed in seeds if not args.reuse else []:
        for opening in OPENINGS:
            d = folder(seed, opening)
            # An opening made from an earlier pour (crosses_tangential_packings
            # --rerun-pours pours anew in place) starts again.
            record = os.path.join(d, "continuation.txt")
            if os.path.exists(record) and (os.path.getmtime(os.path.join(pours[seed],
                                                                         "checkpoint.bin"))
                                           > os.path.getmtime(record)):
                shutil.rmtree(d)
            cmd = [exe, "run", CASE, "--output", d, "--restart", "--quiet", "--threads", "1",
                   "--seed", str(seed), "--set", f"simulation.end_time_s={END_S}"]
            cmd = continuation_command(cmd + opening_settings(opening), d, pours[seed],
                                       END_S - 1e-6)
            if cmd:
                jobs.append((cmd, d))
            else:
                reused_openings.append(wall_time(d, GATE_TIME))
    run_two_at_a_time(jobs, POURS)

    results = {}
    # the yardstick of a base-driven collapse (region 1), as crosses_tangential_map's
    spheres_base_mm = sphere_reference(exe)["bottom_move_mm"]
    for seed in seeds:
        for opening in OPENINGS:
            d = folder(seed, opening)
            subprocess.run([exe, "analyze", d, "--initial-time", str(GATE_TIME)], check=True,
                           stdout=subprocess.DEVNULL)
            r = classify(d, spheres_base_mm)
            s = read_summary(d)
            r["H0_cm"] = 100 * s["H0_m"]
            r["height_ratio"] = s["height_ratio_H0_over_Hinf"]
            r["peak"] = s["peak_mean_speed_over_sqrt_gH0"]
            r["peak_t"] = s["peak_time_over_tau_c"]
            r["com_x_over_L0"] = s["com_displacement_x_over_L0"]
            r["end_speed_m_s"] = diagnostics(d)[-1]["mean_velocity_m_s"]
            r.update(column_motion(d))
            results[(seed, opening)] = r
            print(f"seed {seed}, gate {opening}: region {r['region']} ({r['regime']}), run-out "
                  f"{r['runout_ratio']:.2f}, height lost {100 * r['height_loss']:.1f} %",
                  flush=True)
    elapsed = time.time() - t0 + run_time(reused_pours, reused_openings)
    previous = os.path.join(RESULTS, "crosses_gate_effect.json")
    if args.reuse and os.path.exists(previous):  # keep the time the runs took
        with open(previous) as f:
            elapsed = json.load(f).get("run_time_s", elapsed)

    draw(seeds, results)
    lifted = [results[(seed, "lifted")]["region"] for seed in checked]
    at_once = [results[(seed, "at once")]["region"] for seed in seeds]
    needed = 1 if len(checked) == 1 else 2
    checks = [
        {"quantity": "gate lifted at 43 m/s² (Table 3.1): region on the packings of seeds "
                     + ", ".join(map(str, checked)) + " (crosses_tangential_map's test: 3 if "
                     "not collapsed or the top lost less than 5 % of H0, else 1 if the bottom "
                     "quarter moved at least half as far in one τc as the sphere column's, "
                     "else 2)",
         "measured": ", ".join(map(str, lifted)),
         "thesis": "top-driven collapse, the most common mechanism (§3.3.1, Fig. 3.3)",
         "tolerance": f"region 2 on at least {needed} of {len(checked)}",
         "pass": sum(r == 2 for r in lifted) >= needed}]
    more = [seed for seed in seeds if seed not in checked]
    if more:
        extra = [results[(seed, "lifted")]["region"] for seed in more]
        checks.append({
            "quantity": "gate lifted: region on the packings of seeds " + ", ".join(map(str, more))
                        + " (added after the check above was run; the same test)",
            "measured": ", ".join(map(str, extra)) + f" (region 2 on {sum(r == 2 for r in extra)}"
                        f" of {len(extra)}; on all seeds {sum(r == 2 for r in lifted + extra)} "
                        f"of {len(seeds)})",
            "thesis": "top-driven collapse (§3.3.1, Fig. 3.3)", "tolerance": "reported",
            "pass": None})
    checks.append({"quantity": "gate removed at once: region on the same packings",
                   "measured": ", ".join(map(str, at_once)), "thesis": "—",
                   "tolerance": "reported", "pass": None})
    runout_changes = lift_changes(results, seeds, "runout_ratio")
    near = near_the_line(results, seeds)  # the runs on the region test's line, in words
    for seed, runout, height in zip(seeds, runout_changes,
                                    lift_changes(results, seeds, "height_ratio")):
        checks.append({
            "quantity": f"seed {seed}: (L∞−L0)/L0 lifted − at once; H0/H∞ lifted − at once",
            "measured": f"{runout:+.3f}; {height:+.3f}",
            "thesis": "small (gate-free runs compared with gated experiments, Fig. 3.7-3.8)",
            "tolerance": "reported", "pass": None})
    rows = []
    for seed in seeds:
        for opening in OPENINGS:
            r = results[(seed, opening)]
            rows.append([seed, opening, f"{r['H0_cm']:.1f}", r["region"], r["regime"],
                         f"{r['top_move_mm']:.2f}", f"{r['bottom_move_mm']:.2f}",
                         f"{r['height_loss']:.4f}", f"{r['runout_ratio']:.2f}",
                         f"{r['height_ratio']:.3f}", f"{r['com_x_over_L0']:.3f}", r["past_gate"],
                         f"{1e3 * r['median_rise_m']:.2f}", f"{1e3 * r['median_settling_m']:.2f}",
                         f"{r['peak']:.3f}", f"{r['end_speed_m_s']:.1e}"])
    ok = all(c["pass"] for c in checks if c["pass"] is not None)
    summary = {
        "name": "crosses_gate_effect",
        "title": "Cross column: the gate removed at once or lifted at 43 m/s²",
        "thesis": "§3.2.1, §3.3.1, Fig. 3.3",
        "description": (
            "The 300-cross column of the memory case (Table 3.1, gate at 4 cm) poured with "
            f"seeds {', '.join(map(str, seeds))} and opened twice from the same checkpoint: "
            "the gate removed at once, and the gate slid up at 43 m/s² to 3 m/s with the "
            "particle-wall friction (the thesis' gate effect); regions as in "
            "crosses_tangential_map."),
        "command": "/usr/bin/python3 validation/dem/crosses_gate_effect.py --build BUILD"
                   + (" --quick" if args.quick else "")
                   + (" --seeds " + " ".join(map(str, seeds)) if seeds != SEEDS and not args.quick
                      else ""),
        "figures": ["docs/validation/figures/crosses_gate_effect.png"],
        "checks": checks,
        "tables": [{"caption": "Per run: the quarters' motion at the last output frame within "
                               "one τc of the opening (0.05 s frames: 0.1 s, 0.75 τc); heights, "
                               "run-out, centre of mass (x, over L0) and crosses past the "
                               "gate's face at the end, 0.8 s after the opening; the median "
                               "cross's rise 0.05 s after the opening and its change of height "
                               "at the end; the peak of the mean speed / √(g H0) and the mean "
                               "speed at the end.",
                    "header": ["seed", "gate", "H0 [cm]", "region", "regime", "top moved [mm]",
                               "bottom moved [mm]", "height loss / H0", "(L∞−L0)/L0",
                               "H0/H∞", "centre of mass / L0", "past the gate",
                               "median rise at 0.05 s [mm]", "median height change [mm]",
                               "peak speed", "end speed [m/s]"],
                    "rows": rows}],
        "notes": [
            "Removed at once, the column stands by the region test on "
            f"{sum(r == 3 for r in at_once)} of {len(seeds)} packings (height lost "
            f"{span(across(results, seeds, 'at once', 'height_loss', 100), '.2f')} %); "
            "lifted, the same packings lose "
            + ", ".join(f"{100 * results[(x, 'lifted')]['height_loss']:.2f}" for x in seeds)
            + " % (seeds " + ", ".join(map(str, seeds)) + "). The region test's line is "
            "5 %"
            + (", and " + near + " it: the check's verdict rests on margins far below a "
               "cross's 3 mm thickness" if near else "")
            + ". Of the runs over it, "
            f"{sum(r['region'] == 1 for r in results.values())} moved their bottom quarter in "
            f"one τc at least {BASE_DRIVEN_SHARE:g} of the sphere column's "
            f"{spheres_base_mm:.2f} mm (region 1, base-driven). The top quarter moved more "
            "than the bottom one (the rule of region 2 until 2026-12-06) in "
            f"{sum(r['top_move_mm'] > r['bottom_move_mm'] for r in results.values())} of "
            f"{len(results)} runs, standing ones included.",
            "What the lift does: 0.05 s after the opening the median cross's height has changed by "
            f"{span(across(results, seeds, 'lifted', 'median_rise_m', 1e3), '.2f')} mm, up on "
            f"{sum(v > 0 for v in across(results, seeds, 'lifted', 'median_rise_m'))} of "
            f"{len(seeds)} packings (the gate's friction lifts the crosses it holds and the "
            "entangled column follows them; "
            f"{span(across(results, seeds, 'lifted', 'risen', 1), 'd')} crosses rose more "
            "than 5 mm, at most "
            f"{1e3 * max(across(results, seeds, 'lifted', 'largest_rise_m')):.1f} mm, and "
            "0.1 s after the opening the largest rise left is "
            f"{span(across(results, seeds, 'lifted', 'largest_rise_later_m', 1e3), '.1f')}"
            " mm). The column then falls back and settles: at the end the median cross sits "
            f"{span(across(results, seeds, 'lifted', 'median_settling_m', -1e3), '.1f')}"
            " mm below its height at the opening, against "
            f"{span(across(results, seeds, 'at once', 'median_settling_m', -1e3), '.1f')}"
            " mm with the gate removed at once, so part of the lifted runs' height loss is "
            "that settling, not an avalanche of the top. Crosses past the gate's face at the "
            "end: lifted "
            + ", ".join(str(results[(x, 'lifted')]['past_gate']) for x in seeds)
            + ", at once "
            + ", ".join(str(results[(x, 'at once')]['past_gate']) for x in seeds)
            + ". " + peak_sentence(results, seeds),
            "So the lift raises the height lost on "
            f"{more_when_lifted(results, seeds, 'height_loss')} of {len(seeds)} packings and "
            "the run-out on "
            f"{more_when_lifted(results, seeds, 'runout_ratio')} (run-out lifted minus at once: "
            + ", ".join(f"{d:+.2f}" for d in runout_changes)
            + " L0). The thesis compares its gate-free runs with gated experiments "
            "(Fig. 3.7-3.8), which takes the gate effect to be small; on this model it is not "
            "small for the Table 3.1 column, which sits at the border of regions 2 and 3 "
            "(crosses_tangential_map, crosses_tangential_packings). Whether the lifted runs "
            "are the top-driven avalanche of Fig. 3.3 these measures do not settle.",
            "Heights and run-out are taken 0.8 s (the case's end) after the opening, not at "
            "rest: the mean speed is then "
            f"{span([r['end_speed_m_s'] for r in results.values()], '.1e')} m/s. "
            "crosses_tangential_packings takes them 0.5 s after the opening, so its numbers "
            "for the same trajectories (the runs opened at once) differ.",
            "The lifted gate has the case's acrylic material, so the crosses slide on it "
            "with the particle-wall friction of Table 3.1 (0.62); the thesis' gate is PVC "
            "and its table gives no other wall friction.",
            "The pours are those of crosses_tangential_packings (the same case, seeds and "
            "parameters), made by whichever script runs first; the run time counts them "
            f"({two_at_a_time_span([wall_time(d) for d in pours.values()]) / 60:.0f} min, "
            "two at a time), and so does that script's.",
            "Runs on one thread, two at a time, on the 2-core VM."],
    }
    write_summary(summary, RESULTS, elapsed, args.quick, ok)
    print(f"{'PASS' if ok else 'FAIL'}: lifted regions {lifted}, at once {at_once}, "
          f"{elapsed:.0f} s")
    return 0 if ok else 1


def draw(seeds, results):
    """Left: the mean speed against t / tau_c of every run; right: the height lost and the
    run-out of each packing, both openings side by side."""
    os.makedirs(os.path.dirname(FIGURE), exist_ok=True)
    fig, (left, right) = plt.subplots(1, 2, figsize=(10.0, 3.8))
    colours = {"at once": "tab:blue", "lifted": "tab:red"}
    # one line style per packing, so six seeds stay apart
    styles = ["-", "--", ":", "-.", (0, (5, 1, 1, 1, 1, 1)), (0, (1, 3))]
    top = 0.0  # the highest mean speed drawn
    for k, seed in enumerate(seeds):
        for opening in OPENINGS:
            t, v = velocity_curve(folder(seed, opening))
            top = max(top, max(v))
            left.plot(t, v, color=colours[opening], ls=styles[k % len(styles)],
                      label=f"seed {seed}, gate {opening}")
    left.set_xlabel(r"$t/\tau_c$")
    left.set_ylabel(r"mean speed / $\sqrt{g H_0}$")
    left.set_ylim(0.0, 1.6 * top)  # room for the legend above the curves
    left.legend(fontsize=6, ncol=2, loc="upper right")
    width = 0.38
    for k, opening in enumerate(OPENINGS):
        x = [i + (k - 0.5) * width for i in range(len(seeds))]
        losses = [results[(seed, opening)]["height_loss"] for seed in seeds]
        bars = right.bar(x, losses, width, color=colours[opening], label=f"gate {opening}")
        for bar, seed in zip(bars, seeds):
            r = results[(seed, opening)]
            right.annotate(f"region {r['region']}\n{r['runout_ratio']:.2f}",
                           (bar.get_x() + bar.get_width() / 2, bar.get_height()),
                           textcoords="offset points", xytext=(0, 3), ha="center", fontsize=7)
    right.axhline(0.05, color="k", lw=0.8, ls=":", label="5 %: below it, stable (region 3)")
    right.set_xticks(range(len(seeds)), [f"seed {seed}" for seed in seeds])
    right.set_ylabel("height lost / $H_0$ (labels: region, (L∞−L0)/L0)")
    right.set_ylim(0.0, 1.5 * max(r["height_loss"] for r in results.values()))
    right.legend(fontsize=7, loc="upper left")
    fig.suptitle("300 crosses, Table 3.1: the gate removed at once or lifted at 43 m/s²",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(FIGURE, dpi=130)


if __name__ == "__main__":
    sys.exit(main())
