#!/usr/bin/python3
"""Hopper discharge: repose angle of the heap against the friction coefficient mu_c
(thesis §2.6.3, Table 2.1, Fig. 2.7).

cases/dem/hopper.toml (Table 2.1: 3000 glass beads, R = 1 mm, 2500 kg/m3, en = 0.45,
delta_max = 0.005 R, rolling friction 0.45 between beads and 0.1 on the walls, bead-wall
friction 0.45) is run with the bead-bead mu_c swept from 0.05 to 0.65
(`--set interaction[0].friction=...`), one pour per seed (`--seeds`, default 4, 5 and 6;
`--quick` runs mu_c = 0.05, 0.5 and 0.65 only), two runs at a time on one core each.
`sanguis analyze` reads each heap twice (docs/analysis.md): the cone fitted through the
whole surface between 20 % and 80 % of the height (`repose_cone_angle_deg`, which the
checks grade) and the surface envelope, the highest point in rings around the apex
(`repose_angle_deg`, shown). The angle of a mu_c is the median over its pours whose
discharge did not jam (one pour's angle moves by degrees with the seed).

Which reading is graded, and on which pours. Until 2026-12-07 the checks graded the
envelope, on seeds 1, 2 and 3. The envelope reads the highest profile around the heap,
which is its shallowest flank, so it is biased low on any heap that is not a perfect
cone, and it spread by up to 7.5 degrees from pour to pour, against 2.8 for the cone fit,
on those 21 pours. On these merits the graded reading became the cone fit (stop 76,
2026-12-07, before any pour of seeds 4-6 had finished). The cone fit of seeds 1-3 had
been seen when that was decided (31.7 degrees at mu_c = 0.5), so those pours no longer
grade: the checks grade the pours of seeds 4, 5 and 6, and the pours of seeds 1-3 found
on disk are shown beside them (table and figure). The tolerances are those fixed before
the first sweep.

Reference: thesis Fig. 2.7 (with Yan et al.'s curve): the angle grows with mu_c and
saturates, at about 36 degrees for mu_c = 0.5. Checks (on the medians of the cone fit):
the angle at mu_c = 0.5
within 15 % of 36 degrees; it grows by more
than 5 degrees from mu_c = 0.05 to 0.5; saturation: the angle at 0.65 within 3 degrees
of the angle at 0.5; sanity: every bead has left the funnel (a bead held there would be
the top view's apex).

Writes validation/dem/results/hopper_repose.json and
docs/validation/figures/hopper_repose.png. Run time on the 2-core machine: about 19 min
per run on one core, two at a time (3000 beads, 3.7e6 steps of Tc/20); `--quick` runs
mu_c = 0.05, 0.5 and 0.65 with three pours each (about 1 h 45 min), the full sweep 7
values with three pours each (about 3.5 h).
Each run stops once the heap is at rest (the case's [stop] table), at the latest at 3 s.
`--reuse` analyses the runs already on disk, runs the missing ones, and continues from its
checkpoint a run the case now takes further (one made when the case ended at 1.6 s).

The runs of the case's seed sit in results/runs/hopper_repose/mu_MU, the others in
mu_MU_seed_S. Every run is analysed again at the end (0.5 s each), so the angles are
always those of the build's `sanguis analyze`.

Usage: /usr/bin/python3 validation/dem/hopper_repose.py [--build build] [--quick] [--reuse]
                                                       [--values MU ...] [--seeds S ...]
"""
import argparse
import concurrent.futures
import csv
import functools
import json
import os
import statistics
import subprocess
import sys
import time
import tomllib

import matplotlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _outputs import (log_lines, read_arrays, read_pvd,  # noqa: E402
                      read_summary, reached_time, wall_time)

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CASE = os.path.join(ROOT, "cases", "dem", "hopper.toml")
RESULTS = os.path.join(ROOT, "validation", "dem", "results")
RUNS = os.path.join(RESULTS, "runs", "hopper_repose")
FIGURE = os.path.join(ROOT, "docs", "validation", "figures", "hopper_repose.png")
FRICTIONS = [0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.65]
QUICK_FRICTIONS = [0.05, 0.5, 0.65]
SEEDS = [4, 5, 6]  # the graded pours: three per mu_c, run after the graded reading was chosen
SEEN_SEEDS = [1, 2, 3]  # poured while the envelope was graded: shown, not graded
GRADED = "repose_cone_angle_deg"  # the cone fit through the surface
SHOWN = "repose_angle_deg"  # the surface envelope
PARAMETER = "interaction[0].friction"
THESIS_ANGLE = 36.0  # degrees at mu_c = 0.5 (§2.6.3)
BEAD_DIAMETER = 2e-3  # m (Table 2.1: R = 1 mm)
OUTLET_Z = 0.055  # m: below the funnel's outlet (its walls end at z = 0.0595)


def run_dir(mu, seed=None):
    """The folder of the pour at friction mu with `seed` (None: the case's seed)."""
    name = f"mu_{mu:g}" if seed in (None, case_seed()) else f"mu_{mu:g}_seed_{seed}"
    return os.path.join(RUNS, name)


@functools.cache  # run_dir asks for the case's seed for every file of every pour
def read_case():
    with open(CASE, "rb") as f:
        return tomllib.load(f)


def case_seed():
    return int(read_case()["simulation"]["seed"])


def case_end():
    """(end_time_s, the [stop] table's mean speed [m/s] and check_after_s) of the case."""
    case = read_case()
    stop = case["stop"]
    return (float(case["simulation"]["end_time_s"]), float(stop["mean_velocity_below_m_s"]),
            float(stop.get("check_after_s", 0.0)))


def last_diagnostics(out):
    """(time [s], mean bead speed [m/s]) of the last row of the run's diagnostics.csv."""
    with open(os.path.join(out, "diagnostics.csv"), newline="") as f:
        row = list(csv.DictReader(f))[-1]
    return float(row["time_s"]), float(row["mean_velocity_m_s"])


def run_state(out, end=None):
    """What a run folder needs for the case as it stands: "finished" when it ran to the
    case's end time, stopped at rest, or ended at an output where the case's settle check
    would have stopped it (a run made before the case had its [stop] table: the same bits
    as a run of the case now); "continue" when it has a checkpoint short of that (a
    restart takes it on, the same bits as one run); "fresh" otherwise."""
    end_s, below, after = end or case_end()
    if not os.path.exists(os.path.join(out, "checkpoint.bin")):
        return "fresh"
    lines = [line for line in log_lines(out) if line.startswith("done:")]
    if not lines:
        return "continue" if reached_time(out) > 0 else "fresh"
    if lines[-1].rstrip().endswith("settled") or reached_time(out) >= end_s - 1e-9:
        return "finished"
    t, speed = last_diagnostics(out)
    return "finished" if t >= after and speed < below else "continue"


def run_one(exe, pour, restart):
    """One discharge, pour = (friction, seed), on one core; `restart`: continue the run on
    disk from its checkpoint."""
    mu, seed = pour
    out = run_dir(mu, seed)
    start = time.time()
    subprocess.run([exe, "run", CASE, "--output", out, "--quiet", "--threads", "1",
                    "--set", f"{PARAMETER}={mu}", "--seed", str(seed)]
                   + (["--restart"] if restart else []),
                   check=True,
                   stdout=subprocess.DEVNULL)
    return pour, time.time() - start


def analyse(exe, out):
    subprocess.run([exe, "analyze", out], check=True, stdout=subprocess.DEVNULL)


def pour_median(values, held):
    """Median of the pours' values, the pours that jammed (beads held in the funnel: the
    top view's apex is then a held bead) left out; None when every pour jammed."""
    kept = [v for v, h in zip(values, held) if h == 0]
    return statistics.median(kept) if kept else None


def final_heap(out):
    """(beads of the last frame still above the funnel's outlet, heap top [m])."""
    _, path = read_pvd(os.path.join(out, "particles.pvd"))[-1]
    arrays = read_arrays(path)
    z = arrays["Points"].reshape(-1, 3)[:, 2]
    below = z <= OUTLET_Z
    return int((~below).sum()), float((z[below] + arrays["radius"][below]).max())


