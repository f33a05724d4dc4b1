#include "flow/multigrid.hpp"

#include <unistd.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <type_traits>

#include "flow/coarse_fine.hpp"
#include "flow/conjugate_gradients.hpp"

namespace sanguis::flow {

namespace {

constexpr std::size_t D(int d) {
  return static_cast<std::size_t>(d);
}

/// Pointers to the coefficient arrays of one block.
struct BlockCoefficients {
  const double* alpha;
  std::array<const double*, 3> beta;
};

/// The cells around cell i of a row: the row itself (its neighbours along x
/// at i - 1 and i + 1, ghosts at the ends) and the rows beside it along y
/// and z, in this block (cells or ghost layer) or in a same-level neighbour
/// read in place (neighbour_rows).
struct RowStencil {
  const double* row;
  std::array<const double*, 4> beside;  ///< y_lo, y_hi, z_lo, z_hi
  [[nodiscard]] double low(int d, int i) const {
    return d == 0 ? row[i - 1] : beside[D(2 * d - 2)][i];
  }
  [[nodiscard]] double high(int d, int i) const {
    return d == 0 ? row[i + 1] : beside[D(2 * d - 1)][i];
  }
};

/// The new value of cell c (cell i of the row of `x`) under Gauss-Seidel
/// for eq. (1). `implicit` (times inv_h2) is added to the diagonal and,
/// times the old value, to the numerator: the part of the ghost values that
/// depends on the cell itself (quadratic Dirichlet closure), treated
/// implicitly. `s`: the coefficient arrays' strides (the faces of c are c
/// and c + s[d]).
inline double relaxed_value(const RowStencil& x, int i, double rhs, const BlockCoefficients& k,
                            std::ptrdiff_t c, const std::array<std::ptrdiff_t, 3>& s, double inv_h2,
                            double implicit = 0.0) {
  double num = rhs + implicit * inv_h2 * x.row[i];
  double den = k.alpha[c] + implicit * inv_h2;
  for (int d = 0; d < 3; ++d) {
    const double lo = k.beta[D(d)][c];
    const double hi = k.beta[D(d)][c + s[D(d)]];
    num += inv_h2 * (lo * x.low(d, i) + hi * x.high(d, i));
    den += inv_h2 * (lo + hi);
  }
  return den > 0.0 ? num / den : x.row[i];  // a cell cut off on all sides (solid) keeps its value
}

/// The finest level's operator is the flow's: its fine ghosts beside a
/// coarser block are interpolated from the coarse block alone
/// (CoarseGhosts::Interpolated, the ghosts every field's stencils read; the
/// discretisation the flow validations measured). The coarser multigrid
/// levels, which only have to approximate it, take the composite rule
/// (CoarseGhosts::Composite, coarse_fine.hpp): along the normal the
/// interpolated ghost extrapolates over three coarse cells with weights
/// 1.41, -0.56, 0.16, which makes the coarse cell's row far from an M-matrix,
/// and the coarse-grid correction near the interfaces poor. Measured per
/// V(2,2) cycle (test_adapt_poisson: the refined octant, periodic and
/// Dirichlet at two resolutions, Helmholtz at two, the blob, the concave
/// corner, 22 scattered blocks; uniform 4^3 blocks: 15.2x):
///   interpolated on every level:       13.0/11.6, 15.7/14.5, 16.5/15.0, 10.2, 8.9, 7.8x
///   composite on the coarser levels:   17.9/15.5, 19.2/18.1, 20.4/19.2, 13.9, 12.3, 11.3x (kept)
///   composite on every level:          19.6/15.8, 20.0/18.5, 22.1/19.6, 15.6, 14.9, 13.7x
/// (the last with the diagonals w, 0 on every level, see matched_diagonal).
/// The last changes the flow's discretisation at coarse-fine faces: the
/// manufactured Poisson solutions got 12-28 % more accurate beside them, but
/// the refined Taylor-Green test's velocity error rose by 15 % (1.60e-3
/// against 1.39e-3), and explicit viscous terms (Crank-Nicolson, the
/// transpose term of variable viscosity) must then read the same ghosts or
/// the step goes unstable; not taken (docs/performance.md).
inline bool composite_ghosts_on(int level) {
  return level > 0;
}

/// Coarse cell n of a block of b cells beside a finer block across face
/// (d, side): the weight of the cell itself in the mean of the 4 fine ghost
/// values across that face beside it (the mean of a tensor product over the
/// 2 x 2 transverse positions is the product of the means; along the normal
/// the interpolated ghost's weight on the coarse layer, or the composite
/// rule's kGhostCoarse). The matched ghost is x_c - (h_c / h_f) (fine ghost -
/// fine cell), so it moves with the cell as 1 - 2 w, and the exact
/// linearisation puts 2 w beta on the diagonal for that face.
inline double fine_ghost_self_weight(const std::array<int, 3>& n, int d, int side, int b,
                                     bool composite) {
  double w = 1.0;
  for (int e = 0; e < 3; ++e) {
    const int ne = n[D(e)];
    auto weight_on = [&](int fine) {
      const AxisWeights a = axis_weights(fine, b);
      const int slot = ne - a.first;
      return slot >= 0 && slot < a.count ? a.w[D(slot)] : 0.0;
    };
    if (e != d) {
      w *= 0.5 * (weight_on(2 * ne) + weight_on(2 * ne + 1));
    } else {
      w *= composite ? kGhostCoarse : weight_on(side == 0 ? 0 : 2 * b - 1);
    }
  }
  return w;
}

/// The relaxation's diagonal for a matched face: matched_diagonal() w beta,
/// and for a face of a fine cell towards a coarser block (composite ghosts,
/// which hold kGhostFace of the cell itself: exactly (1 - kGhostFace) beta)
/// kFineFaceDiagonal beta. On the finest level the exact 2 w; on the coarser
/// levels lighter diagonals (w, 0), which over-relax the cells at the
/// interface a little more than the rest. Residual reduction per V(2,2)
/// cycle on the concave corner and the 22 scattered blocks of
/// test_adapt_poisson (4^3 blocks), at the smoother's 1.15 and at the
/// pressure solves' 1.25 (uniform: 15.2x and 31.7x), and on the 1898-block
/// grid of 8^3 blocks with 4 in 10 refined at 1.25 (uniform 26.2x):
///   finest, coarser levels   1.15          1.25          1898 blocks
///   1.5 w;  1 w, 0           11.3, 11.1x    10.1, 9.2x    7.4x
///   2 w;    2 w, 1/3 (exact) 10.9,  9.7x    13.6, 12.0x   10.2x
///   2 w;    1 w, 1/3         11.3, 10.3x    14.4, 12.8x   11.1x
///   2 w;    1 w, 0 (kept)    12.3, 11.3x    15.6, 13.7x   12.3x
///   2.25 w; 1 w, 0           12.2, 10.7x
/// (the refined octant, Dirichlet and Helmholtz cases of test_adapt_poisson
/// lose up to 7 % against 1.5 w on the finest level: 17.9/15.5, 19.2/18.1,
/// 20.4/19.2x against 19.3/15.7, 19.7/18.3, 21.7/19.5x at 1.15). With
/// interpolated ghosts on every level 1.5 w had been best (2026-11-23):
/// 1 w let a cell with three matched faces relax too close to the
/// Gauss-Seidel limit (5.7x on the corner).
inline double matched_diagonal(bool composite) {
  return composite ? 1.0 : 2.0;
}
constexpr double kFineFaceDiagonal = 0.0;

/// (A x)_c = alpha x_c - div(beta grad x)_c, eq. (1), at cell c (cell i of
/// the row of `x`).
inline double applied(const RowStencil& x, int i, const BlockCoefficients& k, std::ptrdiff_t c,
                      const std::array<std::ptrdiff_t, 3>& s, double inv_h2) {
  const double centre = x.row[i];
  double ax = k.alpha[c] * centre;
  for (int d = 0; d < 3; ++d) {
    const double lo = k.beta[D(d)][c];
    const double hi = k.beta[D(d)][c + s[D(d)]];
    ax -= inv_h2 * (hi * (x.high(d, i) - centre) - lo * (centre - x.low(d, i)));
  }
  return ax;
}

/// The faces of a block whose ghosts move with the cells beside them, by
/// face_index: Dirichlet faces with the quadratic closure (the finest level),
/// coarse-fine faces seen from the coarse side (matched fluxes) and from the
/// fine side (the composite ghost, kGhostFace of the cell itself).
struct ClosedFaces {
  std::array<bool, 6> dirichlet{}, matched{}, coarser{};
  bool composite = false;  ///< composite_ghosts_on(level): the rule of the coarse-fine ghosts
};

/// The part of cell n's ghost values that moves with the cell itself (the
/// `implicit` of relaxed_value): 2 beta per Dirichlet face (quadratic closure
/// ghost = (8 g - 6 x0 + x1)/3), (matched_diagonal() w - 1) beta per matched
/// coarse-fine face and, with composite ghosts, (kFineFaceDiagonal - 1) beta
/// per face towards a coarser block. A matched ghost moves with the cell as
/// 1 - 2 w (fine_ghost_self_weight): exactly, its face has 2 w beta on the
/// diagonal (matched_diagonal() w beta is used, see there). Treating the ghost as fixed
/// relative to the cell (beta removed from the diagonal, as first written)
/// makes Gauss-Seidel diverge at coarse cells with finer blocks across two or
/// three faces (concave refined regions). beta_lo(d), beta_hi(d): the cell's
/// lower and upper face coefficients along d.
template <typename Low, typename High>
double closure_implicit(const std::array<int, 3>& n, int b, const ClosedFaces& faces, Low beta_lo,
                        High beta_hi) {
  const auto& [dirichlet, matched, coarser, composite] = faces;
  const double matched_weight = matched_diagonal(composite);
  double implicit = 0.0;
  for (int d = 0; d < 3; ++d) {
    const bool low = n[D(d)] == 0, high = n[D(d)] == b - 1;
    if (coarser[D(face_index(d, 0))] && low) implicit += (kFineFaceDiagonal - 1.0) * beta_lo(d);
    if (coarser[D(face_index(d, 1))] && high) implicit += (kFineFaceDiagonal - 1.0) * beta_hi(d);
    if (dirichlet[D(face_index(d, 0))] && low) implicit += 2.0 * beta_lo(d);
    if (dirichlet[D(face_index(d, 1))] && high) implicit += 2.0 * beta_hi(d);
    if (matched[D(face_index(d, 0))] && low) {
      implicit +=
          (matched_weight * fine_ghost_self_weight(n, d, 0, b, composite) - 1.0) * beta_lo(d);
    }
    if (matched[D(face_index(d, 1))] && high) {
      implicit +=
          (matched_weight * fine_ghost_self_weight(n, d, 1, b, composite) - 1.0) * beta_hi(d);
    }
  }
  return implicit;
}

/// Per face (face_index order), the cells the stencil reads beyond it in
/// place, else null (it reads the ghost layer): a same-level block of this
/// process across the face, or at a Neumann boundary face the block itself,
/// whose ghost is the mirror of the cell inside (`shift` moves the
/// neighbour's row onto the mirrored row). The fused smoother and the
/// V-cycle's residual read them in place instead of copying them into the
/// ghost layer first: the same values, so the same bits
/// (Forest::copy_face_ghosts took 15 % of the 64^3 cavity with 8^3 blocks,
/// the boundary ghosts 5 %, docs/performance.md).
struct AcrossFaces {
  std::array<const double*, 6> cells{};
  std::array<std::ptrdiff_t, 6> shift{};  ///< added to the neighbour's index
};

/// The rows beside row (j, k) along y and z (y_lo, y_hi, z_lo, z_hi): in
/// the block itself (its ghost layer at a face without a neighbour in
/// `across`), or in the same-level neighbour across that face.
[[gnu::always_inline]] inline std::array<const double*, 4> neighbour_rows(const double* row,
                                                                          const BlockLayout& L,
                                                                          const AcrossFaces& across,
                                                                          int j, int k) {
  const int b = L.cells;
  const std::ptrdiff_t sy = L.stride(1), sz = L.stride(2);
  const auto& [cells, shift] = across;
  return {j > 0 || !cells[2] ? row - sy : cells[2] + (L.index(0, b - 1, k) + shift[2]),
          j < b - 1 || !cells[3] ? row + sy : cells[3] + (L.index(0, 0, k) + shift[3]),
          k > 0 || !cells[4] ? row - sz : cells[4] + (L.index(0, j, b - 1) + shift[4]),
          k < b - 1 || !cells[5] ? row + sz : cells[5] + (L.index(0, j, 0) + shift[5])};
}

/// The AcrossFaces of block `blk` of x, whose domain faces have the
/// conditions `kinds`.
AcrossFaces same_level_neighbours(const Forest& forest, const BlockField& x, int blk,
                                  const std::array<BcKind, 6>& kinds) {
  AcrossFaces across;
  const Block& block = forest.block(blk);
  const BlockLayout L = x.layout();
  const int b = L.cells;
  for (int d = 0; d < 3; ++d)
    for (int side = 0; side < 2; ++side) {
      const Neighbour& nb = block.neighbours[D(face_neighbour_slot(d, side))];
      const auto f = D(face_index(d, side));
      if (nb.link == Link::Local && nb.jump == LevelJump::Same) {
        across.cells[f] = x.block(nb.index);
      } else if (nb.link == Link::Boundary && kinds[f] == BcKind::Neumann) {
        // ghost = the cell inside (fill_block_boundary_ghosts): the row
        // read at the neighbour's far layer (b - 1 or 0) is this block's
        // layer beside the face (0 or b - 1).
        across.cells[f] = x.block(blk);
        across.shift[f] = (side == 0 ? -(b - 1) : b - 1) * L.stride(d);
      }
    }
  return across;
}

/// The row's two ghosts along x, copied from the same-level neighbours read
/// in place (one value each, in a cache line the row reads anyway). In a
/// half-sweep only where this colour has the end cell beside the ghost: the
/// other colour's end cells are being written by the neighbour's thread.
/// Where those two ghosts are read (null: not asked for, or the ghost layer
/// holds them).
[[gnu::always_inline]] inline std::array<const double*, 2> row_x_ghosts(const BlockLayout& L,
                                                                        const AcrossFaces& across,
                                                                        int j, int k, bool low,
                                                                        bool high) {
  const int b = L.cells;
  const auto& [cells, shift] = across;
  return {low && cells[0] ? cells[0] + (L.index(b - 1, j, k) + shift[0]) : nullptr,
          high && cells[1] ? cells[1] + (L.index(0, j, k) + shift[1]) : nullptr};
}

[[gnu::always_inline]] inline void pull_row_x_ghosts(double* row, const BlockLayout& L,
                                                     const AcrossFaces& across, int j, int k,
                                                     bool low, bool high) {
  const auto [from_low, from_high] = row_x_ghosts(L, across, j, k, low, high);
  if (from_low) row[-1] = *from_low;
  if (from_high) row[L.cells] = *from_high;
}

/// The ends of the row that a half-sweep whose colour starts the row at
/// i_first relaxes: the ghost beside each end cell of that colour.
[[gnu::always_inline]] inline std::array<bool, 2> colour_ends(const BlockLayout& L, int i_first) {
  return {i_first == 0, ((L.cells - 1 - i_first) & 1) == 0};
}

/// pull_row_x_ghosts in a half-sweep whose colour starts the row at i_first.
[[gnu::always_inline]] inline void pull_row_x_ghosts_of_colour(double* row, const BlockLayout& L,
                                                               const AcrossFaces& across, int j,
                                                               int k, int i_first) {
  const auto [low, high] = colour_ends(L, i_first);
  pull_row_x_ghosts(row, L, across, j, k, low, high);
}

/// Where pull_row_x_ghosts_of_colour would read the row's two ghosts along
/// x (null: the ghost layer holds them).
[[gnu::always_inline]] inline std::array<const double*, 2> row_x_ghosts_of_colour(
    const BlockLayout& L, const AcrossFaces& across, int j, int k, int i_first) {
  const auto [low, high] = colour_ends(L, i_first);
  return row_x_ghosts(L, across, j, k, low, high);
}

/// Whether row (j, k) of a block of b cells lies beside one of its `closed`
/// faces (by face_index): every row when a face along x is closed.
[[gnu::always_inline]] inline bool row_beside_closed_face(const std::array<bool, 6>& closed, int b,
                                                          int j, int k) {
  return closed[D(face_index(0, 0))] || closed[D(face_index(0, 1))] ||
         (j == 0 && closed[D(face_index(1, 0))]) || (j == b - 1 && closed[D(face_index(1, 1))]) ||
         (k == 0 && closed[D(face_index(2, 0))]) || (k == b - 1 && closed[D(face_index(2, 1))]);
}

// GCC/Clang vector types of 4 and 8 doubles, and their lane masks. The
// helpers below pass them by value between inlined functions of this file
// only; on a build without AVX (SANGUIS_NATIVE off) GCC and Clang note that
// such a return changes the ABI (-Wpsabi), which concerns no interface here.
#if defined(__clang__)
#pragma clang diagnostic ignored "-Wpsabi"
#elif defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
typedef double Doubles4 __attribute__((vector_size(32)));
typedef std::int64_t Lanes4 __attribute__((vector_size(32)));
typedef double Doubles8 __attribute__((vector_size(64)));
typedef std::int64_t Lanes8 __attribute__((vector_size(64)));

/// The diagonal part of a row's cells in relax_constant: none (implicit 0,
/// the interior diagonal, one value for the row), or per cell (a row beside
/// a closed face: closure_implicit and its diagonal, kB values each).
struct RowDiagonal {
  double interior = 0.0;
  const double* implicit = nullptr;  ///< per cell, or null: 0 and `interior` everywhere
  const double* den = nullptr;
};

/// relax_row_whole on kLanes cells of a row from cell `at`: whole loads,
/// the scalar loop's operations in its order lane by lane, one blended store.
/// `x_ghosts`: the row's ghosts along x read in place in a same-level
/// neighbour (pull_row_x_ghosts_of_colour), else null: they go into the
/// lanes in registers instead of through the ghost layer, whose
/// single-value store the wide load right after could not forward from.
template <typename Doubles, typename Lanes, int kLanes, bool kClosure>
[[gnu::always_inline]] inline void relax_row_lanes(double* row, const double* f,
                                                   const std::array<const double*, 4>& beside,
                                                   const std::array<const double*, 2>& x_ghosts,
                                                   int at, bool last, int i_first, double beta,
                                                   double inv_h2, const RowDiagonal& diagonal,
                                                   double omega) {
  const auto load = [at](const double* p) {
    Doubles v;
    std::memcpy(&v, p + at, sizeof v);
    return v;
  };
  Lanes lane{};
  for (int i = 0; i < kLanes; ++i) lane[i] = at + i;
  const Doubles centre = load(row);
  Doubles num;
  if constexpr (kClosure) {
    num = load(f) + load(diagonal.implicit) * inv_h2 * centre;
  } else {
    const double implicit = 0.0;
    num = load(f) + implicit * inv_h2 * centre;
  }
  Doubles left = load(row - 1), right = load(row + 1);
  if (at == 0 && x_ghosts[0]) left[0] = *x_ghosts[0];
  if (last && x_ghosts[1]) right[kLanes - 1] = *x_ghosts[1];
  num += inv_h2 * (beta * left + beta * right);
  num += inv_h2 * (beta * load(beside[0]) + beta * load(beside[1]));
  num += inv_h2 * (beta * load(beside[2]) + beta * load(beside[3]));
  Doubles relaxed;
  if constexpr (kClosure) {
    relaxed = centre + omega * (num / load(diagonal.den) - centre);
  } else {
    relaxed = centre + omega * (num / diagonal.interior - centre);
  }
  const Doubles out = (lane & 1) == i_first ? relaxed : centre;
  std::memcpy(row + at, &out, sizeof out);
}

/// One row of a block's half-sweep, kB cells: the new value of every cell
/// of the row is formed from the old values, in vectors of 4 or 8 lanes
/// with fixed trip counts, and the row is stored back with the cells of the
/// half-sweep's colour (from i_first, every second one) replaced. A cell's
/// new value reads only cells of the other colour, which the half-sweep does
/// not write, so each stored value is the one the strided scalar loop of
/// relax_constant forms: the same operations in the same order, the same
/// bits. The other colour's values are formed and dropped (they may read a
/// stale ghost at a row end): twice the arithmetic in a fraction of the
/// instructions. The row goes back whole (the other colour rewritten with
/// its own values) so that the next row's wide loads of this one forward
/// from stores of their own width; single-cell stores stalled them. On
/// several threads a block's first and last layers are read in place by the
/// blocks beside it, which may be relaxed at the same time: their wide loads
/// meet this row's whole store. The lanes they use are the other colour's,
/// which the store rewrites with the values they already hold, and the
/// lanes this store changes are the ones they drop: each value used is the
/// same whichever access comes first (aligned 8-byte lanes, never torn), so
/// the bits do not depend on the threads (KernelsReadingNeighboursInPlace-
/// GiveTheSameBits runs on two). Formally a race on memory; kClosure:
/// the row lies beside a closed face, its implicit parts and diagonals per
/// cell (RowDiagonal); else implicit 0 and the interior diagonal.
template <int kB, bool kClosure>
[[gnu::always_inline]] inline void relax_row_whole(double* row, const double* f,
                                                   const std::array<const double*, 4>& beside,
                                                   const std::array<const double*, 2>& x_ghosts,
                                                   int i_first, double beta, double inv_h2,
                                                   const RowDiagonal& diagonal, double omega) {
  constexpr int kLanes = kB % 8 == 0 ? 8 : 4;
  static_assert(kB % kLanes == 0);
  using Doubles = std::conditional_t<kLanes == 8, Doubles8, Doubles4>;
  using Lanes = std::conditional_t<kLanes == 8, Lanes8, Lanes4>;
  for (int at = 0; at < kB; at += kLanes)
    relax_row_lanes<Doubles, Lanes, kLanes, kClosure>(
        row, f, beside, x_ghosts, at, at + kLanes == kB, i_first, beta, inv_h2, diagonal, omega);
}

/// The 8 cells of colour kFirst (the even cells for 0, the odd ones for 1)
/// among the 16 cells of `low` and `high`, in order.
template <int kFirst>
[[gnu::always_inline]] inline Doubles8 colour_cells(Doubles8 low, Doubles8 high) {
  if constexpr (kFirst == 0) {
    return __builtin_shufflevector(low, high, 0, 2, 4, 6, 8, 10, 12, 14);
  } else {
    return __builtin_shufflevector(low, high, 1, 3, 5, 7, 9, 11, 13, 15);
  }
}

/// `cells` (8 values of a row) with its cells of colour kFirst replaced by
/// `relaxed` from lane `from` on (0 for the first 8 cells of 16, 4 for the
/// last 8).
template <int kFirst, int kFrom>
[[gnu::always_inline]] inline Doubles8 with_colour_cells(Doubles8 cells, Doubles8 relaxed) {
  constexpr int r = 8 + kFrom;  // lane kFrom of `relaxed` in the shuffle's numbering
  if constexpr (kFirst == 0) {
    return __builtin_shufflevector(cells, relaxed, r, 1, r + 1, 3, r + 2, 5, r + 3, 7);
  } else {
    return __builtin_shufflevector(cells, relaxed, 0, r, 2, r + 1, 4, r + 2, 6, r + 3);
  }
}

/// relax_row_whole for rows of a multiple of 16 cells, half-sweep colour
/// kFirst (the i_first of the others): each 16 cells as two vectors of 8,
/// from which the 8 cells of the colour are gathered into one vector (centre,
/// x neighbours, right-hand side, the four neighbouring rows, and with
/// kClosure the implicit parts and diagonals), relaxed there with one
/// division, and put back between the other colour's unchanged values for
/// the same whole store. The same operations in the same order per cell as
/// relax_row_lanes (a lane permutation does not change a value), so the same
/// bits, with half the arithmetic and divisions (docs/performance.md, "One
/// colour per vector in the smoother"). Fixed shuffles: with AVX-512 each is
/// one instruction; relax_row uses this kernel only there.
template <int kB, bool kClosure, int kFirst>
[[gnu::always_inline]] inline void relax_row_colour(double* row, const double* f,
                                                    const std::array<const double*, 4>& beside,
                                                    const std::array<const double*, 2>& x_ghosts,
                                                    double beta, double inv_h2,
                                                    const RowDiagonal& diagonal, double omega) {
  static_assert(kB % 16 == 0);
  const auto gather = [](const double* p, int at) {
    Doubles8 low, high;
    std::memcpy(&low, p + at, sizeof low);
    std::memcpy(&high, p + at + 8, sizeof high);
    return colour_cells<kFirst>(low, high);
  };
  for (int at = 0; at < kB; at += 16) {
    Doubles8 low, high;  // the row's 16 cells, both colours
    std::memcpy(&low, row + at, sizeof low);
    std::memcpy(&high, row + at + 8, sizeof high);
    const Doubles8 centre = colour_cells<kFirst>(low, high);
    Doubles8 num;
    if constexpr (kClosure) {
      num = gather(f, at) + gather(diagonal.implicit, at) * inv_h2 * centre;
    } else {
      const double implicit = 0.0;
      num = gather(f, at) + implicit * inv_h2 * centre;
    }
    Doubles8 left = gather(row - 1, at), right = gather(row + 1, at);
    // Row ends read in place in a neighbour: cell 0's left (colour 0) and
    // cell kB - 1's right (colour 1).
    if (kFirst == 0 && at == 0 && x_ghosts[0]) left[0] = *x_ghosts[0];
    if (kFirst == 1 && at + 16 == kB && x_ghosts[1]) right[7] = *x_ghosts[1];
    num += inv_h2 * (beta * left + beta * right);
    num += inv_h2 * (beta * gather(beside[0], at) + beta * gather(beside[1], at));
    num += inv_h2 * (beta * gather(beside[2], at) + beta * gather(beside[3], at));
    Doubles8 relaxed;
    if constexpr (kClosure) {
      relaxed = centre + omega * (num / gather(diagonal.den, at) - centre);
    } else {
      relaxed = centre + omega * (num / diagonal.interior - centre);
    }
    const Doubles8 out_low = with_colour_cells<kFirst, 0>(low, relaxed);
    const Doubles8 out_high = with_colour_cells<kFirst, 4>(high, relaxed);
    std::memcpy(row + at, &out_low, sizeof out_low);
    std::memcpy(row + at + 8, &out_high, sizeof out_high);
  }
}

/// One row of a half-sweep: relax_row_colour where the row is a multiple of
/// 16 cells and the build has AVX-512 (its shuffles are single instructions
/// there, and its gain was measured there only; AVX2 would split each into
/// several), else relax_row_whole. Either gives the same bits.
template <int kB, bool kClosure>
[[gnu::always_inline]] inline void relax_row(double* row, const double* f,
                                             const std::array<const double*, 4>& beside,
                                             const std::array<const double*, 2>& x_ghosts,
                                             int i_first, double beta, double inv_h2,
                                             const RowDiagonal& diagonal, double omega) {
#if defined(__AVX512F__)
  if constexpr (kB % 16 == 0) {
    if (i_first == 0) {
      relax_row_colour<kB, kClosure, 0>(row, f, beside, x_ghosts, beta, inv_h2, diagonal, omega);
    } else {
      relax_row_colour<kB, kClosure, 1>(row, f, beside, x_ghosts, beta, inv_h2, diagonal, omega);
    }
    return;
  }
#endif
  relax_row_whole<kB, kClosure>(row, f, beside, x_ghosts, i_first, beta, inv_h2, diagonal, omega);
}

/// The implicit parts and diagonals of the kB cells of row (j, k) beside a
/// closed face (all kB: relax_row_whole forms the other colour's values too
/// and drops them; relax_row_colour reads only the colour's).
/// Out of line: the open rows' loop stays small.
template <int kB>
struct ClosureRow {
  alignas(64) std::array<double, kB> implicit, den;
  [[nodiscard]] RowDiagonal diagonal() const { return {0.0, implicit.data(), den.data()}; }
};

/// With matched faces only the cells of the colour starting at i_first are
/// formed (the others' lanes are dropped; they get the open diagonal).
template <int kB, typename DiagonalOf>
[[gnu::noinline]] void form_closure_row(int j, int k, double beta, const ClosedFaces& faces,
                                        bool matched, int i_first, DiagonalOf diagonal_of,
                                        ClosureRow<kB>& out) {
  const auto constant = [beta](int) { return beta; };
  const auto set = [&](int i, double value) {
    out.implicit[D(i)] = value;
    out.den[D(i)] = diagonal_of(value);
  };
  if (matched) {
    const double open = diagonal_of(0.0);
    for (int i = 0; i < kB; ++i) {
      if ((i & 1) == i_first) {
        set(i, closure_implicit({i, j, k}, kB, faces, constant, constant));
      } else {
        out.implicit[D(i)] = 0.0;
        out.den[D(i)] = open;
      }
    }
    return;
  }
  // Without matched faces a cell's implicit part depends on i only at the
  // row's ends (the faces along x): the cells between share one value.
  const double between = closure_implicit({1, j, k}, kB, faces, constant, constant);
  const double between_den = diagonal_of(between);
  for (int i = 1; i < kB - 1; ++i) {
    out.implicit[D(i)] = between;
    out.den[D(i)] = between_den;
  }
  set(0, closure_implicit({0, j, k}, kB, faces, constant, constant));
  set(kB - 1, closure_implicit({kB - 1, j, k}, kB, faces, constant, constant));
}

/// The block a half-sweep relaxes next, whose rows relax_constant_rows asks
/// the memory for while it works on the current block (null: none).
/// Out of cache a block's x and right-hand side arrive row by row as the
/// kernel first reads them, and the hardware's stream prefetchers start
/// afresh at every 4 KB page of the block's rows (docs/performance.md,
/// "Prefetching the next block in the smoother").
struct NextBlock {
  const double* x = nullptr;
  const double* rhs = nullptr;
};

/// Block `blk` of x and rhs as the next block, or none where blk < 0.
inline NextBlock next_block(const BlockField& x, const BlockField& rhs, int blk) {
  return blk >= 0 ? NextBlock{x.block(blk), rhs.block(blk)} : NextBlock{};
}

/// Prefetch row q (in (j, k) order) of `next`: the row's cells and its
/// ghosts along x, x for writing (it is stored back), the right-hand side
/// for reading, with low temporal locality (on x86 prefetcht2 for the
/// right-hand side, prefetchw for x): the next block needs it within a block's
/// work.
[[gnu::always_inline]] inline void prefetch_row(const NextBlock& next, const BlockLayout& L,
                                                int q) {
  if (next.x == nullptr) return;
  const int b = L.cells;
  const std::ptrdiff_t start = L.index(-L.ghost, q % b, q / b);
  const std::ptrdiff_t length = b + 2 * L.ghost;
  constexpr std::ptrdiff_t kLine = 64 / sizeof(double);
  for (std::ptrdiff_t at = 0; at < length + kLine - 1; at += kLine) {
    const std::ptrdiff_t c = start + std::min(at, length - 1);
    __builtin_prefetch(next.x + c, 1, 1);
    __builtin_prefetch(next.rhs + c, 0, 1);
  }
}

/// Bytes of x and the right-hand side, what a half-sweep streams.
double field_bytes(const BlockField& x, const BlockField& rhs) {
  return sizeof(double) *
         (static_cast<double>(x.raw().size()) + static_cast<double>(rhs.raw().size()));
}

/// The last-level cache sysconf reports (32 MiB where it does not tell).
double reported_cache_bytes() {
  static const double bytes = [] {
    long reported = 0;
#ifdef _SC_LEVEL3_CACHE_SIZE  // glibc's; elsewhere the default below
    reported = sysconf(_SC_LEVEL3_CACHE_SIZE);
#endif
    return reported > 0 ? static_cast<double>(reported) : kUsualCoreCache;
  }();
  return bytes;
}

/// What OutOfCache makes of fields of `bytes`: prefetch when they hold more
/// than half the reported last-level cache, so the blocks come from memory;
/// not when they hold at most half of what a core usually reaches
/// (kUsualCoreCache), where the prefetches only add instructions (forced on,
/// 11-15 % of the smoother's time on the 64³ cavity; docs/performance.md,
/// "Prefetching the next block in the smoother"); between the two, where a
/// VM may report more cache than a core has, time both (PrefetchTrial).
enum class PrefetchRule { No, Yes, Timed };
PrefetchRule prefetch_rule(NextBlockPrefetch mode, double bytes) {
  if (mode != NextBlockPrefetch::OutOfCache) {
    return mode == NextBlockPrefetch::Always ? PrefetchRule::Yes : PrefetchRule::No;
  }
  const double reported = reported_cache_bytes();
  if (bytes > 0.5 * reported) return PrefetchRule::Yes;
  if (bytes <= 0.5 * std::min(reported, kUsualCoreCache)) return PrefetchRule::No;
  return PrefetchRule::Timed;
}

/// relax_constant with kB cells per edge, every row through relax_row
/// (docs/performance.md, "Whole rows in the smoother" and "One colour per
/// vector in the smoother"). `closed`: the faces
/// of `faces` that close on the cells beside them; `diagonal_of(implicit)`:
/// the diagonal with that implicit part.
template <int kB, bool kAnyClosed, typename DiagonalOf>
void relax_constant_rows(double* x, const double* rhs, const BlockLayout& L, int first, double beta,
                         double inv_h2, double omega, const ClosedFaces& faces,
                         const std::array<bool, 6>& closed, DiagonalOf diagonal_of,
                         const AcrossFaces& across, const NextBlock& next) {
  RowDiagonal open;
  open.interior = diagonal_of(0.0);
  const bool matched =
      std::any_of(faces.matched.begin(), faces.matched.end(), [](bool m) { return m; });
  // Without matched faces a row's closure depends on (j, k) only through
  // whether each lies on the block's first, last or a middle layer: nine
  // kinds of row, each formed once, when first met. With matched faces
  // (their weights vary along the face) every row is formed.
  ClosureRow<kB> own;
  std::array<ClosureRow<kB>, 9> by_kind;
  std::array<bool, 9> formed{};
  const auto layer = [](int n) { return n == 0 ? 0 : (n == kB - 1 ? 2 : 1); };
  // Rows with j + k even first, then the others: a row reads the four rows
  // beside it along y and z, all of the other kind, so no row reads one that
  // was just stored. In row order each row's loads waited on the previous
  // row's store (whole, its unchanged lanes too), a chain through the
  // division's latency from row to row. Any order gives the same bits: in a
  // half-sweep no cell reads one of its own colour.
  int fetched = 0;  // rows of the next block asked for: one per row relaxed
  for (int kind = 0; kind < 2; ++kind)
    for (int k = 0; k < kB; ++k)
      for (int j = (k + kind) & 1; j < kB; j += 2) {
        prefetch_row(next, L, fetched++);
        double* row = x + L.index(0, j, k);
        const double* f = rhs + L.index(0, j, k);
        const int i_first = (k + j + first) & 1;
        const auto beside = neighbour_rows(row, L, across, j, k);
        const auto x_ghosts = row_x_ghosts_of_colour(L, across, j, k, i_first);
        if (!kAnyClosed || !row_beside_closed_face(closed, kB, j, k)) {
          relax_row<kB, false>(row, f, beside, x_ghosts, i_first, beta, inv_h2, open, omega);
          continue;
        }
        const ClosureRow<kB>* closure = &own;
        if (matched) {
          form_closure_row<kB>(j, k, beta, faces, matched, i_first, diagonal_of, own);
        } else {
          const auto kind_of_row = D(3 * layer(k) + layer(j));
          closure = &by_kind[kind_of_row];
          if (!formed[kind_of_row]) {
            form_closure_row<kB>(j, k, beta, faces, matched, i_first, diagonal_of,
                                 by_kind[kind_of_row]);
            formed[kind_of_row] = true;
          }
        }
        relax_row<kB, true>(row, f, beside, x_ghosts, i_first, beta, inv_h2, closure->diagonal(),
                            omega);
      }
}

/// Red-black Gauss-Seidel on the cells of one colour (i + j + k + first even)
/// of a block whose alpha and beta are constants: relaxed_value, the same
/// operations in the same order, with the implicit part of smooth() (the
/// quadratic Dirichlet closure and the coarse-fine faces of `faces`), without the coefficient loads
/// (the smoother is memory-bound).
inline void relax_constant(double* x, const double* rhs, const BlockLayout& L, int first,
                           double alpha, double beta, double inv_h2, double omega,
                           const ClosedFaces& faces, const AcrossFaces& across,
                           const NextBlock& next = {}) {
  const int b = L.cells;
  auto diagonal = [&](double implicit) {
    double den = alpha + implicit * inv_h2;
    for (int d = 0; d < 3; ++d) den += inv_h2 * (beta + beta);
    return den;
  };
  std::array<bool, 6> closed{};
  for (std::size_t f = 0; f < 6; ++f)
    closed[f] = faces.dirichlet[f] || faces.matched[f] || faces.coarser[f];
  const bool any_closed = std::any_of(closed.begin(), closed.end(), [](bool c) { return c; });
  // By block size, and with or without closed faces (most blocks: none, and
  // their loop tests no row for them).
  const auto rows = [&]<int kB>() {
    if (any_closed) {
      relax_constant_rows<kB, true>(x, rhs, L, first, beta, inv_h2, omega, faces, closed, diagonal,
                                    across, next);
    } else {
      relax_constant_rows<kB, false>(x, rhs, L, first, beta, inv_h2, omega, faces, closed, diagonal,
                                     across, next);
    }
  };
  switch (b) {
    case 4:
      return rows.template operator()<4>();
    case 8:
      return rows.template operator()<8>();
    case 16:
      return rows.template operator()<16>();
    case 32:
      return rows.template operator()<32>();
    default:
      break;
  }
  // Other block sizes (the in-block level of 2 cells): cell by cell.
  const double interior = diagonal(0.0);
  for (int k = 0; k < b; ++k)
    for (int j = 0; j < b; ++j) {
      double* row = x + L.index(0, j, k);
      const double* f = rhs + L.index(0, j, k);
      const bool closure_row = row_beside_closed_face(closed, b, j, k);
      // The neighbouring rows (a neighbour's cells of the other colour: no
      // block writes them in this half-sweep).
      const auto [y_lo, y_hi, z_lo, z_hi] = neighbour_rows(row, L, across, j, k);
      const int i_first = (k + j + first) & 1;
      pull_row_x_ghosts_of_colour(row, L, across, j, k, i_first);
      for (int i = i_first; i < b; i += 2) {
        double implicit = 0.0;
        double den = interior;
        if (closure_row) {
          const auto constant = [beta](int) { return beta; };
          implicit = closure_implicit({i, j, k}, b, faces, constant, constant);
          den = diagonal(implicit);
        }
        double num = f[i] + implicit * inv_h2 * row[i];
        num += inv_h2 * (beta * row[i - 1] + beta * row[i + 1]);
        num += inv_h2 * (beta * y_lo[i] + beta * y_hi[i]);
        num += inv_h2 * (beta * z_lo[i] + beta * z_hi[i]);
        row[i] += omega * (num / den - row[i]);
      }
    }
}

/// r = rhs - A x on a block with constant alpha and beta (every cell active):
/// applied() without the coefficient loads, same operations, same order.
/// Returns the sum of the squared residuals, in the order of block_squares(),
/// when kSquares (else 0: the V-cycle's residual needs no norm, and its loop
/// then vectorises without the ordered sum).
template <bool kSquares>
inline double residual_constant(double* x, const double* rhs, double* r, const BlockLayout& L,
                                double alpha, double beta, double inv_h2, const AcrossFaces& across,
                                const NextBlock& next) {
  const int b = L.cells;
  double squares = 0.0;
  for (int k = 0; k < b; ++k)
    for (int j = 0; j < b; ++j) {
      prefetch_row(next, L, k * b + j);
      const std::ptrdiff_t row = L.index(0, j, k);
      double* xr = x + row;
      // The neighbouring rows and the row's ghosts along x as in
      // relax_constant (no cell is written meanwhile).
      const auto [y_lo, y_hi, z_lo, z_hi] = neighbour_rows(xr, L, across, j, k);
      pull_row_x_ghosts(xr, L, across, j, k, true, true);
      for (int i = 0; i < b; ++i) {
        double ax = alpha * xr[i];
        ax -= inv_h2 * (beta * (xr[i + 1] - xr[i]) - beta * (xr[i] - xr[i - 1]));
        ax -= inv_h2 * (beta * (y_hi[i] - xr[i]) - beta * (xr[i] - y_lo[i]));
        ax -= inv_h2 * (beta * (z_hi[i] - xr[i]) - beta * (xr[i] - z_lo[i]));
        const double value = rhs[row + i] - ax;  // the general residual's factor active is 1 here
        r[row + i] = value;
        if constexpr (kSquares) squares += value * value;
      }
    }
  return squares;
}

/// The sum of f^2 over one block's cells, in the order (k, j, i): the one
/// order of the fused sums in compute_residual(), so rms() of a residual
/// equals the norm that compute_residual() returns, to the last bit.
double block_squares(const BlockField& f, int blk) {
  const int b = f.cells();
  double squares = 0.0;
  for (int k = 0; k < b; ++k)
    for (int j = 0; j < b; ++j)
      for (int i = 0; i < b; ++i) squares += f(blk, i, j, k) * f(blk, i, j, k);
  return squares;
}

// Restriction to the next coarser level: each coarse cell (i, j, k) of every block
// folds its 8 children (2i + di, 2j + dj, 2k + dk), in the order dk, dj, di, with
// `combine` from 0, and stores `finish` of the result. The one loop behind the
// coefficient averages, the activity flags and the residual transfer.
template <typename Combine, typename Finish>
void restrict_cells(const double* fine, const BlockLayout& F, double* coarse, const BlockLayout& C,
                    int coarse_cells, Combine combine, Finish finish) {
  for (int k = 0; k < coarse_cells; ++k)
    for (int j = 0; j < coarse_cells; ++j)
      for (int i = 0; i < coarse_cells; ++i) {
        double acc = 0.0;
        for (int dk = 0; dk < 2; ++dk)
          for (int dj = 0; dj < 2; ++dj)
            for (int di = 0; di < 2; ++di)
              acc = combine(acc, fine[F.index(2 * i + di, 2 * j + dj, 2 * k + dk)]);
        coarse[C.index(i, j, k)] = finish(acc);
      }
}

template <typename Combine, typename Finish>
void restrict_children(const Forest& forest, const BlockField& fine, BlockField& coarse,
                       int coarse_cells, Combine combine, Finish finish) {
  forest.for_each_block([&](int blk) {
    restrict_cells(fine.block(blk), fine.layout(), coarse.block(blk), coarse.layout(), coarse_cells,
                   combine, finish);
  });
}

constexpr auto kAdd = [](double acc, double v) { return acc + v; };
constexpr auto kMean8 = [](double sum) { return sum / 8.0; };

/// One block of `size` values per thread, for a residual that is not kept:
/// written and read back while in cache instead of streamed to memory.
double* thread_scratch(std::ptrdiff_t size) {
  thread_local std::vector<double> scratch;
  if (scratch.size() < static_cast<std::size_t>(size))
    scratch.resize(static_cast<std::size_t>(size));
  return scratch.data();
}

}  // namespace

double MultigridReport::mean_reduction() const {
  if (residuals.size() < 2 || residuals.back() <= 0.0) return 0.0;
  const double cycles_done = static_cast<double>(residuals.size() - 1);
  return std::pow(residuals.front() / residuals.back(), 1.0 / cycles_done);
}

Multigrid::Multigrid(const Forest& forest, const std::array<BcKind, 6>& kinds, bool merge_blocks,
                     bool level_by_level, std::int64_t gathered_blocks_limit)
    : forest_(forest),
      kinds_(kinds),
      merge_blocks_(merge_blocks),
      level_by_level_(level_by_level),
      gathered_blocks_limit_(gathered_blocks_limit) {
  homogeneous_.kind = kinds;
  for (int d = 0; d < 3; ++d) {
    const bool periodic = forest.spec().periodic[D(d)];
    for (int side = 0; side < 2; ++side) {
      if ((kinds_[D(face_index(d, side))] == BcKind::Periodic) != periodic) {
        throw std::invalid_argument(
            "multigrid: boundary kinds disagree with the forest's periodicity");
      }
    }
  }
  rebuild();
}

void Multigrid::rebuild() {
  composite_ = !forest_.uniform();
  const auto merged_spec = merge_blocks_ ? merged_forest_spec(forest_) : std::nullopt;
  if (merged_spec) {
    // The levels of the caller's blocks are not needed: free them.
    levels_.clear();
    shifted_rhs_ = BlockField();
    coarsened_.reset();
    // A regrid that leaves this forest uniform at the same level (the bottom of the
    // level-by-level chain, most of the time) keeps the merged forest and its solver, and
    // so their storage: only the copies are rebuilt, for this forest's new partition.
    if (!merged_ || !(merged_->forest->spec() == *merged_spec)) {
      merged_ = std::make_unique<Merged>();
      merged_->forest = std::make_unique<Forest>(*merged_spec);
      merged_->solver = std::make_unique<Multigrid>(*merged_->forest, kinds_, false,
                                                    level_by_level_, gathered_blocks_limit_);
    }
    merged_->copies = std::make_unique<MergedBlocks>(forest_, *merged_->forest);
    merged_->solver->set_coefficients(nullptr, nullptr);
    const int blocks = merged_->forest->local_blocks(), cells = merged_spec->block_cells;
    merged_->x.reshape(blocks, cells);
    merged_->rhs.reshape(blocks, cells);
    return;  // the solver's coefficients are the reset ones (alpha 0, beta 1)
  }
  merged_.reset();
  const int n = forest_.local_blocks();
  // Level by level: only the finest level here, the rest on the coarsened forest. A
  // uniform forest too when its blocks would make the gathered bottom solve too large.
  const bool too_many_blocks = forest_.uniform() && forest_.max_level() >= 1 &&
                               forest_.global_blocks() > gathered_blocks_limit_;
  const bool by_level = level_by_level_ && (composite_ || too_many_blocks);
  if (!by_level) coarsened_.reset();
  if (by_level) levels_.resize(1);
  std::size_t m = 0;
  for (int b = forest_.block_cells(); b >= 1 && !(by_level && m == 1); b /= 2, ++m) {
    if (levels_.size() == m) levels_.emplace_back();
    // The finest level shares the layout of the caller's fields; coarser
    // ones keep the one ghost layer their smoother and prolongation read.
    const int ghost = b == forest_.block_cells() ? kGhost : 1;
    Level& level = levels_[m];
    level.cells = b;
    level.x.reshape(n, b, ghost);
    level.rhs.reshape(n, b, ghost);
    level.alpha.reshape(n, b, ghost);
    reshape(level.beta, n, b, ghost);
    level.active.reshape(n, b, ghost);
    // Across ranks the fine fluxes of match_fluxes() travel in these; one
    // process reads them in place (match_fluxes_local) and needs none.
    for (BlockField& flux : level.face_flux) {
      if (composite_ && b >= 2 && forest_.ranks() > 1) {
        flux.reshape(n, b, ghost);
      } else {
        flux = BlockField();
      }
    }
  }
  shifted_rhs_.reshape(n, forest_.block_cells());
  if (by_level) {
    // After a regrid the last coarsened forest takes the new one's coarsened leaves and its
    // solver is rebuilt, so that both keep their storage (fresh pages cost a regrid more than the
    // copies: docs/performance.md, "Regrids without fresh pages").
    if (!coarsened_) {
      coarsened_ = std::make_unique<Coarsened>();
      coarsened_->forest = coarsen_finest_level(forest_);
      coarsened_->solver = std::make_unique<Multigrid>(*coarsened_->forest, kinds_, merge_blocks_,
                                                       true, gathered_blocks_limit_);
    } else {
      coarsened_->forest->assign_coarsened_finest_level(forest_);
      coarsened_->solver->rebuild();
    }
    Coarsened& c = *coarsened_;
    c.transfers = std::make_unique<CoarsenedBlocks>(forest_, *c.forest);
    const int blocks = c.forest->local_blocks(), b = forest_.block_cells();
    c.x.reshape(blocks, b);
    c.rhs.reshape(blocks, b);
    c.alpha.reshape(blocks, b);
    c.active.reshape(blocks, b, 1);
    reshape(c.beta, blocks, b, kGhost);  // the layout of the finest level, which takes it
    c.residual.reshape(n, b);
  }
  set_coefficients(nullptr, nullptr);
}

void Multigrid::set_coefficients(const BlockField* alpha, const FaceField* beta) {
  if (merged_) {
    Merged& m = *merged_;
    const int blocks = m.forest->local_blocks(), cells = m.forest->block_cells();
    // Shaped once (a new Merged per rebuild); the copies then write every
    // cell and face the solver reads, each time the coefficients change.
    const auto shaped = [&](const BlockField& f) {
      return f.blocks() == blocks && f.cells() == cells;
    };
    if (alpha) {
      if (!shaped(m.alpha)) m.alpha.reshape(blocks, cells);
      m.copies->to_merged(*alpha, m.alpha);
    }
    if (beta) {
      if (!shaped(m.beta[0])) reshape(m.beta, blocks, cells);
      for (int d = 0; d < 3; ++d) m.copies->faces_to_merged((*beta)[D(d)], d, m.beta[D(d)]);
    }
    m.solver->set_coefficients(alpha ? &m.alpha : nullptr, beta ? &m.beta : nullptr);
    return;
  }
  has_alpha_ = alpha != nullptr;
  Level& fine = levels_.front();
  if (alpha) {
    fine.alpha = *alpha;
  } else {
    fine.alpha.fill(0.0);
  }
  for (int d = 0; d < 3; ++d) {
    if (beta) {
      fine.beta[D(d)] = (*beta)[D(d)];
    } else {
      fine.beta[D(d)].fill(1.0);
    }
  }
  // Coarser levels: alpha averaged over the 8 children, beta over the 4 fine
  // faces that make up a coarse face.
  for (std::size_t m = 1; m < levels_.size(); ++m) {
    const Level& f = levels_[m - 1];
    Level& c = levels_[m];
    const int bc = c.cells;
    restrict_children(forest_, f.alpha, c.alpha, bc, kAdd, kMean8);
    forest_.for_each_block([&](int blk) {
      for (int d = 0; d < 3; ++d) {
        std::array<int, 3> hi{bc, bc, bc};
        hi[D(d)] = bc + 1;  // faces 0..bc along d
        for (int k = 0; k < hi[2]; ++k)
          for (int j = 0; j < hi[1]; ++j)
            for (int i = 0; i < hi[0]; ++i) {
              double sum = 0.0;
              for (int t2 = 0; t2 < 2; ++t2)
                for (int t1 = 0; t1 < 2; ++t1) {
                  std::array<int, 3> fc{2 * i, 2 * j, 2 * k};
                  fc[D((d + 1) % 3)] += t1;
                  fc[D((d + 2) % 3)] += t2;
                  sum += f.beta[D(d)](blk, fc[0], fc[1], fc[2]);
                }
              c.beta[D(d)](blk, i, j, k) = sum / 4.0;
            }
      }
    });
  }
  if (coarsened_) {
    // The coarsened forest's coefficients as the in-block levels take theirs: alpha the
    // mean of the 8 children, beta of the 4 fine faces.
    Coarsened& c = *coarsened_;
    c.transfers->restrict_cells(fine.alpha, c.alpha);
    for (int d = 0; d < 3; ++d) c.transfers->restrict_faces(fine.beta[D(d)], d, c.beta[D(d)]);
    c.solver->set_coefficients(has_alpha_ ? &c.alpha : nullptr, &c.beta);
    cell_activity(*c.forest, c.alpha, c.beta, c.active);
    // The ghost ring, as compute_activity() fills it: the prolongation reads it.
    c.forest->exchange(c.active, 1);
    fill_boundary_ghosts(*c.forest, c.active, uniform_kinds(*c.forest, BcKind::Neumann), 1);
    double all = 1.0;
    for (int blk = 0; blk < c.forest->local_blocks(); ++blk)
      for (int k = -1; k <= fine.cells; ++k)
        for (int j = -1; j <= fine.cells; ++j)
          for (int i = -1; i <= fine.cells; ++i) all = std::min(all, c.active(blk, i, j, k));
    c.all_active = -forest_.max(-all) == 1.0;
  }
  bool dirichlet = false;
  for (const BcKind k : kinds_) dirichlet = dirichlet || k == BcKind::Dirichlet;
  singular_ = !has_alpha_ && !dirichlet;
  compute_activity();
  detect_constant_coefficients();
  build_coarse_operator();
}

void Multigrid::detect_constant_coefficients() {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const int n = forest_.local_blocks();
  for (Level& level : levels_) {
    const int b = level.cells;
    level.block_constant.assign(static_cast<std::size_t>(n), 0);
    level.block_all_active.assign(static_cast<std::size_t>(n), 0);
    level.block_ring_active.assign(static_cast<std::size_t>(n), 0);
    level.block_alpha.assign(static_cast<std::size_t>(n), 0.0);
    level.block_beta.assign(static_cast<std::size_t>(n), 0.0);
    forest_.for_each_block([&](int blk) {
      double a_lo = kInf, a_hi = -kInf, b_lo = kInf, b_hi = -kInf, active_lo = kInf;
      bool not_a_number = false;  // min/max would skip a NaN
      auto take = [&](double v, double& lo, double& hi) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
        not_a_number = not_a_number || std::isnan(v);
      };
      for (int k = 0; k < b; ++k)
        for (int j = 0; j < b; ++j)
          for (int i = 0; i < b; ++i) {
            take(level.alpha(blk, i, j, k), a_lo, a_hi);
            active_lo = std::min(active_lo, level.active(blk, i, j, k));
          }
      for (int d = 0; d < 3; ++d) {
        std::array<int, 3> hi{b, b, b};
        hi[D(d)] = b + 1;  // faces 0..b along d: what the kernels read
        for (int k = 0; k < hi[2]; ++k)
          for (int j = 0; j < hi[1]; ++j)
            for (int i = 0; i < hi[0]; ++i) take(level.beta[D(d)](blk, i, j, k), b_lo, b_hi);
      }
      // The constant kernels drop relaxed_value's den > 0 test and the
      // residual's factor `active`: valid with alpha >= 0, beta > 0 and every
      // cell active. One signed zero for alpha (+0 and -0 compare equal).
      const auto at = static_cast<std::size_t>(blk);
      level.block_constant[at] = !not_a_number && a_lo == a_hi && b_lo == b_hi && a_lo >= 0.0 &&
                                 b_lo > 0.0 && active_lo == 1.0 &&
                                 std::signbit(a_lo) == std::signbit(a_hi);
      level.block_all_active[at] = active_lo == 1.0;
      // The ghost ring too (compute_activity filled it: exchange and mirror).
      bool ring = active_lo == 1.0;
      for (int k = -1; k <= b && ring; ++k)
        for (int j = -1; j <= b && ring; ++j)
          for (int i = -1; i <= b && ring; ++i) ring = level.active(blk, i, j, k) == 1.0;
      level.block_ring_active[at] = ring;
      level.block_alpha[at] = a_lo;
      level.block_beta[at] = b_lo;
    });
    double all = 1.0;
    for (const unsigned char c : level.block_constant) all = c ? all : 0.0;
    level.constant_coefficients = -forest_.max(-all) == 1.0;
  }
}

