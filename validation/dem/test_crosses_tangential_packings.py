"""Unit tests of crosses_tangential_packings' summaries of the 3 x 3 on several pours (run
by ctest ValidationScripts.DemHelpers)."""
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from crosses_tangential_packings import collapse_counts, stands_above_edge  # noqa: E402

KT = [1e2, 3e2, 1e3]
GAMMA = [3e2, 1e3, 3e3]


def grid(standing):
    """{(kt, gamma): region}: 3 at the points in `standing`, 2 elsewhere."""
    return {(kt, g): 3 if (kt, g) in standing else 2 for kt in KT for g in GAMMA}


class StandsAboveEdge(unittest.TestCase):
    def test_a_corner_of_standing_points_at_large_kt_and_gamma_is_one_side_of_an_edge(self):
        self.assertTrue(stands_above_edge(grid({(1e3, 1e3), (1e3, 3e3)})))
        self.assertTrue(stands_above_edge(grid({(3e2, 3e3), (1e3, 1e3), (1e3, 3e3)})))

    def test_all_or_none_standing_has_an_edge(self):
        self.assertTrue(stands_above_edge(grid(set())))
        self.assertTrue(stands_above_edge(grid({(kt, g) for kt in KT for g in GAMMA})))

    def test_a_collapse_above_a_standing_point_breaks_the_edge(self):
        self.assertFalse(stands_above_edge(grid({(3e2, 1e3)})))
        regions = grid({(1e2, 3e2), (3e2, 1e3), (1e3, 3e3)})
        self.assertFalse(stands_above_edge(regions))

    def test_a_base_driven_collapse_counts_as_a_collapse(self):
        regions = grid({(1e3, 3e3)})
        self.assertTrue(stands_above_edge(regions))
        regions[(1e3, 3e3)] = 1
        regions[(1e3, 1e3)] = 3
        self.assertFalse(stands_above_edge(regions))


class CollapseCounts(unittest.TestCase):
    def test_counts_the_pours_where_a_point_is_region_1_or_2(self):
        results = {(1, 3e2, 1e3): {"region": 2}, (2, 3e2, 1e3): {"region": 3},
                   (3, 3e2, 1e3): {"region": 1}, (1, 1e3, 3e3): {"region": 3},
                   (2, 1e3, 3e3): {"region": 3}, (3, 1e3, 3e3): {"region": 3}}
        self.assertEqual(collapse_counts(results, [1, 2, 3], [(3e2, 1e3), (1e3, 3e3)]),
                         {(3e2, 1e3): 2, (1e3, 3e3): 0})


if __name__ == "__main__":
    unittest.main()
