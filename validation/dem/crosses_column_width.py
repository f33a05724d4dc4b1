#!/usr/bin/python3
"""Narrow and wide columns of crosses at a = 3.2: the collapse of thesis Fig. 3.9 (§3.3.2).

The thesis compares the mean speed of collapsing columns of aspect ratio a = H0/L0 = 3.2:
spheres (3200 and 15000; dam_break_scaling checks them) and crosses, a small system of
1000 and a large one of 3000, three packings each. Its small columns of crosses are
"narrow enough - less than the size of two particles - for the whole column to bend
forward" and peak at 34-39 % of sqrt(g H0), "delayed by two to four" tau_c against the
spheres' peak at tau_c; its large ones, "of width greater than the size of three
particles", do not bend: they peak at 18-22 % near 2.5 tau_c and fall below 5 % at about
10 tau_c, where the spheres (and, two to four tau_c later, the small crosses) do at 4 tau_c.

The box. The thesis gives neither box; the width it names is the column's length L0 along
the flow (its Fig. 3.9b-c). This case keeps the experiments' box of crosses_dam_break
(cases/dem/dam-break-crosses.toml) with the back side wall moved to a depth of 15 cm, the
one choice that meets both statements at a = 3.2: with the bulk volume of a poured cross
in this box (1.29 cm^3: the 4 cm gate's 3.9 x 21.5 x 20 cm over 1300 crosses), 1000
crosses stand 5.2 cm long (under two cross lengths, 5.4 cm) and 3000 crosses 9.0 cm (over
three, 8.1 cm); a 20 cm box would give 4.5 and 7.8 cm, the latter under three lengths,
and any depth from 13.8 to 18.4 cm meets both. The gate goes at the L0 of that estimate;
the measured a of each pour is reported.

The parameters. With Table 3.1 the crosses of this model stand at a = 1.9-5.5
(crosses_dam_break: K = 0.25-0.34, peak speeds 0.5-2 % of sqrt(g H0)), so this case runs
the collapse with the calibration of crosses_recalibrated (kt 1e2 N/m, gamma_t 1.91e3 1/s,
fitted to the 4 cm gate's run-out) from packings poured with Table 3.1, as
crosses_calibrated_gates does: the test is whether the crosses fitted to one run-out also
move as the thesis' crosses move. Each pour (seeds 1-3) is followed with the gate removed
at once until at rest (mean speed below 1 mm/s, checked from 1.5 s after the opening) or
for 3 s, with frames every 0.02 s (0.12-0.15 tau_c).

The same collapse with Table 3.1 follows from the first packing (the lowest seed) of each
size (reported, not checked; `--without-table31` leaves it out).

Checks (tolerances fixed before running, those of dam_break_scaling's sphere column: the
peak within 20 % of the thesis' range, its time within 0.5 tau_c of it, the 5 % crossing
within 1 tau_c of it), for each of the six runs:
- small (1000): peak in [0.272, 0.468]; its time in [2.5, 5.5] tau_c (thesis 3-5: the
  spheres' tau_c delayed by 2-4); below 5 % from [5, 9] tau_c (the spheres' 4, delayed);
- large (3000): peak in [0.144, 0.264]; its time in [2.0, 3.0] tau_c; below 5 % from
  [9, 11] tau_c;
and, over the three packings of each size, the thesis' contrast: the large columns' mean
peak lower, their mean 5 % crossing later, and at t = 3 tau_c their highest point nearer
the back wall (x of the five highest crosses over L0) than the small columns'.

Writes validation/dem/results/crosses_column_width.json and
docs/validation/figures/crosses_column_width.png. The runs go two at a time, one thread
each unless `--threads` says more (hours: a pour and a collapse of 1000 crosses about 2 h,
of 3000 crosses several); a run stopped on the way is continued from its checkpoint by the
same command, so the six runs may span several sessions. `--sizes small` (or `--quick`)
runs and reports the small columns only; `--reuse` analyses the finished runs on disk, and with
`--finished-only` reports those that have finished while the others go on (it names them;
the contrast between the sizes is then taken over the packings there are).
`--element-contacts mean` pours and collapses with the element contacts of two crosses
averaged, as Grains3D does (simulation.element_contacts), and Table 3.1 throughout (no
calibration, no second collapse), with the same checks, in its own folders and report
(crosses_column_width_mean.py runs it); `--element-contacts mean --flat-contacts point`
with one contact point per element pair as well, Grains3D's whole model
(crosses_column_width_mean_point.py).
Usage: /usr/bin/python3 validation/dem/crosses_column_width.py [--build build]
           [--sizes small large] [--seeds 1 2 3] [--reuse [--finished-only]]
           [--without-table31] [--quick] [--threads T]
           [--element-contacts sum|mean [--flat-contacts point]]
"""
import argparse
import functools
import math
import os
import subprocess
import sys
from typing import NamedTuple, Optional

