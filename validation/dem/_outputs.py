"""What the validation scripts read from sanguis run folders: the frames (VTK XML,
binary base64, UInt64 headers, Float64 / Int64 arrays) as numpy arrays, and the
summary row of `sanguis analyze`. Not a general VTK reader."""
import base64
import calendar
import csv
import heapq
import json
import os
import re
import shutil
import subprocess
import sys
import time
import tomllib
import xml.etree.ElementTree as ET
from concurrent.futures import ThreadPoolExecutor

import numpy as np

_ARRAY = re.compile(r'<DataArray([^>]*)>\s*([A-Za-z0-9+/=\s]*?)\s*</DataArray>', re.S)


def _attributes(text):
    return dict(re.findall(r'(\w+)="([^"]*)"', text))


def read_arrays(path):
    """Every Float64/Int64 DataArray of a .vtu/.vtp file, by name (points: 'Points')."""
    with open(path) as f:
        text = f.read()
    arrays = {}
    for attrs, payload in _ARRAY.findall(text):
        a = _attributes(attrs)
        kind = {"Float64": "<f8", "Int64": "<i8"}.get(a.get("type"))
        if kind is None:
            continue
        raw = base64.b64decode("".join(payload.split()))
        count = int(np.frombuffer(raw[:8], "<u8")[0])
        values = np.frombuffer(raw[8:8 + count], kind)
        components = int(a.get("NumberOfComponents", "1"))
        arrays[a["Name"]] = values.reshape(-1, components) if components > 1 else values
    return arrays


def read_pvd(path):
    """(time, absolute dataset path) of every frame of a .pvd index."""
    root = ET.parse(path).getroot()
    base = os.path.dirname(os.path.abspath(path))
    return [(float(d.get("timestep")), os.path.join(base, d.get("file")))
            for d in root.iter("DataSet")]


def gate_removal_time(case_path):
    """remove_at_s of the case's obstacle named "gate" [s]: the one place the opening
    time is set, so that the scripts continuing a pour of that case agree with it."""
    with open(case_path, "rb") as f:
        case = tomllib.load(f)
    for obstacle in case.get("obstacle", []):
        if obstacle.get("name") == "gate":
            return float(obstacle["remove_at_s"])
    raise ValueError(f"{case_path}: no obstacle named 'gate' with remove_at_s")


def regime_name(summary):
    """The flow regime of a `sanguis analyze` summary row, in words."""
    return ("stable", "fractured", "collapsed")[int(summary["regime"])]


def speed_landmarks(t, v, line=0.05):
    """Of a mean-speed curve (t / tau_c, speed / sqrt(g H0)): the peak, its time and the
    time from which the speed stays below `line` to the end of the curve (inf if it ends
    above; a collapse that halts and goes on, Fig. 3.10, ends at its last stop; the peak's
    own time if the peak is below the line): the three figures the thesis gives for each
    curve of Fig. 3.9a."""
    peak = max(range(len(v)), key=lambda i: v[i])
    last_above = max((i for i in range(peak, len(v)) if v[i] >= line), default=None)
    if last_above is None:
        below = t[peak]
    else:
        below = t[last_above + 1] if last_above + 1 < len(v) else float("inf")
    return v[peak], t[peak], below


def element_contacts_setting(rule):
    """The `sanguis run` override of simulation.element_contacts ("sum" or "mean": how the
    element contacts of two composite bodies add up)."""
    return ["--set", f'simulation.element_contacts="{rule}"']


def flat_contacts_setting(kind):
    """The `sanguis run` override of simulation.flat_contacts ("patch" or "point": how flat
    faces of two bodies touch)."""
    return ["--set", f'simulation.flat_contacts="{kind}"']


def add_contact_model_options(ap, name, detail):
    """--element-contacts and --flat-contacts, the options with which crosses_column_width,
    crosses_dam_break, crosses_flow_map and crosses_tangential_packings run Grains3D's
    contact model, in the folders and report NAME_mean (--element-contacts mean) or
    NAME_mean_point (and --flat-contacts point); `detail` says what else those runs take
    (their tangential parameters). Read them back with contact_model()."""
    ap.add_argument("--element-contacts", choices=["sum", "mean"], default="sum",
                    help="how the element contacts of two crosses add up (simulation."
                         f"element_contacts): mean, as Grains3D, {detail}, in its own "
                         f"folders and report ({name}_mean)")
    ap.add_argument("--flat-contacts", choices=["patch", "point"], default="patch",
                    help="with --element-contacts mean, point: one contact point per element "
                         "pair (simulation.flat_contacts) too, Grains3D's whole model, in its "
                         f"own folders and report ({name}_mean_point)")


