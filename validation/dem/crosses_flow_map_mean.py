#!/usr/bin/python3
"""crosses_flow_map with the element contacts of two bodies averaged, as Grains3D does for
composite particles (simulation.element_contacts = "mean"), contact patches and the thesis'
Table 3.1 in the pours and the collapses (thesis §3.3.1, Fig. 3.6): the same columns and
checks, in their own folders (validation/dem/results/runs/crosses_flow_map_mean).

Writes validation/dem/results/crosses_flow_map_mean.json and
docs/validation/figures/crosses_flow_map_mean.png.
Usage: /usr/bin/python3 validation/dem/crosses_flow_map_mean.py [--build build] [--quick]
           [--columns 4:150 4:300 ...] [--seeds 1 2 3] [--reuse]
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosses_flow_map  # noqa: E402

if __name__ == "__main__":
    sys.exit(crosses_flow_map.main(["--element-contacts", "mean"] + sys.argv[1:]))
