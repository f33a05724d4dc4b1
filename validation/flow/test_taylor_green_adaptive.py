"""Tests of the grading in validation/flow/taylor_green_adaptive.py: one run against the
four tolerances, a sweep's verdict, and the script's. Run by ctest
(ValidationScripts.FlowHelpers) or by hand:
/usr/bin/python3 -m unittest discover -s validation/flow -p 'test_*.py'"""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import taylor_green_adaptive as tg  # noqa: E402

REFERENCE_CELLS = 128.0 ** 3


def run_row(ratio=6.0, max_mid=5e-3, max_end=5e-3, divergence=1e-8):
    """A row of the driver's CSV: `ratio` times fewer cells than the reference."""
    return {"cells_mean": REFERENCE_CELLS / ratio, "max_mid": max_mid, "max_end": max_end,
            "max_divergence": divergence}


def verdicts(checks):
    return [c[3] for c in checks]


class OneRun(unittest.TestCase):
    def test_a_run_inside_every_tolerance_passes_all_four_checks_and_the_cell_count(self):
        checks = tg.sweep_checks("adaptive zeta 0.04", run_row(), REFERENCE_CELLS, 1e-3)
        self.assertEqual(verdicts(checks), [True] * 5)
        self.assertAlmostEqual(checks[0][1], 6.0)

    def test_the_bounds_of_the_tolerances(self):
        # 5x fewer cells and 1e-2 u0 are inside (>=, <=); 1e-6 1/s of divergence is not (<).
        at_bounds = run_row(ratio=5.0, max_mid=1e-2, max_end=1e-2, divergence=1e-6)
        checks = tg.sweep_checks("r", at_bounds, REFERENCE_CELLS, tg.ENERGY_TOLERANCE)
        self.assertEqual(verdicts(checks), [True, True, True, True, False])

    def test_each_tolerance_fails_on_its_own(self):
        cases = [(run_row(ratio=4.99), 1e-3, 0), (run_row(max_mid=1.01e-2), 1e-3, 1),
                 (run_row(max_end=1.01e-2), 1e-3, 2), (run_row(), 5.01e-3, 3),
                 (run_row(divergence=2e-6), 1e-3, 4)]
        for row, energy, failing in cases:
            expected = [k != failing for k in range(5)]
            self.assertEqual(verdicts(tg.sweep_checks("r", row, REFERENCE_CELLS, energy)), expected)

    def test_the_energy_error_is_the_largest_relative_difference(self):
        reference = np.array([[0.0, 1.0], [0.5, 0.5], [1.0, 0.25]])
        run = np.array([[0.0, 1.0], [0.5, 0.49], [1.0, 0.2525]])
        self.assertAlmostEqual(tg.kinetic_energy_error(reference, run), 0.02)


class Sweeps(unittest.TestCase):
    def rows(self, **runs):
        return {name: tg.sweep_checks(name, row, REFERENCE_CELLS, 1e-3)
                for name, row in runs.items()}

    def test_one_threshold_meeting_every_tolerance_passes_the_sweep(self):
        rows = self.rows(a=run_row(ratio=4.0), b=run_row(ratio=5.1), c=run_row(max_mid=2e-2))
        meeting, check = tg.graded_sweep((1, 2, 3), ["a", "b", "c"], rows)
        self.assertEqual(meeting, ["b"])
        self.assertTrue(check[3])
        self.assertIn("(b)", check[2])

    def test_thresholds_that_each_miss_one_tolerance_fail_the_sweep(self):
        # Cells met by one run, accuracy by another: no threshold meets both.
        rows = self.rows(a=run_row(ratio=4.9), b=run_row(ratio=11.0, max_end=1.9e-2))
        meeting, check = tg.graded_sweep((1, 2), ["a", "b"], rows)
        self.assertEqual(meeting, [])
        self.assertFalse(check[3])
        self.assertIn("none", check[2])

    def test_a_run_missing_from_the_disk_fails_the_sweep(self):
        rows = self.rows(a=run_row())
        meeting, check = tg.graded_sweep((1, 2), ["a"], rows)
        self.assertEqual(meeting, ["a"])
        self.assertFalse(check[3])
        self.assertIn("1 not run", check[2])

    def test_runs_on_disk_are_named_by_threshold_in_the_sweep_order(self):
        runs = {"adaptive zeta 0.0436": {}, "adaptive zeta 0.04 (4^3 blocks)": {},
                "adaptive zeta 0.0519": {}}
        self.assertEqual(tg.on_disk(runs, tg.BISECTION),
                         ["adaptive zeta 0.0436", "adaptive zeta 0.0519"])
        self.assertEqual(tg.on_disk(runs, (0.04,), tg.BLOCKS4), ["adaptive zeta 0.04 (4^3 blocks)"])
        # A bisection run missing from the disk fails its sweep ("1 not run").
        rows = {name: tg.sweep_checks(name, run_row(), REFERENCE_CELLS, 1e-3)
                for name in tg.on_disk(runs, tg.BISECTION)}
        _, check = tg.graded_sweep(tg.BISECTION, tg.on_disk(runs, tg.BISECTION), rows)
        self.assertFalse(check[3])
        self.assertIn("1 not run", check[2])

    def test_the_script_passes_only_if_every_graded_check_does(self):
        passed, failed = ("s", 1, "", True), ("t", 0, "", False)
        reported_miss = ("r", 9.0, "reported", None, False)
        self.assertTrue(tg.script_passes([passed, reported_miss]))
        self.assertFalse(tg.script_passes([passed, failed]))

    def test_the_bisection_is_4e_2_times_powers_of_the_eighth_root_of_2(self):
        # As its docstring and docs/validation/flow.md state, to the 3 digits it ran with.
        expected = [round(0.04 * 2 ** (k / 8), 4) for k in (1, 2, 3)]
        self.assertEqual(list(tg.BISECTION), expected)


if __name__ == "__main__":
    unittest.main()