import matplotlib
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _outputs import (ONE_POINT_PER_PAIR, TWIST_MOMENT_EFFECT, TWIST_MOMENT_FROM,  # noqa: E402
                      add_contact_model_options, call_two_at_a_time, contact_model,
                      contact_model_title, counted_intervals, element_contacts_setting,
                      flat_contacts_setting, paused_note, pool_span, read_arrays, read_pvd,
                      read_summary, regime_name, segment_starts, speed_landmarks,
                      stopped_seconds, stops, wall_time, write_summary)
from crosses_calibrated_gates import (GAMMA_T, KT, collapse, finished,  # noqa: E402
                                      seed_settings)
from crosses_dam_break import (RESULTS, ROOT, Column, diagnostics, draw_velocity_bands,  # noqa: E402
                               pour_gate, stopped, velocity_curve)

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


class Variant(NamedTuple):
    """What the checked collapses are made with: the report's name (also of the runs'
    folder and the figure), the element-contact rule's overrides (in the pours and the
    collapses) and the collapse's tangential (kt, gamma_t); None: Table 3.1's."""
    name: str
    rule: list
    tangential: Optional[tuple]

    def runs(self):
        return os.path.join(RESULTS, "runs", self.name)

    def figure(self):
        return os.path.join(ROOT, "docs", "validation", "figures", self.name + ".png")


# The model's sum with the calibration of crosses_recalibrated, and Grains3D's mean of the
# element contacts with the thesis' own Table 3.1 (crosses_dam_break_mean: its 4 cm gate
# runs out as the thesis' crosses with no calibration). main() chooses one.
SUM = Variant("crosses_column_width", [], (KT, GAMMA_T))
MEAN = Variant("crosses_column_width_mean", element_contacts_setting("mean"), None)
# Grains3D's whole model: the mean and one contact point per pair of touching elements.
MEAN_POINT = Variant("crosses_column_width_mean_point", element_contacts_setting("mean")
                     + flat_contacts_setting("point"), None)
variant = SUM
SPHERES = os.path.join(RESULTS, "runs", "dam_break_scaling", "L0_4.1cm")  # Fig. 3.9 spheres

ASPECT = 3.2             # Fig. 3.9
DEPTH_M = 0.15           # the back side wall (see the module's docstring)
CROSS_VOLUME_M3 = 1.29e-6  # bulk volume of a poured cross, the 4 cm gate of crosses_dam_break
CROSS_LENGTH_M = 0.027   # Table 3.1
FRAME_S = 0.02           # frames during the collapse
SEEDS = (1, 2, 3)
G = 9.81


