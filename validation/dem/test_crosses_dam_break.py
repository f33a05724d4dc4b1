"""Unit tests of crosses_dam_break's end of a collapse (run by ctest
ValidationScripts.DemHelpers)."""
import contextlib
import io
import math
import os
import sys
import tempfile
import tomllib
import unittest
from unittest import mock

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosses_dam_break as db  # noqa: E402

HEADER = "time_s,mean_velocity_m_s\n"


def fake_run(folder, log_lines, rows):
    """A run folder with the run.log lines and diagnostics rows (time, mean speed) given."""
    with open(os.path.join(folder, "run.log"), "w") as f:
        f.write("sanguis 0.1.0\n" + "".join(line + "\n" for line in log_lines))
    with open(os.path.join(folder, "diagnostics.csv"), "w") as f:
        f.write(HEADER + "".join(f"{t},{v}\n" for t, v in rows))
    return folder


def fake_pour(folder, count, log_lines, rows):
    """fake_run with a checkpoint and a last frame of `count` crosses."""
    fake_run(folder, log_lines, rows)
    open(os.path.join(folder, "checkpoint.bin"), "w").close()
    os.makedirs(os.path.join(folder, "particles"), exist_ok=True)
    with open(os.path.join(folder, "particles", "particles_00000001.vtu"), "w") as f:
        f.write(f'<Piece NumberOfPoints="{count}" NumberOfCells="0">')


class EndOfPour(unittest.TestCase):
    def setUp(self):
        self.calls = []
        self.saved = db.gate_runner
        db.gate_runner = lambda *args, **kwargs: (
            lambda end, more=(): self.calls.append((end, list(more))))

    def tearDown(self):
        db.gate_runner = self.saved

    def test_a_pour_stops_at_rest_after_its_last_cross_is_due(self):
        col = db.Column(4, 1300)
        due = 1300 / db.pour_rate(col)
        self.assertEqual(db.pour_stop_settings(col),
                         ["--set", "stop.mean_velocity_below_m_s=1e-3",
                          "--set", f"stop.check_after_s={due + db.POUR_REST_AFTER_S:.4f}"])
        self.assertLess(db.POUR_REST_AFTER_S, db.SETTLE_S)

    def test_pours_that_ended_are_taken_as_they_are(self):
        col = db.Column(4, 1300)
        end = math.ceil(10 * (1300 / db.pour_rate(col) + db.SETTLE_S)) / 10  # the SETTLE_S end
        with tempfile.TemporaryDirectory() as d:
            # Ended at its SETTLE_S end (before the stop at rest): opens there, as it did.
            fake_pour(d, 1300, [f"done: t = {end} s, 9 steps in 1s"], [(end, 1e-5)])
            self.assertAlmostEqual(db.pour_gate("sanguis", col, d, 1), end)
            # Ended at rest before it: opens where it stopped.
            fake_pour(d, 1300, ["done: t = 3.45 s, 9 steps in 1s, settled"], [(3.45, 2e-4)])
            self.assertAlmostEqual(db.pour_gate("sanguis", col, d, 1), 3.45)
        self.assertEqual(self.calls, [])

    def test_a_pour_on_the_way_goes_on_with_the_stop_at_rest(self):
        col = db.Column(4, 1300)
        with tempfile.TemporaryDirectory() as d:
            fake_pour(d, 1300, ["checkpoint: t = 2.5 s, 9 steps in 1s"], [(2.5, 0.02)])

            def advance(end, more=()):
                self.calls.append((end, list(more)))
                fake_pour(d, 1300, ["done: t = 2.8 s, 9 steps in 1s, settled"], [(2.8, 5e-4)])
            db.gate_runner = lambda *args, **kwargs: advance
            self.assertAlmostEqual(db.pour_gate("sanguis", col, d, 1), 2.8)
        self.assertEqual(len(self.calls), 1)
        self.assertEqual(self.calls[0][1], db.pour_stop_settings(col))


