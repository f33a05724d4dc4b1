"""Unit tests of crosses_tangential_map's regions of Fig. 3.17 (run by ctest
ValidationScripts.DemHelpers)."""
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from crosses_tangential_map import BASE_DRIVEN_SHARE, region_of  # noqa: E402


class RegionOf(unittest.TestCase):
    def test_a_column_that_stands_or_loses_under_five_percent_is_region_3(self):
        self.assertEqual(region_of(False, 0.5, 20.0, 17.0), 3)
        self.assertEqual(region_of(True, 0.049, 20.0, 17.0), 3)

    def test_a_base_moving_like_the_spheres_base_is_region_1(self):
        self.assertEqual(region_of(True, 0.8, 17.0, 17.0), 1)
        self.assertEqual(region_of(True, 0.8, BASE_DRIVEN_SHARE * 17.0, 17.0), 1)

    def test_a_collapse_whose_base_moves_less_is_region_2(self):
        self.assertEqual(region_of(True, 0.3, 0.99 * BASE_DRIVEN_SHARE * 17.0, 17.0), 2)
        self.assertEqual(region_of(True, 0.3, 1.0, 17.0), 2)


if __name__ == "__main__":
    unittest.main()
