#!/usr/bin/python3
"""Dam break of cross-shaped particles in the experiments' box (thesis §3.2-3.3,
Table 3.1, Fig. 3.7-3.9, Table B.1).

cases/dem/dam-break-crosses.toml: the acrylic box 64 x 30 x 20 cm, crosses of Table 3.1
poured behind a gate at L = 4 cm (1300 crosses) and released once settled; the gate is
removed at once (no gate effect). `--gates 4 8 12 20 30` runs the five gate positions of
§3.2.1 (1300 to 7000 crosses; hours each on one core); the default is the 4 cm gate.
Each run pours and settles with the gate in place (stopped at the first frame at rest,
mean speed below 1 mm/s, from 0.3 s after the last cross is due; else continued by 0.5 s
until every cross is in and at rest), then removes the gate and follows the
collapse until the pile is at rest (mean speed below 1 mm/s, checked from 1.5 s, about
10 tau_c, after the opening) or 3 s have passed (§3.2's 3 s), in restarts of one
`sanguis run` folder; `sanguis analyze` measures it (top-view intensity at 10 %, error
bars 20 % / 1 %; mean pile height).

References and checks (tolerances fixed before running):
- run-out: for H0/L0 >= 4 the thesis finds the crosses' run-out "almost matches" the
  spheres of Lajeunesse et al. (2005), (L_inf - L0)/L0 = 1.9 a^(2/3): within 35 %
  (the tolerance of the spheres' check); below a = 4 the crosses follow K a with K
  "slightly lower" than the spheres' 1.2: K is reported;
- coordination at the opening: touching neighbours per cross within 20 % of the 8.2 of
  Table B.1;
- sanity: the pour is complete and at rest before the opening (mean speed below
  1 mm/s), largest overlap below 5 % of the bounding radius.
The mean speed against t / tau_c is drawn next to the thesis' bands for its crosses
(Fig. 3.9a: narrow columns, 1000 crosses peak at 34-39 % of sqrt(g H0) 2-4 tau_c late;
wide ones, 3000 crosses, peak at 18-22 % near 2.5 tau_c, below 5 % at 10 tau_c); those
columns (a = 3.2, narrower boxes) differ from the box here, so they are not checked.

Writes validation/dem/results/crosses_dam_break.json and
docs/validation/figures/crosses_dam_break.png. `--reuse`: analyse the runs on disk. A run
folder left with a checkpoint by a stopped run is continued from it (hours-long gates
can span several sessions).
`--element-contacts mean` pours and collapses with the element contacts of two crosses
averaged, as Grains3D does (crosses_dam_break_mean.py runs it), and with it `--sum-control`
pours each column again (the same steps, checked row by row) and opens it with the sum;
`--element-contacts mean --flat-contacts point` runs Grains3D's whole model, one contact point
per element pair too (crosses_dam_break_mean_point.py runs it).
Usage: /usr/bin/python3 validation/dem/crosses_dam_break.py [--build build] [--hold-file F]
           [--gates 4 8 ...] [--threads T] [--reuse] [--quick]
           [--element-contacts sum|mean [--sum-control | --flat-contacts point]]
"""
import argparse
import csv
import math
import os
import re
import subprocess
import sys
import time
from typing import NamedTuple

import matplotlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _outputs import (ONE_POINT_PER_PAIR, add_contact_model_options, contact_model,  # noqa: E402
                      contact_model_settings, contact_model_suffix, contact_model_title,
                      counted_intervals, element_contacts_setting, lajeunesse, read_summary,
                      regime_name, stopped_seconds, stops, wall_time, write_summary)

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CASE = os.path.join(ROOT, "cases", "dem", "dam-break-crosses.toml")
RESULTS = os.path.join(ROOT, "validation", "dem", "results")

