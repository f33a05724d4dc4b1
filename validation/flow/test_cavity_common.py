"""Tests of validation/flow/_cavity_common.py, what the flow validation scripts share:
the reader of our .vtu frames (checked on a frame the sanguis binary writes, when
SANGUIS_BINARY names it, as ctest does), centre-line profiles and CSV rows. Run by ctest
(ValidationScripts.FlowHelpers) or by hand:
SANGUIS_BINARY=build/app/sanguis /usr/bin/python3 -m unittest discover -s validation/flow -p 'test_*.py'"""
import base64
import os
import pathlib
import struct
import sys
import tempfile
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _cavity_common as common  # noqa: E402

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent


def data_array(name, kind, values, components):
    fmt = {"Float64": "d", "Int64": "q", "UInt8": "B"}[kind]
    raw = struct.pack(f"<{len(values)}{fmt}", *values)
    payload = base64.b64encode(struct.pack("<Q", len(raw)) + raw).decode()
    return (f'<DataArray type="{kind}" Name="{name}" NumberOfComponents="{components}" '
            f'format="binary">\n{payload}\n</DataArray>\n')


def unit_grid(n):
    """Centres of an n^3 grid of the unit cube, x fastest."""
    c = (np.arange(n) + 0.5) / n
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    return np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)


class ReadVtu(unittest.TestCase):
    def test_centres_are_the_means_of_the_eight_corners(self):
        # Two unit hexahedra side by side along x.
        points = [0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1]
        points += [p + (1 if k % 3 == 0 else 0) for k, p in enumerate(points)]
        with tempfile.TemporaryDirectory() as tmp:
            path = pathlib.Path(tmp) / "frame.vtu"
            path.write_text("<VTKFile><UnstructuredGrid><Piece><Points>\n"
                            + data_array("Points", "Float64", [float(p) for p in points], 3)
                            + "</Points><Cells>\n"
                            + data_array("connectivity", "Int64", list(range(16)), 1)
                            + data_array("types", "UInt8", [12, 12], 1)
                            + "</Cells><CellData>\n"
                            + data_array("velocity", "Float64", [1, 2, 3, 4, 5, 6], 3)
                            + "</CellData></Piece></UnstructuredGrid></VTKFile>\n")
            centres, arrays = common.read_vtu(path)
        np.testing.assert_array_equal(centres, [[0.5, 0.5, 0.5], [1.5, 0.5, 0.5]])
        np.testing.assert_array_equal(arrays["velocity"], [[1, 2, 3], [4, 5, 6]])
        lo, hi = common.cell_boxes(arrays)
        np.testing.assert_array_equal(lo, [[0, 0, 0], [1, 0, 0]])
        np.testing.assert_array_equal(hi, [[1, 1, 1], [2, 1, 1]])

    @unittest.skipUnless(os.environ.get("SANGUIS_BINARY"), "SANGUIS_BINARY not set")
    def test_reads_a_frame_written_by_sanguis(self):
        case = (ROOT / "cases" / "flow" / "cavity-re100.toml").read_text()
        case = case.replace("cells = [32, 32, 32]", "cells = [16, 16, 16]")
        case = case.replace("end_time_s = 15.0", "end_time_s = 0.1")
        case = case.replace("interval_s = 1.0", "interval_s = 0.1")
        with tempfile.TemporaryDirectory() as tmp:
            runs = pathlib.Path(tmp)
            common.run(os.environ["SANGUIS_BINARY"], runs, "cavity", case)
            centres, arrays = common.read_vtu(common.last_frame(runs, "cavity"))
            rows = common.read_rows(runs / "cavity" / "diagnostics.csv")
        self.assertEqual(centres.shape, (16 ** 3, 3))
        np.testing.assert_allclose(np.sort(np.unique(np.round(centres[:, 0], 12))),
                                   (np.arange(16) + 0.5) / 16)
        velocity = arrays["velocity"]
        self.assertEqual(velocity.shape, (16 ** 3, 3))
        # The lid drags the fluid along +x under it: u > 0 in the top layer, and the
        # centre line reaches into it.
        (y, u), (x, v) = common.centre_lines(centres, velocity, two_d=False)
        self.assertEqual(len(y), 16)
        self.assertEqual(len(x), 16)
        self.assertGreater(u[-1], 0.1)
        self.assertLess(abs(u[0]), u[-1])
        self.assertGreater(rows[-1]["time_s"], 0.099)


class CentreLines(unittest.TestCase):
    def test_profiles_of_a_linear_field(self):
        centres = unit_grid(4)
        velocity = np.stack([centres[:, 1], centres[:, 0], np.zeros(len(centres))], axis=1)
        (y, u), (x, v) = common.centre_lines(centres, velocity, two_d=False)
        np.testing.assert_allclose(y, [0.125, 0.375, 0.625, 0.875])
        np.testing.assert_allclose(u, y)  # u = y, averaged over the cells beside x = z = 0.5
        np.testing.assert_allclose(x, y)
        np.testing.assert_allclose(v, x)

    def test_two_d_averages_over_every_layer(self):
        centres = unit_grid(4)
        velocity = np.stack([centres[:, 2], np.zeros(len(centres)), np.zeros(len(centres))],
                            axis=1)
        (_, u), _ = common.centre_lines(centres, velocity, two_d=True)
        np.testing.assert_allclose(u, 0.5)  # the mean of z over all four layers

    def test_walls_are_added_at_both_ends(self):
        coord, value = common.with_walls(np.array([0.25, 0.75]), np.array([0.1, 0.2]), 1.0)
        np.testing.assert_array_equal(coord, [0.0, 0.25, 0.75, 1.0])
        np.testing.assert_array_equal(value, [0.0, 0.1, 0.2, 1.0])


class Rows(unittest.TestCase):
    def test_csv_rows_as_text_and_as_numbers(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = pathlib.Path(tmp) / "diagnostics.csv"
            path.write_text("time_s,kinetic_energy\n0,0\n0.5,1e-3\n")
            self.assertEqual(common.read_text_rows(path)[1], {"time_s": "0.5",
                                                               "kinetic_energy": "1e-3"})
            self.assertEqual(common.read_rows(path)[1], {"time_s": 0.5, "kinetic_energy": 1e-3})


if __name__ == "__main__":
    unittest.main()
