"""Tests of validation/dem/crosses_runout.py: which pours it reads from the cases'
summaries, that each pour counts once, and how the tall columns are graded. Run by ctest
(ValidationScripts.DemHelpers) or by hand:
/usr/bin/python3 -m unittest discover -s validation/dem -p 'test_*.py'"""
import json
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosses_runout  # noqa: E402

MAP_HEADER = ["gate [cm]", "crosses", "seed", "H0 [cm]", "a", "(L∞−L0)/L0", "H0/H∞",
              "peak v/√(gH0)", "regime", "wall time of finished segments [h]"]
DAM_HEADER = ["gate [cm]", "crosses", "L0 [cm]", "H0 [cm]", "a", "(L∞−L0)/L0", "K",
              "Lajeunesse", "H0/H∞", "peak v/√(gH0)", "peak t/τc", "neighbours",
              "contact points", "regime", "wall time of finished segments [h]"]


def map_row(gate, crosses, seed, a, runout, regime):
    return [gate, crosses, seed, "21.5", a, runout, "1.02", "0.02", regime, "1.0"]


def dam_row(gate, crosses, a, runout, regime):
    return [gate, crosses, "3.9", "21.6", a, runout, "0.5", "5.9", "1.03", "0.02", "1.7",
            "6.7", "8.5", regime, "1.2"]


def write(folder, name, header, rows, quick=False, runs=("2026-12-06 16:37",
                                                          "2026-12-06 18:33")):
    with open(os.path.join(folder, name + ".json"), "w") as f:
        json.dump({"name": name, "quick": quick, "runs_utc": list(runs),
                   "tables": [{"caption": "", "header": header, "rows": rows}]}, f)


