#!/usr/bin/python3
"""A 2D model of the flow multigrid on a composite (two-level) grid of blocks, to ask
which part of the V-cycle loses the rate at coarse-fine faces (issue #7).

The model follows src/flow/multigrid.hpp and coarse_fine.hpp cell by cell, in 2D and
with matrices (numpy, scipy): a periodic unit square of nb x nb blocks of B x B
cells, some blocks refined once; cell-centred Laplacian with matched (conservative)
fluxes at coarse-fine faces; the fine ghost across such a face either the quadratic
interpolant of the coarse block alone ("interpolated", one-sided near the block's
faces, the flow's rule and the finest level's) or the composite rule
g = 8/15 c + 2/3 x_f - 1/5 x_f2 ("composite", the coarser levels' rule); red-black
relaxation with the exact diagonal, each colour relaxed against values fixed for the
half-sweep (as the code's lagged ghosts and matched fluxes); restriction by the average
of the 4 children, bilinear prolongation reading ghosts filled by the interpolated rule;
in-block levels down to one cell per block, solved exactly there.

For each grid it prints the asymptotic reduction per V(2,2) cycle (the spectral radius
of the cycle's error propagation, the constant mode removed), with the coarser levels
rediscretised (as built) or Galerkin (R A P), and the two-grid factor (the level below
the finest solved exactly). A model, not the code: 2D, and the spectral radius rather
than the mean over a solve from a smooth source, so its rates are higher than the 3D
code's; what it can tell is which variant closes the gap to the uniform grid.

Usage: composite_two_grid.py [--blocks 4] [--block-cells 8] [--omega 1.15 1.25]
"""
import argparse

import numpy as np

try:  # Debian's python3-scipy: sparse operators and Arnoldi, 5-10x faster on these sizes
    from scipy import sparse
    from scipy.sparse.linalg import LinearOperator, eigs
except ImportError:  # numpy alone: dense matrices, for small grids (the unit tests)
    sparse = eigs = LinearOperator = None


def as_matrix(values):
    return sparse.csr_matrix(values) if sparse else np.asarray(values)


def matrix_from_entries(values, rows, cols, shape):
    """Sums duplicate entries, as scipy's coo -> csr does."""
    if sparse:
        return sparse.csr_matrix((values, (rows, cols)), shape=shape)
    out = np.zeros(shape)
    np.add.at(out, (np.asarray(rows, dtype=int), np.asarray(cols, dtype=int)), values)
    return out


def diagonal(a):
    return a.diagonal() if sparse else np.diag(a)


def dense(a):
    return a.toarray() if sparse else a

DIRS = ((1, 0), (-1, 0), (0, 1), (0, -1))