def contact_model(ap, args):
    """(mean, point) from the options of add_contact_model_options: the element contacts
    averaged, one contact point per element pair. One point alone is refused (exit 2):
    only Grains3D's whole model takes it."""
    mean, point = args.element_contacts == "mean", args.flat_contacts == "point"
    if point and not mean:
        ap.error("--flat-contacts point runs with --element-contacts mean (Grains3D's model)")
    return mean, point


# Lajeunesse, Monnier & Homsy, Phys. Fluids 17 (2005), quasi-2D channel on a rough bottom:
# (L_inf - L0)/L0 = 1.2 a for a < 1.8 and 1.9 a^(2/3) for a > 2.8. The two fits differ by
# 20 % in between, so the reference takes each as published and switches halfway.
LAJEUNESSE_SWITCH = 2.3


def lajeunesse(a):
    """Lajeunesse et al.'s run-out (L_inf - L0)/L0 of spheres at aspect ratio a."""
    return 1.2 * a if a < LAJEUNESSE_SWITCH else 1.9 * a ** (2.0 / 3.0)


def contact_model_suffix(mean, point):
    """What the model adds to a case's name (its runs' folder, figure and report)."""
    return ("_mean" if mean else "") + ("_point" if point else "")


def contact_model_title(mean, point):
    """What the model adds to a report's title (nothing for the defaults)."""
    return ((", element contacts averaged as in Grains3D" if mean else "")
            + (", one contact point per element pair" if point else ""))


def contact_model_settings(mean, point):
    """The `sanguis run` overrides of the model (none for the defaults, the sum and the
    patches)."""
    return ((element_contacts_setting("mean") if mean else [])
            + (flat_contacts_setting("point") if point else []))


# What one contact point per element pair is, for the notes of the cases that run
# Grains3D's whole model (the mean and one point).
ONE_POINT_PER_PAIR = ("one contact point per pair of touching elements (simulation.flat_contacts "
                      "= \"point\", GJK's closest points), where the model's default spreads "
                      "a contact between flat faces over a patch (docs/theory/dem.md, \"Flat "
                      "contacts\")")


def read_summary(run_dir):
    """The one row of RUN/analysis/summary.csv (written by `sanguis analyze`) as floats."""
    with open(os.path.join(run_dir, "analysis", "summary.csv"), newline="") as f:
        return {k: float(v) for k, v in next(csv.DictReader(f)).items()}


def calibration_value_folder(calibration_dir, value):
    """The run folder of a value in a `sanguis calibrate` output (named value_V, V the
    value's shortest exact form, which Python's formats do not always reproduce)."""
    for name in os.listdir(calibration_dir):
        if name.startswith("value_") and float(name[len("value_"):]) == value:
            return os.path.join(calibration_dir, name)
    raise FileNotFoundError(f"no run folder for the value {value:g} in {calibration_dir}")


def finished_segments(run):
    """(simulated end time [s], wall-clock seconds) of each segment of the run: the `done:`
    lines of its run.log (a restarted run has one per segment). A segment that was
    stopped on the way (a killed call, an ended session) counts up to its last
    `checkpoint:` line, the part a restart keeps; what it ran past that is lost and not
    counted."""
    return _segments(log_lines(run))


def log_lines(run):
    """The lines of the run's run.log, [] where it has none."""
    path = os.path.join(run, "run.log")
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return f.readlines()


def _segments(lines):
    """finished_segments of these lines of a run.log."""
    return [(end, seconds) for end, seconds, _ in _stamped_segments(lines)]


def utc_seconds(text, fmt="%Y-%m-%d %H:%M:%S"):
    return calendar.timegm(time.strptime(text, fmt))


