#!/usr/bin/python3
"""crosses_flow_map_mean_point in the experiments' 20 cm deep box (crosses_dam_break's,
the case's own): Grains3D's contact model (the element contacts of two crosses averaged,
one contact point per pair of touching elements), Table 3.1 (thesis §2.3, §3.3.1,
Fig. 3.6).

In the map's 6 cm deep box every column of Grains3D's model behind the 4 cm gate
fractures, the tall ones (H0 26 cm) included, where the thesis' tall columns always
avalanche; in the 20 cm deep box the same model collapses the 4 cm gate's 1300 crosses (H0
21.6 cm, crosses_dam_break_mean_point). This map asks whether the box's depth is what holds
the narrow box's columns: the same heights with 3.3 times the crosses, but for the tall
column, the dam break's own (1300 crosses behind the 4 cm gate, about 22 cm), whose run
with the case's seed (3) is copied from crosses_dam_break_mean_point when that has
finished.

Writes validation/dem/results/crosses_flow_map_mean_point_deep.json and
docs/validation/figures/crosses_flow_map_mean_point_deep.png.
Usage: /usr/bin/python3 validation/dem/crosses_flow_map_mean_point_deep.py [--build build]
           [--quick] [--columns 4:1300 ...] [--seeds 1 2 3] [--reuse]
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosses_flow_map  # noqa: E402

if __name__ == "__main__":
    sys.exit(crosses_flow_map.main(["--element-contacts", "mean", "--flat-contacts", "point",
                                    "--depth-cm", "20"] + sys.argv[1:]))
