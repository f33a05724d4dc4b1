"""Opens every .pvd index of sanguis run folders in ParaView and prints what it reads.

usage: pvpython --force-offscreen-rendering scripts/paraview_open.py RUN_DIR [RUN_DIR ...]

For each index (flow.pvd, particles.pvd, bodies.pvd, contacts.pvd, branches.pvd,
obstacles.pvd) and each of its times: the data set type ParaView makes, its cells,
points and cell or point arrays; for flow runs also a z slice through the middle of
the last frame, as a user would cut one. ParaView is not a dependency of sanguis
(Debian's paraview package is about 440 MB): this is a smoke check for those who
have it. Exits 1 if an index cannot be opened or a frame reads as empty where the
index lists it.
"""
import glob
import os
import sys

from paraview.simple import OpenDataFile, Slice


def main(runs):
    failures = 0
    for run in runs:
        for index in sorted(glob.glob(os.path.join(run, "*.pvd"))):
            source = OpenDataFile(index)
            if source is None:
                print(f"FAIL: {index}: ParaView cannot open it")
                failures += 1
                continue
            times = list(source.TimestepValues) or [0.0]
            print(f"{index}: {source.GetXMLName()}, {len(times)} time(s)")
            for t in times:
                source.UpdatePipeline(t)
                info = source.GetDataInformation()
                arrays = sorted(source.CellData.keys()) + sorted(source.PointData.keys())
                print(f"  t = {t:.6g}: {info.GetDataSetTypeAsString()}, {info.GetNumberOfCells()} "
                      f"cells, {info.GetNumberOfPoints()} points, arrays {', '.join(arrays)}")
            if os.path.basename(index) == "flow.pvd":
                bounds = source.GetDataInformation().GetBounds()
                cut = Slice(Input=source)
                cut.SliceType.Normal = [0.0, 0.0, 1.0]
                cut.SliceType.Origin = [0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]),
                                        0.5 * (bounds[4] + bounds[5])]
                cut.UpdatePipeline(times[-1])
                cells = cut.GetDataInformation().GetNumberOfCells()
                print(f"  z slice through the middle of the last frame: {cells} cells, pressure "
                      f"in {cut.CellData['pressure'].GetRange()}")
                if cells == 0:
                    print(f"FAIL: {index}: the slice of the last frame is empty")
                    failures += 1
    return 1 if failures else 0


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1:]))