class Size:
    """One system of Fig. 3.9a: the crosses and the thesis' figures for its mean speed."""

    def __init__(self, name, count, peak, peak_time, rest_time):
        self.name, self.count = name, count
        self.peak, self.peak_time, self.rest_time = peak, peak_time, rest_time

    def column(self):
        """The column in the 15 cm deep box: gate at the L0 of a = 3.2, pour region above
        the estimated H0."""
        l0 = math.sqrt(self.count * CROSS_VOLUME_M3 / (DEPTH_M * ASPECT))
        return Column(round(100 * l0, 1), self.count, DEPTH_M,
                      max(0.28, round(ASPECT * l0 + 0.04, 2)))

    def checks(self, label, peak, peak_t, below):
        """The three checks of one run (tolerances in the module's docstring)."""
        moved = peak >= 0.05  # a column that never rose above 5 % has no collapse to time
        lo, hi = 0.8 * self.peak[0], 1.2 * self.peak[1]
        t_lo, t_hi = self.peak_time[0] - 0.5, self.peak_time[1] + 0.5
        r_lo, r_hi = self.rest_time[0] - 1.0, self.rest_time[1] + 1.0
        return [
            {"quantity": f"{label}: peak mean speed / √(g H0)", "measured": round(peak, 3),
             "thesis": span(self.peak), "tolerance": f"[{lo:.3g}, {hi:.3g}] (±20 %)",
             "pass": lo <= peak <= hi},
            {"quantity": f"{label}: time of the peak / τc",
             "measured": round(peak_t, 2) if moved else f"{peak_t:.2f} (the peak under 5 %)",
             "thesis": span(self.peak_time), "tolerance": f"[{t_lo:g}, {t_hi:g}]",
             "pass": moved and t_lo <= peak_t <= t_hi},
            {"quantity": f"{label}: speed below 5 % from t / τc",
             "measured": rest_text(peak, below, 2),
             "thesis": span(self.rest_time), "tolerance": f"[{r_lo:g}, {r_hi:g}]",
             "pass": moved and r_lo <= below <= r_hi}]


def sentence(text):
    """The text with its first letter a capital (the rest unchanged, "Table 3.1" too)."""
    return text[:1].upper() + text[1:]


def rest_text(peak, below, digits):
    """The time the speed stays below 5 % from, in words where it has no such time: a
    curve that never rose to the line, or that ends above it."""
    if peak < 0.05:
        return "never above 5 %"
    return f"{below:.{digits}f}" if math.isfinite(below) else "still above 5 % at the end"


def columns_text(keys):
    """The columns of these (size, seed) keys, in words: "1000 crosses (L0 under two cross
    lengths), packings 1 and 2; 3000 (over three), packing 1"."""
    parts = []
    for size in SIZES:
        seeds = [seed for key_size, seed in keys if key_size == size]
        if not seeds:
            continue
        count = SIZES[size].count
        lengths = "under two cross lengths" if size == "small" else "over three"
        what = (f"{count} ({lengths})" if parts else
                f"{count} crosses (L0 {lengths}{'' if size == 'small' else ' cross lengths'})")
        parts.append(what + (f", packing {seeds[0]}" if len(seeds) == 1 else ", packings "
                             + ", ".join(map(str, seeds[:-1])) + f" and {seeds[-1]}"))
    return "; ".join(parts)


def span(pair):
    return f"{pair[0]:g}" if pair[0] == pair[1] else f"{pair[0]:g}-{pair[1]:g}"


# Fig. 3.9a (§3.3.2): the small crosses follow the spheres (peak at tau_c, 5 % at 4 tau_c)
# two to four tau_c late.
SIZES = {"small": Size("small", 1000, (0.34, 0.39), (3.0, 5.0), (6.0, 8.0)),
         "large": Size("large", 3000, (0.18, 0.22), (2.5, 2.5), (10.0, 10.0))}


def folders(size, seed):
    """The pour, the checked collapse (the calibrated one, or Table 3.1's with the mean)
    and the Table 3.1 collapse of one size and seed (with the mean, the same folder)."""
    tag, runs = f"{size}_seed{seed}", variant.runs()
    checked = (f"{tag}_kt{KT:g}_gamma{GAMMA_T:g}" if variant.tangential else f"{tag}_table31")
    return (os.path.join(runs, f"{tag}_pour"), os.path.join(runs, checked),
            os.path.join(runs, f"{tag}_table31"))


