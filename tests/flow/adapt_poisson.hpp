#pragma once
// The manufactured Poisson problems of poisson_problems.hpp on a statically
// refined forest: the octant [0, 1/2)^3 one level finer than the rest, so
// that the coarse-fine interface has faces, edges and corners (and, when
// periodic, wraps around the domain). Shared by test_adapt_poisson.cpp and
// flow_mpi_check.cpp.

#include "adapt_problems.hpp"
#include "poisson_problems.hpp"

namespace sanguis::flow::testing {

inline bool in_refined_octant(const Vec3& c) {
  return c.x < 0.5 && c.y < 0.5 && c.z < 0.5;
}

struct RefinedPoissonResult : PoissonResult {
  double interface_error = 0.0;  ///< max error over the cells beside a coarse-fine face
};

/// Max |field - f| over the cell layers beside faces to a coarser or finer block.
template <typename F>
double interface_error(const Forest& forest, const BlockField& field, F&& f) {
  const int b = field.cells();
  double e = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const Block& block = forest.block(blk);
    for (int d = 0; d < 3; ++d)
      for (int side = 0; side < 2; ++side) {
        std::array<int, 3> o{0, 0, 0};
        o[static_cast<std::size_t>(d)] = side == 0 ? -1 : 1;
        const Neighbour& nb =
            block.neighbours[static_cast<std::size_t>(neighbour_slot(o[0], o[1], o[2]))];
        if (nb.link == Link::Boundary || nb.jump == LevelJump::Same) continue;
        for (int t2 = 0; t2 < b; ++t2)
          for (int t1 = 0; t1 < b; ++t1) {
            std::array<int, 3> n{};
            n[static_cast<std::size_t>(d)] = side == 0 ? 0 : b - 1;
            n[static_cast<std::size_t>((d + 1) % 3)] = t1;
            n[static_cast<std::size_t>((d + 2) % 3)] = t2;
            e = std::max(e, std::abs(field(blk, n[0], n[1], n[2]) -
                                     f(cell_centre(forest, blk, n[0], n[1], n[2]))));
          }
      }
  }
  return forest.max(e);
}

/// Solves -lap u = f with blocks of 8 cells at base level `level` and the
/// octant at level + 1; the error is the max norm over all cells.
inline RefinedPoissonResult solve_refined_manufactured(bool periodic, int level,
                                                       MPI_Comm comm = MPI_COMM_WORLD,
                                                       double tolerance = 1e-10,
                                                       int max_cycles = 50, int threads = 1) {
  ForestSpec spec;
  spec.periodic = {periodic, periodic, periodic};
  spec.block_cells = 8;
  spec.level = level;
  spec.comm = comm;
  spec.threads = threads;
  Forest forest(spec);
  refine_where(forest, in_refined_octant);
  ScalarBoundary bc;
  bc.kind = uniform_kinds(forest, BcKind::Dirichlet);
  for (auto& v : bc.value) v = dirichlet_exact;
  Multigrid mg(forest, bc.kind);
  const BlockField rhs =
      periodic ? sample(forest, periodic_source) : sample(forest, dirichlet_source);
  RefinedPoissonResult result;
  result.solution = BlockField(forest.local_blocks(), 8);
  MultigridOptions options;
  options.tolerance = tolerance;
  options.max_cycles = max_cycles;
  result.report = mg.solve(result.solution, rhs, bc, options);
  result.error = periodic ? max_error(forest, result.solution, periodic_exact)
                          : max_error(forest, result.solution, dirichlet_exact);
  result.interface_error = periodic ? interface_error(forest, result.solution, periodic_exact)
                                    : interface_error(forest, result.solution, dirichlet_exact);
  return result;
}

}  // namespace sanguis::flow::testing
