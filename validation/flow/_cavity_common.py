"""Shared by the flow validation scripts: reading our .vtu frames and CSV files, cell boxes,
centre-line profiles, running variants of a case file."""
import base64
import csv
import re
import subprocess
import time

import numpy as np


def read_vtu(path):
    """Cell centres and cell arrays of one of our .vtu files."""
    xml = path.read_text()
    arrays = {}
    for m in re.finditer(r'<DataArray type="(\w+)" Name="(\w+)" NumberOfComponents="(\d)" format="binary">\s*(\S+)\s*</DataArray>', xml):
        kind, name, comps, data = m.group(1), m.group(2), int(m.group(3)), m.group(4)
        raw = base64.b64decode(data)[8:]
        values = np.frombuffer(raw, dtype={"Float64": "<f8", "Int64": "<i8", "UInt8": "u1"}[kind])
        arrays[name] = values.reshape(-1, comps) if comps > 1 else values
    points = arrays["Points"]
    cells = arrays["connectivity"].reshape(-1, 8)
    centres = points[cells].mean(axis=1)
    return centres, arrays


def cell_boxes(arrays):
    """Lower and upper corners of every cell of a frame."""
    corners = arrays["Points"][arrays["connectivity"].reshape(-1, 8)]
    return corners.min(axis=1), corners.max(axis=1)


def centre_lines(centres, velocity, two_d):
    """u(y) on x = z = 0.5 and v(x) on y = z = 0.5, averaged over the adjacent cells."""
    h = np.min(np.diff(np.unique(np.round(centres[:, 0], 12))))
    zmid = 0.5 * (centres[:, 2].min() + centres[:, 2].max())
    near_z = np.ones(len(centres), bool) if two_d else np.abs(centres[:, 2] - zmid) < 0.6 * h

    def profile(along, across, component):
        mask = near_z & (np.abs(centres[:, across] - 0.5) < 0.6 * h)
        coords = np.round(centres[mask, along], 12)
        keys = np.unique(coords)
        values = np.array([velocity[mask][coords == k, component].mean() for k in keys])
        return keys, values

    y, u = profile(1, 0, 0)
    x, v = profile(0, 1, 1)
    return (y, u), (x, v)


def with_walls(coord, value, lid):
    """Adds the wall values (0 at the walls, the lid velocity at y = 1 for u)."""
    return np.concatenate(([0.0], coord, [1.0])), np.concatenate(([0.0], value, [lid]))


def run(sanguis, runs, name, text):
    """Writes the case text under runs/ and runs it (quiet); returns the wall seconds."""
    case = runs / f"{name}.toml"
    out = runs / name
    runs.mkdir(parents=True, exist_ok=True)
    case.write_text(text)
    start = time.time()
    subprocess.run([str(sanguis), "run", str(case), "-o", str(out), "--quiet"], check=True,
                   stdout=subprocess.DEVNULL)
    return time.time() - start


def last_frame(runs, name):
    frames = sorted((runs / name / "flow").glob("flow_*.vtu"))
    return frames[-1]


def read_text_rows(path):
    """The rows of a CSV file with a header, as dicts of strings."""
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def read_rows(path):
    """The rows of a diagnostics.csv, every value as a float."""
    return [{k: float(v) for k, v in r.items()} for r in read_text_rows(path)]


def draw_speed_and_blocks(fig, ax, lo, hi, speed, block, label, fraction, linewidth):
    """Cells cut by a plane (lower and upper corners, in x and y) coloured by
    speed, with a white outline around each block."""
    from matplotlib.collections import PolyCollection

    quads = [[(a[0], a[1]), (b[0], a[1]), (b[0], b[1]), (a[0], b[1])] for a, b in zip(lo, hi)]
    speeds = PolyCollection(quads, array=speed, cmap="viridis", edgecolors="none")
    ax.add_collection(speeds)
    fig.colorbar(speeds, ax=ax, label=label, fraction=fraction)
    outlines = []
    for b in np.unique(block):
        sel = block == b
        a, c = lo[sel].min(axis=0), hi[sel].max(axis=0)
        outlines.append([(a[0], a[1]), (c[0], a[1]), (c[0], c[1]), (a[0], c[1])])
    ax.add_collection(PolyCollection(outlines, facecolors="none", edgecolors="w", linewidths=linewidth))


def draw_centre_lines(ax, profiles, centres, styled_names, title, u_line="", v_line=""):
    """u(y) (against y) and v(x) (x against it) of each named run in its line style,
    on one axes; u_line, v_line: where the lines run, for the legend."""
    for name, style in styled_names:
        ax.plot(profiles[name]["u"], centres, style, label=f"{name}, u(y){u_line}")
        ax.plot(centres, profiles[name]["v"], style, label=f"{name}, v(x){v_line}")
    ax.set_xlabel("u / U (against y / L);  x / L (v / U against it)")
    ax.set_ylabel("y / L;  v / U")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=6)
    ax.set_title(title, fontsize=9)


def draw_plane_cut(fig, ax, arrays, values, z, label, title, linewidth):
    """The cells cut by the plane at height z coloured by `values` (one per cell),
    with the blocks outlined, in the unit square."""
    lo, hi = cell_boxes(arrays)
    cut = (lo[:, 2] <= z) & (hi[:, 2] > z)
    draw_speed_and_blocks(fig, ax, lo[cut], hi[cut], values[cut], arrays["block"][cut], label, 0.045, linewidth)
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    ax.set_aspect("equal")
    ax.set_xlabel("x / L")
    ax.set_ylabel("y / L")
    ax.set_title(title, fontsize=9)
