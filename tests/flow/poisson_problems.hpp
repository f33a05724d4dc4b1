#pragma once
// Manufactured Poisson problems shared by the multigrid tests and the 2-rank
// check (tests/flow/flow_mpi_check.cpp).

#include <cmath>
#include <numbers>

#include "flow/boundary.hpp"
#include "flow/forest.hpp"
#include "flow/multigrid.hpp"

namespace sanguis::flow::testing {

inline constexpr double kPi = std::numbers::pi;

/// u = sin(2 pi x) sin(2 pi y) sin(2 pi z) on the periodic unit cube, -lap u = 12 pi^2 u.
inline double periodic_exact(const Vec3& x) {
  return std::sin(2 * kPi * x.x) * std::sin(2 * kPi * x.y) * std::sin(2 * kPi * x.z);
}
inline double periodic_source(const Vec3& x) {
  return 12 * kPi * kPi * periodic_exact(x);
}

/// u = cos(pi x) cos(pi y) cos(pi z) + x + 2 y^2 on a box, Dirichlet all round.
inline double dirichlet_exact(const Vec3& x) {
  return std::cos(kPi * x.x) * std::cos(kPi * x.y) * std::cos(kPi * x.z) + x.x + 2 * x.y * x.y;
}
inline double dirichlet_source(const Vec3& x) {
  return 3 * kPi * kPi * std::cos(kPi * x.x) * std::cos(kPi * x.y) * std::cos(kPi * x.z) - 4.0;
}

/// Cell centre of cell (i,j,k) of block blk.
inline Vec3 cell_centre(const Forest& forest, int blk, int i, int j, int k) {
  const Block& block = forest.block(blk);
  const double h = block.length / forest.block_cells();
  return {block.lower.x + (i + 0.5) * h, block.lower.y + (j + 0.5) * h,
          block.lower.z + (k + 0.5) * h};
}

template <typename F>
BlockField sample(const Forest& forest, F&& f) {
  const int b = forest.block_cells();
  BlockField field(forest.local_blocks(), b);
  for (int blk = 0; blk < forest.local_blocks(); ++blk)
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) field(blk, i, j, k) = f(cell_centre(forest, blk, i, j, k));
  return field;
}

/// Max-norm difference to f over the interior cells of all ranks.
template <typename F>
double max_error(const Forest& forest, const BlockField& field, F&& f) {
  const int b = forest.block_cells();
  double e = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk)
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i)
          e = std::max(e, std::abs(field(blk, i, j, k) - f(cell_centre(forest, blk, i, j, k))));
  return forest.max(e);
}

struct PoissonResult {
  double error = 0.0;
  MultigridReport report;
  BlockField solution;
  bool merged = false;        ///< the multigrid solved on merged blocks (Multigrid::merged)
  int coarsened_forests = 0;  ///< Multigrid::coarsened_forests
};

/// Solves -lap u = f on the unit cube with `cells` cells per direction (blocks of
/// block_cells^3, the multigrid's gathered_blocks_limit).
inline PoissonResult solve_manufactured(
    bool periodic, int cells, MPI_Comm comm = MPI_COMM_WORLD, double tolerance = 1e-10,
    int block_cells = 8, std::int64_t gathered_blocks_limit = Multigrid::kGatheredBlocksLimit) {
  ForestSpec spec;
  spec.periodic = {periodic, periodic, periodic};
  spec.block_cells = block_cells;
  int level = 0;
  while ((block_cells << level) < cells) ++level;
  spec.level = level;
  spec.comm = comm;
  const Forest forest(spec);
  ScalarBoundary bc;
  bc.kind = uniform_kinds(forest, BcKind::Dirichlet);
  for (auto& v : bc.value) v = dirichlet_exact;
  Multigrid mg(forest, bc.kind, true, true, gathered_blocks_limit);
  const BlockField rhs =
      periodic ? sample(forest, periodic_source) : sample(forest, dirichlet_source);
  PoissonResult result;
  result.solution = BlockField(forest.local_blocks(), block_cells);
  MultigridOptions options;
  options.tolerance = tolerance;
  result.report = mg.solve(result.solution, rhs, bc, options);
  result.merged = mg.merged();
  result.coarsened_forests = mg.coarsened_forests();
  result.error = periodic ? max_error(forest, result.solution, periodic_exact)
                          : max_error(forest, result.solution, dirichlet_exact);
  return result;
}

}  // namespace sanguis::flow::testing
