"""Tests of scripts/flow_map.py: the map of flow regimes from ensemble folders. Run by
ctest (ValidationScripts.Scripts) or by hand:
/usr/bin/python3 -m unittest discover -s scripts -p 'test_*.py'"""
import contextlib
import csv
import io
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import flow_map  # noqa: E402


def write_ensemble(folder, l0, h0, collapsed, fractured, stable):
    """An ensemble.csv laid out as `sanguis ensemble` writes it (dem/analysis/analyze.cpp,
    write_ensemble): a row per quantity, then the fraction of the runs in each regime."""
    runs = collapsed + fractured + stable
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "ensemble.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["quantity", "mean", "std", "min", "max", "runs"])
        w.writerow(["particles", 1300, 0, 1300, 1300, runs])
        w.writerow(["L0_m", l0, 0, l0, l0, runs])
        w.writerow(["H0_m", h0, 0.001, h0 - 0.001, h0 + 0.001, runs])
        for name, count in (("stable", stable), ("fractured", fractured),
                            ("collapsed", collapsed)):
            w.writerow([f"fraction_{name}", count / runs, "", "", "", runs])


def run(argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = flow_map.main(argv)
    return status, out.getvalue(), err.getvalue()


class FlowMap(unittest.TestCase):
    def test_a_point_is_repeatable_when_every_run_ends_alike_else_intermittent(self):
        with tempfile.TemporaryDirectory() as tmp:
            write_ensemble(os.path.join(tmp, "study", "L4_H21"), 0.04, 0.216, 3, 0, 0)
            write_ensemble(os.path.join(tmp, "study", "L8_H16"), 0.08, 0.156, 0, 3, 0)
            write_ensemble(os.path.join(tmp, "study", "L5_H17"), 0.052, 0.166, 1, 1, 1)
            write_ensemble(os.path.join(tmp, "alone"), 0.12, 0.10, 0, 0, 5)
            out = os.path.join(tmp, "map")
            status, text, _ = run([os.path.join(tmp, "study"), os.path.join(tmp, "alone"),
                                   "--output", out])
            self.assertEqual(status, 0)
            with open(os.path.join(out, "flow_map.csv"), newline="") as f:
                rows = list(csv.DictReader(f))
            # the subfolders of a folder in sorted order, then the next argument
            self.assertEqual([os.path.basename(r["ensemble"]) for r in rows],
                             ["L4_H21", "L5_H17", "L8_H16", "alone"])
            self.assertEqual([r["outcome"] for r in rows],
                             ["collapsed", "intermittent", "fractured", "stable"])
            self.assertEqual([(r["collapsed"], r["fractured"], r["stable"]) for r in rows],
                             [("3", "0", "0"), ("1", "1", "1"), ("0", "3", "0"),
                              ("0", "0", "5")])
            self.assertAlmostEqual(float(rows[0]["aspect_ratio_H0_over_L0"]), 5.4)
            self.assertIn("L0 5.2 cm, H0 16.6 cm, 3 runs, intermittent", text)
            self.assertGreater(os.path.getsize(os.path.join(out, "flow_map.png")), 1000)
            with open(os.path.join(out, "flow_map.csv"), "rb") as f:
                self.assertNotIn(b"\r", f.read())  # lines end as in sanguis' own CSV files

    def test_bad_input_is_named_and_writes_nothing(self):
        with tempfile.TemporaryDirectory() as tmp:
            good = os.path.join(tmp, "good")
            write_ensemble(good, 0.04, 0.2, 2, 1, 0)
            out = os.path.join(tmp, "map")
            cases = []
            empty = os.path.join(tmp, "empty")
            os.makedirs(empty)
            cases.append(([empty], "no ensemble.csv in it or in its subfolders"))
            cases.append(([os.path.join(tmp, "absent")], "absent: not a folder"))
            runs_csv = os.path.join(tmp, "runs_only")
            os.makedirs(runs_csv)
            with open(os.path.join(runs_csv, "ensemble.csv"), "w") as f:
                f.write("quantity,mean,std,min,max,runs\nL0_m,0.04,0,0.04,0.04,2\n")
            cases.append(([runs_csv], "no row H0_m, fraction_collapsed"))
            broken = os.path.join(tmp, "broken")
            write_ensemble(broken, 0.04, 0.2, 1, 1, 0)
            text = open(os.path.join(broken, "ensemble.csv")).read()
            with open(os.path.join(broken, "ensemble.csv"), "w") as f:
                f.write(text.replace("fraction_collapsed,0.5", "fraction_collapsed,half"))
            cases.append(([broken], "fraction_collapsed, column mean: 'half' is not a number"))
            no_column = os.path.join(tmp, "no_column")
            write_ensemble(no_column, 0.0, 0.2, 1, 0, 0)
            cases.append(([no_column], "L0 0 m, H0 0.2 m: not a column"))
            for dirs, message in cases:
                status, _, err = run([good] + dirs + ["--output", out])
                self.assertEqual(status, 2, dirs)
                self.assertIn(message, err)
                self.assertFalse(os.path.exists(out), "nothing is written on bad input")

    def test_a_map_without_its_figure_leaves_no_older_figure_beside_it(self):
        with tempfile.TemporaryDirectory() as tmp:
            write_ensemble(os.path.join(tmp, "a"), 0.04, 0.2, 2, 1, 0)
            out = os.path.join(tmp, "map")
            self.assertEqual(run([os.path.join(tmp, "a"), "--output", out])[0], 0)
            self.assertTrue(os.path.exists(os.path.join(out, "flow_map.png")))
            self.assertEqual(run([os.path.join(tmp, "a"), "--output", out, "--no-plot"])[0], 0)
            self.assertEqual(sorted(os.listdir(out)), ["flow_map.csv"])

    def test_an_earlier_map_stays_when_the_input_is_bad(self):
        with tempfile.TemporaryDirectory() as tmp:
            good = os.path.join(tmp, "good")
            write_ensemble(good, 0.04, 0.2, 2, 1, 0)
            out = os.path.join(tmp, "map")
            self.assertEqual(run([good, "--output", out, "--no-plot"])[0], 0)
            before = open(os.path.join(out, "flow_map.csv")).read()
            self.assertEqual(run([good, os.path.join(tmp, "absent"), "--output", out])[0], 2)
            self.assertEqual(open(os.path.join(out, "flow_map.csv")).read(), before)


if __name__ == "__main__":
    unittest.main()
