#!/usr/bin/python3
"""A plane slice of a flow run: a PNG for reports and a CSV of the cells it cuts.

usage: flow_slice.py RUN [--frame N | --time T] [--normal x|y|z] [--at M]
                         [--field NAME] [--blocks] [--output FILE.png]

RUN is a run folder of `sanguis run` with a [flow] section (its flow.pvd and
flow/*.vtu or flow/*.vtm frames) or one .vtu or .vtm frame. The slice is the plane normal to
--normal through --at (metres; default: the middle of the domain). Each cell
the plane cuts (lower corner <= at < upper corner, so exactly one layer of
every block) is drawn at its own size, so adaptive grids show their levels;
--blocks outlines the blocks. --field names a cell array of the frame
(velocity, pressure, vorticity_magnitude, viscosity, level, rank, block) or
"speed" (|velocity|, the default); a vector array takes a component with a
suffix, e.g. velocity:x. Speed and vorticity slices carry in-plane velocity
arrows on a regular lattice.

Writes FILE.png (default RUN/slice_<field>_<normal><at>.png) and FILE.csv with
one row per cell cut: its in-plane lower and upper corners and the value.
Exits 2 with a message naming the file and the reason on bad input; an
existing output is replaced only once the new one is complete.
"""
import argparse
import base64
import csv
import os
import re
import sys
import tempfile
import xml.etree.ElementTree as ET

AXES = "xyz"


class SliceError(Exception):
    """Bad input: the message names the file or option and the reason."""


def frames_of(run):
    """[(time, [frame paths])] of a run folder (flow.pvd), or of one .vtu or .vtm file."""
    if os.path.isfile(run):
        if not run.endswith((".vtu", ".vtm")):
            raise SliceError(f"{run}: not a .vtu or .vtm frame nor a run folder")
        return [(None, [run])]
    if not os.path.isdir(run):
        raise SliceError(f"{run}: no such run folder")
    pvd = os.path.join(run, "flow.pvd")
    if not os.path.isfile(pvd):
        raise SliceError(f"{pvd}: missing (is {run} the folder of a flow run?)")
    try:
        root = ET.parse(pvd).getroot()
    except (ET.ParseError, OSError) as e:
        raise SliceError(f"{pvd}: unreadable ({e})") from e
    by_time = {}
    for ds in root.iter("DataSet"):
        t = float(ds.get("timestep", "nan"))
        by_time.setdefault(t, []).append(os.path.join(run, ds.get("file", "")))
    if not by_time:
        raise SliceError(f"{pvd}: lists no frame")
    return sorted(by_time.items())


def read_text(path):
    try:
        with open(path) as f:
            return f.read()
    except OSError as e:
        raise SliceError(f"{path}: unreadable ({e.strerror})") from e


def read_arrays(path, text):
    """The binary DataArrays of one of our VTK XML files, by name."""
    import numpy as np

    kinds = {"Float64": "<f8", "Int64": "<i8", "UInt8": "u1"}
    pattern = re.compile(
        r'<DataArray type="(\w+)" Name="(\w+)" NumberOfComponents="(\d)" format="binary">\s*(\S*)\s*</DataArray>')
    piece = {}
    for m in pattern.finditer(text):
        kind, name, comps, data = m.group(1), m.group(2), int(m.group(3)), m.group(4)
        if kind not in kinds:
            raise SliceError(f"{path}: array {name} of unsupported type {kind}")
        try:
            raw = base64.b64decode(data, validate=True)[8:]  # an 8-byte length header, then the values
            values = np.frombuffer(raw, dtype=kinds[kind])
            piece[name] = values.reshape(-1, comps) if comps > 1 else values
        except ValueError as e:  # binascii.Error is a ValueError
            raise SliceError(f"{path}: array {name} is corrupt ({e})") from e
    return piece


def hexahedra_cells(path):
    """Cell corners and arrays of a .vtu frame (hexahedra)."""
    piece = read_arrays(path, read_text(path))
    if "Points" not in piece or "connectivity" not in piece:
        raise SliceError(f"{path}: not a flow frame of sanguis (no Points or connectivity)")
    try:
        corners = piece["Points"][piece["connectivity"].reshape(-1, 8)]
    except (ValueError, IndexError) as e:
        raise SliceError(f"{path}: cells do not match the points ({e})") from e
    arrays = {n: v for n, v in piece.items() if n not in ("Points", "connectivity", "offsets", "types")}
    return corners.min(axis=1), corners.max(axis=1), arrays