# gate position [cm] -> crosses (§3.2.3: 1300 to 7000); the column is about 16-21 cm tall
CROSSES = {4: 1300, 8: 2000, 12: 3000, 20: 5000, 30: 7000}
GATE_INDEX = 5    # [[obstacle]] number of the gate in the case
SIDE_WALL_INDEX = 4  # [[obstacle]] number of the back side wall (y = 0.20 m)
SETTLE_S = 1.5    # first check after the last cross is due (the 4 cm column was at rest 0.5 s after)
# Since 2026-12-05 evening a pour also stops once at rest (mean speed below 1 mm/s), tested
# at every frame from this long after the last cross is due: the large columns of
# crosses_column_width were at rest 0.5 s after it and would have run 1 s more to SETTLE_S
# (about 2.5 h of one core for 3000 crosses). Pours that reached their SETTLE_S end before
# are kept as they are, and open there.
POUR_REST_AFTER_S = 0.3
COLLAPSE_S = 3.0  # §3.2: 3 s after the opening, at most
# The collapse stops once at rest (mean speed below 1 mm/s), tested from this long after
# the opening: a pile at rest changes no measure, and its steps cost what moving ones do.
AT_REST_AFTER_S = 1.5
# [output] checkpoint_interval_s of every run gate_runner starts (here and in
# crosses_calibrated_gates.py; the case has 0.25): a killed run loses at most this much
# (about 3-10 min of a 2000-cross collapse on 2 cores). Checkpoints do not change the bits
# of a run (test Pouring.CheckpointsAlongTheWayLeaveTheRunUnchanged; on 2026-12-03 also
# 300 crosses of this case to 0.2 s, 20 checkpoints against none: identical outputs).
CHECKPOINT_S = 0.05
SEED = 3


# The 30 cm gate's last run, kept in the report until it is run again (7000 crosses, about
# 6 h on 2 cores); its JSON of 2026-11-23 had these figures.
POINT_MODEL_30CM = (
    "Gate 30 cm (7000 crosses), not run with the contact patches of flat faces: its run of "
    "2026-11-23 (`--gates 4 30`, one contact point per element pair, the model of thesis "
    "§2.3, still there as `--set simulation.flat_contacts=\"point\"`) gave a = 0.48, "
    "(L∞−L0)/L0 = 0.14 (K = 0.30 against the spheres' 1.2), H0/H∞ = 1.00, peak mean "
    "speed 0.3 % of √(g H0), fractured, 7.55 touching neighbours and 9.26 contact points "
    "per cross at the opening, in 5.99 h. With one point the 4 cm gate gave K = 0.54, "
    "(L∞−L0)/L0 = 2.93 against Lajeunesse's 5.88.")


class Column(NamedTuple):
    """A column poured behind the gate: the gate's position [cm], the crosses, the box's
    depth [m] (the back side wall; the case's box is 20 cm deep) and the bottom of the pour
    region [m] (the case's 0.28, above the tallest column of the five gates)."""
    gate_cm: float
    count: int
    depth_m: float = 0.20
    pour_bottom_m: float = 0.28


def column(gate_cm):
    """One of the five columns of §3.2.1 in the case's box."""
    return Column(gate_cm, CROSSES[gate_cm])


def pour_rate(col):
    """Crosses per second asked of the pour (the region's free room grows with its
    length and depth; pour_gate waits for the pour to end whatever rate is reached)."""
    return 150.0 * col.gate_cm * col.depth_m / 0.20


def depth_text(depth_m):
    """The box's depth as the settings write it (the case's 20 cm as "0.20", as always)."""
    return "0.20" if depth_m == 0.20 else f"{depth_m!r}"


def overrides(col):
    """The gate's position, the pour and its region; the gate stays until released. The
    box's depth and the region's bottom are set only where they differ from the case's."""
    l0 = round(col.gate_cm / 100.0, 6)
    rate = pour_rate(col)
    settings = [f"obstacle[{GATE_INDEX}].min_m=[{l0}, -0.01, 0.0]",
                f"obstacle[{GATE_INDEX}].max_m=[{l0 + 0.005:.4f}, 0.21, 0.72]",
                f"obstacle[{GATE_INDEX}].remove_at_s=1e6",
                f"particles[0].count={col.count}",
                f"particles[0].rate_per_s={rate}",
                f"particles[0].region_max_m=[{l0}, {depth_text(col.depth_m)}, 0.72]"]
    if col.depth_m != 0.20:
        depth = depth_text(col.depth_m)
        settings.append(f"obstacle[{SIDE_WALL_INDEX}].point_m=[0.0, {depth}, 0.0]")
    if col.pour_bottom_m != 0.28:
        settings.append(f"particles[0].region_min_m=[0.0, 0.0, {col.pour_bottom_m}]")
    return settings


