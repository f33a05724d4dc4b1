#pragma once
// Helpers shared by the Navier-Stokes tests (uniform, refined, adaptive):
// all-periodic boundaries, a deterministic rough field, volume integrals.

#include <array>
#include <cmath>

#include "flow/navier_stokes.hpp"

namespace sanguis::flow::testing {

inline std::array<FlowBoundary, 6> all_periodic() {
  std::array<FlowBoundary, 6> bcs{};
  for (auto& bc : bcs) bc.kind = FlowBoundaryKind::Periodic;
  return bcs;
}

/// A deterministic rough field in [-1, 1] (no structure the projection could exploit).
inline double rough(const Vec3& x, int seed) {
  const double v = std::sin(12.9898 * x.x + 78.233 * x.y + 37.719 * x.z + 4.1 * seed) * 43758.5453;
  return 2.0 * (v - std::floor(v)) - 1.0;
}

/// Volume integral sum(c V) of a cell field over all cells (all ranks).
inline double total(const Forest& forest, const BlockField& c) {
  const int b = forest.block_cells();
  double sum = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const double h = forest.block(blk).length / b;
    double block_sum = 0.0;
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) block_sum += c(blk, i, j, k);
    sum += block_sum * h * h * h;
  }
  return forest.sum(sum);
}

}  // namespace sanguis::flow::testing
