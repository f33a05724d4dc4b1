"""Unit tests of crosses_column_width's columns and checks (run by ctest
ValidationScripts.DemHelpers)."""
import contextlib
import io
import math
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosses_column_width as cw  # noqa: E402


def folders_of(variant, size, seed):
    """cw.folders() with `variant` chosen, as main() chooses it; the module's variant is
    restored after."""
    saved = cw.variant
    try:
        cw.variant = variant
        return cw.folders(size, seed)
    finally:
        cw.variant = saved


class Columns(unittest.TestCase):
    def test_the_small_column_is_under_two_cross_lengths_the_large_over_three(self):
        small, large = cw.SIZES["small"].column(), cw.SIZES["large"].column()
        self.assertLess(small.gate_cm / 100, 2 * cw.CROSS_LENGTH_M)
        self.assertGreater(large.gate_cm / 100, 3 * cw.CROSS_LENGTH_M)
        self.assertEqual((small.count, large.count), (1000, 3000))
        self.assertEqual(small.depth_m, 0.15)

    def test_the_gate_gives_a_of_fig_3_9_for_the_estimated_bulk_volume(self):
        for size in cw.SIZES.values():
            col = size.column()
            l0 = col.gate_cm / 100
            h0 = size.count * cw.CROSS_VOLUME_M3 / (l0 * col.depth_m)
            self.assertAlmostEqual(h0 / l0, cw.ASPECT, delta=0.1)
            self.assertGreater(col.pour_bottom_m, h0)  # the pour starts above the column

    def test_the_pour_region_stays_at_the_cases_bottom_for_the_small_column(self):
        self.assertEqual(cw.SIZES["small"].column().pour_bottom_m, 0.28)


class Description(unittest.TestCase):
    def test_the_report_names_the_columns_it_reports(self):
        self.assertEqual(cw.columns_text([("small", 1)]),
                         "1000 crosses (L0 under two cross lengths), packing 1")
        self.assertEqual(cw.columns_text([("large", 1), ("small", 1), ("small", 2), ("small", 3)]),
                         "1000 crosses (L0 under two cross lengths), packings 1, 2 and 3; "
                         "3000 (over three), packing 1")
        self.assertEqual(cw.columns_text([("large", 2)]),
                         "3000 crosses (L0 over three cross lengths), packing 2")


