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


if __name__ == "__main__":
    unittest.main()
