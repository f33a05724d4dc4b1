"""Tests of the sampling in validation/flow/cavity_adaptive_3d.py: the mid-plane centre
lines through the four quadrants around each line, and the uniform run's means over the
cells of a coarser grid. Run by ctest (ValidationScripts.FlowHelpers) or by hand:
/usr/bin/python3 -m unittest discover -s validation/flow -p 'test_*.py'"""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cavity_adaptive_3d as cavity3d  # noqa: E402


def frame(lo, hi, field):
    """Arrays as read from a frame: every cell's 8 corners (4 at lo, 4 at hi: only
    their min and max matter) and the velocity field(centres) of the cell centres."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    n = len(lo)
    connectivity = np.array([[k] * 4 + [k + n] * 4 for k in range(n)]).ravel()
    return {"Points": np.concatenate([lo, hi]), "connectivity": connectivity,
            "velocity": field(0.5 * (lo + hi))}


def uniform_cells(n):
    i = np.arange(n)
    x, y, z = np.meshgrid(i, i, i, indexing="ij")
    lo = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1) / n
    return lo, lo + 1.0 / n


def quadratic(c):
    return np.stack([c[:, 0], c[:, 1] ** 2, c[:, 2]], axis=1)


class CentreLines(unittest.TestCase):
    def test_uniform_grid_gives_the_mean_of_the_four_cells_around_the_line(self):
        arrays = frame(*uniform_cells(8), quadratic)
        # u = x on x = 0.5: exactly 0.5 wherever the line is sampled (the end values
        # are the walls' 0 and the lid's 1, so stay inside the first and last centres).
        np.testing.assert_allclose(cavity3d.line_profile(arrays, 1, 0, 0, np.array([0.1, 0.5, 0.9])), 0.5)
        # v = y^2 on y = 0.5: the mean of the cells at y = 0.5 -+ 1/16.
        expected = 0.5 * ((0.5 - 1 / 16) ** 2 + (0.5 + 1 / 16) ** 2)
        np.testing.assert_allclose(cavity3d.line_profile(arrays, 0, 1, 1, np.array([0.3, 0.7])), expected)

    def test_quadrants_of_different_widths_are_interpolated_then_averaged(self):
        # Around the line x = z = 0.5: quadrant (x < 0.5, z < 0.5) holds two cells of
        # 1/4 along y, the others one cell of 1/2; u = y^2 at the centres.
        lo = [[0.25, 0.0, 0.25], [0.25, 0.25, 0.25], [0.5, 0.0, 0.0], [0.0, 0.0, 0.5], [0.5, 0.0, 0.5]]
        hi = [[0.5, 0.25, 0.5], [0.5, 0.5, 0.5], [1.0, 0.5, 0.5], [0.5, 0.5, 1.0], [1.0, 0.5, 1.0]]
        arrays = frame(lo, hi, lambda c: np.stack([c[:, 1] ** 2, 0 * c[:, 1], 0 * c[:, 1]], axis=1))
        # At y = 0.25 the fine quadrant interpolates between its centres 0.125 and
        # 0.375 (u = 1/64 and 9/64): 5/64; each coarse one sits on its centre: 1/16.
        expected = (5 / 64 + 3 / 16) / 4
        np.testing.assert_allclose(cavity3d.line_profile(arrays, 1, 0, 0, np.array([0.25])), expected)


class CellMeans(unittest.TestCase):
    def test_means_over_coarser_cells_match_the_fine_cells_inside(self):
        saved = cavity3d.N
        cavity3d.N = 16
        try:
            grid = cavity3d.uniform_array(frame(*uniform_cells(16), quadratic))
            boxes = [((0, 0, 0), (0.5, 0.5, 0.5)), ((0.5, 0.25, 0.25), (0.75, 0.5, 0.5)),
                     ((0.75, 0.75, 0.75), (0.8125, 0.8125, 0.8125))]
            coarse = frame([b[0] for b in boxes], [b[1] for b in boxes], quadratic)
            means = cavity3d.cell_means(grid, coarse)
        finally:
            cavity3d.N = saved
        for (a, b), m in zip(boxes, means):
            ys = (np.arange(round(a[1] * 16), round(b[1] * 16)) + 0.5) / 16
            np.testing.assert_allclose(m, [(a[0] + b[0]) / 2, np.mean(ys ** 2), (a[2] + b[2]) / 2])


class WallSeconds(unittest.TestCase):
    def test_done_lines_are_summed_up_to_a_time(self):
        import tempfile
        from pathlib import Path

        with tempfile.TemporaryDirectory() as tmp:
            log = Path(tmp) / "run.log"
            log.write_text("grid: ...\n"
                           "done: t = 15 s, 2331 steps in 57m56s (1.406e+06 cell-updates/s)\n"
                           "--- restart from checkpoint at t = 15 s\n"
                           "done: t = 15.5 s, 100 steps in 37s (1.6e+06 cell-updates/s)\n"
                           "done: t = 20 s, 900 steps in 1h02m03s (1.6e+06 cell-updates/s)\n")
            self.assertEqual(cavity3d.log_seconds(log), 3476 + 37 + 3723)
            self.assertEqual(cavity3d.log_seconds(log, 15.0), 3476)


class BoundGrids(unittest.TestCase):
    def test_the_sampled_grids_have_the_cells_of_the_bound(self):
        # A 32^3 field with a sharp layer near y = 1: the bound keeps fine blocks
        # there and coarsens the rest.
        saved = cavity3d.N, cavity3d.CENTRES
        cavity3d.N = 32
        cavity3d.CENTRES = (np.arange(32) + 0.5) / 32
        try:
            lo, hi = uniform_cells(32)
            field = lambda c: np.stack([np.exp(-20 * (1 - c[:, 1])), np.sin(3 * c[:, 0]), 0 * c[:, 2]], axis=1)
            grid = cavity3d.uniform_array(frame(lo, hi, field))
            lines = cavity3d.centre_lines(cavity3d.boxes_frame(lo, hi, grid))
            components = [grid[..., d] for d in range(3)]
            levels = cavity3d.adaptive_potential.level_estimates(components, (False, False, False))
            # zeta 1e-3 coarsens nothing; 1e-2 and 3e-2 coarsen the blocks away from the layer.
            for coarsen, zeta, coarsened in ((1, 1e-2, True), (2, 3e-2, True), (2, 1e-3, False)):
                row = cavity3d.bound_grid_sampling(grid, lines, coarsen, [zeta])[0]
                expected, _ = cavity3d.adaptive_potential.fewest_cells(levels[:coarsen + 1], zeta)
                self.assertEqual(row["cells"], expected)
                self.assertEqual(row["cells"] < 32 ** 3, coarsened)
            # The uniform grid itself (nothing coarsened) samples its own lines exactly.
            row = cavity3d.bound_grid_sampling(grid, lines, 0, [1e-3])[0]
            self.assertEqual(row["cells"], 32 ** 3)
            self.assertEqual(row["centre_line_difference_of_the_averaged_uniform_field"], 0.0)
        finally:
            cavity3d.N, cavity3d.CENTRES = saved


if __name__ == "__main__":
    unittest.main()
