#!/usr/bin/env python3
"""Membrane bending validation (thesis §4.4.1, Fig. 4.3-4.4; issue #8).

Runs build/validation/validate_membrane_bending, which computes on a biconcave
red blood cell (eq. 4.21, R = 1) of 5120 triangles the mean and Gaussian
curvatures, the Laplace-Beltrami of the mean curvature and the Helfrich force
density (Eb = 1, kappa0 = 0) at every node, with the exact values of the
axisymmetric surface, and the error norms on spheres and biconcave cells of
320 to 20480 triangles. Draws the Fig. 4.4 curves against the polar angle and
the convergence plot, and writes docs/validation/membrane.md.

Usage: /usr/bin/python3 validation/membrane/bending.py [--build build]
Exits non-zero if a check fails (the same bounds as tests/membrane/test_bending.cpp).
"""
import argparse
import csv
import datetime
import json
import math
import os
import platform
import subprocess
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
RESULTS = os.path.join(ROOT, "validation", "membrane", "results")
FIGURES = os.path.join(ROOT, "docs", "validation", "figures")
REPORT = os.path.join(ROOT, "docs", "validation", "membrane.md")

# (quantity, shape, triangles, norm, bound): the assertions of test_bending.cpp.
CHECKS = [
    ("kappa", "biconcave", 5120, "linf", 0.018),
    ("kappa_g", "biconcave", 5120, "linf", 0.027),
    ("laplace", "biconcave", 5120, "l2", 0.07),
    ("laplace", "biconcave", 5120, "linf", 0.20),
    ("force", "biconcave", 5120, "l2", 0.08),
    ("force", "biconcave", 5120, "linf", 0.23),
    ("kappa", "sphere", 20480, "linf", 1e-3),
]


def read_csv(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) if k != "shape" else 0.0 for r in rows]) for k in rows[0]}, rows


