#!/usr/bin/python3
"""crosses_flow_map in the experiments' 20 cm deep box (crosses_dam_break's, the case's
own), with the model's defaults (the element contacts of two crosses summed, contact
patches) and Table 3.1 (thesis §3.3.1, Fig. 3.6).

In the map's 6 cm deep box no column of this model collapses, the tall ones (H0 26 cm)
included; in the 20 cm deep box Grains3D's model collapses the 4 cm gate's 1300 crosses on
every pour (crosses_flow_map_mean_point_deep), and this model fractures them on the case's
seed (crosses_dam_break, run-out 2.48 L0). This map asks what it does on other pours: the
same heights as the narrow map with 3.3 times the crosses, but for the tall column, the dam
break's own (1300 crosses behind the 4 cm gate, about 22 cm), whose run with the case's
seed (3) is copied from crosses_dam_break when that has finished.

Writes validation/dem/results/crosses_flow_map_deep.json and
docs/validation/figures/crosses_flow_map_deep.png.
Usage: /usr/bin/python3 validation/dem/crosses_flow_map_deep.py [--build build] [--quick]
           [--columns 4:1300 ...] [--seeds 1 2 3] [--reuse]
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosses_flow_map  # noqa: E402

if __name__ == "__main__":
    sys.exit(crosses_flow_map.main(["--depth-cm", "20"] + sys.argv[1:]))