int Multigrid::constant_blocks(int level) const {
  if (merged_) return merged_->solver->constant_blocks(level);
  if (coarsened_ && level > 0) return coarsened_->solver->constant_blocks(level - 1);
  int count = 0;
  for (const unsigned char c : levels_[D(level)].block_constant) count += c ? 1 : 0;
  return count;
}

void Multigrid::cell_activity(const Forest& forest, const BlockField& alpha, const FaceField& beta,
                              BlockField& active) {
  const int b = alpha.cells();
  const BlockLayout L = alpha.layout();
  const BlockLayout A = active.layout();
  forest.for_each_block([&](int blk) {
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          const std::ptrdiff_t c = L.index(i, j, k);
          double open = alpha.block(blk)[c];
          for (int d = 0; d < 3; ++d) {
            const BlockLayout F = beta[D(d)].layout();
            const std::ptrdiff_t f = F.index(i, j, k);
            open += beta[D(d)].block(blk)[f] + beta[D(d)].block(blk)[f + F.stride(d)];
          }
          active.block(blk)[A.index(i, j, k)] = open > 0.0 ? 1.0 : 0.0;
        }
  });
}

void Multigrid::compute_activity() {
  cell_activity(forest_, levels_.front().alpha, levels_.front().beta, levels_.front().active);
  for (std::size_t m = 1; m < levels_.size(); ++m) {
    const Level& f = levels_[m - 1];
    Level& c = levels_[m];
    const int bc = c.cells;
    restrict_children(
        forest_, f.active, c.active, bc, [](double any, double v) { return std::max(any, v); },
        [](double any) { return any; });
  }
  for (Level& level : levels_) {
    forest_.exchange(level.active, 1);
    fill_boundary_ghosts(forest_, level.active, uniform_kinds(forest_, BcKind::Neumann), 1);
  }
}