def heap_onset_note(frictions, angle, heap_top, flat_below_deg=1.0):
    """What the sweep says about the onset of a heap, from its angles and heap tops [m]:
    the frictions below the first heap spread the beads over the floor (the steep rise over
    [0.05, 0.2] that the thesis reports against Yan et al.)."""
    heaped = [mu for mu in frictions if angle[mu] >= flat_below_deg]
    if not heaped:
        return f"No friction of the sweep forms a heap: every angle is below {flat_below_deg:g}°."
    first = heaped[0]
    flat = [mu for mu in frictions if mu < first]
    if not flat:
        return f"Every friction of the sweep forms a heap ({angle[first]:.1f}° at {first:g})."
    depths = sorted({f"{heap_top[mu] / BEAD_DIAMETER:.1f}" for mu in flat}, key=float)
    depth = depths[0] if len(depths) == 1 else f"{depths[0]}-{depths[-1]}"
    last = frictions[-1]
    skipped = [mu for mu in FRICTIONS if flat[-1] < mu < first]  # not run (--quick)
    if skipped:  # the onset lies somewhere in between: no jump can be read
        return (f"At mu_c = {', '.join(f'{mu:g}' for mu in flat)} no heap forms: the beads "
                f"slide over each other and spread over the floor {depth} bead diameters "
                f"deep (angle below {flat_below_deg:g}°); the next friction run, {first:g}, "
                f"forms a heap of {angle[first]:.1f}° (and {angle[last]:.1f}° at {last:g}). "
                f"The onset lies between {flat[-1]:g} and {first:g}, which this sweep did not "
                f"resolve ({', '.join(f'{mu:g}' for mu in skipped)} not run).")
    return (f"Below mu_c = {first:g} no heap forms: the beads slide over each other and "
            f"spread over the floor {depth} bead diameters deep "
            f"(angle below {flat_below_deg:g}°); the angle jumps to {angle[first]:.1f}° at "
            f"{first:g} (and is {angle[last]:.1f}° at {last:g}): the steep rise at low "
            "friction that the thesis reports against Yan et al.")


def jammed_pours(pours, held):
    """The pours, (friction, seed), with beads still held above the outlet."""
    return [p for p in pours if held[p] > 0]