def _stamped_segments(lines):
    """(simulated end [s], wall-clock seconds, UTC end [s since the epoch] or None) of each
    counted segment of these run.log lines: the end's date is the `done:` line's "ended"
    or the kept checkpoint's (lines written since 2026-12-05 carry one)."""
    units = {"h": 3600, "m": 60, "s": 1}
    kept = None  # the last checkpoint of the segment being read
    out = []
    for line in lines:
        if line.startswith("--- restart") and kept:
            out.append(kept)
            kept = None
        m = re.search(r"steps in (\S+)", line)
        end = re.search(r"t = (\S+) s", line)
        if not (m and end) or not line.startswith(("done:", "checkpoint:")):
            continue
        stamp = re.search(r"(\d{4}-\d{2}-\d{2} \d{2}:\d{2}:\d{2}) UTC", line)
        segment = (float(end.group(1)),
                   sum(int(n) * units[u] for n, u in re.findall(r"(\d+)([hms])", m.group(1))),
                   utc_seconds(stamp.group(1)) if stamp else None)
        if line.startswith("done:"):
            out.append(segment)
            kept = None
        else:
            kept = segment
    if kept:
        out.append(kept)
    return out


# The contact patches' torsional spring changed at this time (UTC; docs/theory/dem.md,
# "The torsional spring until 2026-12-05 evening"): run segments started later use the
# spread spring with its moment as memory (checkpoints CK4), earlier ones the corners'.
TWIST_MOMENT_FROM = "2026-12-05 22:25:00"
# What the change did where it was measured (2026-12-05, 22:54-23:04 UTC, AMD EPYC VM).
TWIST_MOMENT_EFFECT = (
    "Measured on the three 300-cross pours of crosses_tangential_packings (Table 3.1, 0.5 s "
    "after the opening, both models from the same checkpoints): the height lost was 3.4, 1.1 "
    "and 1.4 % of H0 against 4.4, 1.0 and 1.2 % before, region 3 on each either way, and a "
    "step cost 5-7 % more (less since: docs/performance.md, \"The spread torsional spring\").")


def segment_starts(run):
    """When each segment of the run started, from its run.log's start and restart lines:
    the UTC date ("YYYY-MM-DD HH:MM:SS") where the line has one (since 2026-12-05), else
    None."""
    out = []
    for line in log_lines(run):
        if ", started " in line or line.startswith("--- restart from checkpoint"):
            m = re.search(r"(\d{4}-\d{2}-\d{2} \d{2}:\d{2}:\d{2}) UTC", line)
            out.append(m.group(1) if m else None)
    return out


def span(values, fmt):
    """'a-b' for the smallest and largest of the values ('a to b' when a is negative, which
    a dash would garble), or 'a' when they print alike."""
    low, high = format(min(values), fmt), format(max(values), fmt)
    if low == high:
        return low
    return f"{low} to {high}" if min(values) < 0 else f"{low}-{high}"


def uncounted_spans(run):
    """(from, to) simulated times [s] the run went through with no wall time on record: a
    segment stopped before run.log recorded checkpoints (logs written before 2026-12-03)
    leaves no line, yet the restart after it starts from a later checkpoint than the last
    one counted. wall_time leaves these spans out; a report should say so."""
    lines = log_lines(run)
    spans = []
    for i, line in enumerate(lines):
        m = re.match(r"--- restart from checkpoint at t = (\S+) s", line)
        if not m:
            continue
        last = max((end for end, _ in _segments(lines[:i])), default=0.0)
        if float(m.group(1)) > last + 1e-9:
            spans.append((last, float(m.group(1))))
    return spans


def reached_time(run):
    """The latest simulated time [s] a segment of the run finished or left a checkpoint at,
    0 when none did."""
    return max((end for end, _ in finished_segments(run)), default=0.0)


def pour_command(cmd, out, end_s, rerun=False):
    """The command that brings the pour in `out` to end_s, or None when a run got there.
    `cmd`: `sanguis run` with its output folder and overrides, without the end time. A pour
    stopped on the way (a killed run leaves the checkpoint of an earlier time, which is not
    the opening's) is continued from that checkpoint, the same bits as one run; `rerun`
    clears the folder and starts afresh."""
    if rerun:
        shutil.rmtree(out, ignore_errors=True)
    checkpoint = os.path.exists(os.path.join(out, "checkpoint.bin"))
    if checkpoint and reached_time(out) >= end_s - 1e-9:
        return None
    return cmd + (["--restart"] if checkpoint else []) + ["--set", f"simulation.end_time_s={end_s}"]


