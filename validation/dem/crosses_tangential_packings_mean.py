#!/usr/bin/python3
"""crosses_tangential_packings with the element contacts of two bodies averaged, as Grains3D
does for composite particles (simulation.element_contacts = "mean"; thesis §3.4.3, Fig. 3.17).

The 300-cross column poured with seeds 1 to 6 and the mean, each pour continued with the
3 x 3 tangential parameters around Table 3.1 with the mean, classified as in
crosses_tangential_map; the same check (the Table 3.1 point top-driven on every packing)
and the same reported counts, in its own folders
(validation/dem/results/runs/crosses_tangential_packings_mean). Runs are resumable.

Writes validation/dem/results/crosses_tangential_packings_mean.json and
docs/validation/figures/crosses_tangential_packings_mean.png. About 105 min on 2 cores.
Usage: /usr/bin/python3 validation/dem/crosses_tangential_packings_mean.py [--build build]
           [--rerun-pours] [--rerun]
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosses_tangential_packings  # noqa: E402

if __name__ == "__main__":
    sys.exit(crosses_tangential_packings.main(["--element-contacts", "mean"] + sys.argv[1:]))