class Collect(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def test_a_dam_break_run_copied_into_the_map_counts_once(self):
        write(self.dir, "crosses_flow_map_deep", MAP_HEADER,
              [map_row("4", "1300", "1", "5.45", "1.10", "fractured"),
               map_row("4", "1300", "3", "5.46", "2.48", "fractured")])
        write(self.dir, "crosses_dam_break", DAM_HEADER,
              [dam_row("4", "1300", "5.46", "2.48", "fractured"),
               dam_row("8", "2000", "1.95", "0.54", "fractured")])
        pours, sources, _ = crosses_runout.collect(self.dir)
        self.assertEqual(list(sources), ["crosses_dam_break", "crosses_flow_map_deep"])
        # The dam break's own run is kept, the map's copy of it dropped.
        self.assertEqual([(p.gate_cm, p.crosses, p.seed, p.source) for p in pours],
                         [(4.0, 1300, 3, "crosses_dam_break"),
                          (8.0, 2000, 3, "crosses_dam_break"),
                          (4.0, 1300, 1, "crosses_flow_map_deep")])
        self.assertTrue(all(p.model == "sum (defaults)" for p in pours))

    def test_the_same_column_and_seed_of_two_models_are_two_pours(self):
        write(self.dir, "crosses_dam_break", DAM_HEADER,
              [dam_row("4", "1300", "5.46", "2.48", "fractured")])
        write(self.dir, "crosses_dam_break_mean", DAM_HEADER,
              [dam_row("4", "1300", "5.42", "6.21", "collapsed")])
        pours, _, _ = crosses_runout.collect(self.dir)
        self.assertEqual([(p.model, p.seed, p.runout) for p in pours],
                         [("sum (defaults)", 3, 2.48), ("mean", 3, 6.21)])

    def test_a_pour_opened_with_another_model_is_left_out_and_quick_ones_marked(self):
        write(self.dir, "crosses_dam_break_mean", DAM_HEADER,
              [dam_row("4", "1300", "5.42", "6.21", "collapsed"),
               dam_row("4, the same pour opened with the sum", "1300", "5.42", "2.48",
                       "fractured")])
        write(self.dir, "crosses_flow_map_mean_point_deep", MAP_HEADER,
              [map_row("4", "500", "1", "2.19", "0.28", "fractured")], quick=True)
        pours, sources, others = crosses_runout.collect(self.dir)
        self.assertEqual(list(sources), ["crosses_dam_break_mean",
                                         "crosses_flow_map_mean_point_deep"])
        self.assertEqual([(p.model, p.runout) for p in pours],
                         [("mean", 6.21), ("mean, point", 0.28)])
        self.assertEqual(others, ['crosses_dam_break_mean\'s "4, the same pour opened with '
                                  'the sum" (2.48, fractured)'])
        s, _, spans = crosses_runout.summary_of(pours, sources, others)
        self.assertTrue(s["quick"])
        self.assertIn("Written in quick mode: crosses_flow_map_mean_point_deep hold fewer "
                      "pours than their full runs.", s["notes"])
        self.assertIn(others[0], s["notes"][2])
        self.assertEqual(len(spans), 2)


class Checks(unittest.TestCase):
    def pour(self, a, runout, seed=1, model="sum"):
        return crosses_runout.Pour(model, 4.0, 1300, seed, 21.5, a, runout, 1.0,
                                   "collapsed", "x")

    def test_a_tall_column_is_graded_on_the_median_of_its_pours(self):
        # Lajeunesse at a = 5.46: 1.9 a^(2/3) = 5.89; ±35 % is 3.83-7.95.
        runs = [self.pour(5.46, 1.10, 1), self.pour(5.46, 3.86, 2), self.pour(5.46, 2.60, 3)]
        c = crosses_runout.column_check("sum", 4.0, 1300, runs)
        self.assertFalse(c["pass"])
        self.assertEqual(c["measured"], "2.60 (3 pours: 1.10, 3.86, 2.60)")
        runs = [self.pour(5.46, 3.90, 1), self.pour(5.46, 7.9, 2), self.pour(5.46, 1.0, 3)]
        self.assertTrue(crosses_runout.column_check("sum", 4.0, 1300, runs)["pass"])
        # Median 4.0 passes where the mean, 2.7, would not.
        runs = [self.pour(5.46, 0.1, 1), self.pour(5.46, 4.0, 2), self.pour(5.46, 4.1, 3)]
        self.assertTrue(crosses_runout.column_check("sum", 4.0, 1300, runs)["pass"])

    def test_a_column_below_a_4_is_reported_not_graded(self):
        c = crosses_runout.column_check("sum", 8.0, 2000, [self.pour(1.95, 0.54)])
        self.assertIsNone(c["pass"])
        self.assertEqual(c["tolerance"], "reported")
        self.assertIn("2.34", c["thesis"])  # 1.2 a
        self.assertIsNone(crosses_runout.column_check("sum", 4.0, 900, [self.pour(3.5, 9.)])
                          ["pass"])  # above the fits' switch, below a = 4
        self.assertFalse(crosses_runout.column_check("sum", 4.0, 900, [self.pour(4.0, 9.)])
                         ["pass"])  # graded from a = 4: 1.9 4^(2/3) = 4.79

    def test_the_case_passes_only_when_every_graded_column_does(self):
        good = [self.pour(5.4, 6.2, model="mean")]
        bad = [self.pour(5.4, 2.5, model="sum")]
        low = [crosses_runout.Pour("sum", 8.0, 2000, 3, 15.6, 1.95, 0.5, 1.0, "fractured",
                                   "x")]
        _, ok, _ = crosses_runout.summary_of(good + low, {})
        self.assertTrue(ok)
        _, ok, _ = crosses_runout.summary_of(good + bad + low, {})
        self.assertFalse(ok)
        s, ok, _ = crosses_runout.summary_of(low, {})
        self.assertFalse(ok)  # nothing graded is not a pass
        self.assertIn("No column with a ≥ 4 has a pour yet: nothing graded.", s["notes"])
        s, ok, _ = crosses_runout.summary_of([], {})
        self.assertFalse(ok)
        self.assertIn("none yet", s["description"])


if __name__ == "__main__":
    unittest.main()
