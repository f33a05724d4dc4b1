#pragma once
// Coarse-fine transfer kernels for blocks one level apart (issue #7):
//
// * fine cells from a coarse block by tensor-product quadratic Lagrange
//   interpolation of the coarse block's interior (27 cells; one-sided near
//   the block's faces so that no coarse ghost is read): exact for every
//   polynomial of degree <= 2 per direction, so the ghost error is O(h^3)
//   and the flux error at a coarse-fine face O(h^2), which keeps the
//   composite Poisson operator second order (Johansen & Colella 1998);
//   linear for blocks of 2 cells, constant for 1 (the coarse multigrid levels);
// * coarse cells from fine blocks by the average of the 8 fine cells that
//   make up the coarse cell (volume average: conservative, exact for linear);
// * the data transfer of adapt(): children from a parent with minmod-limited
//   slopes (second order, no new extrema), parents by the volume average.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

namespace sanguis::flow {

/// Read access to the interior cells (i,j,k) in [0,b)^3 of one block's field,
/// whether it is a local block (with ghost layers) or a packed remote one.
struct CellReader {
  const double* origin = nullptr;  ///< cell (0,0,0)
  std::array<std::ptrdiff_t, 3> stride{};

  [[nodiscard]] double operator()(int i, int j, int k) const {
    return origin[i * stride[0] + j * stride[1] + k * stride[2]];
  }
};

/// Lagrange weights on the 3 (b >= 3), 2 (b = 2) or 1 (b = 1) coarse cells
/// first..first+n-1 along one direction, at the centre of fine cell `fine`
/// (fine cells counted from the coarse block's lower face, two per coarse cell).
struct AxisWeights {
  int first = 0;
  int count = 1;
  std::array<double, 3> w{1.0, 0.0, 0.0};
};

inline AxisWeights axis_weights(int fine, int coarse_cells) {
  const int cell = fine >> 1;
  // Fine-cell centre in coarse-cell units relative to the coarse cell centre.
  const double offset = (fine & 1) ? 0.25 : -0.25;
  AxisWeights a;
  if (coarse_cells >= 3) {
    const int mid = std::clamp(cell, 1, coarse_cells - 2);
    const double x = (cell - mid) + offset;  // position relative to the middle node
    a.first = mid - 1;
    a.count = 3;
    a.w = {0.5 * x * (x - 1.0), 1.0 - x * x, 0.5 * x * (x + 1.0)};
  } else if (coarse_cells == 2) {
    const double x = cell + offset;  // relative to node 0, node 1 at x = 1
    a.first = 0;
    a.count = 2;
    a.w = {1.0 - x, x, 0.0};
  } else {
    a.first = 0;
    a.count = 1;
  }
  return a;
}

/// axis_weights(fine, coarse_cells) for fine = 0 .. 2 coarse_cells - 1, in a
/// table kept per thread and per block size (the ghost fills call it for
/// every face, at every multigrid level).
inline const AxisWeights* axis_weight_table(int coarse_cells) {
  thread_local std::vector<std::vector<AxisWeights>> tables;
  const auto at = static_cast<std::size_t>(coarse_cells);
  if (tables.size() <= at) tables.resize(at + 1);
  std::vector<AxisWeights>& table = tables[at];
  if (table.empty()) {
    for (int fine = 0; fine < 2 * coarse_cells; ++fine) {
      table.push_back(axis_weights(fine, coarse_cells));
    }
  }
  return table.data();
}

/// The composite operator's fine ghost across a coarse-fine face (the
/// multigrid's rule, Forest::exchange with CoarseGhosts::Composite):
///   g = kGhostCoarse c + kGhostFace x_f + kGhostSecond x_f2,
/// the quadratic along the face normal through c, the coarse layer beside the
/// face interpolated across the face (quadratic, axis_weights) to the fine
/// cell's line, at the coarse cell's centre (1.5 h_f beyond the fine cell
/// x_f), and the two fine cells x_f, x_f2 inside, evaluated at the ghost's
/// centre (h_f beyond x_f): Lagrange weights 8/15, 2/3, -1/5 on the nodes
/// 1.5, 0, -1 (in h_f from x_f) at 1. Exact for quadratics, so the ghost error
/// is O(h^3) and the flux error O(h^2), as for the interpolation from the
/// coarse block alone above, whose weights along the normal (1.41, -0.56,
/// 0.16: an extrapolation over three coarse cells) make the coarse cell's
/// row far from an M-matrix and slowed the multigrid's smoother there
/// (Johansen & Colella 1998 use fine cells the same way; docs/theory/flow.md).
/// Whether a block of `block_cells` cells per side can take the composite
/// ghost: it needs two of its own cells behind the face (x_f and x_f2 below).
/// Forest::exchange and the multigrid's relaxation decide by it alike.
inline bool composite_ghost_fits(int block_cells) {
  return block_cells >= 2;
}

inline constexpr double kGhostCoarse = 8.0 / 15.0;
inline constexpr double kGhostFace = 2.0 / 3.0;
inline constexpr double kGhostSecond = -1.0 / 5.0;

/// Value at the centre of the fine cell `fine` (per direction, fine cells
/// counted from the coarse block's lower corner, each in [0, 2b)).
inline double interpolate_from_coarse(const CellReader& coarse, int coarse_cells,
                                      const std::array<int, 3>& fine) {
  const AxisWeights ax = axis_weights(fine[0], coarse_cells);
  const AxisWeights ay = axis_weights(fine[1], coarse_cells);
  const AxisWeights az = axis_weights(fine[2], coarse_cells);
  double value = 0.0;
  for (int c = 0; c < az.count; ++c) {
    double plane = 0.0;
    for (int b = 0; b < ay.count; ++b) {
      double row = 0.0;
      for (int a = 0; a < ax.count; ++a) {
        row += ax.w[static_cast<std::size_t>(a)] * coarse(ax.first + a, ay.first + b, az.first + c);
      }
      plane += ay.w[static_cast<std::size_t>(b)] * row;
    }
    value += az.w[static_cast<std::size_t>(c)] * plane;
  }
  return value;
}

/// minmod limiter: the smaller one-sided difference, zero at an extremum.
inline double minmod(double a, double b) {
  if (a * b <= 0.0) return 0.0;
  return std::abs(a) < std::abs(b) ? a : b;
}

}  // namespace sanguis::flow