def poured_and_at_rest(run, count):
    """Every cross inserted (last frame) and the mean speed below 1 mm/s (last row)."""
    frames = sorted(f for f in os.listdir(os.path.join(run, "particles")) if f.endswith(".vtu"))
    with open(os.path.join(run, "particles", frames[-1])) as f:
        points = int(re.search(r'NumberOfPoints="(\d+)"', f.read(4096)).group(1))
    return points == count and diagnostics(run)[-1]["mean_velocity_m_s"] < 1e-3


def wait_while(hold_file):
    """Wait before a segment while `hold_file` exists: the machine can be lent to other
    work between segments without disturbing the wall time of any one of them."""
    if hold_file and os.path.exists(hold_file):
        print(f"held while {hold_file} exists", flush=True)
        while os.path.exists(hold_file):
            time.sleep(5)


def gate_runner(exe, col, out, threads, hold_file=None, extra=()):
    """advance(end, more): runs the column's case in `out` up to `end` (continued from
    its checkpoint when there is one), with the column's overrides, `extra` and `more`."""
    base = [exe, "run", CASE, "--output", out, "--quiet", "--threads", str(threads),
            "--set", f"output.checkpoint_interval_s={CHECKPOINT_S}"]
    for o in overrides(col):
        base += ["--set", o]
    base += list(extra)
    checkpoint = os.path.join(out, "checkpoint.bin")

    def advance(end, more=()):
        cmd = base + (["--restart"] if os.path.exists(checkpoint) else []) + list(more)
        cmd += ["--set", f"simulation.end_time_s={end}"]
        wait_while(hold_file)
        print(" ".join(cmd), flush=True)
        subprocess.run(cmd, check=True)
    return advance


def pour_stop_settings(col):
    """The overrides that end a pour once at rest, POUR_REST_AFTER_S after its last cross is
    due on (they change when the run ends, not one bit of its steps)."""
    due = col.count / pour_rate(col)
    return ["--set", "stop.mean_velocity_below_m_s=1e-3",
            "--set", f"stop.check_after_s={due + POUR_REST_AFTER_S:.4f}"]


def pour_gate(exe, col, out, threads, hold_file=None, extra=()):
    """Pour and settle with the gate in place until every cross is in and at rest: the run
    stops at the first frame at rest from POUR_REST_AFTER_S after the last cross is due,
    and otherwise (the pour rate is bounded by the free room of the region) extends by
    0.5 s from SETTLE_S after it until at rest. A folder with a checkpoint of a pour stopped
    on the way is continued, and one that ended at rest is taken as it is; `extra` are more
    overrides (another seed). Returns the time reached, when the gate can go."""
    advance = gate_runner(exe, col, out, threads, hold_file, extra)
    checkpoint = os.path.join(out, "checkpoint.bin")
    t = math.ceil(10 * (col.count / pour_rate(col) + SETTLE_S)) / 10
    reached = diagnostics(out)[-1]["time_s"] if os.path.exists(checkpoint) else 0.0
    if reached > t + 1e-9:  # stopped in an extension of the pour: on the 0.5 s grid beyond t
        t = round(t + 0.5 * math.ceil((reached - t) / 0.5 - 1e-9), 1)
    if reached < t - 1e-9:  # a fresh run, stopped in the pour, or ended at rest before t
        at_rest = os.path.exists(checkpoint) and ended_at_rest(out)
        if not (at_rest and poured_and_at_rest(out, col.count)):
            advance(t, pour_stop_settings(col))
        if ended_at_rest(out) and poured_and_at_rest(out, col.count):
            return diagnostics(out)[-1]["time_s"]
        if diagnostics(out)[-1]["time_s"] < t - 1e-9:  # stopped at rest with crosses to come
            advance(t)
    while not poured_and_at_rest(out, col.count):
        if t > 20.0:
            sys.exit(f"gate {col.gate_cm:g} cm: the pour has not come to rest by {t} s")
        t = round(t + 0.5, 1)
        advance(t)
    return t