class Checks(unittest.TestCase):
    def test_tolerances_widen_the_thesis_ranges_as_for_the_spheres(self):
        small = cw.SIZES["small"]
        checks = small.checks("x", 0.30, 4.0, 7.0)
        self.assertEqual([c["tolerance"] for c in checks],
                         ["[0.272, 0.468] (±20 %)", "[2.5, 5.5]", "[5, 9]"])
        self.assertTrue(all(c["pass"] for c in checks))
        checks = cw.SIZES["large"].checks("x", 0.30, 1.9, math.inf)
        self.assertEqual([c["pass"] for c in checks], [False, False, False])
        self.assertEqual(checks[2]["measured"], "still above 5 % at the end")
        standing = cw.SIZES["large"].checks("x", 0.02, 9.5, 9.5)[2]
        self.assertEqual(standing["measured"], "never above 5 %")
        self.assertFalse(standing["pass"])  # its peak's time is no end of a collapse
        self.assertEqual(checks[1]["tolerance"], "[2, 3]")

    def test_a_column_that_never_moved_has_no_time_of_the_peak_to_pass(self):
        # A standing column's speed creeps to its largest value in the thesis' window (the
        # Grains3D model's narrow column of 2026-12-06: 0.029 at 3.9 tau_c): no collapse.
        peak, time_of_peak, rest = cw.SIZES["small"].checks("x", 0.029, 3.9, math.inf)
        self.assertEqual(time_of_peak["measured"], "3.90 (the peak under 5 %)")
        self.assertEqual([c["pass"] for c in (peak, time_of_peak, rest)], [False] * 3)

    def test_contrast_checks_compare_the_means(self):
        results = {("small", 1): {"peak": 0.3, "below": 7.0, "x_top": 0.9},
                   ("small", 2): {"peak": 0.2, "below": 6.0, "x_top": 0.7},
                   ("large", 1): {"peak": 0.2, "below": 9.0, "x_top": 0.2},
                   ("large", 2): {"peak": 0.25, "below": 4.0, "x_top": 0.3}}
        checks = cw.contrast_checks(results, [1, 2])
        self.assertEqual([c["pass"] for c in checks], [True, False, True])
        self.assertEqual(checks[0]["measured"], "0.225 against 0.250")

    def test_contrast_checks_take_the_packings_there_are(self):
        results = {("small", 1): {"peak": 0.3, "below": 7.0, "x_top": 0.9},
                   ("small", 2): {"peak": 0.2, "below": 6.0, "x_top": 0.7},
                   ("large", 2): {"peak": 0.1, "below": 9.0, "x_top": 0.2}}
        checks = cw.contrast_checks(results, [1, 2, 3])
        self.assertEqual(checks[0]["measured"], "0.100 against 0.250")
        self.assertEqual([c["pass"] for c in checks], [True, True, True])

    def test_finished_only_keeps_the_finished_runs_and_names_the_others(self):
        done = {("small", 1, True), ("small", 2, True), ("large", 1, True), ("small", 1, False)}
        saved = cw.collapse_finished
        cw.collapse_finished = lambda size, seed, table31=False: \
            (size, seed, not table31) in done
        try:
            keys = [(size, seed) for size in ("small", "large") for seed in (1, 2)]
            kept, kept31, note = cw.finished_only(keys, [("small", 1), ("large", 1)])
            everything = cw.finished_only([("small", 1), ("large", 1)], [("small", 1)])
        finally:
            cw.collapse_finished = saved
        self.assertEqual(kept, [("small", 1), ("small", 2), ("large", 1)])
        self.assertEqual(kept31, [("small", 1)])
        self.assertIn("3000 crosses, seed 2; 3000 crosses, seed 1, Table 3.1.", note)
        self.assertEqual(everything, ([("small", 1), ("large", 1)], [("small", 1)], None))

    def test_the_mean_checks_its_table31_collapses_in_its_own_folders(self):
        pour, checked, table31 = folders_of(cw.MEAN, "small", 2)
        self.assertEqual(os.path.basename(os.path.dirname(pour)), "crosses_column_width_mean")
        self.assertEqual(os.path.basename(checked), "small_seed2_table31")
        self.assertEqual(checked, table31)
        self.assertIsNone(cw.MEAN.tangential)
        self.assertIn('simulation.element_contacts="mean"', cw.MEAN.rule)
        self.assertEqual(os.path.basename(cw.folders("small", 2)[1]),
                         f"small_seed2_kt{cw.KT:g}_gamma{cw.GAMMA_T:g}")

    def test_grains3d_model_runs_in_its_own_folders_and_needs_the_mean(self):
        saved = cw.variant
        pour, checked, _ = folders_of(cw.MEAN_POINT, "small", 1)
        self.assertEqual(os.path.basename(os.path.dirname(pour)),
                         "crosses_column_width_mean_point")
        self.assertEqual(os.path.basename(checked), "small_seed1_table31")
        self.assertIsNone(cw.MEAN_POINT.tangential)
        self.assertIn('simulation.element_contacts="mean"', cw.MEAN_POINT.rule)
        self.assertIn('simulation.flat_contacts="point"', cw.MEAN_POINT.rule)
        with contextlib.redirect_stderr(io.StringIO()) as err:
            with self.assertRaises(SystemExit) as stop:
                cw.main(["--flat-contacts", "point", "--build", "no-such-build"])
        self.assertEqual(stop.exception.code, 2)
        self.assertIn("--element-contacts mean", err.getvalue())
        self.assertIs(cw.variant, saved)  # refused before it chose a variant

    def test_a_failed_job_cancels_the_jobs_not_yet_started(self):
        started = []

        def fake_run_one(exe, size, seed, table31, threads=1):
            started.append((size, seed, table31))
            if seed == 1:
                raise RuntimeError("run failed")

        real = cw.run_one
        cw.run_one = fake_run_one
        try:
            keys = [("small", s) for s in (1, 2, 3, 4, 5, 6)]
            with self.assertRaises(RuntimeError):
                cw.run_all_jobs("exe", keys, [("small", 1)])
        finally:
            cw.run_one = real
        self.assertIn(("small", 1, True), started)
        self.assertLess(len(started), len(keys))

    def test_a_row_has_a_cell_per_column(self):
        summary = {"L0_m": 0.052, "H0_m": 0.166, "aspect_ratio_H0_over_L0": 3.19, "halts": 0.0,
                   "runout_ratio": 4.2, "regime": 2.0}
        r = {"summary": summary, "peak": 0.3, "peak_t": 3.1, "below": math.inf, "x_top": 0.8,
             "collapse_s": 3600.0}
        row = cw.table_row("1000 crosses, seed 1", r, "0.50")
        self.assertEqual(len(row), len(cw.TABLE_HEADER))
        self.assertEqual(row[7], "still above 5 % at the end")
        self.assertEqual(row[11], "collapsed")

    def test_sentence(self):
        self.assertEqual(cw.sentence("1000 crosses, seed 1, Table 3.1"),
                         "1000 crosses, seed 1, Table 3.1")
        self.assertEqual(cw.sentence("gate 8 cm"), "Gate 8 cm")

    def test_span(self):
        self.assertEqual(cw.span((2.5, 2.5)), "2.5")
        self.assertEqual(cw.span((0.34, 0.39)), "0.34-0.39")


if __name__ == "__main__":
    unittest.main()