def run_one(exe, size, seed, table31, threads=1):
    """Pour (Table 3.1, gate in place, at rest), then the calibrated collapse and, if
    `table31`, the Table 3.1 one; one thread. Each goes on from its checkpoint when
    stopped on the way."""
    col = SIZES[size].column()
    pour, out, out31 = folders(size, seed)
    opening = pour_gate(exe, col, pour, threads, extra=seed_settings(seed) + variant.rule)
    frames = ["--set", f"output.interval_s={FRAME_S}"] + variant.rule
    collapse(exe, col, pour, out, opening, threads, tangential=variant.tangential, seed=seed,
             extra=frames)
    if table31:
        collapse(exe, col, pour, out31, opening, threads, tangential=None, seed=seed,
                 extra=frames)


def run_all_jobs(exe, keys, with_table31, threads=1):
    """run_one for every (size, seed), two at a time; the first failure (or Ctrl-C)
    cancels the jobs not yet started and is raised once the running ones end."""
    call_two_at_a_time([functools.partial(run_one, exe, size, seed,
                                          (size, seed) in with_table31, threads)
                        for size, seed in keys])


def frame_near(run, time_s):
    """(time, arrays) of the run's particle frame nearest time_s."""
    frames = read_pvd(os.path.join(run, "particles.pvd"))
    t, path = min(frames, key=lambda f: abs(f[0] - time_s))
    return t, read_arrays(path)


def highest_point(points, l0, count=5):
    """The mean x of the `count` highest crosses over L0 (0: the back wall, 1: the gate's
    face), as Fig. 3.9b-c locate the top of the column."""
    top = np.argsort(points[:, 2])[-count:]
    return float(points[top, 0].mean() / l0)


def collapse_finished(size, seed, table31=False):
    """Whether the pour and the checked collapse (`table31`: the Table 3.1 one) of this
    size and seed have both finished."""
    tangential = None if table31 else variant.tangential
    pour, out, out31 = folders(size, seed)
    if not os.path.exists(os.path.join(pour, "diagnostics.csv")):
        return False
    opening = diagnostics(pour)[-1]["time_s"]
    return finished(out31 if table31 else out, tangential, opening)


def finished_only(keys, with_table31):
    """The keys (size, seed) whose calibrated collapse has finished, the Table 3.1 ones
    whose own has, and a sentence naming what is left out (None when nothing is)."""
    done = [key for key in keys if collapse_finished(*key)]
    done31 = [key for key in with_table31 if collapse_finished(*key, table31=True)]
    left = [f"{SIZES[size].count} crosses, seed {seed}" for size, seed in keys
            if (size, seed) not in done]
    left += [f"{SIZES[size].count} crosses, seed {seed}, Table 3.1" for size, seed in with_table31
             if (size, seed) not in done31]
    note = None
    if left:
        note = ("Not finished when this report was written, so left out (the runs go on from "
                "their checkpoints with the same command without --finished-only): "
                + "; ".join(left) + ".")
    return done, done31, note


