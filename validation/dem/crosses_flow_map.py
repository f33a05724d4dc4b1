#!/usr/bin/python3
"""Flow-regime map of crosses: repeatable and intermittent columns (thesis §3.3.1, Fig. 3.6;
issue #4, case 5).

The thesis maps its dam breaks of crosses over the column's initial length L0 and height
H0, each column repeated three to five times (Fig. 3.6): a column is *repeatable* when its
runs end alike and *intermittent* when the packing decides whether it avalanches or stands.
In its simulations "tall columns of initial height H0 greater than 20 cm always result in
an avalanche", while some such columns of the experiments were intermittent, which it
puts down to Table 3.1's tangential parameters (§3.3.1, §3.4.3).

Here the columns are those of crosses_dam_break (cases/dem/dam-break-crosses.toml: the
experiments' acrylic box, Table 3.1, contact patches, the element contacts of two crosses
summed), with the box's back side wall at 6 cm, as the memory case's column (the thesis'
20 cm takes 3.3 times the crosses for the same height: 1300 crosses, about 1.2 h on one
core, for the 4 cm gate's 21 cm): behind the 4 cm gate 150, 300 and 450 crosses (H0 about
9, 17 and 26 cm), behind the 8 cm gate 300 and 600 (about 9 and 17 cm), each poured with
seeds 1, 2 and 3 (`--columns GATE_CM:CROSSES ...`, `--seeds`). Each run pours, settles and
collapses as crosses_dam_break runs its gates (pour until at rest, gate removed at once,
collapse until at rest, at most 3 s), on one thread, two runs at a time; a run stopped on
the way goes on from its checkpoint with the same command. The map reports every column
of its folder whose runs have finished, those of earlier calls with other --columns too
(its command then lists them all). A call that would drop from the summary on disk a
column whose runs are not on disk (a fresh checkout holds the summaries, not the runs)
stops before running, unless --drop-missing. `sanguis analyze` of a column's runs classifies each
(collapsed: H_inf below 95 % of H0; fractured: otherwise, the front moved more than 10 %
of L0; stable: neither) and writes the column's ensemble.csv, and `sanguis flow-map` the
map.

Checks (fixed before the runs):
- tall columns: every run of a column with H0 above 20 cm collapses (§3.3.1: "always
  result in an avalanche"; the strict reading, collapsed, since a fractured tall column
  keeps its height: its top barely fell);
- sanity: every pour complete and at rest at the opening (mean speed below 1 mm/s).
Reported: each column's outcome (repeatable: its regime; intermittent: how many runs
ended in which), the runs' run-out (L_inf - L0)/L0 and H0/H_inf, and how many of the tall
columns' runs avalanched at all (not stable). The thesis' map is qualitative ("to report
qualitative trends rather than to provide accurate flow transitions") and in another
box's depth, so the rest is not graded.
`--quick`: the 4 cm gate's 150 crosses (500 in the deep box), seeds 1 and 2 (no column
above 20 cm: the tall check is reported as not run).

`--element-contacts mean` pours and collapses with the element contacts of two crosses
averaged, as Grains3D, the code of the thesis' crosses, does; with `--flat-contacts point`
too, one contact point per pair of touching elements, Grains3D's whole model. Each model
maps in its own folders and report (crosses_flow_map_mean, crosses_flow_map_mean_point;
the second's wrapper of that name runs it; the narrow box's walls hold its columns whatever
the model, so the mean with the patches has its wrapper in the deep box only).

`--depth-cm 20` maps in the experiments' 20 cm deep box, the case's own, instead: the same
heights with 3.3 times the crosses (4 cm gate 500, 1000 and 1300, 8 cm gate 1000 and 2000;
1300 rather than 1500 for the tall column, H0 about 22 cm, since that is crosses_dam_break's
own column, as the 8 cm gate's 2000 are). Its runs, map and report get the suffix _deep
(crosses_flow_map_deep.py, crosses_flow_map_mean_deep.py and
crosses_flow_map_mean_point_deep.py run the defaults, the mean and Grains3D's model so). A
column that is one of crosses_dam_break's is poured as the dam break pours it, and the dam break's finished run
with the same model and the case's seed (3) is copied as the map's run of that seed (it
must be of the current build, as every run of the report; its note gives its own wall
time and threads, and says if the dam break's run has changed since the copy).

Writes validation/dem/results/crosses_flow_map.json, the map's CSV in the runs' folder
(results/runs/crosses_flow_map/map) and docs/validation/figures/crosses_flow_map.png
(with another model, its name for crosses_flow_map).
Usage: /usr/bin/python3 validation/dem/crosses_flow_map.py [--build build] [--quick]
           [--columns 4:150 4:300 ...] [--seeds 1 2 3] [--reuse] [--drop-missing]
           [--element-contacts sum|mean [--flat-contacts point]] [--depth-cm 6|20]
"""
import argparse
import csv
import functools
import json
import os
import re
import shutil
import subprocess
import sys
import time
from typing import NamedTuple

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _outputs import (ONE_POINT_PER_PAIR, add_contact_model_options, call_two_at_a_time,  # noqa: E402
                      contact_model, contact_model_settings, contact_model_suffix,
                      contact_model_title, counted_intervals, paused_note, pool_span,
                      read_summary, regime_name, stopped_seconds, stops, wall_time,
                      write_summary)