void Multigrid::build_coarse_operator() {
  if (coarsened_) return;  // the coarsened forest's solver has the bottom level
  if (composite_) {
    build_composite_operator();
    return;
  }
  const int level = forest_.min_level();  // uniform: every block at this level (not always
                                          // spec().level once adapted)
  coarse_n_ = forest_.blocks_per_direction(level);
  coarse_h_ = forest_.spec().tree_length / static_cast<double>(std::int64_t{1} << level);
  const auto [nx, ny, nz] = coarse_n_;
  coarse_alpha_.assign(static_cast<std::size_t>(nx * ny * nz), 0.0);
  coarse_active_.assign(static_cast<std::size_t>(nx * ny * nz), 0.0);
  for (int d = 0; d < 3; ++d) {
    auto n = coarse_n_;
    n[D(d)] += 1;
    coarse_beta_[D(d)].assign(static_cast<std::size_t>(n[0] * n[1] * n[2]), 0.0);
  }
  const Level& c = levels_.back();
  for (int blk = 0; blk < forest_.local_blocks(); ++blk) {
    const Block& block = forest_.block(blk);
    const auto& p = block.coord;
    coarse_alpha_[static_cast<std::size_t>((p[2] * ny + p[1]) * nx + p[0])] = c.alpha(blk, 0, 0, 0);
    coarse_active_[static_cast<std::size_t>((p[2] * ny + p[1]) * nx + p[0])] =
        c.active(blk, 0, 0, 0);
    for (int d = 0; d < 3; ++d) {
      auto n = coarse_n_;
      n[D(d)] += 1;
      auto face = [&](std::array<std::int64_t, 3> q) {
        return static_cast<std::size_t>((q[2] * n[1] + q[1]) * n[0] + q[0]);
      };
      coarse_beta_[D(d)][face(p)] = c.beta[D(d)](blk, 0, 0, 0);
      std::array<int, 3> o{0, 0, 0};
      o[D(d)] = 1;
      if (block.neighbours[D(neighbour_slot(o[0], o[1], o[2]))].link == Link::Boundary) {
        auto q = p;
        q[D(d)] += 1;
        std::array<int, 3> up{0, 0, 0};
        up[D(d)] = 1;
        coarse_beta_[D(d)][face(q)] = c.beta[D(d)](blk, up[0], up[1], up[2]);
      }
    }
  }
  MPI_Allreduce(MPI_IN_PLACE, coarse_alpha_.data(), static_cast<int>(coarse_alpha_.size()),
                MPI_DOUBLE, MPI_SUM, forest_.comm());
  MPI_Allreduce(MPI_IN_PLACE, coarse_active_.data(), static_cast<int>(coarse_active_.size()),
                MPI_DOUBLE, MPI_SUM, forest_.comm());
  for (auto& beta : coarse_beta_) {
    MPI_Allreduce(MPI_IN_PLACE, beta.data(), static_cast<int>(beta.size()), MPI_DOUBLE, MPI_SUM,
                  forest_.comm());
  }
}

