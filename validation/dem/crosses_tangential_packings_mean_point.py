#!/usr/bin/python3
"""crosses_tangential_packings with Grains3D's contact model: the element contacts of two
bodies averaged (simulation.element_contacts = "mean") and one contact point per pair of
touching elements (simulation.flat_contacts = "point"; thesis §2.3, §3.4.3, Fig. 3.17).

The 300-cross column poured with seeds 1 to 6 with that model, each pour continued with the
3 x 3 tangential parameters around Table 3.1 with it, classified as in
crosses_tangential_map; the same check (the Table 3.1 point top-driven on every packing)
and the same reported counts, in its own folders
(validation/dem/results/runs/crosses_tangential_packings_mean_point). Runs are resumable.

Writes validation/dem/results/crosses_tangential_packings_mean_point.json and
docs/validation/figures/crosses_tangential_packings_mean_point.png. About 90 min on 2
cores (the pours about 14 min each on one thread, two at a time).
Usage: /usr/bin/python3 validation/dem/crosses_tangential_packings_mean_point.py
           [--build build] [--rerun-pours] [--rerun] [--table31-only]
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosses_tangential_packings  # noqa: E402

if __name__ == "__main__":
    sys.exit(crosses_tangential_packings.main(
        ["--element-contacts", "mean", "--flat-contacts", "point"] + sys.argv[1:]))
