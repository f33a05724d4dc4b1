#!/usr/bin/python3
"""crosses_column_width with the element contacts of two bodies averaged, as Grains3D does
for composite particles (simulation.element_contacts = "mean"), and the thesis' Table 3.1
in the pours and the collapses (thesis §3.3.2, Fig. 3.9).

crosses_column_width sums the element contacts (the model's default) and collapses with the
calibration of crosses_recalibrated, without which its crosses hardly move. With the mean,
the 4 cm gate of crosses_dam_break_mean runs out as the thesis' crosses do with Table 3.1
itself; this case asks whether those crosses also move as the thesis' do: the narrow (1000
crosses) and wide (3000) columns of a = 3.2, with the same checks against Fig. 3.9a, in
their own folders (validation/dem/results/runs/crosses_column_width_mean).

Writes validation/dem/results/crosses_column_width_mean.json and
docs/validation/figures/crosses_column_width_mean.png.
Usage: /usr/bin/python3 validation/dem/crosses_column_width_mean.py [--build build]
           [--sizes small large] [--seeds 1 2 3] [--reuse [--finished-only]] [--quick]
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosses_column_width  # noqa: E402

if __name__ == "__main__":
    sys.exit(crosses_column_width.main(["--element-contacts", "mean"] + sys.argv[1:]))
