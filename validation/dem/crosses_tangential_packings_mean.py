#!/usr/bin/python3
"""crosses_tangential_packings with the element contacts of two bodies averaged, as Grains3D
does for composite particles (simulation.element_contacts = "mean"; thesis §3.4.3, Fig. 3.17).

Grains3D, the code of the thesis' cross simulations, divides the force and torque of each
contact between two composite particles (or a composite particle and a wall) by the number of
contacts the two have at that step (CompositeParticle::InterAction and the contact model's
computeForces). sanguis sums them unless told otherwise. This case pours the same six
columns and runs the same 3 x 3 around Table 3.1 with the mean, in its own folders
(validation/dem/results/runs/crosses_tangential_packings_mean), with the same check: the
Table 3.1 point collapses top-driven (region 2) on every packing.

Writes validation/dem/results/crosses_tangential_packings_mean.json and
docs/validation/figures/crosses_tangential_packings_mean.png.
Usage: /usr/bin/python3 validation/dem/crosses_tangential_packings_mean.py [--build build]
       [--rerun-pours] [--rerun] [--table31-only]
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosses_tangential_packings  # noqa: E402

if __name__ == "__main__":
    sys.exit(crosses_tangential_packings.main(["--element-contacts", "mean"] + sys.argv[1:]))