def measure(exe, size, seed, table31=False):
    """The analysed figures of one finished collapse: the checked one (`table31`: the
    Table 3.1 one)."""
    pour, out, out31 = folders(size, seed)
    out = out31 if table31 else out
    tangential = None if table31 else variant.tangential
    if not os.path.exists(os.path.join(pour, "diagnostics.csv")):
        sys.exit(f"{pour}: no pour; run without --reuse to make it")
    at_opening = diagnostics(pour)[-1]
    opening = at_opening["time_s"]
    if not finished(out, tangential, opening):
        sys.exit(f"{out}: not finished; run without --reuse to finish it")
    subprocess.run([exe, "analyze", out], check=True, stdout=subprocess.DEVNULL)
    s = read_summary(out)
    t, v = velocity_curve(out)
    peak, peak_t, below = speed_landmarks(t, v)
    tau_c = math.sqrt(s["H0_m"] / G)
    frame_t, frame = frame_near(out, opening + 3 * tau_c)  # Fig. 3.9b-c: t = 3 tau_c
    return {"summary": s, "curve": (t, v), "peak": peak, "peak_t": peak_t, "below": below,
            "x_top": highest_point(frame["Points"], s["L0_m"]), "frame": frame,
            "x_top_at": (frame_t - opening) / tau_c, "opening": opening,
            "pour_s": wall_time(pour), "collapse_s": wall_time(out, opening),
            "pour_counted": counted_intervals(pour),
            "collapse_counted": counted_intervals(out, opening),
            "stopped": stopped(out, opening),
            "mean_speed_at_opening": at_opening["mean_velocity_m_s"]}


TABLE_HEADER = ["run", "L0 [cm]", "L0 / cross length", "H0 [cm]", "a", "peak v/√(gH0)",
                "peak t/τc", "below 5 % from t/τc", "top x/L0 at 3 τc", "halts (Fig. 3.10)",
                "(L∞−L0)/L0", "regime", "pour [h]", "collapse [h]"]


def table_row(label, r, pour):
    """One row of the per-run table from measure()'s figures (`pour`: its column's text)."""
    s = r["summary"]
    return [label, f"{100 * s['L0_m']:.1f}", f"{s['L0_m'] / CROSS_LENGTH_M:.2f}",
            f"{100 * s['H0_m']:.1f}", f"{s['aspect_ratio_H0_over_L0']:.2f}",
            f"{r['peak']:.3f}", f"{r['peak_t']:.1f}",
            rest_text(r["peak"], r["below"], 1),
            f"{r['x_top']:.2f}", f"{s['halts']:.0f}", f"{s['runout_ratio']:.2f}",
            regime_name(s), pour, f"{r['collapse_s'] / 3600:.2f}"]


def contrast_checks(results, seeds):
    """The thesis' contrast between the sizes, on the means over the packings (those of
    `seeds` that `results` holds: a report of the finished runs may lack some)."""
    def mean(size, key):
        values = [results[(size, x)][key] for x in seeds if (size, x) in results]
        return sum(values) / len(values)

    small = {k: mean("small", k) for k in ("peak", "below", "x_top")}
    large = {k: mean("large", k) for k in ("peak", "below", "x_top")}
    return [
        {"quantity": "mean peak speed, large columns against small", "measured":
         f"{large['peak']:.3f} against {small['peak']:.3f}",
         "thesis": "lower (18-22 % against 34-39 %)", "tolerance": "large < small",
         "pass": large["peak"] < small["peak"]},
        {"quantity": "mean time below 5 % / τc, large columns against small", "measured":
         f"{large['below']:.2f} against {small['below']:.2f}",
         "thesis": "later (≈ 10 against 6-8)", "tolerance": "large > small",
         "pass": large["below"] > small["below"]},
        {"quantity": "highest point at 3 τc, x / L0 (0: back wall), large columns against small",
         "measured": f"{large['x_top']:.2f} against {small['x_top']:.2f}",
         "thesis": "near the back wall against near the gate (Fig. 3.9b-c)",
         "tolerance": "large < small", "pass": large["x_top"] < small["x_top"]}]


def sphere_curves():
    """The Fig. 3.9 sphere column of dam_break_scaling (a = 3.2), if its runs are here."""
    curves = []
    for k in range(1, 4):
        path = os.path.join(SPHERES, f"seed_{k}")
        if os.path.exists(os.path.join(path, "analysis", "velocity.csv")):
            curves.append(velocity_curve(path))
    return curves