def jam_note(pours, held):
    """The pours, (friction, seed), whose discharge jammed: beads still above the outlet
    at rest."""
    jammed = jammed_pours(pours, held)
    if not jammed:
        return None
    return ("The discharge jammed at " + ", ".join(
        f"mu_c = {mu:g} seed {seed} ({held[(mu, seed)]} beads)" for mu, seed in jammed)
        + ": an arch of beads over the 6-diameter outlet held them at rest above it. The "
        "top view's apex is then one of them, so such a pour's angle does not measure the "
        "heap on the floor, and the medians leave it out.")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--quick", action="store_true", help="mu_c = 0.05, 0.5, 0.65 only")
    ap.add_argument("--reuse", action="store_true", help="keep the runs already on disk")
    ap.add_argument("--values", type=float, nargs="+",
                    help="the mu_c to run (must include 0.05, 0.5 and 0.65, which the checks use)")
    ap.add_argument("--seeds", type=int, nargs="+",
                    help="one pour per seed and mu_c (default: 4 5 6, the graded pours)")
    args = ap.parse_args()
    exe = os.path.join(ROOT, args.build, "app", "sanguis")
    frictions = sorted(args.values) if args.values else (
        QUICK_FRICTIONS if args.quick else FRICTIONS)
    missing = [mu for mu in QUICK_FRICTIONS if mu not in frictions]
    if missing:
        ap.error(f"--values must include {', '.join(f'{m:g}' for m in missing)} (the checks use them)")
    seeds = sorted(set(args.seeds)) if args.seeds else SEEDS
    pours = [(mu, seed) for mu in frictions for seed in seeds]
    t0 = time.time()

    end = case_end()
    state = {p: run_state(run_dir(*p), end) if args.reuse else "fresh" for p in pours}
    todo = [p for p in pours if state[p] != "finished"]
    print(f"hopper_repose: {len(todo)} run(s) to do of {len(pours)}, two at a time "
          "(about 20 min each)", flush=True)
    with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
        runs = pool.map(lambda p: run_one(exe, p, state[p] == "continue"), todo)
        for done, ((mu, seed), seconds) in enumerate(runs, 1):
            elapsed = time.time() - t0
            eta = elapsed / done * (len(todo) - done)
            print(f"  mu_c = {mu:g} seed {seed} done in {seconds / 60:.1f} min "
                  f"({done}/{len(todo)}, ETA {eta / 60:.0f} min)", flush=True)
    # the pours of the seeds seen before the graded reading was chosen, where on disk
    seen = [(mu, s) for mu in FRICTIONS for s in SEEN_SEEDS
            if s not in seeds and run_state(run_dir(mu, s), end) == "finished"]
    for p in pours + seen:
        analyse(exe, run_dir(*p))
    elapsed = time.time() - t0
    if args.reuse:  # runs of earlier calls: the runs' own wall time, two at a time
        elapsed = sum(wall_time(run_dir(*p)) for p in pours) / 2.0

    summaries = {p: read_summary(run_dir(*p)) for p in pours + seen}
    angle = {p: summaries[p][GRADED] for p in pours + seen}
    envelope = {p: summaries[p][SHOWN] for p in pours + seen}
    heap = {p: final_heap(run_dir(*p)) for p in pours + seen}
    held = {p: heap[p][0] for p in pours + seen}
    ends = {p: last_diagnostics(run_dir(*p)) for p in pours}

    def median(values, over_seeds=seeds, over_frictions=frictions):
        """Per mu_c, the median over the seeds' pours, jammed pours left out."""
        return {mu: pour_median([values[(mu, s)] for s in over_seeds],
                                [held[(mu, s)] for s in over_seeds])
                for mu in over_frictions}

    angle_mu = median(angle)
    envelope_mu = median(envelope)
    heap_top_mu = median({p: heap[p][1] for p in pours})
    low, mid, high = (angle_mu[mu] for mu in QUICK_FRICTIONS)

    def graded(value, test):
        return value is not None and test(value)

    def shown(value, fmt):
        return "— (every pour jammed)" if value is None else format(value, fmt) + "°"

    held_graded = sum(held[p] for p in pours)
    growth = None if None in (low, mid) else mid - low
    saturation = None if None in (mid, high) else high - mid
    checks = [
        {"quantity": "repose angle at mu_c = 0.5, cone fit"
                     + (" (median)" if len(seeds) > 1 else ""),
         "measured": shown(mid, ".1f"),
         "thesis": f"≈ {THESIS_ANGLE:g}° (§2.6.3, Fig. 2.7)", "tolerance": "±15 %",
         "pass": graded(mid, lambda a: abs(a / THESIS_ANGLE - 1.0) <= 0.15)},
        {"quantity": "growth from mu_c = 0.05 to 0.5", "measured": shown(growth, "+.1f"),
         "thesis": "grows (Fig. 2.7)", "tolerance": "> 5°",
         "pass": graded(growth, lambda g: g > 5.0)},
        {"quantity": "saturation: angle(0.65) − angle(0.5)",
         "measured": shown(saturation, "+.1f"),
         "thesis": "saturates (Fig. 2.7)", "tolerance": "within ±3°",
         "pass": graded(saturation, lambda d: abs(d) <= 3.0)},
        {"quantity": "sanity: beads left in the funnel (graded pours)",
         "measured": held_graded, "thesis": "—", "tolerance": "0",
         "pass": held_graded == 0},
    ]
    rows = [[f"{mu:g}", seed, f"{angle[(mu, seed)]:.1f}", f"{envelope[(mu, seed)]:.1f}",
             f"{1e3 * heap[(mu, seed)][1]:.1f}",
             held[(mu, seed)], f"{ends[(mu, seed)][0]:.2f}", f"{ends[(mu, seed)][1]:.1e}"]
            for mu, seed in pours]

    def median_rows(over_seeds, over_frictions, cone_mu, top_mu):
        """Per mu_c: the medians of both readings and the pours (* jammed)."""

        def listed(values, mu):
            return ", ".join(f"{values[(mu, s)]:.1f}" + ("*" if held[(mu, s)] else "")
                             for s in over_seeds)
        return [[f"{mu:g}", shown(cone_mu[mu], ".1f"), listed(angle, mu),
                 shown(top_mu[mu], ".1f"), listed(envelope, mu)] for mu in over_frictions]

    median_header = ["mu_c", "median cone fit", "pours, cone fit [deg]", "median envelope",
                     "pours, envelope [deg]"]
    seen_frictions = [mu for mu in FRICTIONS
                      if all((mu, s) in seen for s in SEEN_SEEDS)]
    seen_mu = median(angle, SEEN_SEEDS, seen_frictions)
    seen_envelope_mu = median(envelope, SEEN_SEEDS, seen_frictions)

    os.makedirs(os.path.dirname(FIGURE), exist_ok=True)
    fig, ax = plt.subplots(figsize=(6, 4.2))
    kept = [mu for mu in frictions if angle_mu[mu] is not None]
    line = "-" if frictions == FRICTIONS else ""  # no line across the frictions not run
    ax.plot(kept, [angle_mu[mu] for mu in kept], "o" + line, color="tab:blue",
            label=f"sanguis, Table 2.1 (3000 beads), cone fit, seeds "
            f"{', '.join(map(str, seeds))}" + (": median" if len(seeds) > 1 else ""))
    kept_envelope = [mu for mu in frictions if envelope_mu[mu] is not None]
    ax.plot(kept_envelope, [envelope_mu[mu] for mu in kept_envelope], "s--" if line else "s",
            color="tab:green", ms=4, label="surface envelope (shown, not graded)")
    if len(seeds) > 1:
        free = [p for p in pours if held[p] == 0]
        ax.plot([mu for mu, _ in free], [angle[p] for p in free], ".", color="tab:blue",
                alpha=0.5, label="one pour, cone fit")
    seen_kept = [mu for mu in seen_frictions if seen_mu[mu] is not None]
    if seen_kept:
        ax.plot(seen_kept, [seen_mu[mu] for mu in seen_kept], ":", color="0.45",
                marker="^", ms=4, label="cone fit, seeds 1-3 (seen before grading; shown)")
    jammed = jammed_pours(pours, held)
    if jammed:  # their angle is read with a held bead as the apex: not the heap's
        ax.plot([mu for mu, _ in jammed], [angle[p] for p in jammed], "x", color="tab:red",
                ms=10, mew=2, label="discharge jammed (beads held in the funnel)")
    ax.errorbar([0.5], [THESIS_ANGLE], yerr=[[0.15 * THESIS_ANGLE], [0.15 * THESIS_ANGLE]],
                fmt="ks", capsize=4, label="thesis: ≈ 36° at μc = 0.5 (±15 %)")
    ax.set_xlabel(r"bead-bead friction $\mu_c$")
    ax.set_ylabel("repose angle [deg]")
    ax.set_ylim(0, 60)  # room for the legend above the thesis point
    ax.set_title("Hopper discharge, Table 2.1 (thesis Fig. 2.7)")
    ax.legend(fontsize=7, loc="upper left")  # the jammed pours sit low on the right
    fig.tight_layout()
    fig.savefig(FIGURE, dpi=130)

    ok = all(c["pass"] for c in checks)
    tables = [{"caption": "Repose angle per pour (the seed picks the beads' random initial "
                          "positions).",
               "header": ["mu_c", "seed", "cone fit [deg]", "envelope [deg]", "heap top [mm]",
                          "beads in funnel",
                          "end [s]", "mean speed at the end [m/s]"],
               "rows": rows}]
    if len(seeds) > 1:
        tables.insert(0, {"caption": "Median angle per mu_c over the graded pours (seeds "
                                     f"{', '.join(map(str, seeds))}; * jammed, left out of "
                                     "the median).",
                          "header": median_header,
                          "rows": median_rows(seeds, frictions, angle_mu, envelope_mu)})
    if seen_frictions:
        tables.append({"caption": "Shown, not graded: the pours of seeds 1, 2 and 3, run while "
                                  "the envelope was graded (* jammed).",
                       "header": median_header,
                       "rows": median_rows(SEEN_SEEDS, seen_frictions, seen_mu,
                                           seen_envelope_mu)})
    summary = {
        "name": "hopper_repose",
        "title": "Hopper discharge: repose angle against mu_c",
        "thesis": "§2.6.3, Table 2.1, Fig. 2.7",
        "description": (
            "cases/dem/hopper.toml (Table 2.1: 3000 glass beads, R = 1 mm, rolling friction "
            "0.45 between beads and 0.1 on the walls) discharged through a square funnel "
            "(6-diameter outlet, 4 cm above the floor) onto a flat floor, with the bead-bead "
            f"mu_c swept over {', '.join(f'{m:g}' for m in frictions)}, "
            + (f"one pour per seed ({', '.join(str(s) for s in seeds)}); "
               if len(seeds) > 1 else "one pour each; ")
            + "the heap's angle from `sanguis analyze`."),
        "command": "/usr/bin/python3 validation/dem/hopper_repose.py --build BUILD"
                   + (" --values " + " ".join(f"{m:g}" for m in frictions) if args.values
                      else " --quick" if args.quick else "")
                   + (" --seeds " + " ".join(str(s) for s in seeds)
                      if args.seeds and seeds != SEEDS else ""),
        "figures": ["docs/validation/figures/hopper_repose.png"],
        "checks": checks,
        "tables": tables,
        "notes": ["Fig. 2.7 gives the thesis' curve and Yan et al.'s only as plots; the text "
                  "states the saturation near 36° at mu_c = 0.5 and a steeper rise than Yan et "
                  "al.'s between 0.05 and 0.2, which the checks use. The thesis does not give "
                  "the number of beads, the hopper's geometry or the drop height.",
                  heap_onset_note(kept, angle_mu, heap_top_mu),
                  *filter(None, [jam_note(pours, held)]),
                  "Two readings of each heap (`sanguis analyze`, docs/analysis.md), both "
                  "between 20 % and 80 % of the heap height: the graded cone fit takes the "
                  "mean radius of the heap's contour at each height, a slope averaged over the "
                  "azimuths; the surface envelope takes the highest point in rings around the "
                  "apex, the highest profile, which is the shallowest (on an elliptic heap of "
                  "slopes 26.6° and 42.0°, the envelope reads 26.6° and the cone fit a slope "
                  "between). Both read a cone of spheres to within 1° "
                  "(tests/dem/test_top_view.cpp).",
                  "Until 2026-12-07 the checks graded the envelope, on seeds 1-3. On the "
                  "merits above, and because the envelope spread by up to 7.5° from pour to "
                  "pour against the cone fit's 2.8° on those 21 pours, the cone fit became the "
                  "graded reading before any pour of seeds 4-6 had finished. The cone fit of "
                  "seeds 1-3 had been seen by then, so they no longer grade: they are shown in "
                  "the last table and the figure. The tolerances are those fixed before the "
                  "first sweep.",
                  "The case file as shipped pours with seed 3, one of the shown pours. Every run "
                  "used one thread (results do not depend on the thread count). Run time: "
                  "the runs' wall time, two at a time on the 2 cores."],
        "run_time_s": round(elapsed, 1),
        "date": time.strftime("%Y-%m-%d %H:%M"),
        "quick": bool(args.quick),
        "pass": bool(ok),
    }
    os.makedirs(RESULTS, exist_ok=True)
    with open(os.path.join(RESULTS, "hopper_repose.json"), "w") as f:
        json.dump(summary, f, indent=1)
    print(f"{'PASS' if ok else 'FAIL'}: angle {shown(mid, '.1f')} at mu_c = 0.5 "
          f"({elapsed / 60:.0f} min)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
