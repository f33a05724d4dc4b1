#!/usr/bin/python3
"""crosses_column_width with Grains3D's contact model: the element contacts of two bodies
averaged (simulation.element_contacts = "mean") and one contact point per pair of touching
elements (simulation.flat_contacts = "point"), with the thesis' Table 3.1 in the pours and
the collapses (thesis §2.3, §3.3.2, Fig. 3.9).

With the mean alone (crosses_column_width_mean) the narrow columns fracture and stand;
with the mean and one point the 300-cross column of crosses_tangential_packings_mean_point
collapses top-driven with Table 3.1 on 4 of 6 pours. This case asks whether that model
also moves the columns of a = 3.2 as the thesis' crosses move: the same columns and checks
against Fig. 3.9a, in their own folders
(validation/dem/results/runs/crosses_column_width_mean_point).

Writes validation/dem/results/crosses_column_width_mean_point.json and
docs/validation/figures/crosses_column_width_mean_point.png.
Usage: /usr/bin/python3 validation/dem/crosses_column_width_mean_point.py [--build build]
           [--sizes small large] [--seeds 1 2 3] [--reuse [--finished-only]] [--quick]
           [--threads T]
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosses_column_width  # noqa: E402

if __name__ == "__main__":
    sys.exit(crosses_column_width.main(["--element-contacts", "mean", "--flat-contacts", "point"]
                                       + sys.argv[1:]))
