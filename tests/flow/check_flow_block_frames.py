"""The flow frames written as blocks ([output] vtk_format = "vtm") read back
through VTK's own readers (python3-vtk9, as ParaView reads them) and hold
exactly the cells and values of the hexahedral .vtu frames of the same run;
on 2 MPI ranks the same cells and values to round-off, each rank's blocks
listed by rank 0.

Usage: check_flow_block_frames.py SANGUIS_BINARY [MPIRUN]
A small adaptive lid-driven cavity (16^3 cells, blocks of 8^3, levels 1-2 at
the last frame) runs three times: .vtu, .vtm, and .vtm on 2 ranks when MPIRUN
is given. `sanguis slice` (scripts/flow_slice.py) must cut the same cells and
values from either format. Exits 1 with the differences if a check fails.
"""
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np

try:
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
except ImportError:
    sys.exit("check_flow_block_frames: VTK's Python module is missing: install python3-vtk9 "
             "(scripts/install-deps.sh does)")

CASE = """
[simulation]
name = "blocks"
end_time_s = 0.1
threads = 1

[flow.grid]
size_m = [1.0, 1.0, 1.0]
cells = [16, 16, 16]
block_cells = 8

[flow.fluid]
density_kg_m3 = 1.0
viscosity_Pa_s = 0.01

[flow.boundary]
x_min = { type = "wall" }
x_max = { type = "wall" }
y_min = { type = "wall" }
y_max = { type = "wall", velocity_m_s = [1.0, 0.0, 0.0] }
z_min = { type = "wall" }
z_max = { type = "wall" }

[flow.adapt]
velocity_threshold_m_s = 3e-2
coarsen_levels = 1
every_steps = 2

[flow.time]
max_time_step_s = 0.01

[output]
interval_s = 0.05
"""

SLICE = Path(__file__).resolve().parents[2] / "scripts" / "flow_slice.py"
ARRAYS = ("velocity", "pressure", "vorticity_magnitude", "viscosity", "level", "rank", "block")


def frames(run_dir):
    """The files the run's flow.pvd lists, in order."""
    root = ElementTree.parse(run_dir / "flow.pvd").getroot()
    return [run_dir / d.get("file") for d in root.iter("DataSet")]


def cells_of(dataset):
    """Cell centres and the arrays of one VTK data set."""
    centres = vtk.vtkCellCenters()
    centres.SetInputData(dataset)
    centres.Update()
    data = dataset.GetCellData()
    arrays = {}
    for name in ARRAYS:
        array = data.GetArray(name)
        if array is None:
            raise AssertionError(f"array {name} missing")
        arrays[name] = vtk_to_numpy(array).reshape(dataset.GetNumberOfCells(), -1)
    return vtk_to_numpy(centres.GetOutput().GetPoints().GetData()), arrays


def read_blocks(path):
    """Every block of a .vtm frame, checked to be ImageData of its level's spacing;
    returns the cells in a canonical order and the levels listed."""
    reader = vtk.vtkXMLMultiBlockDataReader()
    reader.SetFileName(str(path))
    reader.Update()
    levels = reader.GetOutput()
    centres, arrays, names = [], {name: [] for name in ARRAYS}, []
    for group in range(levels.GetNumberOfBlocks()):
        name = levels.GetMetaData(group).Get(vtk.vtkCompositeDataSet.NAME())
        names.append(name)
        h = float(name.split("h = ")[1].split(" m")[0])
        blocks = levels.GetBlock(group)
        for n in range(blocks.GetNumberOfBlocks()):
            block = blocks.GetBlock(n)
            if not block.IsA("vtkImageData"):
                raise AssertionError(f"{path}: {name} block {n} is a {block.GetClassName()}")
            if not np.allclose(block.GetSpacing(), h, rtol=1e-5):
                raise AssertionError(f"{path}: {name} block {n} has spacing {block.GetSpacing()}")
            c, a = cells_of(block)
            centres.append(c)
            for key in ARRAYS:
                arrays[key].append(a[key])
    return sort_cells(np.concatenate(centres), {k: np.concatenate(v) for k, v in arrays.items()}), names


