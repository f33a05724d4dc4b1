"""Tests of validation/dem/hopper_repose.py: the note on the onset of a heap is read from
the sweep's angles and heap tops, not written in. Run by ctest
(ValidationScripts.DemHelpers) or by hand:
/usr/bin/python3 -m unittest discover -s validation/dem -p 'test_*.py'"""
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hopper_repose  # noqa: E402

FRICTIONS = [0.05, 0.1, 0.2, 0.3, 0.65]


class HeapOnsetNote(unittest.TestCase):
    def test_the_flat_frictions_their_depth_and_the_jump_come_from_the_sweep(self):
        angle = {0.05: 0.0, 0.1: 0.4, 0.2: 23.3, 0.3: 29.4, 0.65: 34.5}
        top = {0.05: 3.6e-3, 0.1: 6.4e-3, 0.2: 12.6e-3, 0.3: 14.6e-3, 0.65: 18e-3}
        note = hopper_repose.heap_onset_note(FRICTIONS, angle, top)
        self.assertIn("Below mu_c = 0.2 no heap forms", note)
        self.assertIn("1.8-3.2 bead diameters deep", note)
        self.assertIn("jumps to 23.3° at 0.2", note)
        self.assertIn("grows by 11.2° more up to 0.65", note)

    def test_a_heap_at_the_lowest_friction_is_said_so(self):
        angle = {mu: 20.0 + 10 * mu for mu in FRICTIONS}
        top = {mu: 1e-2 for mu in FRICTIONS}
        note = hopper_repose.heap_onset_note(FRICTIONS, angle, top)
        self.assertEqual(note, "Every friction of the sweep forms a heap (20.5° at 0.05).")

    def test_no_heap_at_all_is_said_so(self):
        angle = {mu: 0.2 for mu in FRICTIONS}
        top = {mu: 4e-3 for mu in FRICTIONS}
        note = hopper_repose.heap_onset_note(FRICTIONS, angle, top)
        self.assertIn("No friction of the sweep forms a heap", note)

    def test_a_flat_friction_above_the_first_heap_does_not_move_the_onset(self):
        angle = {0.05: 0.1, 0.1: 12.0, 0.2: 0.5, 0.3: 25.0, 0.65: 30.0}
        top = {mu: 4e-3 for mu in FRICTIONS}
        note = hopper_repose.heap_onset_note(FRICTIONS, angle, top)
        self.assertIn("Below mu_c = 0.1 no heap forms", note)
        self.assertIn("floor 2.0 bead diameters deep", note)


if __name__ == "__main__":
    unittest.main()
