#!/usr/bin/python3
"""Settling of 750 spheres with and without contact memory (thesis §2.6.2, Fig. 2.6).

cases/dem/settling-750.toml pours 750 glass beads (radius 1 mm +- 10 %, §2.4 procedure
with en = 0.45, et = 0.3, mu_c = 0.5, mu_r = 0.1, 1 % overlap at 0.5 m/s; leapfrog,
dt = Tc/20 = 3.9 us) at random into a 15 x 15 mm box 90 mm tall; they fall and settle
for 3 s of simulated time. This script writes six variants of it (memory true/false x
seeds 1, 2, 3; `--quick`: seed 1 only) under validation/dem/results/runs/, runs them one
after another with BUILD/app/sanguis, and checks the last row of each diagnostics.csv:

* with memory (tangential and rolling springs): mean velocity < 1e-10 m/s and mean
  angular velocity < 1e-8 rad/s (the packing comes to a true rest);
* without memory (dashpots with Coulomb limits only, kt = kr = 0): mean velocity
  > 1e-4 m/s and mean angular velocity > 1e-1 rad/s (it keeps creeping);
* every run: largest overlap < 5 % of the radius and more contacts than particles
  (a packed bed, not a gas) as sanity checks.

Writes validation/dem/results/settling_750.csv and .json and
docs/validation/figures/settling_750.png. Exits 1 if a check fails.

Run time (measured on one core of an AMD EPYC, 2 cores in all): a variant is 765 000
steps of 750 spheres, 54-57 s with memory and 69-71 s without (more contacts), i.e.
8-10e6 particle-steps/s; the six take about 6.5 minutes, `--quick` about 2 minutes.
`--replot` re-checks and redraws the runs already on disk without running anything.

Usage: /usr/bin/python3 validation/dem/settling_750.py [--build build] [--quick]
"""
import argparse
import csv
import json
import os
import re
import subprocess
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CASE = os.path.join(ROOT, "cases", "dem", "settling-750.toml")
RESULTS = os.path.join(ROOT, "validation", "dem", "results")
RUNS = os.path.join(RESULTS, "runs")
FIGURE = os.path.join(ROOT, "docs", "validation", "figures", "settling_750.png")

END_TIME = 3.0  # [s] simulated
SEEDS = (1, 2, 3)
# thesis §2.6.2: residual motion at the end of the settling
MEMORY_V_MAX, MEMORY_W_MAX = 1e-10, 1e-8          # [m/s], [rad/s]
NO_MEMORY_V_MIN, NO_MEMORY_W_MIN = 1e-4, 1e-1     # [m/s], [rad/s]
MAX_OVERLAP_RATIO = 0.05
COUNT = 750


def sci(x):
    """1e-4, not 0.0001 or 1e-04."""
    m, e = f"{x:.0e}".split("e")
    return f"{m}e{int(e)}"


def variant_name(memory, seed):
    return f"settling-750_{'memory' if memory else 'no-memory'}_seed{seed}"


def write_variant(text, memory, seed, end_time):
    """The case file with memory, seed, end time and name replaced."""
    subs = [(r"(?m)^memory = (true|false)$", f"memory = {'true' if memory else 'false'}", 2),
            (r"(?m)^seed = \d+$", f"seed = {seed}", 1),
            (r"(?m)^end_time_s = [0-9.eE+-]+$", f"end_time_s = {end_time}", 1),
            (r'(?m)^name = "settling-750"$', f'name = "{variant_name(memory, seed)}"', 1)]
    for pattern, repl, expected in subs:
        text, count = re.subn(pattern, repl, text)
        if count != expected:
            sys.exit(f"error: {CASE}: expected {expected} line(s) matching {pattern}, "
                     f"found {count}")
    path = os.path.join(RUNS, variant_name(memory, seed) + ".toml")
    with open(path, "w") as f:
        f.write(text)
    return path


