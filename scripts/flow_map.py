#!/usr/bin/python3
"""A flow-regime map of dam breaks (thesis Fig. 3.6) from `sanguis ensemble` folders.

usage: flow_map.py DIR... [--output OUT]

Each DIR is an ensemble folder (its ensemble.csv, written by `sanguis ensemble` or by
`sanguis analyze RUN... --out DIR`), or a folder whose subfolders are ensembles. Every
ensemble is one column: one (L0, H0) point of the map, repeated over its seeds. A point
whose runs all end in one regime (collapsed, fractured or stable, `sanguis analyze`'s
classification) is repeatable; one whose runs end in different regimes is intermittent,
as the thesis calls the columns whose outcome the packing decides (§3.3.1).

Writes OUT/flow_map.csv (one row per ensemble: L0, H0, aspect ratio, runs, how many
collapsed, fractured and stood, the outcome) and OUT/flow_map.png (H0 against L0, one
marker per outcome). Exit status 2, with a message naming the file and the reason, when an
input is missing or malformed; nothing is written then.
"""
import argparse
import csv
import math
import os
import sys

REGIMES = ("collapsed", "fractured", "stable")
INTERMITTENT = "intermittent"
NEEDED = ("L0_m", "H0_m") + tuple(f"fraction_{r}" for r in REGIMES)


class InputError(Exception):
    """An input the map cannot use: the message names the file and the reason."""


def ensemble_files(paths):
    """The ensemble.csv of each path, or of each subfolder of a path that has none, in the
    order given (subfolders sorted)."""
    found = []
    for path in paths:
        if not os.path.isdir(path):
            raise InputError(f"{path}: not a folder")
        own = os.path.join(path, "ensemble.csv")
        if os.path.isfile(own):
            found.append(own)
            continue
        below = sorted(os.path.join(path, d, "ensemble.csv") for d in os.listdir(path)
                       if os.path.isfile(os.path.join(path, d, "ensemble.csv")))
        if not below:
            raise InputError(f"{path}: no ensemble.csv in it or in its subfolders (make one "
                             "with `sanguis ensemble CASE --seeds N`, or `sanguis analyze "
                             "RUN RUN... --out DIR` of two runs or more)")
        found += below
    return found


def read_ensemble(path):
    """L0, H0 (means over the runs) and the runs in each regime of one ensemble.csv."""
    try:
        with open(path, newline="") as f:
            table = {r["quantity"]: r for r in csv.DictReader(f) if r.get("quantity")}
    except (OSError, UnicodeDecodeError, csv.Error) as e:
        raise InputError(f"{path}: cannot be read ({e})") from e
    missing = [q for q in NEEDED if q not in table]
    if missing:
        raise InputError(f"{path}: no row {', '.join(missing)} (not an ensemble.csv of "
                         "`sanguis ensemble` or `sanguis analyze`)")

    def number(quantity, column):
        text = table[quantity].get(column) or ""
        try:
            value = float(text)
        except ValueError:
            raise InputError(f"{path}: {quantity}, column {column}: '{text}' is not a "
                             "number") from None
        if not math.isfinite(value):
            raise InputError(f"{path}: {quantity}, column {column}: {text} is not finite")
        return value

    runs = number("fraction_collapsed", "runs")
    if runs < 1 or runs != int(runs):
        raise InputError(f"{path}: fraction_collapsed, column runs: {runs:g} runs")
    counts = {}
    for regime in REGIMES:
        fraction = number(f"fraction_{regime}", "mean")
        if not 0.0 <= fraction <= 1.0:
            raise InputError(f"{path}: fraction_{regime}: {fraction:g} is not a fraction")
        counts[regime] = round(fraction * runs)
    if sum(counts.values()) != int(runs):
        raise InputError(f"{path}: the regime fractions do not add up to its {int(runs)} runs")
    l0, h0 = number("L0_m", "mean"), number("H0_m", "mean")
    if l0 <= 0 or h0 <= 0:
        raise InputError(f"{path}: L0 {l0:g} m, H0 {h0:g} m: not a column (no gate removed?)")
    return {"ensemble": os.path.dirname(path) or ".", "L0_m": l0, "H0_m": h0,
            "runs": int(runs), **counts}


def outcome(point):
    """The regime all runs of a point ended in, or 'intermittent' where they differ."""
    seen = [r for r in REGIMES if point[r] > 0]
    return seen[0] if len(seen) == 1 else INTERMITTENT