def plot_curves(data, path):
    order = np.argsort(data["theta"])
    theta = data["theta"]
    fig, axes = plt.subplots(2, 2, figsize=(10, 8))
    panels = [
        (axes[0, 0], [("kappa", r"$\kappa R$"), ("kappa_g", r"$\kappa_g R^2$")], "curvatures"),
        (axes[0, 1], [("laplace", r"$\Delta_s \kappa\, R^3$")], "Laplace-Beltrami of the mean curvature"),
        (axes[1, 0], [("force", r"$f_b R^3 / E_b$")], "bending force density"),
    ]
    for ax, series, title in panels:
        for key, label in series:
            ax.plot(theta, data[key], ".", ms=3, label=label + " (5120 triangles)")
            ax.plot(theta[order], data[key + "_exact"][order], "k-", lw=1, label=label + " exact")
        ax.set_xlabel(r"polar angle $\theta$ (0: axis, $\pi/2$: rim)")
        ax.set_title(title)
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    ax = axes[1, 1]
    ax.plot(theta, data["laplace"] - data["laplace_exact"], ".", ms=3)
    ax.set_xlabel(r"polar angle $\theta$")
    ax.set_title(r"error of $\Delta_s\kappa\, R^3$ (numerical - exact)")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_convergence(rows, path):
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, shape in zip(axes, ["sphere", "biconcave"]):
        sel = [r for r in rows if r["shape"] == shape]
        n = np.array([float(r["triangles"]) for r in sel])
        for key, label in [("kappa", r"$\kappa$"), ("kappa_g", r"$\kappa_g$"),
                           ("laplace", r"$\Delta_s\kappa$"), ("force", "force")]:
            ax.loglog(n, [float(r[key + "_l2"]) for r in sel], "o-", label=label + " L2")
            ax.loglog(n, [float(r[key + "_linf"]) for r in sel], "x--", label=label + " Linf")
        ax.loglog(n, 0.5 * (n / n[0]) ** -1.0, "k:", label="second order")
        ax.set_xlabel("triangles")
        ax.set_ylabel("relative error")
        ax.set_title(shape)
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def observed_orders(rows, shape, key):
    sel = [r for r in rows if r["shape"] == shape]
    out = []
    for a, b in zip(sel, sel[1:]):
        # h halves per subdivision: order = log2(e_coarse / e_fine).
        out.append(math.log2(float(a[key]) / float(b[key])))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--quick", action="store_true", help="accepted for run_all compatibility")
    args = parser.parse_args()
    driver = os.path.join(args.build, "validation", "validate_membrane_bending")
    os.makedirs(RESULTS, exist_ok=True)
    os.makedirs(FIGURES, exist_ok=True)
    start = time.time()
    subprocess.run([driver, RESULTS], check=True)
    run_time = time.time() - start

    data, _ = read_csv(os.path.join(RESULTS, "biconcave_5120.csv"))
    with open(os.path.join(RESULTS, "convergence.csv")) as f:
        rows = list(csv.DictReader(f))
    plot_curves(data, os.path.join(FIGURES, "membrane_biconcave_curvatures.png"))
    plot_convergence(rows, os.path.join(FIGURES, "membrane_bending_convergence.png"))

    checks = []
    for quantity, shape, triangles, norm_name, bound in CHECKS:
        row = next(r for r in rows if r["shape"] == shape and int(r["triangles"]) == triangles)
        value = float(row[f"{quantity}_{norm_name}"])
        checks.append({"quantity": f"{quantity} {norm_name}, {shape} {triangles}", "measured": value,
                       "tolerance": f"< {bound}", "pass": value < bound})
    passed = all(c["pass"] for c in checks)

    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip()
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(l.split(":", 1)[1].strip() for l in f if l.startswith("model name"))
    except (OSError, StopIteration):
        pass

    lines = [
        "# Membrane validation report",
        "",
        "Generated by `/usr/bin/python3 validation/membrane/bending.py --build build` "
        f"on {datetime.date.today()} (commit {commit}, {cpu}, {os.cpu_count()} cores; "
        f"driver run time {run_time:.1f} s). Elastic checks (uniaxial tension vs "
        "Barthès-Biesel to 1e-8, energy gradient, rigid motions, net force and torque, "
        "relaxation) are unit tests in `tests/membrane/` and are not repeated here.",
        "",
        "## Bending: curvatures, Laplace-Beltrami and force density (thesis §4.4.1, Fig. 4.3-4.4)",
        "",
        "Biconcave red blood cell of eq. 4.21 (largest radius R = 1, symmetry axis z), "
        "kappa0 = 0, Eb = 1, paraboloid fits over the one-ring with 4 normal corrections. "
        "Exact values from the axisymmetric surface (`src/membrane/biconcave_profile.hpp`). "
        "Polar angle theta from the symmetry axis (0 at the dimple, pi/2 on the rim); both "
        "halves of the cell are folded onto [0, pi/2]. Sign convention: kappa > 0 on a "
        "sphere with the outward normal; force density positive outward "
        "(`docs/theory/membrane.md`).",
        "",
        "![curvatures](figures/membrane_biconcave_curvatures.png)",
        "",
        "## Error norms vs refinement",
        "",
        "L2 = RMS over the nodes of (numerical - exact), Linf = largest |numerical - exact|, "
        "both divided by the largest |exact| (on the sphere, where Delta_s kappa = 0, by "
        "1/R^3; sphere force with kappa0 = 0.5/R, exact density 1 Eb/R^3).",
        "",
        "| shape | triangles | kappa L2 | kappa Linf | kappa_g L2 | kappa_g Linf | "
        "Δs kappa L2 | Δs kappa Linf | force L2 | force Linf |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in sorted(rows, key=lambda r: (r["shape"], int(r["triangles"]))):
        lines.append("| " + " | ".join([r["shape"], r["triangles"]] + [
            f"{float(r[k]):.3g}" for k in ["kappa_l2", "kappa_linf", "kappa_g_l2", "kappa_g_linf",
                                           "laplace_l2", "laplace_linf", "force_l2", "force_linf"]]) + " |")
    fmt = lambda xs: ", ".join(f"{x:.2f}" for x in xs)  # noqa: E731
    lines += [
        "",
        "Observed orders per refinement (error ratio, log2, between successive meshes "
        "320 → 1280 → 5120 → 20480):",
        "",
        f"- sphere kappa Linf: {fmt(observed_orders(rows, 'sphere', 'kappa_linf'))}; "
        f"kappa_g Linf: {fmt(observed_orders(rows, 'sphere', 'kappa_g_linf'))}; "
        f"Δs kappa L2: {fmt(observed_orders(rows, 'sphere', 'laplace_l2'))}",
        f"- biconcave kappa L2: {fmt(observed_orders(rows, 'biconcave', 'kappa_l2'))}; "
        f"kappa_g L2: {fmt(observed_orders(rows, 'biconcave', 'kappa_g_l2'))}; "
        f"Δs kappa L2: {fmt(observed_orders(rows, 'biconcave', 'laplace_l2'))}",
        "",
        "![convergence](figures/membrane_bending_convergence.png)",
        "",
        "Reading: kappa and kappa_g converge at second order. Delta_s kappa, a fourth "
        "derivative of the geometry, does not converge in the maximum norm: the largest "
        "errors sit at valence-5 nodes, where five neighbours make the second "
        "fit (five unknowns) an interpolation of the O(h^2) curvature error, which it "
        "differentiates twice. The thesis reports the same behaviour ('a few outliers "
        "deviate ... by a few percents', Fig. 4.4b-c) and so do Guckenberger et al. (2016, "
        "Fig. 6c, 8e). On the biconcave cell the RMS error of Delta_s kappa falls to 5.6 % "
        "at 5120 triangles and rises again at 20480: the fit noise (curvature error / h^2) "
        "no longer decreases. A two-ring fit would smooth it; the thesis method (one-ring) "
        "is kept.",
        "",
        "## Checks",
        "",
        "| quantity | measured | bound | pass |",
        "|---|---|---|---|",
    ]
    for c in checks:
        lines.append(f"| {c['quantity']} | {c['measured']:.4g} | {c['tolerance']} | "
                     f"{'PASS' if c['pass'] else 'FAIL'} |")
    lines.append("")
    with open(REPORT, "w") as f:
        f.write("\n".join(lines))
    with open(os.path.join(RESULTS, "bending.json"), "w") as f:
        json.dump({"name": "bending", "checks": checks, "run_time_s": run_time, "pass": passed}, f,
                  indent=1)
    print(f"wrote {REPORT}: {'PASS' if passed else 'FAIL'}")
    return 0 if passed else 1


if __name__ == "__main__":
    sys.exit(main())