def at_rest_settings(opening):
    """The overrides that stop a collapse once at rest (AT_REST_AFTER_S after the opening
    on): they change when a run ends, not one bit of its steps."""
    return ["--set", "stop.mean_velocity_below_m_s=1e-3",
            "--set", f"stop.check_after_s={opening + AT_REST_AFTER_S}"]


def ended_at_rest(run):
    """Whether the run's last finished segment stopped at rest (its `done:` line)."""
    done = [line for line in open(os.path.join(run, "run.log")) if line.startswith("done:")]
    return bool(done) and done[-1].rstrip().endswith("settled")


def stopped(run, opening):
    """When a collapse ended, in words (the at-rest test starts AT_REST_AFTER_S after the
    opening, so an end there means at rest by then)."""
    last = diagnostics(run)[-1]
    after = last["time_s"] - opening
    if after <= AT_REST_AFTER_S + 1e-6:
        return f"was at rest at the first check, {AT_REST_AFTER_S:g} s after the opening"
    if after >= COLLAPSE_S - 1e-6:
        speed = last["mean_velocity_m_s"]
        if speed >= 1e-3:
            return (f"ran the full {COLLAPSE_S:g} s and was still moving (mean speed "
                    f"{speed:.2g} m/s at the end, so its run-out is a lower bound)")
        return f"ran the full {COLLAPSE_S:g} s"
    return f"came to rest {after:.2f} s after the opening"


def seed_settings(seed):
    """The override that pours another packing (none for the case's own seed)."""
    return [] if seed == SEED else ["--set", f"simulation.seed={seed}"]


def run_gate(exe, gate, out, threads, hold_file=None, extra=(), collapse_extra=()):
    """run_column for the column of one of the five gates of §3.2.1."""
    return run_column(exe, column(gate), out, threads, hold_file, extra, collapse_extra)


def run_column(exe, col, out, threads, hold_file=None, extra=(), collapse_extra=()):
    """pour_gate, then remove the gate and follow the collapse until at rest (at most
    COLLAPSE_S). A folder with a checkpoint (a run stopped on the way) is continued from
    it; `extra` are more overrides, in the pour and the collapse, and `collapse_extra` more
    still, in the collapse only (they come last, so they win). Returns the opening time."""
    advance = gate_runner(exe, col, out, threads, hold_file, extra)
    checkpoint = os.path.join(out, "checkpoint.bin")

    def collapse(t):
        """Follow the collapse in segments that end on the checkpoint grid: a segment
        stopped on the way restarts from its own start, so the `done:` lines of run.log
        add up to the wall time of the whole collapse (nothing run twice, nothing lost)."""
        reached = diagnostics(out)[-1]["time_s"]
        end = t + COLLAPSE_S
        while reached < end - 1e-9 and not (reached > t + 1e-9 and ended_at_rest(out)):
            nxt = min(end, CHECKPOINT_S * (math.floor(reached / CHECKPOINT_S + 1e-6) + 1))
            advance(round(nxt, 6), ["--set", f"obstacle[{GATE_INDEX}].remove_at_s={t}"]
                    + at_rest_settings(t) + list(collapse_extra))
            reached = diagnostics(out)[-1]["time_s"]

    if os.path.exists(checkpoint) and opening_time(out) < 1e5:  # stopped in the collapse
        t = opening_time(out)
    else:
        t = pour_gate(exe, col, out, threads, hold_file, extra)
    collapse(t)
    return t


def opening_time(run):
    """When the gate went (obstacles.csv)."""
    with open(os.path.join(run, "obstacles.csv"), newline="") as f:
        return min(float(r["remove_at_s"]) for r in csv.DictReader(f) if r["name"] == "gate")


def copied_from(run):
    """The run folder's record of where it was copied from, as a sentence ('' if none)."""
    path = os.path.join(run, "copied_from.txt")
    return f" The folder is {open(path).read().strip()}." if os.path.exists(path) else ""


def diagnostics(run):
    with open(os.path.join(run, "diagnostics.csv"), newline="") as f:
        return [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]


