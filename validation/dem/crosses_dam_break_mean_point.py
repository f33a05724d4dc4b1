#!/usr/bin/python3
"""crosses_dam_break with Grains3D's contact model: the element contacts of two bodies
averaged (simulation.element_contacts = "mean") and one contact point per pair of touching
elements (simulation.flat_contacts = "point"), with the thesis' Table 3.1 in the pour and
the collapse (thesis §2.3, §3.2-3.3, Fig. 3.7-3.9).

In the experiments' box (20 cm deep) the 4 cm gate's column collapses with the mean and
the patches (crosses_dam_break_mean) and fractures with the sum (crosses_dam_break); in the
6 cm deep box of crosses_flow_map_mean_point the tall column (450 crosses, H0 26 cm)
fractures with this model on all three pours (2026-12-06).
This case runs the same gates and checks as crosses_dam_break with Grains3D's whole model,
in its own folders (validation/dem/results/runs/crosses_dam_break_mean_point).

Writes validation/dem/results/crosses_dam_break_mean_point.json and
docs/validation/figures/crosses_dam_break_mean_point.png.
Usage: /usr/bin/python3 validation/dem/crosses_dam_break_mean_point.py [--build build]
           [--gates 4 8 ...] [--threads T] [--reuse] [--hold-file F]
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosses_dam_break  # noqa: E402

if __name__ == "__main__":
    sys.exit(crosses_dam_break.main(["--element-contacts", "mean", "--flat-contacts", "point"]
                                    + sys.argv[1:]))
