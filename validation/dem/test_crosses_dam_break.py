"""Unit tests of crosses_dam_break's end of a collapse (run by ctest
ValidationScripts.DemHelpers)."""
import os
import sys
import tempfile
import unittest

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

    def test_stopped_says_how_the_collapse_ended(self):
        with tempfile.TemporaryDirectory() as d:
            opening = 3.2
            fake_run(d, [], [(3.2, 0.0), (opening + db.AT_REST_AFTER_S, 2e-4)])
            self.assertIn("at rest at the first check", db.stopped(d, opening))
            fake_run(d, [], [(3.2, 0.0), (opening + 2.0, 2e-4)])
            self.assertIn("came to rest 2.00 s", db.stopped(d, opening))
            fake_run(d, [], [(3.2, 0.0), (opening + db.COLLAPSE_S, 5e-3)])
            self.assertIn("still moving", db.stopped(d, opening))


if __name__ == "__main__":
    unittest.main()
