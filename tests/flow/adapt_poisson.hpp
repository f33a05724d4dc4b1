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

/// Solves -lap u = f with blocks of 8 cells at base level `level` and the
/// octant at level + 1; the error is the max norm over all cells.
inline PoissonResult solve_refined_manufactured(bool periodic, int level,
                                                MPI_Comm comm = MPI_COMM_WORLD,
                                                double tolerance = 1e-10, int max_cycles = 50) {
  ForestSpec spec;
  spec.periodic = {periodic, periodic, periodic};
  spec.block_cells = 8;
  spec.level = level;
  spec.comm = comm;
  Forest forest(spec);
  refine_where(forest, in_refined_octant);
  ScalarBoundary bc;
  bc.kind = uniform_kinds(forest, BcKind::Dirichlet);
  for (auto& v : bc.value) v = dirichlet_exact;
  Multigrid mg(forest, bc.kind);
  const BlockField rhs =
      periodic ? sample(forest, periodic_source) : sample(forest, dirichlet_source);
  PoissonResult result;
  result.solution = BlockField(forest.local_blocks(), 8);
  MultigridOptions options;
  options.tolerance = tolerance;
  options.max_cycles = max_cycles;
  result.report = mg.solve(result.solution, rhs, bc, options);
  result.error = periodic ? max_error(forest, result.solution, periodic_exact)
                          : max_error(forest, result.solution, dirichlet_exact);
  return result;
}

}  // namespace sanguis::flow::testing
