#!/usr/bin/python3
"""crosses_flow_map with Grains3D's contact model: the element contacts of two bodies
averaged (simulation.element_contacts = "mean") and one contact point per pair of touching
elements (simulation.flat_contacts = "point"), with the thesis' Table 3.1 in the pours and
the collapses (thesis §2.3, §3.3.1, Fig. 3.6).

With the model's defaults (the sum, contact patches) the map has no collapsed column: the
tall columns of the 4 cm gate fracture and stand on every pour, where the thesis' always
avalanche. Grains3D's model collapses the 300-cross column of
crosses_tangential_packings_mean_point on 4 pours of 6. This case asks whether it gives
the thesis' map: the same columns and checks, in their own folders
(validation/dem/results/runs/crosses_flow_map_mean_point).

Writes validation/dem/results/crosses_flow_map_mean_point.json and
docs/validation/figures/crosses_flow_map_mean_point.png.
Usage: /usr/bin/python3 validation/dem/crosses_flow_map_mean_point.py [--build build]
           [--quick] [--columns 4:150 4:300 ...] [--seeds 1 2 3] [--reuse]
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosses_flow_map  # noqa: E402

if __name__ == "__main__":
    sys.exit(crosses_flow_map.main(["--element-contacts", "mean", "--flat-contacts", "point"]
                                   + sys.argv[1:]))
