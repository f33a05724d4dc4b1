#!/usr/bin/python3
"""The 3 x 3 around the Table 3.1 point of the tangential map on six packings (thesis
§3.4.3, Fig. 3.17).

crosses_tangential_map classifies every (kt, gamma_t) on one settled 300-cross column,
the pour of the case's own seed; where the edge of its band of top-driven collapses
passes depends on that pour (on 2026-12-06 a factor 3 below Table 3.1 on the map's pour,
a factor 3 above on another). This case pours the same column with seeds 1 to 6
(cases/dem/dam-break-crosses-memory.toml to the gate's opening, Table 3.1 parameters,
one thread, two runs at a time; 5 is the case's own seed, so that pour is the map's) and
continues each with the 3 x 3 of the map around
Table 3.1 (kt 1e2, 3e2, 1e3 N/m; gamma_t 3e2, 1e3, 3e3 1/s; both interactions),
classified as in crosses_tangential_map.
Check: the Table 3.1 point is top-driven (region 2) on every packing (the thesis: region
2, as in the experiments). Reported: on how many pours each point collapses, and whether
on every pour the standing points lie on one side of an edge (a point that stands has
every point of larger or equal kt and gamma_t standing, as region 3 lies above the band in
Fig. 3.17).
Until 2026-12-06 this case ran two points (Table 3.1 and kt 1e2, gamma_t 3e2) on three
pours. Runs are resumable: a pour or continuation that reached its end is kept.

Writes validation/dem/results/crosses_tangential_packings.json and
docs/validation/figures/crosses_tangential_packings.png.

`--element-contacts mean` pours and runs everything with the element contacts of two
crosses averaged, as Grains3D does for composite particles (simulation.element_contacts),
in runs/crosses_tangential_packings_mean, and writes crosses_tangential_packings_mean.json
and .png (the wrapper crosses_tangential_packings_mean.py runs it so for the report).
`--table31-only` runs the pours and the Table 3.1 point only and prints the regions;
with `--element-contacts mean`, `--open-with-sum` opens the same pours with the sum (the
rule's effect on the same packings; docs/theory/dem.md), `--open-with-point` with one
contact point per element pair and the mean (Grains3D's model). `--element-contacts mean
--flat-contacts point` pours and runs everything with that model, in
runs/crosses_tangential_packings_mean_point (the wrapper crosses_tangential_packings_mean_point.py
for the report).
Usage: /usr/bin/python3 validation/dem/crosses_tangential_packings.py [--build build]
       [--rerun-pours] [--rerun] [--element-contacts sum|mean [--flat-contacts point]]
       [--table31-only
       [--open-with-sum | --open-with-point]]
"""
import argparse
import os
import shutil
import subprocess
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from _outputs import (ONE_POINT_PER_PAIR, add_contact_model_options, contact_model,  # noqa: E402
                      contact_model_settings, contact_model_suffix, contact_model_title,
                      continuation_command, counted_intervals, flat_contacts_setting,
                      paused_note, pour_command, read_summary, run_two_at_a_time, span,
                      stopped_seconds, stops, two_at_a_time_span, wall_time, write_summary)
from crosses_tangential_map import (CASE, GATE_TIME, LOCAL_GAMMA, LOCAL_KT, RESULTS,  # noqa: E402
                                    ROOT, TABLE_31, classify, settings, sphere_reference)

RUNS = os.path.join(RESULTS, "runs", "crosses_tangential_packings")
FIGURE = os.path.join(ROOT, "docs", "validation", "figures", "crosses_tangential_packings.png")
SEEDS = [1, 2, 3, 4, 5, 6]
POINTS = [(kt, g) for kt in LOCAL_KT for g in LOCAL_GAMMA]


def run_folder(seed, kt, g, runs=RUNS):
    return os.path.join(runs, f"seed_{seed}_kt_{kt:g}_gamma_{g:g}")


def stands_above_edge(regions):
    """True when the standing points (region 3) of one pour's {(kt, gamma_t): region} lie on
    one side of an edge: every point with kt and gamma_t both at least a standing point's
    stands too."""
    standing = [p for p, r in regions.items() if r == 3]
    return all(regions[q] == 3 for p in standing for q in regions
               if q[0] >= p[0] and q[1] >= p[1])


def collapses(result):
    """Whether a classified run collapsed (region 1 or 2)."""
    return result["region"] != 3