def run_pour(cmd, out, end_s, rerun=False):
    """Runs pour_command's command, if any, so that the pour in `out` stands at end_s;
    False when an earlier run had got there (nothing ran)."""
    command = pour_command(cmd, out, end_s, rerun)
    if command:
        subprocess.run(command, check=True)
    return bool(command)


def command_record(cmd):
    """A `sanguis run` command as its folder's record keeps it: without the program and the
    output folder, which do not change what it computes."""
    kept, skip = [], False
    for arg in cmd[1:]:
        if skip:
            skip = False
        elif arg in ("--output", "-o"):
            skip = True
        else:
            kept.append(arg)
    return " ".join(kept)


def continue_or_copy(out, start_from, record_line):
    """Prepares `out`, a run continued from the run folder `start_from`: True when `out`
    holds a continuation stopped on the way whose start record (continuation.txt) is
    `record_line` and a checkpoint, which a restart takes on to the bits of one run;
    otherwise the folder starts again as a copy of `start_from` with that record (False)."""
    record = os.path.join(out, "continuation.txt")
    if (os.path.exists(record) and open(record).read().strip() == record_line
            and os.path.exists(os.path.join(out, "checkpoint.bin"))):
        return True
    shutil.rmtree(out, ignore_errors=True)
    shutil.copytree(start_from, out)
    with open(record, "w") as f:
        f.write(record_line + "\n")
    return False


def continuation_command(cmd, out, start_from, after_s):
    """The command that takes `out`, a run continued from the run folder `start_from` (a
    pour) past after_s [s], to its end, or None when an earlier call got there. `cmd`: the
    `sanguis run ... --restart` of it; a continuation stopped on the way goes on from its
    own checkpoint (continue_or_copy)."""
    if continue_or_copy(out, start_from, command_record(cmd)) and \
            any(t > after_s + 1e-9 for t in done_times(out)):
        return None
    return cmd


def done_times(run):
    """The simulated end time [s] of each `done:` line of the run's log: the segments that
    ran to their end (or stopped at rest)."""
    path = os.path.join(run, "run.log")
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return [float(m.group(1)) for m in (re.match(r"done: t = (\S+) s", line) for line in f)
                if m]


def wall_time(run, after=-1.0):
    """Wall-clock seconds of the run: the sum of its finished segments, or of those that
    ended after time `after` [s]."""
    return sum(seconds for end, seconds in finished_segments(run) if end > after + 1e-9)


def pool_span(durations, workers=2):
    """Wall-clock seconds of jobs of these durations run by a pool of `workers` in this
    order, each started as soon as any worker is free (concurrent.futures' executors)."""
    free = [0.0] * workers
    for d in durations:
        start = heapq.heappop(free)
        heapq.heappush(free, start + d)
    return max(free)


def run_two_at_a_time(jobs, base):
    """Runs the (command, folder) jobs two at a time, waiting on the older of the two
    running, and names each as it starts by its folder relative to `base`; exits on the
    first failure."""
    running = []
    while jobs or running:
        while jobs and len(running) < 2:
            cmd, d = jobs.pop(0)
            print(f"started {os.path.relpath(d, base)}", flush=True)
            running.append((subprocess.Popen(cmd, stdout=subprocess.DEVNULL), d))
        proc, d = running.pop(0)
        if proc.wait() != 0:
            sys.exit(f"run failed: {d}")


def call_two_at_a_time(calls):
    """Runs the calls (functions of no argument, each running its jobs in this process)
    two at a time; the first failure (or Ctrl-C) cancels the calls not yet started and is
    raised once the running ones end."""
    with ThreadPoolExecutor(max_workers=2) as pool:
        jobs = [pool.submit(call) for call in calls]
        try:
            for job in jobs:
                job.result()
        except BaseException:
            pool.shutdown(wait=True, cancel_futures=True)
            raise