def write_csv(points, path):
    """The map's table as `path` + ".tmp" (main moves it into place)."""
    with open(path + ".tmp", "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")  # as sanguis writes its CSV files
        w.writerow(["ensemble", "L0_m", "H0_m", "aspect_ratio_H0_over_L0", "runs"]
                   + list(REGIMES) + ["outcome"])
        for p in points:
            w.writerow([p["ensemble"], f"{p['L0_m']:.6g}", f"{p['H0_m']:.6g}",
                        f"{p['H0_m'] / p['L0_m']:.4g}", p["runs"]]
                       + [p[r] for r in REGIMES] + [outcome(p)])


STYLE = {"collapsed": ("o", "tab:blue", "collapsed (repeatable)"),
         "fractured": ("^", "tab:green", "fractured (repeatable)"),
         "stable": ("s", "0.4", "stable (repeatable)"),
         INTERMITTENT: ("X", "tab:red", "intermittent (outcome differs by seed)")}


def draw(points, path):
    """The map's figure as `path` + ".tmp.png" (main moves it into place)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4.5))
    for kind, (marker, colour, label) in STYLE.items():
        chosen = [p for p in points if outcome(p) == kind]
        if not chosen:
            continue
        ax.scatter([100 * p["L0_m"] for p in chosen], [100 * p["H0_m"] for p in chosen],
                   marker=marker, s=70, color=colour, label=label, zorder=3)
        if kind == INTERMITTENT:
            for p in chosen:
                # offset clear of the marker (s=70 is about 8 points across)
                ax.annotate("/".join(f"{p[r]}{r[0]}" for r in REGIMES if p[r]),
                            (100 * p["L0_m"], 100 * p["H0_m"]), xytext=(7, 5),
                            textcoords="offset points", fontsize=7)
    top = 1.15 * max(100 * p["H0_m"] for p in points)
    right = 1.15 * max(100 * p["L0_m"] for p in points)
    for a in (1, 3, 10):  # lines of constant aspect ratio H0 / L0
        ax.plot([0, right], [0, a * right], color="0.85", lw=0.8, zorder=1)
        if a * right > top:
            ax.annotate(f"a = {a}", (top / a, top), fontsize=7, color="0.5", va="top")
        else:
            ax.annotate(f"a = {a}", (right, a * right), fontsize=7, color="0.5", ha="right")
    ax.set_xlim(0, right)
    ax.set_ylim(0, top)
    ax.set_xlabel("$L_0$ [cm]")
    ax.set_ylabel("$H_0$ [cm]")
    ax.set_title("flow regimes (thesis Fig. 3.6); c/f/s: runs collapsed, fractured, stable",
                 fontsize=8)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    fig.tight_layout()
    fig.savefig(path + ".tmp.png", dpi=130)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dirs", nargs="+", metavar="DIR")
    parser.add_argument("--output", "-o", default="flow-map",
                        help="folder for flow_map.csv and flow_map.png (default flow-map)")
    parser.add_argument("--no-plot", action="store_true", help="the CSV only")
    args = parser.parse_args(argv)
    try:
        points = [read_ensemble(f) for f in ensemble_files(args.dirs)]
        if os.path.exists(args.output) and not os.path.isdir(args.output):
            raise InputError(f"{args.output}: exists and is not a folder")
    except InputError as e:
        print(f"flow-map: error: {e}", file=sys.stderr)
        return 2
    os.makedirs(args.output, exist_ok=True)
    table = os.path.join(args.output, "flow_map.csv")
    figure = os.path.join(args.output, "flow_map.png")
    # Both files made aside first, then moved into place: a failure leaves the last map
    # whole, and a map without a figure leaves no older figure beside it.
    write_csv(points, table)
    if not args.no_plot:
        draw(points, figure)
        os.replace(figure + ".tmp.png", figure)
    elif os.path.exists(figure):
        os.remove(figure)
    os.replace(table + ".tmp", table)
    for p in points:
        print(f"{p['ensemble']}: L0 {100 * p['L0_m']:.1f} cm, H0 {100 * p['H0_m']:.1f} cm, "
              f"{p['runs']} runs, {outcome(p)}")
    print(f"flow map: {table}" + ("" if args.no_plot else f", {figure}"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