def collapse_counts(results, seeds, points):
    """{point: number of the seeds' pours on which it collapses}."""
    return {p: sum(collapses(results[(s, *p)]) for s in seeds) for p in points}


def draw(results, counts, seeds, figure=FIGURE, model=""):
    """Left: on how many pours each point collapses; right: each pour's height loss."""
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10.0, 4.0),
                                 gridspec_kw={"width_ratios": [1, 1.6]})
    grid = [[counts[(kt, g)] for kt in LOCAL_KT] for g in LOCAL_GAMMA]
    image = ax.imshow(grid, origin="lower", cmap="Reds", vmin=0, vmax=len(seeds))
    for i, g in enumerate(LOCAL_GAMMA):
        for j, kt in enumerate(LOCAL_KT):
            ax.text(j, i, f"{counts[(kt, g)]}/{len(seeds)}", ha="center", va="center",
                    fontsize=10, fontweight="bold" if (kt, g) == TABLE_31 else "normal")
    j31, i31 = LOCAL_KT.index(TABLE_31[0]), LOCAL_GAMMA.index(TABLE_31[1])
    ax.add_patch(plt.Rectangle((j31 - 0.5, i31 - 0.5), 1, 1, fill=False, lw=2.0, ec="k"))
    ax.set_xticks(range(len(LOCAL_KT)), [f"{kt:g}" for kt in LOCAL_KT])
    ax.set_yticks(range(len(LOCAL_GAMMA)), [f"{g:g}" for g in LOCAL_GAMMA])
    ax.set_xlabel("kt [N/m]")
    ax.set_ylabel("γt [1/s]")
    ax.set_title("pours on which the column collapses\n(framed: Table 3.1)", fontsize=9)
    fig.colorbar(image, ax=ax, shrink=0.8)
    markers = {1: "s", 2: "o", 3: "^"}
    for k, (kt, g) in enumerate(POINTS):
        for s in seeds:
            r = results[(s, kt, g)]
            x = k + (s - (len(seeds) + 1) / 2) * 0.12
            bx.scatter(x, 100 * r["height_loss"], marker=markers[r["region"]],
                       color=f"C{s - 1}", s=28, label=f"seed {s}" if k == 0 else None)
    bx.axhline(5.0, color="k", lw=0.8, ls=":")
    bx.text(len(POINTS) - 0.5, 5.5, "5 %: region 3 below", ha="right", fontsize=7)
    bx.set_xticks(range(len(POINTS)), [f"{kt:g}\n{g:g}" for kt, g in POINTS], fontsize=7)
    bx.set_xlabel("kt [N/m] / γt [1/s]   (▲ region 3, ● region 2, ■ region 1)")
    bx.set_ylabel("height lost / $H_0$ within 0.5 s [%]")
    bx.legend(fontsize=7, ncol=3, loc="upper right")
    fig.suptitle("300 crosses, six pours (thesis: Table 3.1 is top-driven, region 2)"
                 + (f"\n{model}" if model else ""), fontsize=10)
    fig.tight_layout()
    fig.savefig(figure, dpi=130)


