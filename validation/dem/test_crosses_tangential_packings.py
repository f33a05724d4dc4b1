"""Unit tests of crosses_tangential_packings' range format (run by ctest
ValidationScripts.DemHelpers)."""
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from crosses_tangential_packings import span  # noqa: E402


class Span(unittest.TestCase):
    def test_a_range_of_positive_values_takes_a_dash(self):
        self.assertEqual(span([2.5, 0.98, 16.34], ".2f"), "0.98-16.34")

    def test_a_range_from_a_negative_value_is_written_out(self):
        self.assertEqual(span([-0.15, 2.48, 0.11], ".2f"), "-0.15 to 2.48")

    def test_values_that_print_alike_give_one(self):
        self.assertEqual(span([3.001, 3.004], ".1f"), "3.0")
        self.assertEqual(span([7], "d"), "7")


if __name__ == "__main__":
    unittest.main()
