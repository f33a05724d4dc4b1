#!/usr/bin/python3
"""crosses_flow_map in the experiments' 20 cm deep box (crosses_dam_break's, the case's
own) with the element contacts of two crosses averaged, as Grains3D does for composite
particles (simulation.element_contacts = "mean"), contact patches, Table 3.1 (thesis
§3.3.1, Fig. 3.6).

The third model of the deep box's map, between the defaults (crosses_flow_map_deep: the
tall column intermittent, one pour of three collapsing) and Grains3D's whole model
(crosses_flow_map_mean_point_deep: every pour of the tall column collapsing). The mean
with the patches collapses the dam break's own pour of the tall column
(crosses_dam_break_mean, 6.21 L0); this map asks whether it does on every pour. Its seed 3
of the tall column (1300 crosses behind the 4 cm gate) is copied from
crosses_dam_break_mean. The map in the 6 cm deep box with this model
(`crosses_flow_map.py --element-contacts mean`) is not in the report: that box's walls
hold its columns whatever the model (docs/theory/dem.md).

Writes validation/dem/results/crosses_flow_map_mean_deep.json and
docs/validation/figures/crosses_flow_map_mean_deep.png.
Usage: /usr/bin/python3 validation/dem/crosses_flow_map_mean_deep.py [--build build]
           [--quick] [--columns 4:1300 ...] [--seeds 1 2 3] [--reuse]
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosses_flow_map  # noqa: E402

if __name__ == "__main__":
    sys.exit(crosses_flow_map.main(["--element-contacts", "mean", "--depth-cm", "20"]
                                   + sys.argv[1:]))
