#!/usr/bin/python3
"""Figures of a `sanguis analyze` folder (or of an ensemble folder).

usage: plot_analysis.py DIR

Draws, from the CSV files present in DIR:
  runout.png     top-view column intensity before/after, with L at 20/10/1 %  (Fig. 3.2a)
  velocity.png   mean speed / sqrt(g H0) against t / tau_c                    (Fig. 3.9)
  force_pdf.png  PDF of Fc/<Fc>, linear and log                               (Fig. 3.12, B.3)
  fabric.png     rose of branch-vector angles in the xz-plane                 (Fig. 3.14)
"""
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def column(table, name):
    return [float(r[name]) for r in table]


def plot_runout(d):
    table = rows(os.path.join(d, "runout.csv"))
    summary = rows(os.path.join(d, "summary.csv"))[0] if os.path.exists(os.path.join(d, "summary.csv")) else {}
    x = column(table, "x_from_wall_m")
    fig, ax = plt.subplots(figsize=(7, 3.2))
    ax.plot(x, column(table, "initial_intensity"), color="0.6", label="initial column")
    ax.plot(x, column(table, "final_intensity"), color="k", label="final deposit")
    for key, style, label in (("Linf_m", "--", "L (10%)"), ("Linf_20pc_m", ":", "20%"), ("Linf_1pc_m", ":", "1%")):
        if key in summary:
            ax.axvline(float(summary[key]), ls=style, color="tab:red", label=label)
    ax.set_xlabel("distance from the back wall [m]")
    ax.set_ylabel("column intensity")
    ax.set_ylim(0, 1.05)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "runout.png"), dpi=130)
    plt.close(fig)


def plot_velocity(d):
    table = rows(os.path.join(d, "velocity.csv"))
    fig, ax = plt.subplots(figsize=(5, 3.5))
    ax.plot(column(table, "time_over_tau_c"), column(table, "mean_speed_over_sqrt_gH0"), "k-")
    ax.set_xlabel(r"$t/\tau_c$,  $\tau_c=\sqrt{H_0/g}$")
    ax.set_ylabel(r"$\langle |v| \rangle / \sqrt{g H_0}$")
    ax.set_xlim(left=0)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "velocity.png"), dpi=130)
    plt.close(fig)


def plot_force_pdf(d):
    table = rows(os.path.join(d, "force_pdf.csv"))
    fig, (lin, log) = plt.subplots(1, 2, figsize=(9, 3.5))
    for ax, kind in ((lin, "linear"), (log, "log")):
        part = [r for r in table if r["bins"] == kind]
        ax.plot([float(r["centre"]) for r in part], [float(r["pdf"]) for r in part], "k.-")
        ax.set_xlabel(r"$F_c/\langle F_c\rangle$")
        ax.set_ylabel("PDF")
        if kind == "log":
            ax.set_xscale("log")
            ax.set_yscale("log")
    fig.tight_layout()
    fig.savefig(os.path.join(d, "force_pdf.png"), dpi=130)
    plt.close(fig)


def plot_fabric(d):
    table = rows(os.path.join(d, "fabric.csv"))
    centres = [math.radians(float(r["centre_deg"])) for r in table]
    pdf = [float(r["pdf"]) for r in table]
    width = math.radians(float(table[0]["upper_deg"]) - float(table[0]["lower_deg"]))
    fig = plt.figure(figsize=(4.5, 4.5))
    ax = fig.add_subplot(projection="polar")
    # A branch has no sign: theta and theta + 180 are the same direction.
    ax.bar(centres + [c + math.pi for c in centres], pdf + pdf, width=width, color="0.4", edgecolor="k")
    ax.set_title(r"branch vectors in the $xz$-plane ($\theta$ from $x$)", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "fabric.png"), dpi=130)
    plt.close(fig)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    d = sys.argv[1]
    drawn = []
    for name, draw in (("runout.csv", plot_runout), ("velocity.csv", plot_velocity),
                       ("force_pdf.csv", plot_force_pdf), ("fabric.csv", plot_fabric)):
        if os.path.exists(os.path.join(d, name)):
            draw(d)
            drawn.append(name.replace(".csv", ".png"))
    print("plot_analysis: " + (", ".join(drawn) if drawn else "nothing to draw") + " in " + d)


if __name__ == "__main__":
    main()