def snapshot(ax, size, seed, result):
    """Side view (x, z) of a run at the frame nearest 3 tau_c, coloured by speed."""
    s = result["summary"]
    speed = np.linalg.norm(result["frame"]["velocity"], axis=1)
    p = result["frame"]["Points"]
    ax.scatter(100 * p[:, 0], 100 * p[:, 2], c=speed, s=4, cmap="jet")
    ax.axvline(100 * s["L0_m"], color="k", lw=0.8, ls=":")
    ax.set_aspect("equal")
    ax.set_xlim(0, 100 * max(4 * s["L0_m"], s["Linf_m"] + 0.02))
    ax.set_ylim(0, 100 * 1.1 * s["H0_m"])
    ax.set_xlabel("x [cm]")
    ax.set_ylabel("z [cm]")
    ax.set_title(f"{size}, seed {seed}, t = {result['x_top_at']:.1f} τc "
                 f"(top at x = {result['x_top']:.2f} L0)", fontsize=8)


def draw(results, table31, sizes, seeds):
    fig = plt.figure(figsize=(12, 4.4))
    ax = fig.add_subplot(1, 2, 1)
    for k, (t, v) in enumerate(sphere_curves()):
        ax.plot(t, v, color="0.6", lw=0.8, label="spheres, a = 3.2 (dam_break_scaling)"
                if k == 0 else None)
    colours = {"small": "tab:blue", "large": "tab:red"}
    styles = ["-", "--", ":"]
    for size in sizes:
        for k, seed in enumerate(seeds):
            if (size, seed) not in results:
                continue
            t, v = results[(size, seed)]["curve"]
            ax.plot(t, v, color=colours[size], ls=styles[k % 3],
                    label=f"{SIZES[size].count} crosses, seed {seed}")
        for (of_size, seed), r in table31.items():
            if of_size == size:
                t, v = r["curve"]
                ax.plot(t, v, color=colours[size], lw=0.6, alpha=0.6,
                        label=f"{SIZES[size].count} crosses, seed {seed}, Table 3.1")
    draw_velocity_bands(ax)
    ax.set_xlim(0, 16)
    ax.set_title(f"a = {ASPECT}, " + (f"kt {KT:g} N/m, γt {GAMMA_T:g} 1/s" if variant.tangential
                                      else "Table 3.1, element contacts averaged"
                                      + (", one point per element pair (Grains3D)"
                                         if variant is MEAN_POINT else "")), fontsize=9)
    for k, size in enumerate(sizes):
        shown = [seed for seed in seeds if (size, seed) in results]
        if shown:
            snapshot(fig.add_subplot(2, 2, 2 * (k + 1)), size, shown[0],
                     results[(size, shown[0])])
    fig.tight_layout()
    os.makedirs(os.path.dirname(variant.figure()), exist_ok=True)
    fig.savefig(variant.figure(), dpi=130)


def twist_model_note(keys, with_table31):
    """Which of the reported runs used which torsional spring of the contact patches: the
    model changed at _outputs.TWIST_MOMENT_FROM, and a run restarted across the change is
    made of both."""
    before, across, after = [], [], []
    for size, seed in keys:
        pour, out, out31 = folders(size, seed)
        for folder in [pour, out] + ([out31] if (size, seed) in with_table31 else []):
            starts = segment_starts(folder)
            later = sum(1 for t in starts if t and t >= TWIST_MOMENT_FROM)
            name = os.path.basename(folder)
            (before if later == 0 else after if later == len(starts) else across).append(name)
    parts = [f"{label} {', '.join(names)}" for label, names in
             (("before it:", before), ("partly after it:", across), ("after it:", after)) if names]
    return (f"The contact patches' torsional spring changed at {TWIST_MOMENT_FROM[:16]} UTC "
            "(docs/theory/dem.md, \"The torsional spring until 2026-12-05 evening\"); the runs "
            "reported here ran " + "; ".join(parts) + ". " + TWIST_MOMENT_EFFECT)