from crosses_dam_break import (COLLAPSE_S, CROSSES, RESULTS, ROOT, SEED, Column,  # noqa: E402
                               column, diagnostics, ended_at_rest, opening_time,
                               run_column, seed_settings, stopped)


class Model(NamedTuple):
    """The contact model a map is made with: the report's name (also of the runs' folder
    and the figure), its overrides (in the pours and the collapses), how the report names
    it, and the crosses_dam_break case of the same model (experiments_run)."""
    name: str
    settings: list
    words: str
    dam_break: str

    def in_experiments_box(self):
        """The same model's map in the experiments' 20 cm deep box (--depth-cm 20)."""
        return self._replace(name=self.name + DEEP_SUFFIX)

    def runs(self):
        return os.path.join(RESULTS, "runs", self.name)

    def map(self):
        return os.path.join(self.runs(), "map")

    def figure(self):
        return os.path.join(ROOT, "docs", "validation", "figures", f"{self.name}.png")

    def script(self):
        return f"validation/dem/{self.name}.py"


# The model's defaults (the sum, the patches); the element contacts of two crosses averaged,
# as Grains3D, the code of the thesis' crosses, does; and that with one contact point per
# pair of touching elements, Grains3D's whole model. main() chooses one.
def model_of(mean, point, words):
    """The map of a contact model: its name and its dam break's, suffixed as every cross
    case's (contact_model_suffix), and its overrides (contact_model_settings)."""
    suffix = contact_model_suffix(mean, point)
    return Model("crosses_flow_map" + suffix, contact_model_settings(mean, point), words,
                 "crosses_dam_break" + suffix)


SUM = model_of(False, False, "the element contacts summed, contact patches")
MEAN = model_of(True, False, "the element contacts of two crosses averaged as in Grains3D, "
                "contact patches")
MEAN_POINT = model_of(True, True, "Grains3D's model: the element contacts of two crosses "
                      "averaged, one contact point per pair of touching elements")
