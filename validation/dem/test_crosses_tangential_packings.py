"""Unit tests of crosses_tangential_packings' summaries of the 3 x 3 on several pours (run
by ctest ValidationScripts.DemHelpers)."""
import contextlib
import io
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from crosses_tangential_packings import (collapse_counts, main, model_label,  # noqa: E402
                                         stands_above_edge)

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


class Variants(unittest.TestCase):
    def test_the_figure_names_what_differs_from_the_default_model(self):
        self.assertEqual(model_label(False, False), "")
        self.assertEqual(model_label(True, False), "element contacts: the mean")
        self.assertEqual(model_label(True, True), "element contacts: the mean and one contact "
                                                  "point per element pair (Grains3D)")

    def test_one_point_per_element_pair_runs_with_the_mean_only(self):
        # Refused before anything runs: Grains3D's model is the point and the mean together,
        # and the --open-with options reopen pours made with the patches.
        for argv in (["--flat-contacts", "point"],
                     ["--element-contacts", "mean", "--flat-contacts", "point",
                      "--table31-only", "--open-with-sum"]):
            with contextlib.redirect_stderr(io.StringIO()) as err:
                with self.assertRaises(SystemExit) as stop:
                    main(argv + ["--build", "no-such-build"])
            self.assertEqual(stop.exception.code, 2)
            self.assertIn("--flat-contacts point", err.getvalue())

    def test_the_pours_are_opened_another_way_at_table31_with_the_mean_only(self):
        # Each of these ran the whole 3 x 3 with the pours' own rule before (the option
        # ignored), overwriting that rule's runs and summary; two ways at once ran one.
        for argv, reason in ((["--open-with-point"], "--element-contacts mean --table31-only"),
                             (["--element-contacts", "mean", "--open-with-sum"],
                              "--element-contacts mean --table31-only"),
                             (["--element-contacts", "mean", "--table31-only",
                               "--open-with-sum", "--open-with-point"], "give one")):
            with contextlib.redirect_stderr(io.StringIO()) as err:
                with self.assertRaises(SystemExit) as stop:
                    main(argv + ["--build", "no-such-build"])
            self.assertEqual(stop.exception.code, 2)
            self.assertIn(reason, err.getvalue())


if __name__ == "__main__":
    unittest.main()