def read_hexahedra(path):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    return sort_cells(*cells_of(reader.GetOutput()))


def sort_cells(centres, arrays):
    order = np.lexsort(np.round(centres, 12).T[::-1])
    return centres[order], {k: v[order] for k, v in arrays.items()}


def run(binary, directory, fmt, mpirun=None):
    command = [binary, "run", str(directory / "case.toml"), "-q", "-o", str(directory / fmt),
               "--set", f'output.vtk_format="{fmt.split("-")[0]}"']
    if mpirun:
        command = [mpirun, "-np", "2", "--allow-run-as-root", "--oversubscribe"] + command
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    return directory / fmt


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    binary, mpirun = sys.argv[1], (sys.argv[2] if len(sys.argv) > 2 else None)
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        directory = Path(tmp)
        (directory / "case.toml").write_text(CASE)
        hexahedra = frames(run(binary, directory, "vtu"))
        blocks = frames(run(binary, directory, "vtm"))
        if not hexahedra or [p.suffix for p in blocks] != [".vtm"] * len(hexahedra):
            sys.exit(f"FAIL: flow.pvd lists {blocks}, expected {len(hexahedra)} (> 0) .vtm frames")
        # Exact equality of the cell centres holds as the case's sizes are powers of two.
        for hex_file, block_file in zip(hexahedra, blocks):
            (c1, a1) = read_hexahedra(hex_file)
            (c2, a2), names = read_blocks(block_file)
            same = c1.shape == c2.shape and np.array_equal(c1, c2) and all(
                np.array_equal(a1[k], a2[k]) for k in ARRAYS)
            print(f"{block_file.name}: {len(c2)} cells in {', '.join(names)}; "
                  f"{'the same cells and values as' if same else 'DIFFERENT from'} {hex_file.name}")
            if not same:
                failures.append(f"{block_file.name} differs from {hex_file.name}")
        # `sanguis slice` (scripts/flow_slice.py) reads both formats: the same cells cut.
        slices = []
        for fmt in ("vtu", "vtm"):
            csv = directory / f"slice_{fmt}.csv"
            subprocess.run([sys.executable, str(SLICE), str(directory / fmt), "--field", "pressure",
                            "--normal", "x", "--output", str(csv.with_suffix(".png"))],
                           check=True, stdout=subprocess.DEVNULL)
            slices.append(sorted(csv.read_text().splitlines()))
        print(f"sanguis slice: {len(slices[1]) - 1} cells cut, "
              f"{'the same' if slices[0] == slices[1] else 'DIFFERENT'} rows from both formats")
        if slices[0] != slices[1] or len(slices[1]) < 2:
            failures.append("flow_slice.py cuts different cells or values from the .vtm frame")
        if len(names) < 2:
            failures.append(f"the last frame has one level only ({names}): the case no longer "
                            "tests a composite grid")
        if not mpirun:
            print("2 ranks: not checked (no mpirun given)")
        else:
            shared = frames(run(binary, directory, "vtm-2", mpirun))
            (c1, a1), _ = read_blocks(blocks[-1])
            (c2, a2), names = read_blocks(shared[-1])
            scale = max(np.abs(a1["velocity"]).max(), np.abs(a1["pressure"]).max())
            diff = max(np.abs(a1[k] - a2[k]).max() for k in ("velocity", "pressure"))
            ranks = sorted(set(a2["rank"].ravel().tolist()))
            print(f"2 ranks, {shared[-1].name}: {len(c2)} cells, ranks {ranks}, largest difference "
                  f"of velocity and pressure from 1 rank {diff:.2e} (largest value {scale:.3f})")
            if c1.shape != c2.shape or not np.array_equal(c1, c2):
                failures.append("2 ranks: the cells differ from 1 rank")
            elif diff > 1e-10 * scale:
                failures.append(f"2 ranks: values differ from 1 rank by {diff:.2e}")
            if ranks != [0, 1]:
                failures.append(f"2 ranks: the blocks come from ranks {ranks}")
    for failure in failures:
        print("FAIL:", failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