def sum_notes(results, packing, table31, max_collapse_base, base_reference):
    """The report's notes for the summed element contacts (the model's default)."""
    return ["Why this case: crosses_tangential_map uses one pour, and where the edge of "
            "its band of top-driven collapses passes changes with that pour. Here six "
            "pours of the same case place the edge around the Table 3.1 point; seed 5 is "
            "the case's own, so its pour and its 3 x 3 are the map's (the same bits).",
            # The runs of 2026-11-24 (pours to 2.4 s), quoted from this file's JSON then.
            "Since 2026-11-25 the pours run to the gate's opening at t = 3.0 s, when the "
            "column is at rest (before: 2.4 s, with the case's own seed still "
            "settling). For seeds 1-3 it changed little: with the opening at "
            "2.4 s they stood at H0 17.8-18.2 cm with 6.35-6.66 neighbours, the Table "
            "3.1 point lost 1.7-3.8 % (region 3) and kt 1e2, γt 3e2 27-55 % (region 2); "
            "opened at 3.0 s, with one contact point per element pair (2026-11-25), "
            "17.8-18.1 cm, 6.35-6.65, 1.2-3.1 % and 35-59 %. On the case's own seed, "
            "settled, the Table 3.1 point collapsed then (23 %, crosses_tangential_map): "
            "the point sat on the border of regions 2 and 3.",
            # The collapses of 2026-12-05 23:16-23:26 UTC; the pours are older.
            "On 2026-12-05 evening (two points on three pours, AMD EPYC VM) with the "
            "torsional spring of the patches spread over them (docs/theory/dem.md, \"The "
            "torsional spring until 2026-12-05 evening\"): the Table 3.1 point lost "
            "1.1-3.4 % on every pour (region 3) and kt 1e2, γt 3e2 26-55 % (region 2); "
            "with the corners' spring before, 1.0-4.4 % and 26-61 %, the same regions.",
            "Since 2026-12-06 (an Intel Xeon VM: a build for another processor rounds "
            "otherwise with -march=native, so the same seeds pack otherwise) the pours "
            f"stand at H0 {span([100 * packing[s]['H0_m'] for s in SEEDS], '.1f')} cm "
            f"with {span([packing[s]['pair_coordination'] for s in SEEDS], '.2f')} "
            "touching neighbours per cross. The Table 3.1 point loses "
            f"{span([100 * results[(s, *TABLE_31)]['height_loss'] for s in SEEDS], '.1f')}"
            f" % of H0 and collapses top-driven on {table31.count(2)} pour(s) of "
            f"{len(SEEDS)}; kt 1e2, γt 3e2 loses "
            f"{span([100 * results[(s, 1e2, 3e2)]['height_loss'] for s in SEEDS], '.0f')}"
            " %. Regions by the rule of crosses_tangential_map that measures the base "
            "against a column of spheres: the collapses here move their base at most "
            f"{max_collapse_base:.1f} mm in one τc, against the spheres' "
            f"{base_reference:.1f} mm."]


def model_label(mean, point):
    """How the variant's element contacts differ from the default (sum, contact patches),
    for the figure's title; empty for the default."""
    parts = (["element contacts: the mean"] if mean else []) + (
        ["one contact point per element pair"] if point else [])
    return " and ".join(parts) + (" (Grains3D)" if mean and point else "")