void Multigrid::coarse_solve() {
  if (composite_) {
    composite_solve();
    return;
  }
  Level& c = levels_.back();
  // Named copies, not a structured binding: the lambda below reads them, and clang
  // before 16 (Debian 12 ships 14) cannot capture structured bindings.
  const std::int64_t nx = coarse_n_[0], ny = coarse_n_[1], nz = coarse_n_[2];
  const auto cells = static_cast<std::size_t>(nx * ny * nz);
  std::vector<double> rhs(cells, 0.0);
  auto cell = [&](const std::array<std::int64_t, 3>& p) {
    return static_cast<std::size_t>((p[2] * ny + p[1]) * nx + p[0]);
  };
  for (int blk = 0; blk < forest_.local_blocks(); ++blk) {
    rhs[cell(forest_.block(blk).coord)] = c.rhs(blk, 0, 0, 0);
  }
  MPI_Allreduce(MPI_IN_PLACE, rhs.data(), static_cast<int>(cells), MPI_DOUBLE, MPI_SUM,
                forest_.comm());
  // Inactive cells (closed on all sides) are left out: zero rows, zero values.
  double active_cells = 0.0;
  for (std::size_t i = 0; i < cells; ++i) {
    rhs[i] *= coarse_active_[i];
    active_cells += coarse_active_[i];
  }
  auto remove_mean = [&](std::vector<double>& v) {
    if (active_cells == 0.0) return;
    double sum = 0.0;
    for (std::size_t i = 0; i < cells; ++i) sum += coarse_active_[i] * v[i];
    const double m = sum / active_cells;
    for (std::size_t i = 0; i < cells; ++i) v[i] -= coarse_active_[i] * m;
  };
  if (singular_) remove_mean(rhs);

  const double inv_h2 = 1.0 / (coarse_h_ * coarse_h_);
  const std::array<std::int64_t, 3> n = coarse_n_;
  auto apply = [&](const std::vector<double>& x, std::vector<double>& ax) {
    for (std::int64_t k = 0; k < nz; ++k)
      for (std::int64_t j = 0; j < ny; ++j)
        for (std::int64_t i = 0; i < nx; ++i) {
          const std::array<std::int64_t, 3> p{i, j, k};
          const std::size_t c0 = cell(p);
          double sum = coarse_alpha_[c0] * x[c0];
          for (int d = 0; d < 3; ++d) {
            auto nf = n;
            nf[D(d)] += 1;
            auto face = [&](const std::array<std::int64_t, 3>& q) {
              return static_cast<std::size_t>((q[2] * nf[1] + q[1]) * nf[0] + q[0]);
            };
            const double beta_lo = coarse_beta_[D(d)][face(p)];
            auto up = p;
            up[D(d)] += 1;
            double beta_hi = 0.0;
            double x_lo = 0.0, x_hi = 0.0;
            const BcKind kind_lo = kinds_[D(face_index(d, 0))];
            const BcKind kind_hi = kinds_[D(face_index(d, 1))];
            auto wrapped = p;
            if (p[D(d)] > 0) {
              wrapped[D(d)] = p[D(d)] - 1;
              x_lo = x[cell(wrapped)];
            } else if (kind_lo == BcKind::Periodic) {
              wrapped[D(d)] = n[D(d)] - 1;
              x_lo = x[cell(wrapped)];
            } else {
              x_lo = kind_lo == BcKind::Dirichlet ? -x[c0] : x[c0];
            }
            wrapped = p;
            if (p[D(d)] < n[D(d)] - 1) {
              wrapped[D(d)] = p[D(d)] + 1;
              x_hi = x[cell(wrapped)];
              beta_hi = coarse_beta_[D(d)][face(up)];
            } else if (kind_hi == BcKind::Periodic) {
              wrapped[D(d)] = 0;
              x_hi = x[cell(wrapped)];
              beta_hi = coarse_beta_[D(d)][face(wrapped)];
            } else {
              x_hi = kind_hi == BcKind::Dirichlet ? -x[c0] : x[c0];
              beta_hi = coarse_beta_[D(d)][face(up)];
            }
            sum -= inv_h2 * (beta_hi * (x_hi - x[c0]) - beta_lo * (x[c0] - x_lo));
          }
          ax[c0] = sum;
        }
  };
  // Conjugate gradients: the operator is symmetric positive (semi-)definite.
  std::vector<double> x = conjugate_gradients(rhs, apply, [&](std::vector<double>& r) {
    if (singular_) remove_mean(r);
  });
  if (singular_) remove_mean(x);
  for (int blk = 0; blk < forest_.local_blocks(); ++blk) {
    c.x(blk, 0, 0, 0) = x[cell(forest_.block(blk).coord)];
  }
}

