#!/usr/bin/python3
"""crosses_dam_break with the element contacts of two bodies averaged, as Grains3D does for
composite particles (simulation.element_contacts = "mean"; thesis §3.2-3.3, Table 3.1,
Fig. 3.7-3.9).

Grains3D, the code of the thesis' cross simulations, divides the force and torque of each
contact between two composite particles (or a composite particle and a wall) by the number of
contacts the two have at that step; sanguis sums them unless told otherwise. This case pours
and releases the same columns (the 4 cm gate by default, `--gates` for the others) with the
mean, in its own folders (validation/dem/results/runs/crosses_dam_break_mean), with the same
checks as crosses_dam_break. `--sum-control` pours each column again with the mean (the
same steps, checked row by row against the first pour) and opens it with the sum, in
folders *_opened_sum: what the rule changes after the opening alone.

Writes validation/dem/results/crosses_dam_break_mean.json and
docs/validation/figures/crosses_dam_break_mean.png.
Usage: /usr/bin/python3 validation/dem/crosses_dam_break_mean.py [--build build]
           [--gates 4 8 ...] [--threads T] [--reuse] [--hold-file F] [--sum-control]
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosses_dam_break  # noqa: E402

if __name__ == "__main__":
    sys.exit(crosses_dam_break.main(["--element-contacts", "mean"] + sys.argv[1:]))