model = SUM
DEEP_SUFFIX = "_deep"   # of the maps in the experiments' box (--depth-cm 20)
COPIED_FROM = "copy_of.txt"  # in a run copied from crosses_dam_break (copy_experiments_run)
DEPTH_M = 0.06          # the box's depth: the memory case's column (cases/dem/README.md)
DEEP_M = 0.20           # the experiments' box, the case's own (`--depth-cm 20`)
depth_m = DEPTH_M       # main() sets it
COLUMNS = [(4, 150), (4, 300), (4, 450), (8, 300), (8, 600)]  # (gate [cm], crosses)
QUICK_COLUMNS = [(4, 150)]
# The same heights in the experiments' box (3.3 times the crosses); the tall column and the
# 8 cm gate's 2000 are crosses_dam_break's own columns (column_of).
DEEP_COLUMNS = [(4, 500), (4, 1000), (4, 1300), (8, 1000), (8, 2000)]
DEEP_QUICK_COLUMNS = [(4, 500)]
SEEDS = [1, 2, 3]
QUICK_SEEDS = [1, 2]
TALL_M = 0.20           # §3.3.1: columns taller than 20 cm always avalanche
# Crosses per cubic metre of column: the memory case's 300 crosses stand 17.4-18.3 cm tall
# behind its 4 cm gate in the 6 cm deep box (crosses_gate_effect).
CROSSES_PER_M3 = 300 / (0.175 * 0.04 * DEPTH_M)
POUR_ABOVE_M = 0.06     # the pour region starts this far above the column's expected top


def default_columns(deep, quick):
    """The columns a map runs without --columns: of the 6 cm deep box or (deep) of the
    experiments' box, all or (quick) the one of --quick."""
    if deep:
        return DEEP_QUICK_COLUMNS if quick else DEEP_COLUMNS
    return QUICK_COLUMNS if quick else COLUMNS


def expected_height(gate_cm, count):
    """The column's height [m] from its crosses in the map's box, as the memory case's
    column packs."""
    return count / (CROSSES_PER_M3 * gate_cm / 100.0 * depth_m)


def column_of(gate_cm, count):
    """The Column of crosses_dam_break for this gate and count in the map's box, the pour
    region (up to the case's 0.72 m) starting POUR_ABOVE_M above the column's expected top,
    or at the case's 0.28 m where that is higher: no cross is placed where the pile will
    stand. In the experiments' box, a gate with the crosses of crosses_dam_break's column
    (1300 behind the 4 cm gate) is that column, pour region and all: its run with the
    case's seed is the dam break's own (experiments_run)."""
    if depth_m == DEEP_M and CROSSES.get(gate_cm) == count:
        return column(gate_cm)
    bottom = max(0.28, round(expected_height(gate_cm, count) + POUR_ABOVE_M, 2))
    return Column(gate_cm, count, depth_m, bottom)


def folder(gate_cm, count, seed):
    return os.path.join(model.runs(), f"L{gate_cm:g}cm_{count}", f"seed_{seed}")


def command_script(mean, point, deep):
    """The script (and its options) that runs this map: the wrapper of the model's name
    where there is one, else crosses_flow_map.py with the options."""
    if os.path.exists(os.path.join(ROOT, model.script())):
        return model.script()
    return (f"validation/dem/{SUM.name}.py" + (" --element-contacts mean" if mean else "")
            + (" --flat-contacts point" if point else "") + (" --depth-cm 20" if deep else ""))


def experiments_run(gate_cm, count, seed):
    """The folder of crosses_dam_break's run (with the map's model) that is this column and
    seed, or None: in the experiments' box its columns are among the map's (column_of),
    and its runs pour with the case's seed."""
    if seed != SEED or gate_cm not in CROSSES or column_of(gate_cm, count) != column(gate_cm):
        return None
    return os.path.join(RESULTS, "runs", model.dam_break, f"L{gate_cm:g}cm_seed{seed}")


def last_segment(run):
    """The last `done:` line of the run's run.log ('' if none): what identifies a run."""
    path = os.path.join(run, "run.log")
    if not os.path.exists(path):
        return ""
    done = [line.strip() for line in open(path) if line.startswith("done:")]
    return done[-1] if done else ""