class EndOfCollapse(unittest.TestCase):
    def test_the_at_rest_test_starts_after_the_opening(self):
        self.assertEqual(db.at_rest_settings(3.2),
                         ["--set", "stop.mean_velocity_below_m_s=1e-3",
                          "--set", f"stop.check_after_s={3.2 + db.AT_REST_AFTER_S}"])
        self.assertLess(db.AT_REST_AFTER_S, db.COLLAPSE_S)

    def test_ended_at_rest_reads_the_last_done_line(self):
        with tempfile.TemporaryDirectory() as d:
            fake_run(d, ["done: t = 3.2 s, 640000 steps in 1h15m (2.8e+05 particle-steps/s)",
                         "settled at t = 4.7 s: mean velocity below 0.001 m/s",
                         "done: t = 4.7 s, 600000 steps in 35m50s (5.6e+05 particle-steps/s), "
                         "settled"], [])
            self.assertTrue(db.ended_at_rest(d))
            fake_run(d, ["done: t = 4.7 s, 600000 steps in 35m50s, settled",
                         "done: t = 4.75 s, 20000 steps in 1m2s (5.6e+05 particle-steps/s)"], [])
            self.assertFalse(db.ended_at_rest(d))
            fake_run(d, ["checkpoint: t = 0.05 s, 20000 steps in 0s"], [])
            self.assertFalse(db.ended_at_rest(d))
            # The lines as stamped with the date since 2026-12-05.
            fake_run(d, ["done: t = 4.7 s, 600000 steps in 35m50s (5.6e+05 particle-steps/s), "
                         "ended 2026-12-05 21:11:40 UTC, settled"], [])
            self.assertTrue(db.ended_at_rest(d))
            fake_run(d, ["done: t = 4.75 s, 20000 steps in 1m2s (5.6e+05 particle-steps/s), "
                         "ended 2026-12-05 21:11:40 UTC"], [])
            self.assertFalse(db.ended_at_rest(d))

    def test_stopped_says_how_the_collapse_ended(self):
        with tempfile.TemporaryDirectory() as d:
            opening = 3.2
            fake_run(d, [], [(3.2, 0.0), (opening + db.AT_REST_AFTER_S, 2e-4)])
            self.assertIn("at rest at the first check", db.stopped(d, opening))
            fake_run(d, [], [(3.2, 0.0), (opening + 2.0, 2e-4)])
            self.assertIn("came to rest 2.00 s", db.stopped(d, opening))
            fake_run(d, [], [(3.2, 0.0), (opening + db.COLLAPSE_S, 5e-3)])
            self.assertIn("still moving", db.stopped(d, opening))


class CommandRecord(unittest.TestCase):
    def test_controls_on_some_gates_take_a_call_of_their_own(self):
        base = "/usr/bin/python3 validation/dem/crosses_dam_break_mean.py --build BUILD"
        self.assertEqual(db.command_record("crosses_dam_break", [4], [], 1),
                         "/usr/bin/python3 validation/dem/crosses_dam_break.py --build BUILD")
        self.assertEqual(db.command_record("crosses_dam_break_mean", [4, 8], [4, 8], 2),
                         base + " --gates 4 8 --sum-control --threads 2")
        # --sum-control with --gates 4 8 would run an 8 cm control that the report lacks
        self.assertEqual(db.command_record("crosses_dam_break_mean", [4, 8], [4], 2),
                         base + " --sum-control --threads 2`, then `" + base
                         + " --gates 4 8 --threads 2")