def image_block_cells(path):
    """Cell corners and arrays of one .vti block (cubes, x fastest, then y, then z)."""
    import numpy as np

    text = read_text(path)
    m = re.search(r'<ImageData WholeExtent="0 (\d+) 0 (\d+) 0 (\d+)" Origin="(\S+) (\S+) (\S+)" '
                  r'Spacing="(\S+) \S+ \S+"', text)
    if not m:
        raise SliceError(f"{path}: not a block of a sanguis flow frame (no ImageData extent)")
    n = [int(m.group(i)) for i in (1, 2, 3)]
    origin = np.array([float(m.group(i)) for i in (4, 5, 6)])
    h = float(m.group(7))
    k, j, i = np.meshgrid(np.arange(n[2]), np.arange(n[1]), np.arange(n[0]), indexing="ij")
    index = np.stack([i.ravel(), j.ravel(), k.ravel()], axis=1)
    arrays = read_arrays(path, text)
    for name, values in arrays.items():
        if len(values) != len(index):
            raise SliceError(f"{path}: array {name} has {len(values)} values for {len(index)} cells")
    # Corners as the .vtu's points are computed (lower + index h), to the same bits.
    return origin + h * index, origin + h * (index + 1), arrays


def block_files(path):
    """The .vti files a .vtm frame lists, relative to its folder."""
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError) as e:
        raise SliceError(f"{path}: unreadable ({e})") from e
    files = [os.path.join(os.path.dirname(path), d.get("file", "")) for d in root.iter("DataSet")]
    if not files:
        raise SliceError(f"{path}: lists no block")
    return files


def read_frame(paths):
    """Cell lower corners, upper corners and cell arrays of one frame (all its pieces:
    the .vtu of every rank, or every block a .vtm lists)."""
    import numpy as np

    pieces = []
    for path in paths:
        if path.endswith(".vtm"):
            pieces.extend(image_block_cells(block) for block in block_files(path))
        else:
            pieces.append(hexahedra_cells(path))
    arrays = {}
    for _, _, piece in pieces:
        for name, values in piece.items():
            arrays.setdefault(name, []).append(values)
    return (np.concatenate([p[0] for p in pieces]), np.concatenate([p[1] for p in pieces]),
            {name: np.concatenate(parts) for name, parts in arrays.items()})


def field_values(arrays, field, where):
    """The values of --field (speed, NAME or NAME:x|y|z) and its label."""
    import numpy as np

    names = sorted(arrays) + ["speed"]
    if field == "speed":
        if "velocity" not in arrays:
            raise SliceError(f"--field speed: the frame has no velocity (arrays: {', '.join(names)})")
        return np.linalg.norm(arrays["velocity"], axis=1), "speed |u| (m/s)"
    name, _, component = field.partition(":")
    if name not in arrays:
        raise SliceError(f"{where}: --field {field}: no such cell array (arrays: {', '.join(names)})")
    values = arrays[name]
    if values.ndim == 2:
        if component not in ("x", "y", "z"):
            raise SliceError(f"--field {field}: {name} is a vector; give {name}:x, :y or :z")
        return values[:, AXES.index(component)], f"{name} {component}"
    if component:
        raise SliceError(f"--field {field}: {name} is a scalar, it has no component")
    return values.astype(float), name