namespace {

/// The coarse-fine ghosts of the operator on `level` (composite_ghosts_on);
/// values alone (the prolongation) are interpolated.
CoarseGhosts ghost_rule(int level, bool operator_ghosts) {
  return operator_ghosts && composite_ghosts_on(level) ? CoarseGhosts::Composite
                                                       : CoarseGhosts::Interpolated;
}

/// The cells of a block's layers beside faces with finer blocks across
/// (ClosedFaces::matched) that a half-sweep relaxes ((i + j + k + first) even,
/// as in relax_block), each cell once, in a fixed order: f(face slot, u, v, cell).
/// The other colour is left alone: other blocks may be reading it meanwhile.
template <typename F>
void for_each_matched_layer_cell(const BlockLayout& L, const std::array<bool, 6>& matched,
                                 int first, F f) {
  const int b = L.cells;
  for (int d = 0; d < 3; ++d)
    for (int side = 0; side < 2; ++side) {
      if (!matched[D(face_index(d, side))]) continue;
      const int u_axis = d == 0 ? 1 : 0;
      const int v_axis = d == 2 ? 1 : 2;
      for (int v = 0; v < b; ++v)
        for (int u = 0; u < b; ++u) {
          std::array<int, 3> q{};
          q[D(d)] = side == 0 ? 0 : b - 1;
          q[D(u_axis)] = u;
          q[D(v_axis)] = v;
          // A cell on an edge or corner of two matched faces belongs to the first.
          bool earlier = false;
          for (int e = 0; e <= d && !earlier; ++e)
            for (int t = 0; t < 2 && !earlier; ++t)
              earlier = (e < d || t < side) && matched[D(face_index(e, t))] &&
                        q[D(e)] == (t == 0 ? 0 : b - 1);
          if (!earlier && ((q[0] + q[1] + q[2] + first) & 1) == 0)
            f(face_index(d, side), u, v, L.index(q[0], q[1], q[2]));
        }
    }
}

}  // namespace