class CompositeLevel:
    """The leaves of one multigrid level: blocks of bc x bc cells (bc = B >> m)."""

    def __init__(self, refined, nb, bc):
        self.refined, self.nb, self.bc = refined, nb, bc
        self.cells = []
        for bi in range(nb):
            for bj in range(nb):
                level = refined[bi][bj]
                side = bc << level
                for i in range(bi * side, (bi + 1) * side):
                    for j in range(bj * side, (bj + 1) * side):
                        self.cells.append((level, i, j))
        self.index = {c: k for k, c in enumerate(self.cells)}

    def n(self, level):
        return self.nb * (self.bc << level)

    def h(self, level):
        return 1.0 / self.n(level)

    def block_level(self, level, i, j):
        side = self.bc << level
        return self.refined[i // side][j // side]

    def wrap(self, level, i, j):
        n = self.n(level)
        return level, i % n, j % n

    # --- values of virtual cells, as weights on the leaves -------------------------------

    def value(self, level, i, j):
        """The value a ghost of cell size h(level) at (i, j) reads: the leaf itself, the
        mean of finer leaves, or the interpolated rule from the coarser block."""
        level, i, j = self.wrap(level, i, j)
        at = self.block_level(level, i, j)
        if at == level:
            return {self.index[(level, i, j)]: 1.0}
        if at > level:
            out = {}
            for a in (0, 1):
                for b in (0, 1):
                    for k, w in self.value(level + 1, 2 * i + a, 2 * j + b).items():
                        out[k] = out.get(k, 0.0) + 0.25 * w
            return out
        return self.from_coarse(level, i, j)

    def axis_weights(self, fine):
        """coarse_fine.hpp's axis_weights: nodes and weights within the coarse block."""
        bc = self.bc
        cell = fine >> 1
        offset = 0.25 if fine & 1 else -0.25
        if bc >= 3:
            mid = min(max(cell, 1), bc - 2)
            x = (cell - mid) + offset
            return mid - 1, [0.5 * x * (x - 1.0), 1.0 - x * x, 0.5 * x * (x + 1.0)]
        if bc == 2:
            x = cell + offset
            return 0, [1.0 - x, x]
        return 0, [1.0]

    def from_coarse(self, level, i, j):
        """Interpolated rule: quadratic Lagrange on the coarse block's own cells."""
        bc, coarse = self.bc, level - 1
        bi, bj = i // (2 * bc), j // (2 * bc)
        fx, ax = self.axis_weights(i - bi * 2 * bc)
        fy, ay = self.axis_weights(j - bj * 2 * bc)
        out = {}
        for a, wa in enumerate(ax):
            for b, wb in enumerate(ay):
                k = self.index[(coarse, bi * bc + fx + a, bj * bc + fy + b)]
                out[k] = out.get(k, 0.0) + wa * wb
        return out

    def composite_ghost(self, level, i, j, d):
        """Composite rule for the ghost of fine leaf (level, i, j) across face d."""
        if self.bc < 2:
            return self.value(level, i + d[0], j + d[1])
        gl, gi, gj = self.wrap(level, i + d[0], j + d[1])
        bc, coarse = self.bc, level - 1
        bi, bj = gi // (2 * bc), gj // (2 * bc)
        ci, cj = gi // 2, gj // 2  # the coarse layer beside the face
        out = {}
        if d[0] != 0:  # interpolate along y within the coarse block
            first, w = self.axis_weights(gj - bj * 2 * bc)
            nodes = [(ci, bj * bc + first + b) for b in range(len(w))]
        else:
            first, w = self.axis_weights(gi - bi * 2 * bc)
            nodes = [(bi * bc + first + a, cj) for a in range(len(w))]
        for (ni, nj), wn in zip(nodes, w):
            k = self.index[(coarse, ni, nj)]
            out[k] = out.get(k, 0.0) + 8.0 / 15.0 * wn
        own = self.index[(level, i, j)]
        out[own] = out.get(own, 0.0) + 2.0 / 3.0
        for k, w in self.value(level, i - d[0], j - d[1]).items():
            out[k] = out.get(k, 0.0) - 0.2 * w
        return out

    def ghost(self, level, i, j, d, rule):
        if rule == "composite":
            return self.composite_ghost(level, i, j, d)
        return self.value(level, i + d[0], j + d[1])

    # --- operator, transfers ---------------------------------------------------------------

    def operator(self, rule):
        """-div grad on the leaves, fluxes matched at coarse-fine faces."""
        n = len(self.cells)
        a = np.zeros((n, n))
        for row, (level, i, j) in enumerate(self.cells):
            h = self.h(level)
            for d in DIRS:
                nl, ni, nj = self.wrap(level, i + d[0], j + d[1])
                at = self.block_level(nl, ni, nj)
                flux = {}
                if at == level:
                    flux = {self.index[(nl, ni, nj)]: 1.0 / h, row: -1.0 / h}
                elif at < level:  # our ghost on the coarse side
                    for k, w in self.ghost(level, i, j, d, rule).items():
                        flux[k] = flux.get(k, 0.0) + w / h
                    flux[row] = flux.get(row, 0.0) - 1.0 / h
                else:  # matched: the mean of the two fine fluxes beside the face
                    hf = h / 2.0
                    for t in (0, 1):
                        fi = 2 * ni + (0 if d[0] > 0 else 1) if d[0] != 0 else 2 * ni + t
                        fj = 2 * nj + (0 if d[1] > 0 else 1) if d[1] != 0 else 2 * nj + t
                        fl, fi, fj = self.wrap(level + 1, fi, fj)
                        back = (-d[0], -d[1])
                        kf = self.index[(fl, fi, fj)]
                        flux[kf] = flux.get(kf, 0.0) + 0.5 / hf
                        for k, w in self.ghost(fl, fi, fj, back, rule).items():
                            flux[k] = flux.get(k, 0.0) - 0.5 * w / hf
                for k, w in flux.items():
                    a[row, k] -= w / h
        return a

    def colours(self):
        return np.array([(i + j) % 2 for (_, i, j) in self.cells])


def restriction(fine, coarse):
    rows, cols = [], []
    for row, (level, i, j) in enumerate(coarse.cells):
        for a in (0, 1):
            for b in (0, 1):
                rows.append(row)
                cols.append(fine.index[(level, 2 * i + a, 2 * j + b)])
    return matrix_from_entries(np.full(len(rows), 0.25), rows, cols,
                               (len(coarse.cells), len(fine.cells)))


def prolongation(fine, coarse):
    """Bilinear from the coarse level's cells and ghosts (9/16, 3/16, 3/16, 1/16)."""
    rows, cols, vals = [], [], []
    for row, (level, i, j) in enumerate(fine.cells):
        bilinear(coarse, level, i, j, row, rows, cols, vals)
    return matrix_from_entries(vals, rows, cols, (len(fine.cells), len(coarse.cells)))


def bilinear(coarse, level, i, j, row, rows, cols, vals):
    """The entries of fine cell (level, i, j)'s row of a bilinear prolongation."""
    ci, cj = i // 2, j // 2
    sx = 1 if i % 2 else -1
    sy = 1 if j % 2 else -1
    for (oi, oj), w in (((0, 0), 9 / 16), ((sx, 0), 3 / 16), ((0, sy), 3 / 16),
                        ((sx, sy), 1 / 16)):
        for k, wk in coarse.value(level, ci + oi, cj + oj).items():
            rows.append(row), cols.append(k), vals.append(w * wk)


def smooth(a, colours, omega, sweeps, x):
    """Applies `sweeps` red-black sweeps (each colour relaxed against values fixed for the
    half-sweep) to the errors in the columns of x; omega: one value or one per row."""
    inv_diag = 1.0 / diagonal(a)
    for _ in range(sweeps):
        for colour in (0, 1):
            scale = omega * np.where(colours == colour, inv_diag, 0.0)
            x = x - scale[:, None] * (a @ x)
    return x


def coarsen_fine_blocks(fine, coarse):
    """Transfers between the composite grid and the same grid with its refined blocks
    coarsened to the coarse blocks' cells (a uniform grid for two levels): a coarse leaf
    keeps its value both ways; a fine leaf is averaged into its parent (R) and gets the
    bilinear interpolant of the coarser grid (P)."""
    rows, cols, vals = [], [], []
    prow, pcol, pval = [], [], []
    for row, (level, i, j) in enumerate(fine.cells):
        if fine.block_level(level, i, j) == 0:
            k = coarse.index[(0, i, j)]
            rows.append(k), cols.append(row), vals.append(1.0)
            prow.append(row), pcol.append(k), pval.append(1.0)
            continue
        rows.append(coarse.index[(0, i // 2, j // 2)]), cols.append(row), vals.append(0.25)
        bilinear(coarse, 0, i, j, row, prow, pcol, pval)
    shape = (len(coarse.cells), len(fine.cells))
    return (matrix_from_entries(vals, rows, cols, shape),
            matrix_from_entries(pval, prow, pcol, shape[::-1]))


def hierarchy(refined, nb, block_cells, finest_rule, coarser):
    """coarser: "rediscretised" (every block halves its cells, the composite rule on the
    coarser levels: as built), "galerkin" (the same levels, R A P), or "level by level"
    (the refined blocks coarsened first, to the coarse blocks' cells, then the uniform
    hierarchy; the same as block by block where no block is refined)."""
    levels, bc = [CompositeLevel(refined, nb, block_cells)], block_cells
    if coarser == "level by level" and any(any(row) for row in refined):
        uniform = [[0] * nb for _ in range(nb)]
        while bc >= 1:
            levels.append(CompositeLevel(uniform, nb, bc))
            bc //= 2
        transfers = [coarsen_fine_blocks(levels[0], levels[1])]
    else:
        bc //= 2
        while bc >= 1:
            levels.append(CompositeLevel(refined, nb, bc))
            bc //= 2
        transfers = [(restriction(levels[0], levels[1]), prolongation(levels[0], levels[1]))]
    transfers += [(restriction(levels[k], levels[k + 1]), prolongation(levels[k], levels[k + 1]))
                  for k in range(1, len(levels) - 1)]
    ops = [as_matrix(levels[0].operator(finest_rule))]
    for k in range(1, len(levels)):
        r, p = transfers[k - 1]
        ops.append(as_matrix(r @ ops[k - 1] @ p) if coarser == "galerkin" else
                   as_matrix(levels[k].operator("composite")))
    return levels, ops, transfers


def beside_finer_rows(level, a):
    """The rows whose stencil reaches a finer cell: the coarse cells beside a finer block,
    which hold the matched fluxes (MultigridOptions::beside_finer_relaxation)."""
    a = sparse.csr_matrix(a) if sparse else np.asarray(a)
    cell_level = np.array([c[0] for c in level.cells])
    rows = np.zeros(len(cell_level), dtype=bool)
    for row in range(len(cell_level)):
        cols = a.indices[a.indptr[row]:a.indptr[row + 1]] if sparse else np.nonzero(a[row])[0]
        rows[row] = np.any(cell_level[cols] > cell_level[row])
    return rows


def cycle_error(levels, ops, transfers, omega, sweeps, exact, k, x, inverses):
    """The error after one V-cycle at level k from the errors in the columns of x; level
    `exact` and below solved exactly; omega: per level, one value or one per row."""
    a = ops[k]
    if k >= exact:
        return x - inverses[k] @ (a @ x)
    x = smooth(a, levels[k].colours(), omega[k], sweeps, x)
    r, p = transfers[k]
    y = inverses[k + 1] @ (r @ (a @ x))  # the exact correction, then its cycle's error
    if k + 1 < exact:
        y = y - cycle_error(levels, ops, transfers, omega, sweeps, exact, k + 1, y, inverses)
    x = x - p @ y
    return smooth(a, levels[k].colours(), omega[k], sweeps, x)


def rate(levels, ops, transfers, omega, sweeps, exact, beside_finer=None):
    """Asymptotic reduction per cycle: 1 / spectral radius, constant mode removed. With
    beside_finer, the rows beside finer cells relax at min(omega, beside_finer) (the code's
    rule since 2026-12-05); without, at omega as the rest."""
    omegas = [omega] * len(levels)
    if beside_finer is not None:
        for k, level in enumerate(levels):
            omegas[k] = np.where(beside_finer_rows(level, ops[k]), min(omega, beside_finer),
                                 omega)
    inverses = [np.linalg.pinv(dense(op)) if 0 < k <= exact else None
                for k, op in enumerate(ops)]
    n = ops[0].shape[0]
    volume = np.array([levels[0].h(c[0]) ** 2 for c in levels[0].cells])
    volume /= volume.sum()

    def without_mean(x):  # the constant mode is every cycle's eigenvector of eigenvalue 1
        return x - np.outer(np.ones(n), volume @ x) if x.ndim == 2 else x - volume @ x

    def cycle(x):
        return without_mean(cycle_error(levels, ops, transfers, omegas, sweeps, exact, 0,
                                        without_mean(x), inverses))

    if eigs:  # Arnoldi (ARPACK) on the cycle applied to vectors, a few eigenvalues for safety
        operator = LinearOperator((n, n), matvec=lambda v: cycle(v.reshape(n, 1)).ravel(),
                                  dtype=float)
        eig = eigs(operator, k=4, which="LM", return_eigenvectors=False, tol=1e-8)
    else:
        eig = np.linalg.eigvals(cycle(np.eye(n)))
    return 1.0 / np.max(np.abs(eig))


GRIDS = {
    "uniform": lambda nb: [],
    "uniform, fine": lambda nb: [(i, j) for i in range(nb) for j in range(nb)],
    "quadrant": lambda nb: [(i, j) for i in range(nb // 2) for j in range(nb // 2)],
    "corner": lambda nb: [(i, j) for i in range(nb // 2) for j in range(nb // 2)
                          if not (i == nb // 2 - 1 and j == nb // 2 - 1)],
    "scattered": lambda nb: [(0, 0), (1, 2), (2, 0), (3, 3)],
}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--blocks", type=int, default=4)
    parser.add_argument("--block-cells", type=int, default=8)
    parser.add_argument("--omega", type=float, nargs="+", default=[1.15, 1.25])
    parser.add_argument("--grids", nargs="+", default=list(GRIDS))
    parser.add_argument("--work", action="store_true",
                        help="only the cells of each level per cell of the finest, per hierarchy")
    parser.add_argument("--finest", nargs="+", default=["interpolated", "composite"])
    parser.add_argument("--coarser", nargs="+",
                        default=["rediscretised", "galerkin", "level by level"])
    parser.add_argument("--beside-finer", type=float, nargs="*", default=[],
                        help="also the cycles with the rows beside finer cells relaxed at "
                             "min(omega, this), one row per value (the code's default: 1.0)")
    args = parser.parse_args()
    nb, bc = args.blocks, args.block_cells
    if args.work:
        print(f"{'grid':14s} {'coarser levels':15s} cells per level / cells of the finest level")
        for name in args.grids:
            refined = [[0] * nb for _ in range(nb)]
            for i, j in GRIDS[name](nb):
                refined[i][j] = 1
            for coarser in ("rediscretised", "level by level"):
                levels = hierarchy(refined, nb, bc, "interpolated", coarser)[0]
                counts = [len(level.cells) for level in levels]
                shares = ", ".join(f"{c / counts[0]:.3f}" for c in counts)
                print(f"{name:14s} {coarser:15s} {sum(counts) / counts[0]:.3f} = {shares}")
        return
    print("reduction per cycle (1/spectral radius), V(2,2); two-grid = level 1 solved exactly")
    print(f"{'grid':14s} {'finest rule':12s} {'coarser levels':29s}"
          + "".join(f" {'V w=' + str(w):>10s} {'2-grid':>8s}" for w in args.omega))
    for name in args.grids:
        refined = [[0] * nb for _ in range(nb)]
        for i, j in GRIDS[name](nb):
            refined[i][j] = 1
        variants = [(f, c) for f in ("interpolated", "composite")
                    for c in ("rediscretised", "galerkin", "level by level")]
        if name.startswith("uniform"):
            variants = [("interpolated", "rediscretised"), ("interpolated", "galerkin")]
        variants = [v for v in variants if v[1] in args.coarser and v[0] in args.finest]
        for finest, coarser in variants:
            levels, ops, transfers = hierarchy(refined, nb, bc, finest, coarser)
            composite = not name.startswith("uniform")
            for beside in [None] + (args.beside_finer if composite else []):
                cells = []
                for w in args.omega:
                    v = rate(levels, ops, transfers, w, 2, len(levels) - 1, beside)
                    t = rate(levels, ops, transfers, w, 2, 1, beside)
                    cells.append(f" {v:10.1f} {t:8.1f}")
                label = coarser if beside is None else f"{coarser}, {beside:g} by finer"
                print(f"{name:14s} {finest:12s} {label:29s}" + "".join(cells), flush=True)


if __name__ == "__main__":
    main()
