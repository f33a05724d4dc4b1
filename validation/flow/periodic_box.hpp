#pragma once
// What the adaptive validation drivers (vortex_adaptive_main.cpp,
// taylor_green_adaptive_main.cpp) share: a box periodic in every direction
// made of trees 1/4 m long with blocks of 8^3 cells (by default), the solver's settings
// for them (multigrid tolerances 1e-8, so that the grids and not the solves
// make the differences), and the regrid by the wavelet criterion (thesis
// eq. 4.11) on the three velocity components.
#include <array>
#include <functional>
#include <span>

#include "flow/adapt_criterion.hpp"
#include "flow/navier_stokes.hpp"

namespace sanguis::flow::validation {

/// trees[0] x trees[1] x trees[2] trees of `tree_length` (1/4 m by default),
/// blocks of block_cells^3 cells (8^3 by default) at `level`.
inline ForestSpec periodic_box(const std::array<int, 3>& trees, int level, int threads,
                               int block_cells = 8, double tree_length = 0.25) {
  ForestSpec spec;
  spec.trees = trees;
  spec.tree_length = tree_length;
  spec.periodic = {true, true, true};
  spec.level = level;
  spec.block_cells = block_cells;
  spec.threads = threads;
  return spec;
}

inline std::array<FlowBoundary, 6> periodic_boundaries() {
  std::array<FlowBoundary, 6> bcs{};
  for (auto& bc : bcs) bc.kind = FlowBoundaryKind::Periodic;
  return bcs;
}

inline NavierStokesOptions tight_solves() {
  NavierStokesOptions options;
  options.pressure.tolerance = 1e-8;
  options.viscous.tolerance = 1e-8;
  return options;
}

/// One regrid: flags from the criterion on the velocity, the solver's fields
/// and `scalars` carried to the new grid.
inline RegridReport regrid_on_velocity(NavierStokes& ns, Forest& forest,
                                       const WaveletCriterion& criterion,
                                       std::span<BlockField* const> scalars = {}) {
  BlockField* velocity[] = {&ns.velocity()[0], &ns.velocity()[1], &ns.velocity()[2]};
  return ns.regrid(forest, wavelet_flags(forest, velocity, criterion), scalars,
                   criterion.max_level);
}

/// The initial grid of an adaptive run: from the forest's level up, regrid
/// on the initial field and set it again, once per level the criterion may add.
inline void initial_grid(NavierStokes& ns, Forest& forest, const WaveletCriterion& criterion,
                         const std::function<Vec3(const Vec3&)>& initial) {
  for (int pass = 0; pass <= criterion.max_level - criterion.min_level; ++pass) {
    regrid_on_velocity(ns, forest, criterion);
    ns.set_velocity(initial);
  }
}

}  // namespace sanguis::flow::validation