void Multigrid::fill_ghosts(int level, BlockField& x, const ScalarBoundary* bc, bool faces_only,
                            bool match) {
  forest_.exchange(x, 1, faces_only, ghost_rule(level, match));
  if (bc) {
    fill_boundary_ghosts(forest_, x, *bc, 1, false);
  } else {
    fill_boundary_ghosts(forest_, x, kinds_, 1);
  }
  if (composite_ && match) match_fluxes(level, x);
}

void Multigrid::fill_ghosts_between_blocks_apart(int level, BlockField& x) {
  if (!forest_.faces_local_same_level()) {
    forest_.exchange_face_ghosts_but_local_same_level(x, ghost_rule(level, true));
  }
  if (composite_) match_fluxes(level, x);
}

void Multigrid::fill_block_ghosts(int blk, BlockField& x, const ScalarBoundary* bc, int colour,
                                  bool in_place) const {
  if (!in_place) forest_.copy_face_ghosts(x, blk, colour);
  if (bc) {
    fill_block_boundary_ghosts(forest_, x, blk, bc->kind, &bc->value, 1, colour, !in_place);
  } else {
    fill_block_boundary_ghosts(forest_, x, blk, kinds_, nullptr, 1, colour, !in_place);
  }
}

void Multigrid::relax_block(int level, int blk, BlockField& x, const BlockField& rhs,
                            const ScalarBoundary* bc, int colour, bool in_place,
                            int next_blk) const {
  const Level& lv = levels_[D(level)];
  const BlockLayout L = x.layout();
  const int b = L.cells;
  const std::array<std::ptrdiff_t, 3> s{L.stride(0), L.stride(1), L.stride(2)};
  const Block& block = forest_.block(blk);
  const double h = block.length / b;
  const double inv_h2 = 1.0 / (h * h);
  const auto parity = static_cast<int>((block.coord[0] + block.coord[1] + block.coord[2]) * b) & 1;
  const BlockCoefficients k{lv.alpha.block(blk),
                            {lv.beta[0].block(blk), lv.beta[1].block(blk), lv.beta[2].block(blk)}};
  double* xb = x.block(blk);
  const double* rb = rhs.block(blk);
  // Dirichlet faces of this block with the quadratic closure (finest level):
  // ghost = (8 g - 6 x0 + x1)/3 depends on x0 with weight -2.
  ClosedFaces faces;
  bool any = false;
  if (composite_) {
    // Coarse-fine faces. Seen from the coarse side the ghost carries the
    // matched fine flux, which moves with this cell through the fine ghosts
    // interpolated from it; seen from the fine side a composite ghost holds
    // kGhostFace of the cell itself (see matched_diagonal and closure_implicit).
    faces.composite = composite_ghosts_on(level) && composite_ghost_fits(b);
    for (int d = 0; d < 3; ++d)
      for (int side = 0; side < 2; ++side) {
        const LevelJump jump = block.neighbours[D(face_neighbour_slot(d, side))].jump;
        faces.matched[D(face_index(d, side))] = jump == LevelJump::Finer;
        faces.coarser[D(face_index(d, side))] = faces.composite && jump == LevelJump::Coarser;
        any = any || faces.matched[D(face_index(d, side))] || faces.coarser[D(face_index(d, side))];
      }
  }
  if (bc != nullptr) {
    for (int d = 0; d < 3; ++d)
      for (int side = 0; side < 2; ++side) {
        std::array<int, 3> o{0, 0, 0};
        o[D(d)] = side == 0 ? -1 : 1;
        const bool on =
            block.neighbours[D(neighbour_slot(o[0], o[1], o[2]))].link == Link::Boundary &&
            kinds_[D(face_index(d, side))] == BcKind::Dirichlet;
        faces.dirichlet[D(face_index(d, side))] = on;
        any = any || on;
      }
  }
  const auto at = static_cast<std::size_t>(blk);
  const int first = (parity + colour) & 1;
  const AcrossFaces across =
      in_place ? same_level_neighbours(forest_, x, blk, bc ? bc->kind : kinds_) : AcrossFaces{};
  // The cells beside a finer block relax at beside_finer_omega_ (see
  // MultigridOptions::beside_finer_relaxation): the kernels relax them at
  // omega_ with the rest, and their change is scaled back afterwards.
  const bool scale_beside_finer =
      composite_ && beside_finer_omega_ != omega_ &&
      std::any_of(faces.matched.begin(), faces.matched.end(), [](bool m) { return m; });
  double* before = nullptr;
  if (scale_beside_finer) {
    before = thread_scratch(6 * static_cast<std::ptrdiff_t>(b) * b);
    for_each_matched_layer_cell(
        L, faces.matched, first,
        [&](int f, int u, int v, std::ptrdiff_t c) { before[(f * b + v) * b + u] = xb[c]; });
  }
  const auto scale_changes_beside_finer = [&] {
    if (!scale_beside_finer) return;
    const double scale = beside_finer_omega_ / omega_;
    for_each_matched_layer_cell(L, faces.matched, first,
                                [&](int f, int u, int v, std::ptrdiff_t c) {
                                  const double old = before[(f * b + v) * b + u];
                                  xb[c] = old + scale * (xb[c] - old);
                                });
  };
  if (constant_kernels_ && lv.block_constant[at]) {
    relax_constant(xb, rb, L, first, lv.block_alpha[at], lv.block_beta[at], inv_h2, omega_, faces,
                   across, next_block(x, rhs, next_blk));
    scale_changes_beside_finer();
    return;
  }
  // The general kernel, by rows, reading same-level neighbours as relax_constant does.
  for (int kk = 0; kk < b; ++kk)
    for (int j = 0; j < b; ++j) {
      const std::ptrdiff_t start = L.index(0, j, kk);
      double* row = xb + start;
      const int i_first = (kk + j + first) & 1;
      pull_row_x_ghosts_of_colour(row, L, across, j, kk, i_first);
      const RowStencil around{row, neighbour_rows(row, L, across, j, kk)};
      for (int i = i_first; i < b; i += 2) {
        const std::ptrdiff_t c = start + i;
        const double implicit =
            any ? closure_implicit(
                      {i, j, kk}, b, faces, [&](int d) { return k.beta[D(d)][c]; },
                      [&](int d) { return k.beta[D(d)][c + s[D(d)]]; })
                : 0.0;
        row[i] += omega_ * (relaxed_value(around, i, rb[c], k, c, s, inv_h2, implicit) - row[i]);
      }
    }
  scale_changes_beside_finer();
}