def copy_experiments_run(source, out):
    """Copies crosses_dam_break's finished run `source` as the map's run `out` (the same
    column, seed and model: the same steps, so it is not run twice), with COPIED_FROM
    saying from where, when, and the source's last segment (copied_source). The copy is
    made under another name and renamed once whole: an interrupted copy leaves no folder
    that could pass for the map's own run. The source is taken as it is: it must be of the
    current build, like every run the report names."""
    partial = out + ".partial"
    shutil.rmtree(partial, ignore_errors=True)
    shutil.copytree(source, partial)
    with open(os.path.join(partial, COPIED_FROM), "w") as f:
        f.write(f"{os.path.relpath(source, ROOT)}\n"
                f"{time.strftime('%Y-%m-%d %H:%M', time.gmtime())} UTC\n{last_segment(source)}\n")
    os.rename(partial, out)


def copied_source(run):
    """(source folder, copy date, the source's last segment when copied) of a run copied by
    copy_experiments_run, or None for a run of the map's own."""
    path = os.path.join(run, COPIED_FROM)
    if not os.path.exists(path):
        return None
    source, date, segment = (open(path).read().split("\n") + ["", ""])[:3]
    return os.path.join(ROOT, source), date, segment


def copy_note(gate_cm, count, seed, run):
    """The report's note on a copied run: whose it is, its own wall time and threads (its
    stops, listed in its case's PAUSES.txt, left out), and whether the source has changed."""
    source, date, segment = copied_source(run)
    threads = re.findall(r"^threads\s+(\d+) requested", open(os.path.join(run, "run.log")).read(),
                         re.M)
    stopped_s = stopped_seconds(counted_intervals(run), stops(os.path.dirname(source)))
    changed = ("" if last_segment(source) == segment else
               " The dam break's run has changed (or gone) since: this is the earlier run.")
    return (f"Gate {gate_cm:g} cm, {count} crosses, seed {seed}: crosses_dam_break's column "
            f"and seed with this model, so its run {os.path.relpath(source, ROOT)} is copied "
            f"({date}), not run again: {(wall_time(run) - stopped_s) / 3600:.2f} h on "
            f"{threads[-1] if threads else '?'} thread(s), not in this map's run time "
            f"({stopped_s / 60:.1f} min of stops left out, its case's PAUSES.txt).{changed}")


def accounted(gate_cm, count, seed, run, stop_list):
    """What the map's run time counts of a run: (its wall time less its stops [s], those
    stops [s], its counted_intervals, None); a run copied from crosses_dam_break counts
    nothing, (0, 0, [], copy_note), since this map did not run it."""
    if copied_source(run):
        return 0.0, 0.0, [], copy_note(gate_cm, count, seed, run)
    intervals = counted_intervals(run)
    stopped_s = stopped_seconds(intervals, stop_list)
    return wall_time(run) - stopped_s, stopped_s, intervals, None


def dam_break_pour_notes(columns, seeds):
    """The report's notes on the dam break's columns mapped without the case's seed: that
    pour is the dam break's own run with this model (experiments_run), in its own section,
    not in this map; crosses_runout counts it with this map's pours of the column."""
    if SEED in seeds:
        return []
    return [f"Gate {g:g} cm, {n} crosses: the case's seed ({SEED}) is {model.dam_break}'s own "
            f"pour of this column, left out of this map (--seeds {' '.join(map(str, seeds))}); "
            "its outcome is in that case's section, and crosses_runout counts it with this "
            "map's pours." for g, n in columns if experiments_run(g, n, SEED)]


def run_one(exe, gate_cm, count, seed):
    """Pour, open and collapse one column and seed (one thread; map_columns analyses it),
    or copy crosses_dam_break's finished run of it (experiments_run)."""
    out = folder(gate_cm, count, seed)
    if copied_source(out):  # copied already: finished, and not the map's to continue
        return
    source = experiments_run(gate_cm, count, seed)
    if source and not os.path.exists(out) and unfinished(source) is None:
        copy_experiments_run(source, out)
        return
    run_column(exe, column_of(gate_cm, count), out, 1,
               extra=model.settings + seed_settings(seed))