def main(argv=None):
    global variant
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--sizes", nargs="+", default=list(SIZES), choices=list(SIZES))
    ap.add_argument("--seeds", type=int, nargs="+", default=list(SEEDS))
    ap.add_argument("--reuse", action="store_true", help="analyse the finished runs on disk")
    ap.add_argument("--without-table31", action="store_true",
                    help="leave out the Table 3.1 collapse of each size's first packing")
    ap.add_argument("--quick", action="store_true", help="the small columns only")
    ap.add_argument("--finished-only", action="store_true",
                    help="with --reuse: report the runs that have finished, naming the others")
    ap.add_argument("--threads", type=int, default=1,
                    help="threads of each run (two run at a time; one run alone on two "
                         "threads gives its result in half the time, and the same bits)")
    add_contact_model_options(ap, SUM.name, "with Table 3.1 throughout (no calibration)")
    args = ap.parse_args(argv)
    mean, point = contact_model(ap, args)
    variant = (MEAN_POINT if point else MEAN) if mean else SUM
    if args.finished_only and not args.reuse:
        ap.error("--finished-only reports runs on disk: give --reuse as well")
    if args.quick:
        args.sizes = ["small"]
    if len(set(args.seeds)) != len(args.seeds) or min(args.seeds) < 0:
        ap.error("--seeds: distinct non-negative integers")
    exe = os.path.join(ROOT, args.build, "app", "sanguis")
    keys = [(size, seed) for size in args.sizes for seed in args.seeds]
    first = min(args.seeds)
    with_table31 = ([] if args.without_table31 or not variant.tangential
                    else [(size, first) for size in args.sizes])
    if not args.reuse:
        run_all_jobs(exe, keys, with_table31, args.threads)
    left_out = None
    if args.finished_only:
        keys, with_table31, left_out = finished_only(keys, with_table31)
        if not keys:
            sys.exit("no collapse has finished yet: nothing to report")
    results = {key: measure(exe, *key) for key in keys}
    table31 = {key: measure(exe, *key, table31=True) for key in with_table31}

    checks, rows, notes = [], [], []
    if left_out:
        notes.append(left_out)
    if not variant.tangential:
        notes.append("The element contacts of two crosses (up to four pairs of arms), and of a "
                     "cross and one wall, averaged as Grains3D, the thesis' code, does for "
                     "composite particles (simulation.element_contacts = \"mean\"), in the "
                     "pours and the collapses, with the thesis' Table 3.1 throughout (no "
                     "calibration): crosses_column_width sums them and collapses with the "
                     "calibration of crosses_recalibrated."
                     + (f" And {ONE_POINT_PER_PAIR}: Grains3D's whole contact model, poured "
                        "and collapsed with it." if point else ""))
    for (size, seed), r in results.items():
        label = f"{SIZES[size].count} crosses, seed {seed}"
        checks += SIZES[size].checks(label, r["peak"], r["peak_t"], r["below"])
        checks.append({"quantity": f"sanity, {label}: mean speed at the opening [m/s]",
                       "measured": f"{r['mean_speed_at_opening']:.2g}", "thesis": "—",
                       "tolerance": "< 1e-3", "pass": r["mean_speed_at_opening"] < 1e-3})
        rows.append(table_row(label, r, f"{r['pour_s'] / 3600:.2f}"))
        notes.append(f"{sentence(label)}: poured with Table 3.1 and at rest at "
                     f"{r['opening']:g} s; the collapse {r['stopped']}.")
    for (size, seed), r in table31.items():
        label = f"{SIZES[size].count} crosses, seed {seed}, Table 3.1 (kt 3e2, γt 1e3)"
        checks.append({"quantity": f"{label}: peak mean speed / √(g H0); below 5 % from t / τc",
                       "measured": f"{r['peak']:.3f}; " + rest_text(r["peak"], r["below"], 2),
                       "thesis": f"{span(SIZES[size].peak)}; {span(SIZES[size].rest_time)}",
                       "tolerance": "reported", "pass": None})
        rows.append(table_row(label, r, "(as above)"))
        notes.append(f"{sentence(label)}: the collapse from the same packing "
                     f"{r['stopped']}.")
    if all(any(key[0] == size for key in results) for size in SIZES):
        checks += contrast_checks(results, args.seeds)
    if args.threads != 1:
        notes.append(f"Runs on {args.threads} threads (`--threads {args.threads}`; the results "
                     "do not depend on the thread count), so the run time adds their times.")
    if not point:  # the torsional spring belongs to the contact patches
        notes.append(twist_model_note(keys, with_table31))
    notes.append("The thesis' sphere curves of Fig. 3.9a are checked by dam_break_scaling "
                 "(its column of a = 3.2); they are drawn here in grey when its runs are on "
                 "disk.")
    # Each run's wall time less the stops (PAUSES.txt) that fell in its counted segments.
    stop_list = stops(variant.runs())
    durations, paused, counted = [], 0.0, []
    for key, r in results.items():
        spans = [r["pour_counted"], r["collapse_counted"]] + (
            [table31[key]["collapse_counted"]] if key in table31 else [])
        counted += [interval for intervals in spans for interval in intervals]
        stopped_s = sum(stopped_seconds(intervals, stop_list) for intervals in spans)
        paused += stopped_s / 60.0
        durations.append(r["pour_s"] + r["collapse_s"] - stopped_s
                         + (table31[key]["collapse_s"] if key in table31 else 0.0))
    if paused:
        notes.append(paused_note(paused, variant.name))
    draw(results, table31, args.sizes, args.seeds)
    # Two runs at a time on one thread each share the two cores; runs on two threads each
    # take them both, so their times add up.
    elapsed = pool_span(durations, workers=2 if args.threads == 1 else 1)
    ok = all(c["pass"] for c in checks if c["pass"] is not None)
    collapsed_with = (f"collapsed with kt {KT:g} N/m, γt {GAMMA_T:g} 1/s (the calibration of "
                      "crosses_recalibrated)" if variant.tangential else
                      "collapsed with Table 3.1 too, the element contacts of two crosses "
                      "averaged as in Grains3D" + (" and one contact point per element pair"
                                                   if point else "") + " throughout")
    summary = {
        "name": variant.name,
        "title": "Narrow and wide columns of crosses at a = 3.2"
                 + contact_model_title(mean, point),
        "thesis": "§3.3.2, Fig. 3.9",
        "description": (
            "The box of crosses_dam_break 15 cm deep; columns of a = 3.2 of "
            + columns_text(sorted(results)) + ", poured with Table 3.1"
            + (" and the same model" if not variant.tangential else "")
            + f", {collapsed_with}, until at rest; the mean speed against the thesis' Fig. "
            "3.9a curves."),
        "command": f"/usr/bin/python3 validation/dem/{variant.name}.py --build BUILD"
                   + (" --quick" if args.quick else "" if args.sizes == list(SIZES)
                      else " --sizes " + " ".join(args.sizes))
                   + ("" if args.seeds == list(SEEDS)
                      else " --seeds " + " ".join(map(str, args.seeds)))
                   + (" --without-table31" if args.without_table31 and variant.tangential
                      else "")
                   + (f" --threads {args.threads}" if args.threads != 1 else "")
                   + (" --reuse --finished-only" if args.finished_only else ""),
        "figures": [f"docs/validation/figures/{variant.name}.png"],
        "checks": checks,
        "tables": [{"caption": "Per run (`sanguis analyze`; the top's x at 3 τc).",
                    "header": TABLE_HEADER,
                    "rows": rows}],
        "notes": notes,
    }
    write_summary(summary, RESULTS, elapsed, args.quick, ok, counted)
    print(f"{'PASS' if ok else 'FAIL'}: {len(results)} run(s), {elapsed / 3600:.2f} h")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