void Multigrid::smooth(int level, BlockField& x, const BlockField& rhs, const ScalarBoundary* bc,
                       int sweeps) {
  const int b = x.layout().cells;
  // With an even b (the colours match across periodic faces) each block fills
  // its face ghosts towards same-level blocks of this rank and its boundary
  // ghosts right before it relaxes, while its cells are in cache, instead of
  // a pass over all blocks first. It copies the colour the half-sweep reads,
  // which no block changes meanwhile: the same values, in any block order and
  // on any number of threads. The other faces (level jumps, other ranks, and
  // the matched fluxes) are filled first, as before. With
  // read_neighbours_in_place it reads the same-level neighbours in place
  // instead of copying them (relax_constant and the general kernel alike).
  const bool fused = b % 2 == 0;
  // The block each half-sweep takes next on this thread (the first colour
  // runs forwards, the second backwards), or on the thread beside at the end
  // of a share: its rows are prefetched meanwhile, when the fields do not fit
  // in the cache (blocks 0: no prefetching).
  const auto [prefetch, timed] = prefetching(level, x, rhs, true);
  const int blocks = prefetch ? x.blocks() : 0;
  const auto start = std::chrono::steady_clock::now();
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    for (int colour = 0; colour < 2; ++colour) {
      if (fused) {
        fill_ghosts_between_blocks_apart(level, x);
      } else {
        fill_ghosts(level, x, bc, true);  // the 7-point stencil reads face ghosts only
      }
      const auto relax = [&](int blk) {
        const bool in_place = fused && in_place_;
        if (fused) fill_block_ghosts(blk, x, bc, 1 - colour, in_place);
        const int next = colour == 0 ? blk + 1 : blk - 1;
        relax_block(level, blk, x, rhs, bc, colour, in_place,
                    next >= 0 && next < blocks ? next : -1);
      };
      // In a half-sweep each block writes only its own cells and ghosts, and
      // reads other blocks only through ghosts copied from, or in place in,
      // cells of the colour no block writes in it; so its block order is
      // free. The second colour runs backwards over each thread's blocks and
      // starts on those the first one left in cache (what a grid larger than
      // the cache saves), with the same bits.
      if (colour == 0) {
        forest_.for_each_block(relax);
      } else {
        forest_.for_each_block_backward(relax);
      }
    }
  }
  if (timed) {  // prefetching() made the level's trial
    prefetch_trials_[D(level)].record(
        prefetch, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  if (level == 0) {
    const auto decided = timed ? prefetch_trials_[0].decision() : std::nullopt;
    finest_prefetch_ = !timed ? (prefetch ? "on" : "off")
                              : (decided ? (*decided ? "timed on" : "timed off") : "timing");
  }
}

bool PrefetchTrial::next_choice(double field_bytes) {
  if (field_bytes > 2.0 * bytes_ || field_bytes < 0.5 * bytes_) *this = PrefetchTrial{};
  bytes_ = field_bytes;
  if (decided_) return *decided_;
  // Thue-Morse: 0 1 1 0 1 0 0 1 1 0 0 1 0 1 1 0; 1 prefetches.
  return (std::popcount(static_cast<unsigned>(calls_)) & 1) != 0;
}

void PrefetchTrial::record(bool prefetching, double seconds) {
  if (decided_) return;
  double& best = best_[prefetching ? 1 : 0];
  best = std::min(best, seconds);
  if (++calls_ == kTrialCalls) decided_ = best_[1] < best_[0];
}

Multigrid::PrefetchChoice Multigrid::prefetching(int level, const BlockField& x,
                                                 const BlockField& rhs, bool trial) {
  const double bytes = field_bytes(x, rhs);
  switch (prefetch_rule(prefetch_, bytes)) {
    case PrefetchRule::No:
      return {false, false};
    case PrefetchRule::Yes:
      return {true, false};
    case PrefetchRule::Timed:
      break;
  }
  if (prefetch_trials_.size() <= D(level)) prefetch_trials_.resize(D(level) + 1);
  PrefetchTrial& timed = prefetch_trials_[D(level)];
  // The residual does not take turns: it prefetches once the trial says so.
  return {trial ? timed.next_choice(bytes) : timed.decision().value_or(false), true};
}

void Multigrid::compute_residual(int level, BlockField& x, const BlockField& rhs,
                                 const ScalarBoundary* bc, BlockField* r, bool squares_wanted,
                                 bool ghosts_wanted, BlockField* restricted) {
  const Level& lv = levels_[D(level)];
  const BlockLayout L = x.layout();
  const int b = L.cells;
  const std::array<std::ptrdiff_t, 3> s{L.stride(0), L.stride(1), L.stride(2)};
  fill_ghosts_between_blocks_apart(level, x);  // the rest block by block, as in smooth()
  block_squares_.resize(static_cast<std::size_t>(forest_.local_blocks()));
  const int blocks = prefetching(level, x, rhs, false).on ? x.blocks() : 0;  // as in smooth()
  forest_.for_each_block([&](int blk) {
    const auto at = static_cast<std::size_t>(blk);
    // Same-level neighbours of this process are read in place, unless the
    // ghosts are wanted.
    const bool in_place = !ghosts_wanted && in_place_;
    fill_block_ghosts(blk, x, bc, -1, in_place);
    const double h = forest_.block(blk).length / b;
    const double inv_h2 = 1.0 / (h * h);
    const BlockCoefficients k{
        lv.alpha.block(blk), {lv.beta[0].block(blk), lv.beta[1].block(blk), lv.beta[2].block(blk)}};
    double* xb = x.block(blk);
    const double* fb = rhs.block(blk);
    const double* ab = lv.active.block(blk);
    // A residual that is not kept lives in a block of scratch, in cache.
    double* rb = r ? r->block(blk) : thread_scratch(L.size());
    const AcrossFaces across =
        in_place ? same_level_neighbours(forest_, x, blk, bc ? bc->kind : kinds_) : AcrossFaces{};
    if (constant_kernels_ && lv.block_constant[at]) {
      const NextBlock next = next_block(x, rhs, blk + 1 < blocks ? blk + 1 : -1);
      block_squares_[at] = squares_wanted
                               ? residual_constant<true>(xb, fb, rb, L, lv.block_alpha[at],
                                                         lv.block_beta[at], inv_h2, across, next)
                               : residual_constant<false>(xb, fb, rb, L, lv.block_alpha[at],
                                                          lv.block_beta[at], inv_h2, across, next);
    } else {
      double squares = 0.0;
      for (int kk = 0; kk < b; ++kk)
        for (int j = 0; j < b; ++j) {
          const std::ptrdiff_t start = L.index(0, j, kk);
          double* row = xb + start;
          pull_row_x_ghosts(row, L, across, j, kk, true, true);
          const RowStencil around{row, neighbour_rows(row, L, across, j, kk)};
          for (int i = 0; i < b; ++i) {
            const std::ptrdiff_t c = start + i;
            const double value = (fb[c] - applied(around, i, k, c, s, inv_h2)) * ab[c];
            rb[c] = value;
            squares += value * value;
          }
        }
      block_squares_[at] = squares;
    }
    if (restricted) {
      restrict_cells(rb, L, restricted->block(blk), restricted->layout(), b / 2, kAdd, kMean8);
    }
  });
}

namespace {

// The trilinear prolongation of vcycle() where every coarse cell is active:
// the same terms in the same order (dk, dj, di), so the same bits (the
// weights are exact binary fractions summing to 1 exactly), from four coarse
// rows per fine row instead of an index computation per term.
void prolong_all_active(const BlockField& coarse, int blk, int b, BlockField& x) {
  constexpr double kNear = 0.75, kFar = 0.25;
  const BlockLayout C = coarse.layout();
  const BlockLayout F = x.layout();
  const double* cb = coarse.block(blk);
  double* fb = x.block(blk);
  for (int k = 0; k < b; ++k)
    for (int j = 0; j < b; ++j) {
      const int cj = j >> 1, ck = k >> 1;
      const int sj = (j & 1) ? 1 : -1, sk = (k & 1) ? 1 : -1;
      // rows (dj, dk): 00, 10, 01, 11
      const double* r00 = cb + C.index(0, cj, ck);
      const double* r10 = cb + C.index(0, cj + sj, ck);
      const double* r01 = cb + C.index(0, cj, ck + sk);
      const double* r11 = cb + C.index(0, cj + sj, ck + sk);
      double* row = fb + F.index(0, j, k);
      const double w00 = kNear * kNear, w10 = kNear * kFar;  // wy * wz, exact
      const double w01 = kFar * kNear, w11 = kFar * kFar;
      // Fine cells 2c and 2c + 1 of coarse cell c: the far neighbour is c - 1
      // for the first, c + 1 for the second. By coarse cell, so the loads are
      // unit-stride and the loop vectorises.
      for (int c = 0; c < b / 2; ++c) {
        double low = 0.0, high = 0.0;
        // One coarse row's two terms (near, far) for each fine cell.
        const auto add = [&](double w, const double* r) {
          low += kNear * w * r[c];
          low += kFar * w * r[c - 1];
          high += kNear * w * r[c];
          high += kFar * w * r[c + 1];
        };
        add(w00, r00);
        add(w10, r10);
        add(w01, r01);
        add(w11, r11);
        row[2 * c] += low;  // / weight, which is exactly 1
        row[2 * c + 1] += high;
      }
    }
}

}  // namespace

void Multigrid::vcycle(int level, BlockField& x, const BlockField& rhs, const ScalarBoundary* bc) {
  if (coarsened_) {
    vcycle_level_by_level(x, rhs, bc);
    return;
  }
  if (static_cast<std::size_t>(level) + 1 == levels_.size()) {
    coarse_solve();
    return;
  }
  smooth(level, x, rhs, bc, pre_sweeps_);
  Level& fine = levels_[D(level)];
  Level& coarse = levels_[D(level + 1)];
  // The residual restricted block by block as it is formed (no norm).
  compute_residual(level, x, rhs, bc, nullptr, false, false, &coarse.rhs);
  coarse.x.fill(0.0);
  vcycle(level + 1, coarse.x, coarse.rhs, nullptr);
  fill_ghosts(level + 1, coarse.x, nullptr, false, false);  // values, not matched fluxes
  // Trilinear prolongation of the correction (weights 3/4, 1/4 per direction),
  // from active coarse cells only. Where every coarse cell and ghost the block
  // reads is active (1 exactly: a constant-coefficient level, or a block away
  // from solids), the factor is skipped: same bits.
  const int b = fine.cells;
  const bool all_active = coarse.constant_coefficients && constant_kernels_;
  forest_.for_each_block([&](int blk) {
    if (all_active || coarse.block_ring_active[static_cast<std::size_t>(blk)]) {
      prolong_all_active(coarse.x, blk, b, x);
      return;
    }
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          const WeightedSum sum = trilinear_sum(
              coarse.x, all_active ? nullptr : &coarse.active, blk, {i >> 1, j >> 1, k >> 1},
              {(i & 1) ? 1 : -1, (j & 1) ? 1 : -1, (k & 1) ? 1 : -1});
          if (sum.weight > 0.0) x(blk, i, j, k) += sum.value / sum.weight;
        }
  });
  smooth(level, x, rhs, bc, post_sweeps_);
}

