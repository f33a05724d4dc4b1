"""Every VTK file a granular run writes, read back through VTK's own readers
(Debian's python3-vtk9, the readers ParaView uses): no reader error, the
numbers of points and cells the file declares, and every array (points,
point and cell data) equal, value for value, to its own base64 payload.

Usage: check_vtk_outputs.py SANGUIS_BINARY
Runs two small cases: the 200-bead dam break of the integration tests
(spheres, planes and a gate box removed during the run: particles, contacts
of kinds 0 and 1, branches, obstacles) and 40 crosses poured into a box
(bodies as surfaces, contacts of kinds 2 and 3). Exits 1 naming the file and
the difference if a check fails.
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
    sys.exit("check_vtk_outputs: VTK's Python module is missing: install python3-vtk9 "
             "(scripts/install-deps.sh does)")

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
from flow_slice import read_arrays  # noqa: E402  (our own decoding of the payloads)

READERS = {".vtu": vtk.vtkXMLUnstructuredGridReader, ".vtp": vtk.vtkXMLPolyDataReader}


class ErrorCatcher:
    """Collects the error and warning events of a VTK object."""

    def __init__(self, obj):
        self.messages = []
        for event in ("ErrorEvent", "WarningEvent"):
            obj.AddObserver(event, self)

    def __call__(self, caller, event):
        self.messages.append(f"{event} from {caller.GetClassName()}")


def vtk_arrays(dataset):
    """name -> values of the points and of every point and cell data array VTK read."""
    arrays = {}
    if dataset.GetPoints() is not None and dataset.GetNumberOfPoints() > 0:
        arrays["Points"] = vtk_to_numpy(dataset.GetPoints().GetData())
    for data in (dataset.GetPointData(), dataset.GetCellData()):
        for n in range(data.GetNumberOfArrays()):
            array = data.GetAbstractArray(n)
            arrays[array.GetName()] = vtk_to_numpy(array)
    return arrays


def check_file(path, failures, counts):
    reader = READERS[path.suffix]()
    errors = ErrorCatcher(reader)
    reader.SetFileName(str(path))
    reader.Update()
    dataset = reader.GetOutput()
    if errors.messages:
        failures.append(f"{path}: {', '.join(errors.messages)}")
        return
    text = path.read_text()
    piece = ElementTree.fromstring(text).find(".//Piece")
    declared_points = int(piece.get("NumberOfPoints"))
    declared_cells = sum(int(piece.get(key, 0)) for key in
                         ("NumberOfCells", "NumberOfVerts", "NumberOfLines", "NumberOfStrips",
                          "NumberOfPolys"))
    if (dataset.GetNumberOfPoints(), dataset.GetNumberOfCells()) != (declared_points,
                                                                      declared_cells):
        failures.append(f"{path}: VTK read {dataset.GetNumberOfPoints()} points and "
                        f"{dataset.GetNumberOfCells()} cells, the file declares {declared_points} "
                        f"and {declared_cells}")
    ours = read_arrays(path, text)
    theirs = vtk_arrays(dataset)
    for name, values in ours.items():
        if name in ("connectivity", "offsets", "types") or (name == "Points" and not len(values)):
            continue
        if name not in theirs:
            failures.append(f"{path}: array {name} is missing in what VTK read")
        elif not np.array_equal(theirs[name].ravel(), values.ravel()):
            failures.append(f"{path}: array {name} differs from its payload")
    counts["files"] += 1
    counts["points"] += declared_points
    counts["cells"] += declared_cells
    if "kind" in ours:
        counts["kinds"].update(int(k) for k in ours["kind"])


def check_run(run_dir, failures):
    counts = {"files": 0, "points": 0, "cells": 0, "kinds": set()}
    indexes = sorted(run_dir.glob("*.pvd"))
    for pvd in indexes:
        entries = list(ElementTree.parse(pvd).getroot().iter("DataSet"))
        if not entries:
            failures.append(f"{pvd}: lists no file")
        for entry in entries:
            check_file(run_dir / entry.get("file"), failures, counts)
    print(f"{run_dir.name}: {', '.join(p.name for p in indexes)}: {counts['files']} files read "
          f"by VTK, {counts['points']} points and {counts['cells']} cells in all, contact kinds "
          f"{sorted(counts['kinds'])}")
    return counts


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    binary = sys.argv[1]
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        spheres, crosses = Path(tmp) / "spheres", Path(tmp) / "crosses"
        subprocess.run([binary, "run", str(ROOT / "tests" / "integration" / "data" /
                                           "dam-break-tiny.toml"),
                        "-q", "-o", str(spheres), "--set", "simulation.end_time_s=0.3",
                        "--set", "output.interval_s=0.1"], check=True, stdout=subprocess.DEVNULL)
        subprocess.run([binary, "run", str(ROOT / "cases" / "dem" / "crosses-poured.toml"), "-q",
                        "-o", str(crosses), "--set", "particles[0].count=40",
                        "--set", "particles[0].region_max_m=[0.12, 0.30, 0.08]",
                        "--set", "simulation.end_time_s=0.4", "--set", "output.interval_s=0.1"],
                       check=True, stdout=subprocess.DEVNULL)
        expected = {spheres: ({"particles.pvd", "contacts.pvd", "branches.pvd", "obstacles.pvd"},
                              {0, 1}),
                    crosses: ({"particles.pvd", "bodies.pvd", "contacts.pvd", "branches.pvd",
                               "obstacles.pvd"}, {2, 3})}
        for run_dir, (indexes, kinds) in expected.items():
            counts = check_run(run_dir, failures)
            found = {p.name for p in run_dir.glob("*.pvd")}
            if not indexes <= found:
                failures.append(f"{run_dir.name}: missing {sorted(indexes - found)}")
            if not kinds <= counts["kinds"]:
                failures.append(f"{run_dir.name}: no contact of kind {sorted(kinds - counts['kinds'])}"
                                " was written: the case no longer tests them")
    for failure in failures:
        print("FAIL:", failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
