"""Unit tests of crosses_gate_effect's gate lift (run by ctest ValidationScripts.DemHelpers)."""
import os
import sys
import tomllib
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crosses_gate_effect as ge  # noqa: E402


class Lift(unittest.TestCase):
    def test_ramp_then_constant_speed(self):
        ramp = ge.LIFT_SPEED / ge.LIFT_ACCELERATION  # 0.07 s, §3.2.1
        self.assertAlmostEqual(ramp, 0.0698, places=4)
        self.assertEqual(ge.lift_distance(0.0), 0.0)
        self.assertAlmostEqual(ge.lift_distance(0.05), 0.5 * 43.0 * 0.05**2, places=12)
        # continuous at the end of the ramp, then 3 m/s
        self.assertAlmostEqual(ge.lift_distance(ramp), 0.5 * ge.LIFT_SPEED * ramp, places=12)
        self.assertAlmostEqual(ge.lift_distance(ramp + 0.1) - ge.lift_distance(ramp), 0.3,
                               places=12)

    def test_the_gate_goes_only_once_it_has_left_the_domain(self):
        self.assertGreater(ge.lift_distance(ge.REMOVE_AFTER_S), ge.DOMAIN_TOP)

    def test_the_constants_are_the_case_files(self):
        with open(ge.CASE, "rb") as f:
            case = tomllib.load(f)
        gate = case["obstacle"][ge.GATE_INDEX]
        self.assertEqual(gate["name"], "gate")
        self.assertEqual(gate["remove_at_s"], ge.GATE_TIME)
        self.assertEqual(gate["min_m"][2], 0.0)  # the lower edge that must clear the domain
        self.assertEqual(gate["max_m"][0], ge.GATE_FACE_X)
        self.assertEqual(case["domain"]["max_m"][2], ge.DOMAIN_TOP)
        self.assertAlmostEqual(case["simulation"]["end_time_s"], ge.END_S, places=12)

    def test_overrides(self):
        self.assertEqual(ge.opening_settings("at once"), [])
        lifted = ge.opening_settings("lifted")
        self.assertEqual(lifted[0::2], ["--set", "--set"])
        self.assertTrue(lifted[1].startswith(f"obstacle[{ge.GATE_INDEX}].translation={{ "))
        self.assertIn('law = "ramp"', lifted[1])
        self.assertIn(f"start_s = {ge.GATE_TIME}", lifted[1])
        self.assertEqual(lifted[3],
                         f"obstacle[{ge.GATE_INDEX}].remove_at_s={ge.GATE_TIME + ge.REMOVE_AFTER_S}")


class Notes(unittest.TestCase):
    """The notes' counts come from the runs: two packings, one lifted run peaking at the
    first frame and one later."""
    RESULTS = {(1, "at once"): {"height_loss": 0.02, "runout_ratio": 1.0, "peak_t": 1.5},
               (1, "lifted"): {"height_loss": 0.07, "runout_ratio": 2.0, "peak_t": 0.37},
               (2, "at once"): {"height_loss": 0.16, "runout_ratio": 4.3, "peak_t": 4.8},
               (2, "lifted"): {"height_loss": 0.15, "runout_ratio": 4.6, "peak_t": 3.66}}

    def test_packings_where_the_lift_adds(self):
        self.assertEqual(ge.more_when_lifted(self.RESULTS, [1, 2], "height_loss"), 1)
        self.assertEqual(ge.more_when_lifted(self.RESULTS, [1, 2], "runout_ratio"), 2)

    def test_where_the_lifted_runs_peak(self):
        both = ge.peak_sentence(self.RESULTS, [1, 2])
        self.assertIn("first output frame after the opening (0.05 s, 0.37 τc) on seeds 1:", both)
        self.assertIn("later on seeds 2, at 3.7 τc", both)
        self.assertNotIn("later", ge.peak_sentence(self.RESULTS, [1]))
        self.assertNotIn("first output frame", ge.peak_sentence(self.RESULTS, [2]))


if __name__ == "__main__":
    unittest.main()