def read_diagnostics(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def run_variant(exe, toml, out_dir):
    t0 = time.time()
    with open(out_dir + ".log", "w") as log:
        subprocess.run([exe, "run", toml, "--output", out_dir, "--quiet"], check=True,
                       stdout=log, stderr=subprocess.STDOUT)
    return time.time() - t0


def plot(runs, path):
    fig, axes = plt.subplots(1, 2, figsize=(11, 5.2), sharex=True)
    colors = {1: "tab:blue", 2: "tab:orange", 3: "tab:green"}
    for r in runs:
        d = r["diagnostics"]
        t = d["time_s"]
        ls = "-" if r["memory"] else ":"
        lw = 1.4 if r["memory"] else 1.6
        label = f"seed {r['seed']}, {'with' if r['memory'] else 'without'} memory"
        for ax, key in ((axes[0], "mean_velocity_m_s"), (axes[1], "mean_angular_velocity_rad_s")):
            y = np.where(d[key] > 0.0, d[key], np.nan)
            ax.semilogy(t, y, linestyle=ls, linewidth=lw, color=colors.get(r["seed"], "k"),
                        label=label)
    for ax, lo, hi, unit in ((axes[0], MEMORY_V_MAX, NO_MEMORY_V_MIN, "m/s"),
                             (axes[1], MEMORY_W_MAX, NO_MEMORY_W_MIN, "rad/s")):
        ax.axhline(hi, color="0.4", linestyle="--", linewidth=0.9)
        ax.axhline(lo, color="0.4", linestyle="-.", linewidth=0.9)
        ax.text(0.99, hi / 1.6, f"without memory: above {sci(hi)} {unit} (thesis)", ha="right",
                va="top", fontsize=7.5, color="0.3", transform=ax.get_yaxis_transform())
        ax.text(0.99, lo * 1.6, f"with memory: below {sci(lo)} {unit} (thesis)", ha="right",
                va="bottom", fontsize=7.5, color="0.3", transform=ax.get_yaxis_transform())
        ax.set_xlabel("time t [s]")
        ax.grid(True, which="major", linewidth=0.4, alpha=0.6)
        ax.set_xlim(0.0, max(r["diagnostics"]["time_s"][-1] for r in runs))
    axes[0].set_ylabel("mean translational velocity [m/s]")
    axes[1].set_ylabel("mean angular velocity [rad/s]")
    axes[0].set_title("translational", fontsize=10)
    axes[1].set_title("rotational", fontsize=10)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=8)
    fig.suptitle(f"{COUNT} spheres settling in a 15 x 15 mm box (thesis Fig. 2.6): "
                 "solid = with memory, dotted = without", fontsize=10)
    fig.tight_layout(rect=(0, 0.1, 1, 1))
    fig.savefig(path, dpi=130)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build", help="CMake build directory (default: build)")
    ap.add_argument("--quick", action="store_true", help="seed 1 only (two runs)")
    ap.add_argument("--end-time", type=float, default=END_TIME,
                    help=f"simulated time per run [s] (default {END_TIME})")
    ap.add_argument("--replot", action="store_true",
                    help="do not run; check and plot the runs already in results/runs/")
    args = ap.parse_args()
    build = args.build if os.path.isabs(args.build) else os.path.join(ROOT, args.build)
    exe = os.path.join(build, "app", "sanguis")
    if not args.replot and not os.path.isfile(exe):
        sys.exit(f"error: {exe} not found; build with `cmake --build {build}`")
    os.makedirs(RUNS, exist_ok=True)
    os.makedirs(os.path.dirname(FIGURE), exist_ok=True)
    with open(CASE) as f:
        text = f.read()

    seeds = SEEDS[:1] if args.quick else SEEDS
    variants = [(m, s) for s in seeds for m in (True, False)]
    previous = {}
    summary_path = os.path.join(RESULTS, "settling_750.json")
    if args.replot and os.path.isfile(summary_path):
        with open(summary_path) as f:
            previous = json.load(f)
    previous_wall = {r["name"]: r.get("wall_s") for r in previous.get("runs", [])}
    runs, total = [], 0.0
    for k, (memory, seed) in enumerate(variants):
        name = variant_name(memory, seed)
        out_dir = os.path.join(RUNS, name)
        wall = previous_wall.get(name)
        if not args.replot:
            toml = write_variant(text, memory, seed, args.end_time)
            print(f"[{k + 1}/{len(variants)}] {name}: {args.end_time:g} s simulated ...",
                  end="", flush=True)
            wall = run_variant(exe, toml, out_dir)
            total += wall
            left = (len(variants) - k - 1) * total / (k + 1)
            print(f" {wall:.0f} s (total {total:.0f} s, about {left:.0f} s left)", flush=True)
        d = read_diagnostics(os.path.join(out_dir, "diagnostics.csv"))
        runs.append({"name": name, "memory": memory, "seed": seed, "wall_s": wall,
                     "diagnostics": d})

    checks, ok = [], True

    def check(quantity, measured, thesis, tolerance, good):
        nonlocal ok
        ok &= bool(good)
        checks.append({"quantity": quantity, "measured": measured, "thesis": thesis,
                       "tolerance": tolerance, "pass": bool(good)})

    print(f"\n{'run':<34}{'t_end [s]':>10}{'mean v [m/s]':>14}{'mean w [rad/s]':>16}"
          f"{'contacts':>10}{'max d/R':>9}  result")
    for r in runs:
        d = r["diagnostics"]
        v, w = float(d["mean_velocity_m_s"][-1]), float(d["mean_angular_velocity_rad_s"][-1])
        contacts = int(d["particle_contacts"][-1] + d["wall_contacts"][-1])
        overlap = float(np.max(d["max_overlap_over_radius"]))
        last = d["time_s"] >= d["time_s"][-1] - 0.5

        def geomean(x):
            x = x[x > 0.0]
            return float(np.exp(np.mean(np.log(x)))) if x.size else 0.0

        v_late = geomean(d["mean_velocity_m_s"][last])
        w_late = geomean(d["mean_angular_velocity_rad_s"][last])
        who = f"seed {r['seed']}, {'with' if r['memory'] else 'without'} memory"
        if r["memory"]:
            gv, gw = v < MEMORY_V_MAX, w < MEMORY_W_MAX
            check(f"final mean velocity, {who}", f"{v:.3g} m/s", f"< {sci(MEMORY_V_MAX)} m/s",
                  "one-sided bound", gv)
            check(f"final mean angular velocity, {who}", f"{w:.3g} rad/s",
                  f"< {sci(MEMORY_W_MAX)} rad/s", "one-sided bound", gw)
        else:
            gv, gw = v > NO_MEMORY_V_MIN, w > NO_MEMORY_W_MIN
            check(f"final mean velocity, {who}", f"{v:.3g} m/s",
                  f"> {sci(NO_MEMORY_V_MIN)} m/s", "one-sided bound", gv)
            check(f"final mean angular velocity, {who}", f"{w:.3g} rad/s",
                  f"> {sci(NO_MEMORY_W_MIN)} rad/s", "one-sided bound", gw)
        sane = overlap < MAX_OVERLAP_RATIO and contacts > COUNT
        check(f"sanity, {who}: largest overlap / radius; contacts at the end",
              f"{overlap:.4f}; {contacts}", "—", f"< {MAX_OVERLAP_RATIO}; > {COUNT}", sane)
        good = gv and gw and sane
        r.update({"final_time_s": float(d["time_s"][-1]), "final_mean_velocity_m_s": v,
                  "final_mean_angular_velocity_rad_s": w,
                  "geomean_last_0.5s_mean_velocity_m_s": v_late,
                  "geomean_last_0.5s_mean_angular_velocity_rad_s": w_late,
                  "final_contacts": contacts, "max_overlap_over_radius": overlap,
                  "pass": bool(good)})
        print(f"{r['name']:<34}{r['final_time_s']:>10.3f}{v:>14.3e}{w:>16.3e}{contacts:>10d}"
              f"{overlap:>9.4f}  {'PASS' if good else 'FAIL'}")

    notes = []
    free = [r for r in runs if not r["memory"]]
    if free:
        v_min, w_min = [], []
        for r in free:
            d = r["diagnostics"]
            late = d["time_s"] >= 1.0
            v_min.append(float(np.min(d["mean_velocity_m_s"][late])))
            w_min.append(float(np.min(d["mean_angular_velocity_rad_s"][late])))
        def window_geomean(lo, hi):
            vals = np.concatenate([
                r["diagnostics"]["mean_angular_velocity_rad_s"][
                    (r["diagnostics"]["time_s"] >= lo) & (r["diagnostics"]["time_s"] <= hi)]
                for r in free])
            vals = vals[vals > 0.0]
            return float(np.exp(np.mean(np.log(vals)))) if vals.size else float("nan")

        t_end = free[0]["final_time_s"]
        early_w, late_w = window_geomean(1.0, 1.5), window_geomean(t_end - 0.5, t_end)
        v_end = [r["final_mean_velocity_m_s"] for r in free]
        w_end = [r["final_mean_angular_velocity_rad_s"] for r in free]
        notes.append(
            "Without memory the motion decays slowly and fluctuates: at the end the mean "
            f"velocity is {min(v_end):.2g}-{max(v_end):.2g} m/s and the mean angular velocity "
            f"{min(w_end):.2g}-{max(w_end):.2g} rad/s, but after t = 1 s their lowest samples "
            f"are {min(v_min):.2g} m/s and {min(w_min):.2g} rad/s. The angular velocity is "
            "still decreasing (geometric mean over all runs without memory: "
            f"{early_w:.2g} rad/s over 1.0-1.5 s, {late_w:.2g} rad/s over the last 0.5 s), so "
            "the margin over the thesis' 1e-1 rad/s is small and depends on the run length.")
    rest = [r for r in runs if r["memory"]]
    if rest:
        notes.append(
            "With memory the mean velocity ends at "
            f"{min(r['final_mean_velocity_m_s'] for r in rest):.2g}-"
            f"{max(r['final_mean_velocity_m_s'] for r in rest):.2g} m/s, the level of "
            "round-off, several decades below the thesis' bound.")

    plot(runs, FIGURE)
    keys = ["name", "memory", "seed", "final_time_s", "final_mean_velocity_m_s",
            "final_mean_angular_velocity_rad_s", "geomean_last_0.5s_mean_velocity_m_s",
            "geomean_last_0.5s_mean_angular_velocity_rad_s", "final_contacts",
            "max_overlap_over_radius", "wall_s", "pass"]
    with open(os.path.join(RESULTS, "settling_750.csv"), "w", newline="") as f:
        wr = csv.writer(f)
        wr.writerow(keys)
        for r in runs:
            wr.writerow([r[k] if r[k] is not None else "" for k in keys])

    summary = {
        "name": "settling_750",
        "title": f"{COUNT} spheres settling with and without contact memory",
        "thesis": "§2.6.2, Fig. 2.6",
        "description": (
            f"{COUNT} glass beads (radius 1 mm ± 10 %, §2.4 procedure: en = 0.45, et = 0.3, "
            "mu_c = 0.5, mu_r = 0.1, 1 % overlap at 0.5 m/s, leapfrog, dt = Tc/20) poured at "
            "random into a 15 × 15 mm box settle under gravity for "
            f"{runs[0]['final_time_s']:.1f} s (cases/dem/settling-750.toml). With memory the "
            "tangential and rolling springs hold the packing; without memory (kt = kr = 0, "
            "dashpots with Coulomb limits) nothing holds it. Seeds "
            f"{', '.join(str(s) for s in seeds)}; values are the last diagnostics row."),
        "command": "/usr/bin/python3 validation/dem/settling_750.py --build BUILD"
                   + (" --quick" if args.quick else ""),
        "figures": ["docs/validation/figures/settling_750.png"],
        "checks": checks,
        "tables": [{
            "caption": "Per run: last diagnostics row, geometric mean over the last 0.5 s, "
                       "contacts (particle + wall) at the end, largest overlap over the run, "
                       "wall-clock time.",
            "header": ["seed", "memory", "final mean v [m/s]", "final mean ω [rad/s]",
                       "last 0.5 s v [m/s]", "last 0.5 s ω [rad/s]", "contacts",
                       "max overlap / R", "wall time [s]"],
            "rows": [[r["seed"], "yes" if r["memory"] else "no",
                      f"{r['final_mean_velocity_m_s']:.3g}",
                      f"{r['final_mean_angular_velocity_rad_s']:.3g}",
                      f"{r['geomean_last_0.5s_mean_velocity_m_s']:.3g}",
                      f"{r['geomean_last_0.5s_mean_angular_velocity_rad_s']:.3g}",
                      r["final_contacts"], f"{r['max_overlap_over_radius']:.4f}",
                      "—" if r["wall_s"] is None else f"{r['wall_s']:.0f}"] for r in runs]}],
        "notes": notes,
        "runs": [{k: r[k] for k in keys} for r in runs],
        "run_time_s": round(total, 1) if not args.replot else previous.get("run_time_s"),
        "replotted": bool(args.replot),
        # when replotting, the date of the runs: the newest diagnostics file
        "date": time.strftime("%Y-%m-%d %H:%M", time.localtime(max(
            os.path.getmtime(os.path.join(RUNS, r["name"], "diagnostics.csv")) for r in runs))),
        "quick": bool(args.quick),
        "pass": bool(ok),
    }
    with open(summary_path, "w") as f:
        json.dump(summary, f, indent=1)
    print(f"\n{'PASS' if ok else 'FAIL'}: settling of {COUNT} spheres"
          + (f" ({total:.0f} s of runs)" if not args.replot else ""))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