def unfinished(run):
    """Why the run in `run` cannot be mapped yet (None when it has finished): missing, still
    pouring (the gate in place), or stopped in the collapse before it was at rest or had run
    COLLAPSE_S."""
    if not os.path.exists(os.path.join(run, "diagnostics.csv")):
        return "not run"
    opening = opening_time(run)
    if opening >= 1e5:
        return "stopped in the pour"
    last = diagnostics(run)[-1]["time_s"]
    if last < opening + COLLAPSE_S - 1e-6 and not ended_at_rest(run):
        return f"stopped in the collapse at {last:g} s (opened at {opening:g} s)"
    return None


def column_key(gate_cm, count):
    """A column as the map keys it: (gate [cm], crosses), a whole gate as an int."""
    gate = float(gate_cm)
    return (int(gate) if gate == int(gate) else gate, int(count))


def summary_path():
    """This map's summary, the file run_all.py reads (write_summary)."""
    return os.path.join(RESULTS, model.name + ".json")


def finished_columns(seeds):
    """The columns of this map's folder whose runs of every seed have finished: those of
    earlier calls with other --columns too. The map reports them all, so that a call that
    runs one more column does not drop the others from the report."""
    found = []
    runs = model.runs()
    for name in sorted(os.listdir(runs)) if os.path.isdir(runs) else []:
        m = re.fullmatch(r"L(\d+(?:\.\d+)?)cm_(\d+)", name)
        if m:
            key = column_key(m.group(1), m.group(2))
            if all(unfinished(folder(*key, s)) is None for s in seeds):
                found.append(key)
    return found


def columns_in_summary():
    """The columns (gate, crosses) of this map's full summary on disk (results/NAME.json,
    its per-run table), [] where there is none or it was written by --quick."""
    path = summary_path()
    if not os.path.isfile(path):
        return []
    with open(path) as f:
        summary = json.load(f)
    if summary.get("quick"):
        return []
    found = set()
    for table in summary.get("tables", []):
        if table["header"][:2] == ["gate [cm]", "crosses"]:
            found.update(column_key(row[0], row[1]) for row in table["rows"])
    return sorted(found)


def dropped_columns(columns):
    """The columns of the summary on disk that this call would leave out of it: their runs
    are not on disk (a fresh checkout holds the summaries, not the runs) and this call does
    not run them."""
    return [c for c in columns_in_summary() if c not in columns]


def in_run_order(columns, seeds):
    """(gate, count, seed) of every run in the order run_all starts them: the columns of
    most crosses first (the longest runs: two at a time then ends with short ones)."""
    return [(g, n, s) for g, n in sorted(columns, key=lambda c: -c[1]) for s in seeds]


def run_all(exe, columns, seeds):
    """run_one for every column and seed, two at a time, in_run_order; the first failure
    (or Ctrl-C) cancels the runs not yet started and is raised once the running ones end."""
    call_two_at_a_time([functools.partial(run_one, exe, g, n, s)
                        for g, n, s in in_run_order(columns, seeds)])


def point_folder(gate_cm, count):
    """The folder of a column's ensemble.csv (`sanguis analyze` of its runs)."""
    return os.path.join(model.runs(), "points", f"L{gate_cm:g}cm_{count}")