void Multigrid::vcycle_level_by_level(BlockField& x, const BlockField& rhs,
                                      const ScalarBoundary* bc) {
  smooth(0, x, rhs, bc, pre_sweeps_);
  Coarsened& c = *coarsened_;
  compute_residual(0, x, rhs, bc, &c.residual, false);
  c.transfers->restrict_cells(c.residual, c.rhs);
  c.solver->correction(c.x, c.rhs);
  // Trilinear on the coarsened families, from active coarse cells only (as vcycle()).
  c.transfers->prolong_add(c.x, c.all_active ? nullptr : &c.active, x);
  smooth(0, x, rhs, bc, post_sweeps_);
}

void Multigrid::correction(BlockField& x, const BlockField& rhs) {
  if (merged_) {
    to_merged(nullptr, rhs);
    merged_->solver->correction(merged_->x, merged_->rhs);
    from_merged(x, homogeneous_, true);
    return;
  }
  // Level 0 here is a finest level (its Dirichlet closure, its ghost rule), with zero
  // boundary values: the correction's.
  x.fill(0.0);
  vcycle(0, x, rhs, &homogeneous_);
  fill_ghosts(0, x, &homogeneous_, false, false);  // values, not matched fluxes
}

double Multigrid::rms(const BlockField& f) {
  block_squares_.resize(static_cast<std::size_t>(forest_.local_blocks()));
  forest_.for_each_block(
      [&](int blk) { block_squares_[static_cast<std::size_t>(blk)] = block_squares(f, blk); });
  return root_mean_square(f.cells());
}

double Multigrid::root_mean_square(int b) const {
  // Per-block sums added in block order: the same bits on any number of
  // threads, and the blocks' sums computed in parallel.
  double local = 0.0;
  for (const double squares : block_squares_) local += squares;
  const double cells = static_cast<double>(forest_.global_blocks()) * b * b * b;
  return std::sqrt(forest_.sum(local) / cells);
}

double Multigrid::mean(const BlockField& f) const {
  const int b = f.cells();
  const Level& finest = levels_.front();
  const BlockField& active = finest.active;
  double local = 0.0, count = 0.0;
  for (int blk = 0; blk < forest_.local_blocks(); ++blk) {
    // Composite grids: weighted by the cell volume (in finest-cell units, so
    // that a uniform forest keeps the plain count).
    const double volume =
        composite_ ? std::ldexp(1.0, 3 * (forest_.max_level() - forest_.block(blk).level)) : 1.0;
    if (finest.block_all_active[static_cast<std::size_t>(blk)]) {
      // active is 1 in every cell: the same terms without reading it.
      for (int k = 0; k < b; ++k)
        for (int j = 0; j < b; ++j)
          for (int i = 0; i < b; ++i) {
            local += volume * f(blk, i, j, k);
            count += volume;
          }
      continue;
    }
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          local += volume * active(blk, i, j, k) * f(blk, i, j, k);
          count += volume * active(blk, i, j, k);
        }
  }
  const double cells = forest_.sum(count);
  return cells > 0.0 ? forest_.sum(local) / cells : 0.0;
}

void Multigrid::shift_interior(BlockField& f, double by) const {
  const int b = f.cells();
  const Level& finest = levels_.front();
  forest_.for_each_block([&](int blk) {
    if (finest.block_all_active[static_cast<std::size_t>(blk)]) {
      for (int k = 0; k < b; ++k)
        for (int j = 0; j < b; ++j)
          for (int i = 0; i < b; ++i) f(blk, i, j, k) -= by;  // by * active, active = 1
      return;
    }
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) f(blk, i, j, k) -= by * finest.active(blk, i, j, k);
  });
}

void Multigrid::to_merged(const BlockField* x, const BlockField& rhs) {
  if (x) merged_->copies->to_merged(*x, merged_->x);
  merged_->copies->to_merged(rhs, merged_->rhs);
}

void Multigrid::from_merged(BlockField& x, const ScalarBoundary& bc, bool fill_ghosts) const {
  merged_->copies->to_fine(merged_->x, x);
  if (fill_ghosts) fill_caller_ghosts(x, bc);
}

void Multigrid::fill_caller_ghosts(BlockField& x, const ScalarBoundary& bc) const {
  forest_.exchange(x, 1, false, CoarseGhosts::Interpolated);
  fill_boundary_ghosts(forest_, x, bc, 1, false);
}

void Multigrid::residual(BlockField& x, const BlockField& rhs, const ScalarBoundary& bc,
                         BlockField& r) {
  if (merged_) {
    to_merged(&x, rhs);
    Merged& m = *merged_;
    if (m.r.blocks() != m.forest->local_blocks()) {
      m.r.reshape(m.forest->local_blocks(), m.forest->block_cells());
    }
    m.solver->residual(m.x, m.rhs, bc, m.r);
    m.copies->to_fine(m.r, r);
    fill_caller_ghosts(x, bc);  // x unchanged; its ghosts filled with bc, as below
    return;
  }
  compute_residual(0, x, rhs, &bc, &r, true, true);
}

void Multigrid::take_options(const MultigridOptions& options) {
  pre_sweeps_ = options.pre_sweeps;
  post_sweeps_ = options.post_sweeps;
  omega_ = options.relaxation;
  beside_finer_omega_ = std::min(options.relaxation, options.beside_finer_relaxation);
  constant_kernels_ = options.constant_coefficient_kernels;
  in_place_ = options.read_neighbours_in_place;
  prefetch_ = options.prefetch;
  // The solvers that take the coarse corrections (correction() does not take options).
  if (merged_) merged_->solver->take_options(options);
  if (coarsened_) coarsened_->solver->take_options(options);
}

void Multigrid::relax(BlockField& x, const BlockField& rhs, const ScalarBoundary& bc, int sweeps,
                      const MultigridOptions& options) {
  if (merged_) {
    to_merged(&x, rhs);
    merged_->solver->relax(merged_->x, merged_->rhs, bc, sweeps, options);
    from_merged(x, bc, false);
    return;
  }
  take_options(options);
  smooth(0, x, rhs, &bc, sweeps);
}

MultigridReport Multigrid::solve(BlockField& x, const BlockField& rhs, const ScalarBoundary& bc,
                                 const MultigridOptions& options) {
  if (merged_) {
    to_merged(&x, rhs);
    MultigridOptions inner = options;
    inner.fill_ghosts_on_return = false;  // filled on the caller's blocks
    const MultigridReport report = merged_->solver->solve(merged_->x, merged_->rhs, bc, inner);
    from_merged(x, bc, options.fill_ghosts_on_return);
    return report;
  }
  take_options(options);
  const BlockField* source = &rhs;
  BlockField& shifted = shifted_rhs_;
  if (singular_) {
    // Compatibility: a singular problem only has a solution for a zero-mean rhs.
    shifted.raw().assign(rhs.raw().begin(), rhs.raw().end());  // reuses the buffer
    shift_interior(shifted, mean(rhs));
    source = &shifted;
  }
  MultigridReport report;
  report.rhs_norm = rms(*source);
  Level& fine = levels_.front();
  compute_residual(0, x, *source, &bc, nullptr);  // the norm alone
  report.residuals.push_back(root_mean_square(fine.cells));
  const double scale = report.rhs_norm > 0.0 ? report.rhs_norm : report.residuals.front();
  const double target = std::max(options.tolerance * scale, options.absolute_tolerance);
  report.converged = report.residuals.back() <= target;
  while (!report.converged && report.cycles < options.max_cycles) {
    vcycle(0, x, *source, &bc);
    if (singular_) shift_interior(x, mean(x));
    compute_residual(0, x, *source, &bc, nullptr);  // the norm alone
    report.residuals.push_back(root_mean_square(fine.cells));
    ++report.cycles;
    report.converged = report.residuals.back() <= target;
  }
  if (options.fill_ghosts_on_return) fill_ghosts(0, x, &bc, false, false);
  return report;
}

}  // namespace sanguis::flow