def draw_velocity_bands(ax):
    """The thesis' Fig. 3.9 peaks (mean speed against t / tau_c) as bands, the 0.05
    line, axis labels and legend: the frame of every mean-speed panel."""
    ax.fill_between([3.0, 5.0], 0.34, 0.39, color="0.85", label="thesis, 1000 crosses (narrow)")
    ax.fill_between([2.0, 3.0], 0.18, 0.22, color="0.65", label="thesis, 3000 crosses (wide)")
    ax.axhline(0.05, color="k", lw=0.8, ls=":")
    ax.set_xlabel(r"$t/\tau_c$")
    ax.set_ylabel(r"mean speed / $\sqrt{g H_0}$")
    ax.legend(fontsize=8)


def velocity_curve(run):
    with open(os.path.join(run, "analysis", "velocity.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    return ([float(r["time_over_tau_c"]) for r in rows],
            [float(r["mean_speed_over_sqrt_gH0"]) for r in rows])


def table_row(label, gate, s, seconds):
    """One row of the report's table: `sanguis analyze`'s summary `s` of a run of the
    gate, and the wall time of its finished segments."""
    a, ratio = s["aspect_ratio_H0_over_L0"], s["runout_ratio"]
    return [label, f"{CROSSES[gate]}", f"{100 * s['L0_m']:.1f}", f"{100 * s['H0_m']:.1f}",
            f"{a:.2f}", f"{ratio:.2f}", f"{ratio / a:.2f}", f"{lajeunesse(a):.2f}",
            f"{s['height_ratio_H0_over_Hinf']:.2f}", f"{s['peak_mean_speed_over_sqrt_gH0']:.3f}",
            f"{s['peak_time_over_tau_c']:.1f}", f"{s['pair_coordination']:.2f}",
            f"{s['contact_point_coordination']:.2f}", regime_name(s), f"{seconds / 3600:.2f}"]


def same_pour(control, run):
    """Whether the control's rows of diagnostics.csv up to its opening are the run's,
    digit for digit (the same pour: the runs are deterministic), and how many there are."""
    opening = opening_time(control)
    with open(os.path.join(control, "diagnostics.csv")) as f:
        mine = f.read().splitlines()
    with open(os.path.join(run, "diagnostics.csv")) as f:
        theirs = f.read().splitlines()
    count = sum(1 for line in mine[1:] if float(line.split(",", 1)[0]) <= opening + 1e-9)
    return opening == opening_time(run) and mine[:count + 1] == theirs[:count + 1], count


def control_rows(gate, control, run, rows, checks, notes, points):
    """The control of a gate (poured with the mean, opened with the sum): its row, the
    check that its pour is the mean run's, and a note; the run-out is reported, not
    graded (the control tells what the rule does after the opening, it validates nothing)."""
    s = read_summary(control)
    a, ratio = s["aspect_ratio_H0_over_L0"], s["runout_ratio"]
    opening = opening_time(control)
    label = f"{gate}, the same pour opened with the sum"
    points.append((f"gate {gate} cm, opened with the sum", s, control))
    rows.append(table_row(label, gate, s, wall_time(control)))
    identical, count = same_pour(control, run)
    checks += [
        {"quantity": f"(L∞−L0)/L0, gate {gate} cm, a = {a:.2f}, the mean's pour opened "
                     "with the sum",
         "measured": round(ratio, 3), "thesis": f"{lajeunesse(a):.2f} (Lajeunesse)",
         "tolerance": "reported (a control)", "pass": None},
        {"quantity": f"sanity, gate {gate} cm: the control's pour is the mean run's "
                     "(diagnostics rows up to the opening, digit for digit)",
         "measured": f"{count} rows, {'identical' if identical else 'different'}",
         "thesis": "—", "tolerance": "identical", "pass": identical}]
    notes.append(f"Control, gate {gate} cm: the column poured again with the mean (the same "
                 f"steps: {count} diagnostics rows up to the opening at {opening:g} s, "
                 f"{'identical to' if identical else 'NOT identical to'} the mean run's) and "
                 f"opened with the sum; the collapse {stopped(control, opening)}, "
                 f"{wall_time(control, opening) / 3600:.2f} h. Run-out {ratio:.2f}, H0/H∞ "
                 f"{s['height_ratio_H0_over_Hinf']:.2f}, peak mean speed "
                 f"{100 * s['peak_mean_speed_over_sqrt_gH0']:.1f} % of √(g H0) at "
                 f"{s['peak_time_over_tau_c']:.1f} τc, {regime_name(s)}: what the rule "
                 "changes after the opening alone, on one packing.")


def command_record(name, gates, controls, threads):
    """The command that makes the report's runs: one call, or, when the controls (with
    --sum-control) cover some of the gates only, the call that makes them and then the
    one for every gate (--sum-control on it would run the other gates' controls too)."""
    def call(these, control):
        return (f"/usr/bin/python3 validation/dem/{name}.py --build BUILD"
                + ("" if these == [4] else " --gates " + " ".join(map(str, these)))
                + (" --sum-control" if control else "")
                + (f" --threads {threads}" if threads != 1 else ""))
    if not controls or sorted(controls) == sorted(gates):
        return call(gates, bool(controls))
    return f"{call(sorted(controls), True)}`, then `{call(gates, False)}"


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--gates", type=int, nargs="+", default=[4], choices=sorted(CROSSES))
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--reuse", action="store_true", help="analyse the runs already on disk")
    ap.add_argument("--quick", action="store_true", help="same as the default (the 4 cm gate)")
    ap.add_argument("--hold-file", help="before each run segment, wait while this file exists")
    add_contact_model_options(ap, "crosses_dam_break", "with Table 3.1")
    ap.add_argument("--sum-control", action="store_true",
                    help="with --element-contacts mean: pour each column again with the mean "
                         "(the same bits) and open it with the sum (folders *_opened_sum): "
                         "what the rule changes after the opening alone")
    args = ap.parse_args(argv)
    mean, point = contact_model(ap, args)
    if args.sum_control and not mean:
        ap.error("--sum-control opens pours made with the mean: give --element-contacts mean")
    if args.sum_control and point:
        ap.error("--sum-control opens the mean's pours with the sum and the patches: leave "
                 "out --flat-contacts point")
    exe = os.path.join(ROOT, args.build, "app", "sanguis")
    name = "crosses_dam_break" + contact_model_suffix(mean, point)
    run_root = os.path.join(RESULTS, "runs", name)
    figure = os.path.join(ROOT, "docs", "validation", "figures", name + ".png")
    rule = contact_model_settings(mean, point)
    runs = {}  # (gate, opened with the sum after a pour with the mean) -> folder
    for gate in args.gates:
        out = os.path.join(run_root, f"L{gate}cm_seed{SEED}")
        runs[(gate, False)] = out
        control = out + "_opened_sum"
        control_on_disk = os.path.exists(os.path.join(control, "diagnostics.csv"))
        if mean and (args.sum_control or control_on_disk):
            runs[(gate, True)] = control  # a control on disk stays in the report
        if not (args.reuse and os.path.exists(os.path.join(out, "diagnostics.csv"))):
            run_gate(exe, gate, out, args.threads, args.hold_file, rule)
        if args.sum_control and not (args.reuse and control_on_disk):
            run_gate(exe, gate, control, args.threads, args.hold_file, rule,
                     element_contacts_setting("sum"))
    for out in runs.values():
        subprocess.run([exe, "analyze", out], check=True, stdout=subprocess.DEVNULL)

    checks, rows, points, notes = [], [], [], []
    for (gate, opened_sum), out in runs.items():
        if opened_sum:
            control_rows(gate, out, runs[(gate, False)], rows, checks, notes, points)
            continue
        s = read_summary(out)
        a = s["aspect_ratio_H0_over_L0"]
        ratio = s["runout_ratio"]
        opening = opening_time(out)
        diag = diagnostics(out)
        before = [r for r in diag if r["time_s"] <= opening + 1e-9][-1]
        overlap = max(r["max_overlap_over_radius"] for r in diag)
        seconds = wall_time(out)
        points.append((f"gate {gate} cm", s, out))
        rows.append(table_row(f"{gate}", gate, s, seconds))
        if a >= 4.0:
            ref = 1.9 * a ** (2.0 / 3.0)
            checks.append({"quantity": f"(L∞−L0)/L0, gate {gate} cm, a = {a:.2f}",
                           "measured": round(ratio, 3),
                           "thesis": f"{ref:.2f} (Lajeunesse, a ≳ 4, §3.3)",
                           "tolerance": "±35 %", "pass": abs(ratio / ref - 1) <= 0.35})
        else:
            checks.append({"quantity": f"K = (L∞−L0)/(L0 a), gate {gate} cm, a = {a:.2f}",
                           "measured": round(ratio / a, 3),
                           "thesis": "slightly below the spheres' 1.2 (§3.3)",
                           "tolerance": "reported", "pass": None})
        zp, zc = s["pair_coordination"], s["contact_point_coordination"]
        checks += [
            {"quantity": f"touching neighbours per cross at the opening, gate {gate} cm",
             "measured": round(zp, 3), "thesis": "8.2 (Table B.1)", "tolerance": "±20 %",
             "pass": abs(zp / 8.2 - 1) <= 0.2},
            {"quantity": f"contact points per cross at the opening, gate {gate} cm",
             "measured": round(zc, 3), "thesis": "16.5 (§3.3.3; see the notes)",
             "tolerance": "reported", "pass": None},
            {"quantity": f"sanity, gate {gate} cm: mean speed before the opening [m/s]; "
                         "largest overlap / radius",
             "measured": f"{before['mean_velocity_m_s']:.2g}; {overlap:.3g}",
             "thesis": "—", "tolerance": "< 1e-3; < 0.05",
             "pass": before["mean_velocity_m_s"] < 1e-3 and overlap < 0.05}]
        notes.append(f"Gate {gate} cm: {CROSSES[gate]} crosses, opening at {opening:g} s; the "
                     f"collapse {stopped(out, opening)}. "
                     f"{seconds / 3600:.2f} h in the run segments that reached their end "
                     "(`done:` lines of run.log; a segment stopped and restarted is not counted), "
                     f"of which the collapse took {wall_time(out, opening) / 3600:.2f} h "
                     "(segments on the checkpoint grid, so a stopped one is run again whole)."
                     + copied_from(out)
                     + " The pile's height fell by "
                     f"{100 * (1 - 1 / s['height_ratio_H0_over_Hinf']):.1f} % of H0 and {s['particles_touching_obstacles_fraction'] * 100:.0f} % of "
                     "the crosses touched a wall, the floor or the gate at the opening; the "
                     "mean speed peaked at "
                     f"{100 * s['peak_mean_speed_over_sqrt_gH0']:.1f} % of √(g H0) at "
                     f"{s['peak_time_over_tau_c']:.1f} τc, against the thesis' 18-39 % (Fig. "
                     "3.9a, other boxes); the centre of mass moved "
                     f"{s['com_displacement_x_over_L0']:.3f} L0.")
    if args.threads != 1:
        notes.append(f"Runs on {args.threads} threads (`--threads {args.threads}`; the results "
                     "do not depend on the thread count).")
    notes.append("The thesis' gate is lifted at 43 m/s², the gate here vanishes at once (as in "
                 "the thesis' own simulations of Fig. 3.7-3.9). crosses_gate_effect measures "
                 "what the lift changes, on the 300-cross column of the same parameters.")
    if mean:
        notes.insert(0, "The element contacts of two crosses (up to four pairs of arms), and "
                        "of a cross and one wall, averaged as Grains3D, the thesis' code, does "
                        "for composite particles: simulation.element_contacts = \"mean\" in "
                        "the pour and the collapse (crosses_dam_break sums them, the model's "
                        "default)" + (f"; and {ONE_POINT_PER_PAIR}: Grains3D's whole contact "
                                      "model." if point else "."))
    elif 30 not in args.gates:
        notes.append(POINT_MODEL_30CM)
    # Each run's stops (PAUSES.txt) that fell in its counted segments: its wall time holds them.
    stop_list = stops(run_root)
    counted = {out: counted_intervals(out) for out in runs.values()}
    stopped_s = {out: stopped_seconds(counted[out], stop_list) for out in runs.values()}
    paused = sum(stopped_s.values()) / 60.0
    if paused:
        notes.append(f"The wall times of the table include {paused:.1f} min during which the "
                     "runs were stopped (SIGSTOP) while other work used the cores (each run's "
                     "stops, added up), as listed in "
                     f"validation/dem/results/runs/{name}/PAUSES.txt; the run time "
                     "of the report leaves them out.")
    notes.append("Coordination: Table B.1 gives 8.2 for crosses and §3.3.3 gives "
                 "2 x 98939 / 12000 = 16.5; 98939 / 12000 = 8.24 matches Table B.1, so the two "
                 "differ by the factor 2 of the formula. Touching neighbours are checked "
                 "against Table B.1; contact points are reported.")

    os.makedirs(os.path.dirname(figure), exist_ok=True)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    a_line = [0.3 * 1.05 ** k for k in range(70)]
    a1.loglog(a_line, [lajeunesse(a) for a in a_line], "k--", label="Lajeunesse et al. (spheres)")
    for label, s, _ in points:
        l0 = s["L0_m"]
        lo = (s["Linf_20pc_m"] - l0) / l0
        hi = (s["Linf_1pc_m"] - l0) / l0
        r = s["runout_ratio"]
        bar = a1.errorbar([s["aspect_ratio_H0_over_L0"]], [r],
                          yerr=[[max(0.0, r - lo)], [max(0.0, hi - r)]], fmt="o", capsize=3,
                          label=f"sanguis, {label}")
        a1.plot([s["aspect_ratio_H0_over_L0"]], [s["com_displacement_x_over_L0"]], "d",
                mfc="none", color=bar.lines[0].get_color())
    a1.plot([], [], "d", mfc="none", color="0.3", label="centre-of-mass shift / L0 (same colour)")
    a1.set_xlabel(r"$a = H_0/L_0$")
    a1.set_ylabel(r"$(L_\infty - L_0)/L_0$")
    a1.legend(fontsize=8)
    for label, _, out in points:
        t, v = velocity_curve(out)
        a2.plot(t, v, label=f"sanguis, {label}")
    draw_velocity_bands(a2)
    fig.tight_layout()
    fig.savefig(figure, dpi=130)

    # The runs' own wall time (their segments may span several calls and sessions, and a
    # folder may come from another case), less the pauses listed beside them.
    elapsed = sum(wall_time(out) - stopped_s[out] for out in runs.values())
    ok = all(c["pass"] for c in checks if c["pass"] is not None)
    others = [g for g in sorted(CROSSES) if g not in args.gates]
    summary = {
        "name": name,
        "title": "Dam break of crosses in the experiments' box"
                 + contact_model_title(mean, point),
        "thesis": "§3.2-3.3, Table 3.1, Fig. 3.7-3.9, Table B.1",
        "description": (
            "cases/dem/dam-break-crosses.toml: box 64 x 30 x 20 cm, Table 3.1 crosses poured "
            "behind the gate, settled, gate removed at once, the collapse followed until at "
            f"rest (tested from {AT_REST_AFTER_S:g} s after the opening) or for "
            f"{COLLAPSE_S:g} s; gates "
            + ", ".join(f"{g} cm" for g in args.gates)
            + " of the five of §3.2.1"
            + (f" (the others: `--gates {' '.join(map(str, others))}`, hours each)" if others else "")
            + "."),
        "command": command_record(name, args.gates, [g for g, control in runs if control],
                                  args.threads),
        "figures": [f"docs/validation/figures/{name}.png"],
        "checks": checks,
        "tables": [{"caption": "Per run (`sanguis analyze`; coordination at the opening).",
                    "header": ["gate [cm]", "crosses", "L0 [cm]", "H0 [cm]", "a", "(L∞−L0)/L0",
                               "K", "Lajeunesse", "H0/H∞", "peak v/√(gH0)", "peak t/τc",
                               "neighbours", "contact points", "regime", "wall time of finished segments [h]"],
                    "rows": rows}],
        "notes": notes,
    }
    write_summary(summary, RESULTS, elapsed, args.quick, ok,
                  [interval for intervals in counted.values() for interval in intervals])
    print(f"{'PASS' if ok else 'FAIL'}: {len(points)} run(s), {elapsed / 3600:.2f} h")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