class Columns(unittest.TestCase):
    def test_the_experiments_columns_set_no_depth_nor_pour_bottom(self):
        settings = db.overrides(db.column(8))
        self.assertEqual(settings, ["obstacle[5].min_m=[0.08, -0.01, 0.0]",
                                    "obstacle[5].max_m=[0.0850, 0.21, 0.72]",
                                    "obstacle[5].remove_at_s=1e6",
                                    "particles[0].count=2000",
                                    "particles[0].rate_per_s=1200.0",
                                    "particles[0].region_max_m=[0.08, 0.20, 0.72]"])

    def test_the_indices_and_defaults_are_the_cases(self):
        with open(db.CASE, "rb") as f:
            case = tomllib.load(f)
        self.assertEqual(case["obstacle"][db.GATE_INDEX]["name"], "gate")
        wall = case["obstacle"][db.SIDE_WALL_INDEX]
        self.assertEqual((wall["name"], wall["point_m"][1]), ("side wall, back", 0.20))
        self.assertEqual(case["particles"][0]["region_min_m"][2], db.Column(4, 1).pour_bottom_m)
        self.assertEqual(case["domain"]["max_m"][1], db.Column(4, 1).depth_m)

    def test_another_depth_moves_the_side_wall_and_the_pour(self):
        settings = db.overrides(db.Column(5.2, 1000, 0.15, 0.33))
        self.assertIn("obstacle[5].min_m=[0.052, -0.01, 0.0]", settings)
        self.assertIn("particles[0].region_max_m=[0.052, 0.15, 0.72]", settings)
        self.assertIn(f"obstacle[{db.SIDE_WALL_INDEX}].point_m=[0.0, 0.15, 0.0]", settings)
        self.assertIn("particles[0].region_min_m=[0.0, 0.0, 0.33]", settings)
        self.assertAlmostEqual(db.pour_rate(db.Column(4, 1300, 0.15)), 0.75 * 600.0)

    def test_the_pour_region_and_the_wall_take_the_same_depth(self):
        settings = db.overrides(db.Column(5, 100, 0.135))
        self.assertIn("particles[0].region_max_m=[0.05, 0.135, 0.72]", settings)
        self.assertIn(f"obstacle[{db.SIDE_WALL_INDEX}].point_m=[0.0, 0.135, 0.0]", settings)


class SumControl(unittest.TestCase):
    def folder(self, root, name, rows, opening=0.2):
        d = os.path.join(root, name)
        os.makedirs(d)
        fake_run(d, [], rows)
        with open(os.path.join(d, "obstacles.csv"), "w") as f:
            f.write(f"name,remove_at_s\nfloor,1e30\ngate,{opening}\n")
        return d

    def test_the_pours_must_agree_digit_for_digit_up_to_the_opening(self):
        pour = [(0.1, 0.5), (0.2, 1e-4)]
        with tempfile.TemporaryDirectory() as root:
            run = self.folder(root, "mean", pour + [(0.3, 0.02)])
            same = self.folder(root, "same", pour + [(0.3, 0.01)])  # differs after it only
            other = self.folder(root, "other", [(0.1, 0.5), (0.2, 1.0001e-4), (0.3, 0.01)])
            late = self.folder(root, "late", pour + [(0.3, 0.01)], opening=0.3)
            self.assertEqual(db.same_pour(same, run), (True, 2))
            self.assertEqual(db.same_pour(other, run), (False, 2))
            self.assertFalse(db.same_pour(late, run)[0])  # opened elsewhere

    def refused(self, argv):
        """The exit code and message of db.main(argv); a run started fails the test."""
        err = io.StringIO()
        with mock.patch.object(db, "run_gate", side_effect=AssertionError("a run started")), \
                contextlib.redirect_stderr(err), self.assertRaises(SystemExit) as raised:
            db.main(argv)
        return raised.exception.code, err.getvalue()

    def test_the_control_needs_the_mean(self):
        code, message = self.refused(["--sum-control"])
        self.assertEqual(code, 2)
        self.assertIn("--sum-control opens pours made with the mean", message)

    def test_one_point_needs_the_mean_and_has_no_control(self):
        # one point alone is not Grains3D's model; the control opens the mean's patch-made
        # pours with the sum
        code, message = self.refused(["--flat-contacts", "point"])
        self.assertEqual(code, 2)
        self.assertIn("--flat-contacts point runs with", message)
        code, message = self.refused(["--element-contacts", "mean", "--flat-contacts", "point",
                                      "--sum-control"])
        self.assertEqual(code, 2)
        self.assertIn("leave out --flat-contacts point", message)

    def test_grains3d_model_has_a_wrapper_that_chooses_it(self):
        here = os.path.dirname(os.path.abspath(__file__))
        with open(os.path.join(here, "crosses_dam_break_mean_point.py")) as f:
            self.assertIn('crosses_dam_break.main(["--element-contacts", "mean", '
                          '"--flat-contacts", "point"]', f.read())

if __name__ == "__main__":
    unittest.main()