def map_columns(exe, columns, seeds):
    """Each column's runs analysed together (ensemble.csv), then `sanguis flow-map` of them
    all; returns the map's rows by (gate, count) and draws the figure."""
    points = []
    for gate_cm, count in columns:
        runs = [folder(gate_cm, count, s) for s in seeds]
        point = point_folder(gate_cm, count)
        shutil.rmtree(point, ignore_errors=True)
        subprocess.run([exe, "analyze", *runs, "--out", point], check=True,
                       stdout=subprocess.DEVNULL)
        points.append(point)
    subprocess.run([exe, "flow-map", *points, "--output", model.map()], check=True,
                   stdout=subprocess.DEVNULL)
    os.makedirs(os.path.dirname(model.figure()), exist_ok=True)
    shutil.copyfile(os.path.join(model.map(), "flow_map.png"), model.figure())
    with open(os.path.join(model.map(), "flow_map.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    return {key: row for key, row in zip(columns, rows)}


def at_rest_at_opening(run, opening):
    """The mean speed [m/s] of the last diagnostics row at or before the opening [s]."""
    return [r for r in diagnostics(run) if r["time_s"] <= opening + 1e-9][-1]["mean_velocity_m_s"]


def run_row(gate_cm, count, seed, s, seconds):
    return [f"{gate_cm:g}", f"{count}", f"{seed}", f"{100 * s['H0_m']:.1f}",
            f"{s['aspect_ratio_H0_over_L0']:.2f}", f"{s['runout_ratio']:.2f}",
            f"{s['height_ratio_H0_over_Hinf']:.2f}", f"{s['peak_mean_speed_over_sqrt_gH0']:.3f}",
            regime_name(s), f"{seconds / 3600:.2f}"]


def outcome_text(row):
    if row["outcome"] != "intermittent":
        return f"{row['outcome']} (repeatable)"
    return ("intermittent: " + ", ".join(f"{row[r]} {r}" for r in ("collapsed", "fractured",
                                                                   "stable") if row[r] != "0"))


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--quick", action="store_true",
                    help="the 4 cm gate's 150 crosses (500 with --depth-cm 20), seeds 1 and 2")
    ap.add_argument("--columns", nargs="+", metavar="GATE_CM:CROSSES",
                    help="columns to run (default " + " ".join(f"{g}:{n}" for g, n in COLUMNS)
                    + ")")
    ap.add_argument("--seeds", type=int, nargs="+", help="packings (default 1 2 3)")
    ap.add_argument("--reuse", action="store_true", help="analyse the runs on disk")
    ap.add_argument("--drop-missing", action="store_true",
                    help="write the summary even where it drops columns of the one on disk "
                    "whose runs are not on disk (by default the call stops before running)")
    ap.add_argument("--depth-cm", type=int, choices=(6, 20), default=6,
                    help="the box's depth: 6 (the memory case's column, the default) or 20 "
                    "(the experiments' box; the map's runs, folder and report get the "
                    f"suffix {DEEP_SUFFIX}, and its default columns are "
                    + " ".join(f"{g}:{n}" for g, n in DEEP_COLUMNS) + ")")
    add_contact_model_options(ap, SUM.name, "with Table 3.1")
    args = ap.parse_args(argv)
    global model, depth_m
    mean, point = contact_model(ap, args)
    model = (MEAN_POINT if point else MEAN) if mean else SUM
    depth_m = args.depth_cm / 100.0
    deep = args.depth_cm == 20
    if deep:
        model = model.in_experiments_box()
    columns = default_columns(deep, args.quick)
    if args.columns:
        try:
            columns = [column_key(g, n) for g, n in (c.split(":") for c in args.columns)]
        except ValueError:
            ap.error("--columns: give GATE_CM:CROSSES, e.g. 4:300")
        if any(g <= 0 or n < 1 for g, n in columns):
            ap.error("--columns: the gate and the crosses must be positive")
    columns = list(dict.fromkeys(columns))  # one run folder per column and seed
    seeds = list(dict.fromkeys(args.seeds or (QUICK_SEEDS if args.quick else SEEDS)))
    if len(seeds) < 2:
        ap.error("--seeds: a column's outcome needs at least two packings")
    exe = os.path.join(ROOT, args.build, "app", "sanguis")
    if not args.quick and not args.drop_missing:
        dropped = dropped_columns(set(columns) | set(finished_columns(seeds)))
        if dropped:
            sys.exit(f"{os.path.relpath(summary_path(), ROOT)} "
                     "holds columns whose runs are not on disk and that this call does not "
                     "run: " + " ".join(f"{g:g}:{n}" for g, n in dropped) + ". Add them to "
                     "--columns to run them again, or pass --drop-missing to write a summary "
                     "without them.")
    t0 = time.time()
    if not args.reuse:
        run_all(exe, columns, seeds)
    left = [f"{folder(g, n, s)}: {why}" for g, n, s in in_run_order(columns, seeds)
            if (why := unfinished(folder(g, n, s)))]
    if left:
        sys.exit("not mapped, runs not finished (run without --reuse to finish them):\n"
                 + "\n".join(left))
    if not args.quick:  # a quick map stays the quick columns
        columns = sorted(set(columns) | set(finished_columns(seeds)))
    rows = map_columns(exe, columns, seeds)

    stop_list = stops(model.runs())
    counted, table, sanity, tall_runs, unsettled, copies = [], [], [], [], [], []
    durations, paused = {}, 0.0
    for gate_cm, count in columns:
        for seed in seeds:
            run = folder(gate_cm, count, seed)
            s = read_summary(run)
            opening = opening_time(run)
            end = stopped(run, opening)
            if end.startswith("ran the full"):
                unsettled.append(f"Gate {gate_cm:g} cm, {count} crosses, seed {seed}: the "
                                 f"collapse {end}.")
            seconds = wall_time(run)
            duration, stopped_s, intervals, note = accounted(gate_cm, count, seed, run,
                                                             stop_list)
            durations[(gate_cm, count, seed)] = duration
            paused += stopped_s
            counted += intervals
            copies += [note] if note else []
            table.append(run_row(gate_cm, count, seed, s, seconds))
            sanity.append(at_rest_at_opening(run, opening))
            if s["H0_m"] > TALL_M:
                tall_runs.append((gate_cm, count, seed, regime_name(s)))
    # The runs' wall times laid out two at a time in the order they started.
    elapsed = pool_span([durations[key] for key in in_run_order(columns, seeds)])
    tall_collapsed = sum(r[3] == "collapsed" for r in tall_runs)
    tall_moved = sum(r[3] != "stable" for r in tall_runs)
    tall_ok = bool(tall_runs) and tall_collapsed == len(tall_runs)
    sane = max(sanity) < 1e-3
    ok = sane and (tall_ok or not tall_runs)
    tall_measured = ("no column above 20 cm was run" if not tall_runs else
                     f"{tall_collapsed} of {len(tall_runs)} collapsed ("
                     + ", ".join(f"{g:g} cm, {n} crosses, seed {x}: {r}"
                                 for g, n, x, r in tall_runs) + ")")
    checks = [{"quantity": "runs of columns taller than 20 cm that collapse",
               "measured": tall_measured,
               "thesis": "all: \"tall columns of initial height H0 greater than 20 cm always "
                         "result in an avalanche\" (§3.3.1, its simulations)",
               "tolerance": "every run", "pass": tall_ok if tall_runs else None},
              {"quantity": "sanity: largest mean speed at the opening [m/s]",
               "measured": f"{max(sanity):.1e}", "thesis": "—", "tolerance": "< 1e-3",
               "pass": sane}]
    for (gate_cm, count), row in rows.items():
        checks.append({"quantity": f"gate {gate_cm:g} cm, {count} crosses: H0 [cm], a; "
                                   "outcome of its runs",
                       "measured": f"{100 * float(row['H0_m']):.1f}, "
                                   f"{float(row['aspect_ratio_H0_over_L0']):.2f}; "
                                   + outcome_text(row),
                       "thesis": "Fig. 3.6 (qualitative)", "tolerance": "reported",
                       "pass": None})
    intermittent = [key for key, row in rows.items() if row["outcome"] == "intermittent"]
    notes = [
        "Outcomes as `sanguis flow-map` gives them (docs/analysis.md): repeatable when every "
        "run of a column ends in one regime, intermittent otherwise. The thesis calls a "
        "column intermittent when the packing decides between an avalanche and a column "
        "that stands; a column whose runs collapse or fracture by packing is intermittent "
        "here too.",
        f"Intermittent columns: {len(intermittent)} of {len(rows)}"
        + (" (" + "; ".join(f"gate {g:g} cm, {n} crosses" for g, n in intermittent) + ")"
           if intermittent else "") + ".",
        ("Columns taller than 20 cm: " + f"{tall_moved} of {len(tall_runs)} runs avalanched "
         "at all (collapsed or fractured, not stable)." if tall_runs else
         "No column above 20 cm in this run (--quick or --columns)."),
    ] + (["The element contacts of two crosses (up to four pairs of arms), and of a cross "
          "and a wall, are averaged, as Grains3D, the code of the thesis' crosses, does for "
          "composite particles (simulation.element_contacts = \"mean\"), in the pours and "
          "the collapses" + (f"; and {ONE_POINT_PER_PAIR}." if point else ".")]
         if mean else []) + [
        ("The box is the experiments' 20 cm deep one, the case's own (--depth-cm 20), as in "
         "crosses_dam_break: 3.3 times the crosses of the 6 cm deep map for the same "
         "heights, but for the tall column, crosses_dam_break's own 1300 crosses (about "
         "22 cm, against the narrow map's 26). The thesis does not give the depth of the "
         "columns of its map; its simulations of the experiments' box hold 1300 to 7000 "
         "crosses (§3.2.3)." if deep
         else "The box is 6 cm deep (the back side wall moved, the memory case's column), "
         "not the experiments' 20 cm: the same heights with 3.3 times fewer crosses. The "
         "thesis does not give the depth of the columns of its map."),
        "Runs on one thread, two at a time, on the 2-core VM; the run time lays their wall "
        "times (finished segments: a run stopped and continued counts once) two at a time "
        "in the order they started, the columns of most crosses first"
        + (" (a run copied from crosses_dam_break counts nothing: see its note)." if copies
           else "."),
    ] + copies + dam_break_pour_notes(columns, seeds) + (
        [paused_note(paused / 60, model.name)] if paused > 0 else [])
    summary = {
        "name": model.name,
        "title": "Flow-regime map of crosses: repeatable and intermittent columns"
                 + contact_model_title(mean, point)
                 + (", in the experiments' 20 cm deep box" if deep else ""),
        "thesis": "§3.3.1, Fig. 3.6",
        "description": "Columns of crosses behind the gates of crosses_dam_break's box "
                       f"(Table 3.1, {model.words}), {args.depth_cm} cm deep: "
                       + ", ".join(f"{n} crosses at {g:g} cm" for g, n in columns)
                       + f", each poured with seeds {', '.join(map(str, seeds))} and "
                       "released at rest with the gate removed at once; each run classified "
                       "by `sanguis analyze`, each column's runs mapped by `sanguis flow-map`.",
        "command": f"/usr/bin/python3 {command_script(mean, point, deep)} --build BUILD"
                   + (" --quick" if args.quick else "")
                   + (" --columns " + " ".join(f"{g:g}:{n}" for g, n in columns)
                      if set(columns) != set(default_columns(deep, args.quick)) else "")
                   + (" --seeds " + " ".join(map(str, seeds)) if args.seeds else ""),
        "figures": [os.path.relpath(model.figure(), ROOT)],
        "checks": checks,
        "tables": [{"caption": "Per run (`sanguis analyze`).",
                    "header": ["gate [cm]", "crosses", "seed", "H0 [cm]", "a", "(L∞−L0)/L0",
                               "H0/H∞", "peak v/√(gH0)", "regime",
                               "wall time of finished segments [h]"],
                    "rows": table}],
        "notes": notes + unsettled,
    }
    write_summary(summary, RESULTS, elapsed, args.quick, ok, counted)
    print(f"{'PASS' if ok else 'FAIL'}: {tall_measured}; intermittent {len(intermittent)} of "
          f"{len(rows)} columns; {time.time() - t0:.0f} s")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