def two_at_a_time_span(durations):
    """Wall-clock seconds of jobs of these durations run two at a time in this order, the
    next one started when the older of the two running finishes (as the scripts' runners
    wait on them): what a phase of runs reused from an earlier call took."""
    now, running = 0.0, []
    for d in durations:
        if len(running) == 2:
            now = max(now, running.pop(0))
        running.append(now + d)
    return max([now] + running)


def stops(runs_dir):
    """(start, end) [UTC s since the epoch] of each stop of a case's runs (SIGSTOP, while
    benchmarks or CI used the cores) listed in RUNS_DIR/PAUSES.txt, one per line: its date
    to the minute or the second, then its length, "2026-12-06T13:18 stopped for the CI of
    c8ee68c (5.1 min)"; [] without that file. Lines without a length (a note that a session
    ended) are no stops. A stop dated to the minute is taken to start on that minute, which
    the one who stopped the runs wrote when they did: up to a minute early."""
    path = os.path.join(runs_dir, "PAUSES.txt")
    if not os.path.exists(path):
        return []
    out = []
    with open(path) as f:
        for number, line in enumerate(f, 1):
            length = re.search(r"(?:\(|about )([0-9]+(?:\.[0-9]+)?) min", line)
            if not length:
                continue
            date = re.match(r"(\d{4}-\d{2}-\d{2})T(\d{2}:\d{2}(?::\d{2})?)", line)
            if not date:
                sys.exit(f"{path}:{number}: a stop of {length.group(1)} min without a date: "
                         "begin the line with YYYY-MM-DDTHH:MM, when the runs were stopped "
                         "(the run time leaves out the stops that fall in its runs)")
            clock = date.group(2) + ("" if date.group(2).count(":") == 2 else ":00")
            start = utc_seconds(f"{date.group(1)} {clock}")
            out.append((start, start + 60.0 * float(length.group(1))))
    return out


def _merged(intervals):
    """The union of (start, end) intervals, as disjoint intervals in order."""
    out = []
    for start, end in sorted(intervals):
        if out and start <= out[-1][1]:
            out[-1] = (out[-1][0], max(out[-1][1], end))
        else:
            out.append((start, end))
    return out


def counted_intervals(run, after=-1.0):
    """(start, end) [UTC s since the epoch] of the segments wall_time(run, after) adds
    (a segment without a date, written before 2026-12-05, is left out)."""
    return [(stamp - seconds, stamp) for end, seconds, stamp in
            _stamped_segments(log_lines(run)) if end > after + 1e-9 and stamp is not None]


def runs_utc(intervals):
    """The first start and last end of these counted_intervals, as UTC dates to the minute
    ("YYYY-MM-DD HH:MM"), for a summary's "runs_utc"; None when there are none."""
    if not intervals:
        return None
    return [time.strftime("%Y-%m-%d %H:%M", time.gmtime(t))
            for t in (min(a for a, _ in intervals), max(b for _, b in intervals))]


def stopped_seconds(intervals, stop_list):
    """Seconds of the stops inside the union of these intervals (counted_intervals of one
    run, or of several runs together): what their wall times hold of the stops."""
    return sum(max(0.0, min(end, stop_end) - max(start, stop_start))
               for start, end in _merged(intervals) for stop_start, stop_end in _merged(stop_list))


def paused_note(minutes, name):
    """The report's note on the stops of the case `name` (its runs' PAUSES.txt) that its
    run time leaves out."""
    return (f"The wall times include {minutes:.1f} min in which the runs were stopped "
            "(SIGSTOP) while other work used the cores (listed in "
            f"results/runs/{name}/PAUSES.txt); the run time leaves them out.")


def write_summary(summary, results_dir, elapsed, quick, ok, intervals=()):
    """Completes a case's summary (run time, date, quick, pass, and the span of its runs'
    counted `intervals` when given) and writes it as RESULTS/<name>.json, the file
    run_all.py reads for the report."""
    summary.update({"run_time_s": round(elapsed, 1), "date": time.strftime("%Y-%m-%d %H:%M"),
                    "quick": bool(quick), "pass": bool(ok)})
    if runs_utc(intervals):
        summary["runs_utc"] = runs_utc(intervals)
    with open(os.path.join(results_dir, summary["name"] + ".json"), "w") as f:
        json.dump(summary, f, indent=1)