def atomic_write(path, write):
    """write(temporary path) then rename: an existing file is replaced only when complete."""
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    suffix = os.path.splitext(path)[1]
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=".slice-", suffix=suffix)
    os.close(fd)
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", help="flow run folder (flow.pvd) or one .vtu or .vtm frame")
    when = parser.add_mutually_exclusive_group()
    when.add_argument("--frame", type=int, help="frame index (default: the last; negative counts back)")
    when.add_argument("--time", type=float, help="the frame nearest to this time (s)")
    parser.add_argument("--normal", choices=list(AXES), default="z", help="normal of the plane (default z)")
    parser.add_argument("--at", type=float, help="position of the plane along the normal (m; default mid-domain)")
    parser.add_argument("--field", default="speed", help="cell array, NAME:x for a component, or speed")
    parser.add_argument("--blocks", action="store_true", help="outline the blocks")
    parser.add_argument("--output", "-o", help="PNG file (a CSV is written beside it)")
    a = parser.parse_args(argv)

    import numpy as np

    frames = frames_of(a.run)
    if a.time is not None:
        if frames[0][0] is None:
            raise SliceError("--time needs a run folder (one frame file has no time)")
        index = min(range(len(frames)), key=lambda k: abs(frames[k][0] - a.time))
    else:
        index = len(frames) - 1 if a.frame is None else a.frame
        if not -len(frames) <= index < len(frames):
            raise SliceError(f"--frame {a.frame}: the run has {len(frames)} frames (0..{len(frames) - 1})")
    time, paths = frames[index]
    lo, hi, arrays = read_frame(paths)
    n = AXES.index(a.normal)
    extent = (lo[:, n].min(), hi[:, n].max())
    at = 0.5 * (extent[0] + extent[1]) if a.at is None else a.at
    if not extent[0] <= at <= extent[1]:
        raise SliceError(f"--at {at}: outside the domain along {a.normal} [{extent[0]:g}, {extent[1]:g}] m")
    # The cells whose box holds the plane (the upper domain face belongs to the last layer).
    cut = (lo[:, n] <= at) & ((at < hi[:, n]) | ((at == extent[1]) & (hi[:, n] == extent[1])))
    values, label = field_values(arrays, a.field, paths[0])
    u_axis, v_axis = [d for d in range(3) if d != n]
    lo2, hi2, val = lo[cut][:, [u_axis, v_axis]], hi[cut][:, [u_axis, v_axis]], values[cut]

    tag = a.field.replace(":", "_")
    output = a.output or os.path.join(a.run if os.path.isdir(a.run) else os.path.dirname(a.run) or ".",
                                      f"slice_{tag}_{a.normal}{at:g}.png")
    if not output.endswith(".png"):
        raise SliceError(f"--output {output}: give a .png file name")
    table = os.path.splitext(output)[0] + ".csv"
    names = [AXES[u_axis] + "_low_m", AXES[v_axis] + "_low_m", AXES[u_axis] + "_high_m",
             AXES[v_axis] + "_high_m", tag]

    def write_csv(path):
        with open(path, "w", newline="") as f:
            w = csv.writer(f, lineterminator="\n")
            w.writerow(names)
            for p, q, v in zip(lo2, hi2, val):
                w.writerow([f"{p[0]:.17g}", f"{p[1]:.17g}", f"{q[0]:.17g}", f"{q[1]:.17g}", f"{v:.17g}"])

    def write_png(path):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.collections import PolyCollection

        quads = [[(p[0], p[1]), (q[0], p[1]), (q[0], q[1]), (p[0], q[1])] for p, q in zip(lo2, hi2)]
        width = hi2[:, 0].max() - lo2[:, 0].min()
        height = hi2[:, 1].max() - lo2[:, 1].min()
        aspect = min(3.0, max(1.0 / 3.0, width / height))  # the figure follows the plane, within 3:1
        fig, ax = plt.subplots(figsize=(1.8 + 6.0 * max(1.0, aspect), 1.2 + 6.0 * max(1.0, 1.0 / aspect)))
        cells = PolyCollection(quads, array=val, cmap="viridis", edgecolors="none")
        ax.add_collection(cells)
        fig.colorbar(cells, ax=ax, label=label, shrink=0.8)
        if a.blocks and "block" in arrays:
            blocks = arrays["block"][cut]
            ranks = arrays["rank"][cut] if "rank" in arrays else np.zeros_like(blocks)
            outlines = []
            for key in sorted(set(zip(ranks.tolist(), blocks.tolist()))):
                mine = (ranks == key[0]) & (blocks == key[1])
                p, q = lo2[mine].min(axis=0), hi2[mine].max(axis=0)
                outlines.append([(p[0], p[1]), (q[0], p[1]), (q[0], q[1]), (p[0], q[1])])
            ax.add_collection(PolyCollection(outlines, facecolors="none", edgecolors="w", linewidths=0.5))
        if "velocity" in arrays and a.field in ("speed", "vorticity_magnitude"):
            # In-plane velocity on a regular lattice of about 24 points along the longer side,
            # each arrow the value of the cell that holds its point.
            vel = arrays["velocity"][cut][:, [u_axis, v_axis]]
            step = max(width, height) / 24.0
            px, py, pu, pv = [], [], [], []
            for x in np.arange(lo2[:, 0].min() + 0.5 * step, hi2[:, 0].max(), step):
                for y in np.arange(lo2[:, 1].min() + 0.5 * step, hi2[:, 1].max(), step):
                    holds = (lo2[:, 0] <= x) & (x < hi2[:, 0]) & (lo2[:, 1] <= y) & (y < hi2[:, 1])
                    if holds.any():
                        c = int(np.argmax(holds))
                        px.append(x)
                        py.append(y)
                        pu.append(vel[c, 0])
                        pv.append(vel[c, 1])
            ax.quiver(px, py, pu, pv, color="w", alpha=0.8, width=0.002)
        ax.set_xlim(lo2[:, 0].min(), hi2[:, 0].max())
        ax.set_ylim(lo2[:, 1].min(), hi2[:, 1].max())
        ax.set_aspect("equal")
        ax.set_xlabel(f"{AXES[u_axis]} (m)")
        ax.set_ylabel(f"{AXES[v_axis]} (m)")
        when_text = f", t = {time:g} s" if time is not None else ""
        ax.set_title(f"{label}, plane {a.normal} = {at:g} m{when_text}, {int(cut.sum())} cells")
        fig.tight_layout()
        fig.savefig(path, dpi=130)
        plt.close(fig)

    atomic_write(table, write_csv)
    atomic_write(output, write_png)
    print(f"slice {a.normal} = {at:g} m of {paths[0]}"
          f"{'' if time is None else f' (t = {time:g} s)'}: {int(cut.sum())} cells, "
          f"{tag} in [{val.min():.6g}, {val.max():.6g}]")
    print(f"written: {output}, {table}")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except SliceError as e:
        print(f"flow_slice: error: {e}", file=sys.stderr)
        sys.exit(2)
