#pragma once
// Helpers shared by the Navier-Stokes tests (uniform, refined, adaptive):
// all-periodic boundaries, the sheared channel, the periodic cube forest, a
// deterministic rough field, volume integrals.

#include <array>
#include <cmath>
#include <numbers>

#include "flow/navier_stokes.hpp"

namespace sanguis::flow::testing {

inline std::array<FlowBoundary, 6> all_periodic() {
  std::array<FlowBoundary, 6> bcs{};
  for (auto& bc : bcs) bc.kind = FlowBoundaryKind::Periodic;
  return bcs;
}

/// Channel periodic in x and z, walls at y = 0 and y = H (the upper one moving with `lid`).
inline std::array<FlowBoundary, 6> channel(double lid) {
  auto bcs = all_periodic();
  bcs[face_index(1, 0)].kind = FlowBoundaryKind::Wall;
  bcs[face_index(1, 1)].kind = FlowBoundaryKind::Wall;
  bcs[face_index(1, 1)].wall_velocity = {lid, 0.0, 0.0};
  return bcs;
}

/// Periodic unit cube, 8 blocks of 8^3 cells (16^3 cells).
inline ForestSpec periodic_cube(int threads = 1) {
  ForestSpec spec;
  spec.level = 1;
  spec.periodic = {true, true, true};
  spec.threads = threads;
  return spec;
}

/// The lid-driven cavity: walls all round, the lid y = max moving along x at 1.
inline std::array<FlowBoundary, 6> lid_driven_cavity() {
  std::array<FlowBoundary, 6> bcs{};
  bcs[face_index(1, 1)].wall_velocity = {1.0, 0.0, 0.0};
  return bcs;
}

/// A deterministic rough field in [-1, 1] (no structure the projection could exploit).
inline double rough(const Vec3& x, int seed) {
  const double v = std::sin(12.9898 * x.x + 78.233 * x.y + 37.719 * x.z + 4.1 * seed) * 43758.5453;
  return 2.0 * (v - std::floor(v)) - 1.0;
}

/// The 2D Taylor-Green vortex of the unit square (wave number 2 pi), kinematic
/// viscosity nu, at time t: an exact solution of the Navier-Stokes equations.
inline Vec3 taylor_green_velocity(const Vec3& x, double nu, double t) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  const double decay = std::exp(-2.0 * kTwoPi * kTwoPi * nu * t);
  return Vec3{std::sin(kTwoPi * x.x) * std::cos(kTwoPi * x.y) * decay,
              -std::cos(kTwoPi * x.x) * std::sin(kTwoPi * x.y) * decay, 0.0};
}

/// Periodic Taylor-Green options: Crank-Nicolson, solver tolerances 1e-10.
inline NavierStokesOptions taylor_green_options() {
  NavierStokesOptions options;
  options.viscous_theta = 0.5;
  options.pressure.tolerance = 1e-10;
  options.viscous.tolerance = 1e-10;
  return options;
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