def mean_notes(results, packing, table31, point=False):
    """The report's notes for the element contacts averaged as in Grains3D (with `point`,
    and one contact point per element pair, as Grains3D too)."""
    loss = [100 * results[(s, *TABLE_31)]["height_loss"] for s in SEEDS]
    soft = [100 * results[(s, 1e2, 3e2)]["height_loss"] for s in SEEDS]
    flat = (f"; and {ONE_POINT_PER_PAIR}. Grains3D uses one point, so this variant is the "
            "thesis' code's contact model, poured and opened with it" if point else "")
    return [
        "The same six seeds and 3 x 3 as crosses_tangential_packings, with simulation."
        "element_contacts = \"mean\" in the pours and the continuations: the force and torque "
        "of each element contact between two crosses (up to four pairs of arms), or between "
        "a cross and one wall, divided by the number of element contacts the two have at that "
        "step, as Grains3D's composite particles do (CompositeParticle::InterAction passes "
        "that number to the contact model, which multiplies each contact's force by its "
        f"inverse){flat}. The thesis ran its crosses on Grains3D; with the sum and the "
        "patches (the model's defaults) this check fails (crosses_tangential_packings).",
        f"The pours stand at H0 {span([100 * packing[s]['H0_m'] for s in SEEDS], '.1f')} cm "
        f"with {span([packing[s]['pair_coordination'] for s in SEEDS], '.2f')} touching "
        f"neighbours per cross. The Table 3.1 point loses {span(loss, '.1f')} % of H0 and "
        f"collapses top-driven on {table31.count(2)} pour(s) of {len(SEEDS)}; kt 1e2, "
        f"γt 3e2 loses {span(soft, '.0f')} %.",
    ]


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--rerun-pours", action="store_true", help="pour again (and run again)")
    ap.add_argument("--rerun", action="store_true", help="run every continuation again")
    ap.add_argument("--quick", action="store_true", help="same as the full run")
    add_contact_model_options(ap, "crosses_tangential_packings",
                              "the same 3 x 3 in the pours and the continuations")
    ap.add_argument("--table31-only", action="store_true",
                    help="pour and run the Table 3.1 point only, print its regions, no report")
    ap.add_argument("--open-with-sum", action="store_true",
                    help="with --element-contacts mean --table31-only: open the mean's pours "
                         "with the sum (folders *_opened_sum), the rule's effect on the same "
                         "packings")
    ap.add_argument("--open-with-point", action="store_true",
                    help="with --element-contacts mean --table31-only: open the mean's pours "
                         "with one contact point per element pair and the mean, the model of "
                         "the thesis' Grains3D (folders *_opened_point)")
    args = ap.parse_args(argv)
    mean, point = contact_model(ap, args)
    if point and (args.open_with_sum or args.open_with_point):
        ap.error("--open-with-sum and --open-with-point open pours made with the patches: "
                 "leave out --flat-contacts point")
    if args.open_with_sum and args.open_with_point:
        ap.error("--open-with-sum and --open-with-point each open the pours one way: give one")
    if (args.open_with_sum or args.open_with_point) and not (mean and args.table31_only):
        # Without both, the continuations would run with the pours' own rule and overwrite
        # that rule's runs and summary.
        ap.error("--open-with-sum and --open-with-point open the mean's pours at Table 3.1 "
                 "only: give --element-contacts mean --table31-only")
    exe = os.path.join(ROOT, args.build, "app", "sanguis")
    name = "crosses_tangential_packings" + contact_model_suffix(mean, point)
    runs = os.path.join(RESULTS, "runs", name)
    figure = os.path.join(ROOT, "docs", "validation", "figures", name + ".png")
    rule = contact_model_settings(mean, point)
    t0 = time.time()
    pours = {seed: os.path.join(runs, f"pour_seed_{seed}") for seed in SEEDS}
    reused = []  # wall times of runs kept from an earlier call: they count in the run time
    jobs = []
    for seed, d in pours.items():
        cmd = pour_command([exe, "run", CASE, "--output", d, "--quiet", "--threads", "1",
                            "--seed", str(seed)] + rule, d, GATE_TIME, args.rerun_pours)
        if cmd:
            jobs.append((cmd, d))
        else:
            reused.append(wall_time(d))
    run_two_at_a_time(jobs, runs)
    packing = {}
    for seed, d in pours.items():
        subprocess.run([exe, "analyze", d], check=True, stdout=subprocess.DEVNULL)
        packing[seed] = read_summary(d)

    jobs = []
    points = [TABLE_31] if args.table31_only else POINTS
    suffix, opening_rule = "", rule
    if args.open_with_sum:
        suffix, opening_rule = "_opened_sum", []
    elif args.open_with_point:
        suffix, opening_rule = "_opened_point", rule + flat_contacts_setting("point")
    for seed, pour in pours.items():
        for kt, g in points:
            d = run_folder(seed, kt, g, runs) + suffix
            if args.rerun or args.rerun_pours:  # a new pour makes the old runs stale
                shutil.rmtree(d, ignore_errors=True)
            cmd = continuation_command([exe, "run", CASE, "--output", d, "--restart", "--quiet",
                                        "--threads", "1"] + opening_rule + settings(kt, g), d,
                                       pour, GATE_TIME)
            if cmd:
                jobs.append((cmd, d))
            else:
                reused.append(wall_time(d, GATE_TIME))
    run_two_at_a_time(jobs, runs)
    base_reference = sphere_reference(exe)["bottom_move_mm"]
    results = {}
    for seed in SEEDS:
        for kt, g in points:
            d = run_folder(seed, kt, g, runs) + suffix
            subprocess.run([exe, "analyze", d], check=True, stdout=subprocess.DEVNULL)
            results[(seed, kt, g)] = classify(d, base_reference)
    elapsed = time.time() - t0 + two_at_a_time_span(reused)
    if args.table31_only:
        for seed in SEEDS:
            r = results[(seed, *TABLE_31)]
            print(f"seed {seed}: H0 {100 * packing[seed]['H0_m']:.1f} cm, neighbours "
                  f"{packing[seed]['pair_coordination']:.2f}; Table 3.1 region {r['region']}, "
                  f"height loss {100 * r['height_loss']:.1f} %, run-out {r['runout_ratio']:.2f}")
        return 0

    counts = collapse_counts(results, SEEDS, POINTS)
    os.makedirs(os.path.dirname(figure), exist_ok=True)
    draw(results, counts, SEEDS, figure, model_label(mean, point))

    max_collapse_base = max((r["bottom_move_mm"] for r in results.values() if r["region"] != 3),
                            default=0.0)
    table31 = [results[(seed, *TABLE_31)]["region"] for seed in SEEDS]
    ordered = [stands_above_edge({p: results[(s, *p)]["region"] for p in POINTS})
               for s in SEEDS]
    seeds_text = ", ".join(map(str, SEEDS))
    checks = [
        {"quantity": f"Table 3.1 point (kt 3e2, γt 1e3): region on the packings of seeds "
                     f"{seeds_text}",
         "measured": ", ".join(map(str, table31)),
         "thesis": "region 2 (top-driven, as the experiments)", "tolerance": "2 on every packing",
         "pass": all(r == 2 for r in table31)},
        {"quantity": "pours on which each point collapses (kt [N/m], γt [1/s]: count)",
         "measured": "; ".join(f"{kt:g}, {g:g}: {counts[(kt, g)]}" for kt, g in POINTS),
         "thesis": "Table 3.1 in the band of top-driven collapses", "tolerance": "reported",
         "pass": None},
        {"quantity": "pours whose standing points lie above one edge (larger kt and γt stand)",
         "measured": f"{sum(ordered)} of {len(SEEDS)}", "thesis": "region 3 above the band",
         "tolerance": "reported", "pass": None},
    ]
    rows = []
    for seed in SEEDS:
        p = packing[seed]
        for kt, g in POINTS:
            r = results[(seed, kt, g)]
            rows.append([seed, f"{100 * p['H0_m']:.1f}", f"{p['pair_coordination']:.2f}",
                         f"{kt:g}", f"{g:g}", r["region"], r["regime"], f"{r['top_move_mm']:.2f}",
                         f"{r['bottom_move_mm']:.2f}", f"{r['height_loss']:.3f}",
                         f"{r['runout_ratio']:.2f}"])
    ok = all(c["pass"] for c in checks if c["pass"] is not None)
    notes = mean_notes(results, packing, table31, point) if mean else sum_notes(
        results, packing, table31, max_collapse_base, base_reference)
    # The stops (PAUSES.txt) that fell while a run of the case was counted: the run time,
    # the span of runs two at a time, holds each once.
    counted = [interval for d in pours.values() for interval in counted_intervals(d)] + [
        interval for seed in SEEDS for kt, g in points
        for interval in counted_intervals(run_folder(seed, kt, g, runs) + suffix, GATE_TIME)]
    paused = stopped_seconds(counted, stops(runs)) / 60.0
    if paused:
        notes.append(paused_note(paused, name))
        elapsed -= 60.0 * paused
    summary = {
        "name": name,
        "title": "Cross column: the 3 x 3 around Table 3.1 on six packings"
                 + contact_model_title(mean, point),
        "thesis": "§3.4.3, Fig. 3.17",
        "description": (
            f"The 300-cross column of the memory case poured with seeds {seeds_text} and "
            "continued from the gate's opening with the 3 x 3 tangential parameters of "
            "crosses_tangential_map around Table 3.1 (kt 1e2, 3e2, 1e3 N/m; γt 3e2, 1e3, "
            "3e3 1/s; both interactions); regions as in crosses_tangential_map (3 stable: "
            "the highest particle lost less than 5 % of H0)."),
        "command": f"/usr/bin/python3 validation/dem/{name}.py --build BUILD",
        "figures": [f"docs/validation/figures/{name}.png"],
        "checks": checks,
        "tables": [{"caption": "Per run (packing at the opening: H0 and touching neighbours "
                               "per cross).",
                    "header": ["seed", "H0 [cm]", "neighbours", "kt [N/m]", "γt [1/s]",
                               "region", "regime", "top moved [mm]", "bottom moved [mm]",
                               "height loss / H0", "(L∞−L0)/L0"],
                    "rows": rows},
                   {"caption": "Per pour: the packing at the opening and how many of the 9 "
                               "points collapse on it.",
                    "header": ["seed", "H0 [cm]", "neighbours", "points collapsing",
                               "Table 3.1 region", "standing points above one edge"],
                    "rows": [[s, f"{100 * packing[s]['H0_m']:.1f}",
                              f"{packing[s]['pair_coordination']:.2f}",
                              sum(collapses(results[(s, *p)]) for p in POINTS),
                              results[(s, *TABLE_31)]["region"],
                              "yes" if edge else "no"]
                             for s, edge in zip(SEEDS, ordered)]}],
        "notes": notes,
    }
    write_summary(summary, RESULTS, elapsed, args.quick, ok, counted)
    print(f"{'PASS' if ok else 'FAIL'}: Table 3.1 regions {table31}, collapses per point "
          f"{counts}, {elapsed:.0f} s")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
