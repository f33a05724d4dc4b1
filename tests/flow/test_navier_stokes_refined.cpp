// Navier-Stokes on statically refined forests (issue #7, second milestone):
// exact divergence on every cell after a projection, a passive tracer
// conserved to round-off across coarse-fine faces, Taylor-Green with a
// refined centre against the uniform coarse and fine grids, Couette exact
// and Poiseuille across a refined band, the time step from the finest cells.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "adapt_problems.hpp"
#include "flow/navier_stokes.hpp"
#include "navier_stokes_problems.hpp"
#include "poisson_problems.hpp"

namespace sanguis::flow {
namespace {

using testing::all_periodic;
using testing::cell_centre;
using testing::channel;
using testing::kPi;
using testing::periodic_cube;
using testing::refine_where;
using testing::rough;
using testing::total;

/// Periodic unit cube, 16^3 cells in 8 blocks, the two blocks at x, y < 1/2
/// refined: coarse-fine faces along x and y, edges and corners included.
void refine_two_blocks(Forest& forest) {
  refine_where(forest, [](const Vec3& c) { return c.x < 0.5 && c.y < 0.5; });
}

TEST(FlowRefinedNavierStokes, ProjectionLeavesEveryCellDivergenceFree) {
  Forest forest(periodic_cube());
  refine_two_blocks(forest);
  ASSERT_EQ(forest.max_level(), forest.min_level() + 1);
  NavierStokesOptions options;
  options.pressure.tolerance = 1e-13;
  options.pressure.max_cycles = 100;
  NavierStokes ns(forest, all_periodic(), Fluid{1.0, 0.0}, options);
  ns.set_velocity([](const Vec3& x) { return Vec3{rough(x, 1), rough(x, 2), rough(x, 3)}; });
  ASSERT_TRUE(ns.last_pressure_report().converged);
  // The velocities are O(1) on cells of h = 1/32: an unprojected field has
  // |div uf| ~ 1/h = 32. The discrete divergence of every cell, coarse cells
  // beside coarse-fine faces included, equals the composite multigrid's
  // residual (driven to 1e-13 of the rhs or the 1e-12 max|uf|/h floor of
  // project()): 1e-9 leaves a factor ~30 for the max against the RMS norm.
  const double divergence = ns.max_divergence();
  std::printf("refined projection: max |div uf| %.2e after %d V-cycles\n", divergence,
              ns.last_pressure_report().cycles);
  EXPECT_LT(divergence, 1e-9);
}

TEST(FlowRefinedNavierStokes, TracerAndFluxesAreConservedAcrossCoarseFineFaces) {
  Forest forest(periodic_cube());
  refine_two_blocks(forest);
  NavierStokesOptions options;
  options.pressure.tolerance = 1e-10;
  options.viscous.tolerance = 1e-10;
  NavierStokes ns(forest, all_periodic(), Fluid{1.0, 0.01}, options);
  // A 3D flow through the coarse-fine faces (ABC flow), a tracer blob on the interface.
  ns.set_velocity([](const Vec3& x) {
    const double k = 2 * kPi;
    return Vec3{std::sin(k * x.z) + std::cos(k * x.y), std::sin(k * x.x) + std::cos(k * x.z),
                std::sin(k * x.y) + std::cos(k * x.x)};
  });
  BlockField tracer(forest.local_blocks(), forest.block_cells());
  testing::fill_cells(forest, tracer, [](const Vec3& x) {
    const double r2 =
        (x.x - 0.5) * (x.x - 0.5) + (x.y - 0.3) * (x.y - 0.3) + (x.z - 0.5) * (x.z - 0.5);
    return 1.0 + std::exp(-r2 / 0.02);
  });
  const double before = total(forest, tracer);
  double worst_divergence = 0.0;
  for (int s = 0; s < 40; ++s) {
    const double dt = ns.stable_dt();
    ns.step(dt);
    ns.advect_scalar(tracer, dt);
    worst_divergence = std::max(worst_divergence, ns.max_divergence());
  }
  const double drift = std::abs(total(forest, tracer) / before - 1.0);
  std::printf("refined tracer: relative change of the total over 40 steps %.2e, max |div| %.2e\n",
              drift, worst_divergence);
  // Each step adds and removes the same face fluxes: only round-off of the
  // sums (~1e-16 per step on O(1) values, 6000 cells) remains.
  EXPECT_LT(drift, 1e-13);
  EXPECT_LT(worst_divergence, 1e-6);  // projection tolerance 1e-10 of |div| ~ 1/h
}

TEST(FlowRefinedNavierStokes, TimeStepFollowsTheCflConditionOnTheFinestCells) {
  Forest forest(periodic_cube());
  refine_two_blocks(forest);
  NavierStokesOptions options;
  options.cfl = 0.8;
  NavierStokes ns(forest, all_periodic(), Fluid{1.0, 0.0}, options);
  ns.set_velocity([](const Vec3&) { return Vec3{1.0, 0.0, 0.0}; });
  // A uniform flow moves as fast on the coarse cells (h = 1/16) as on the
  // fine ones (h = 1/32): the fine cells set dt = cfl h_fine / |u| = 0.025.
  EXPECT_NEAR(ns.stable_dt(), 0.8 / 32.0, 1e-14);
}

TEST(FlowRefinedNavierStokes, TwoThreadsGiveTheOneThreadAnswerBitForBit) {
  auto run = [](int threads) {
    ForestSpec spec = periodic_cube();
    spec.threads = threads;
    Forest forest(spec);
    refine_two_blocks(forest);
    NavierStokes ns(forest, all_periodic(), Fluid{1.0, 0.01});
    ns.set_velocity([](const Vec3& x) { return Vec3{rough(x, 1), rough(x, 2), rough(x, 3)}; });
    BlockField tracer(forest.local_blocks(), forest.block_cells());
    testing::fill_cells(forest, tracer, [](const Vec3& x) { return rough(x, 4); });
    for (int s = 0; s < 3; ++s) {
      ns.step(0.005);
      ns.advect_scalar(tracer, 0.005);
    }
    std::vector<double> values(tracer.raw().begin(), tracer.raw().end());
    for (const auto& u : ns.velocity()) values.insert(values.end(), u.raw().begin(), u.raw().end());
    return values;
  };
  const auto one = run(1);
  const auto two = run(2);
  ASSERT_EQ(one.size(), two.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < one.size(); ++i) differ += one[i] != two[i] ? 1 : 0;
  EXPECT_EQ(differ, 0u);  // every block's work is independent of the thread doing it
}

/// Max and RMS (volume-weighted) velocity error of the Taylor-Green vortex
/// (unit square, periodic, one tree thick in z; `trees`^2 trees of 8^3-cell
/// blocks at `level`, the central quarter [1/4, 3/4]^2 refined once if
/// `refine_centre`) at t = 1/32 with dt = 1/512 on every grid, so that only
/// the space discretisation differs.
struct TaylorGreenError {
  double max = 0.0, rms = 0.0;
  Vec3 worst_at{};          ///< centre of the cell with the largest error (this rank's)
  int worst_level = 0;      ///< its block's level
  int worst_component = 0;  ///< and the velocity component
};

/// The periodic unit square, one tree thick in z: trees^2 trees of
/// `block_cells`^3-cell blocks at `level`.
ForestSpec unit_square(int trees, int level, int block_cells) {
  ForestSpec spec;
  spec.trees = {trees, trees, 1};
  spec.tree_length = 1.0 / trees;
  spec.block_cells = block_cells;
  spec.level = level;
  spec.periodic = {true, true, true};
  return spec;
}

/// Refines once the blocks whose centre lies in the central quarter [1/4, 3/4]^2.
void refine_central_quarter(Forest& forest) {
  refine_where(forest, [](const Vec3& c) {
    return std::abs(c.x - 0.5) < 0.25 && std::abs(c.y - 0.5) < 0.25;
  });
}

/// Max and RMS (volume-weighted) difference between the cell velocities and
/// exact(x) at the cell centres, over all ranks.
template <typename Exact>
TaylorGreenError velocity_error(const Forest& forest, const NavierStokes& ns, Exact&& exact) {
  TaylorGreenError e;
  double sum = 0.0, volume = 0.0;
  const int b = forest.block_cells();
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const double h = forest.block(blk).length / b;
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          const Vec3 u = exact(cell_centre(forest, blk, i, j, k));
          for (int c = 0; c < 3; ++c) {
            const double err =
                std::abs(ns.velocity()[static_cast<std::size_t>(c)](blk, i, j, k) - u[c]);
            if (err > e.max) {
              e.max = err;
              e.worst_at = cell_centre(forest, blk, i, j, k);
              e.worst_level = forest.block(blk).level;
              e.worst_component = c;
            }
            sum += err * err * h * h * h;
          }
          volume += h * h * h;
        }
  }
  e.max = forest.max(e.max);
  e.rms = std::sqrt(forest.sum(sum) / forest.sum(volume));
  return e;
}

TaylorGreenError taylor_green_error(int trees, int level, bool refine_centre,
                                    bool level_matched = false, bool refine_centre_twice = false) {
  const double nu = 0.01, t_end = 1.0 / 32.0;
  const int steps = 16;
  Forest forest(unit_square(trees, level, 8));
  if (refine_centre) refine_central_quarter(forest);
  if (refine_centre_twice) {  // the central eighth once more: three levels
    refine_where(forest, [](const Vec3& c) {
      return std::abs(c.x - 0.5) < 0.125 && std::abs(c.y - 0.5) < 0.125;
    });
  }
  NavierStokesOptions options = testing::taylor_green_options();
  options.level_matched_advection = level_matched;
  NavierStokes ns(forest, all_periodic(), Fluid{1.0, nu}, options);
  auto exact = [nu](const Vec3& x, double t) { return testing::taylor_green_velocity(x, nu, t); };
  ns.set_velocity([&](const Vec3& x) { return exact(x, 0.0); });
  for (int s = 0; s < steps; ++s) ns.step(t_end / steps);
  EXPECT_LT(ns.max_divergence(), 1e-7);
  return velocity_error(forest, ns, [&](const Vec3& x) { return exact(x, ns.time()); });
}

TEST(FlowRefinedNavierStokes, TaylorGreenWithARefinedCentreConvergesAtSecondOrder) {
  const TaylorGreenError coarse = taylor_green_error(4, 0, false);   // 32^2
  const TaylorGreenError fine = taylor_green_error(4, 1, false);     // 64^2
  const TaylorGreenError refined = taylor_green_error(4, 0, true);   // 32^2, 64^2 centre
  const TaylorGreenError refined2 = taylor_green_error(8, 0, true);  // 64^2, 128^2 centre
  std::printf(
      "Taylor-Green (nu 0.01, t 1/32, dt 1/512), max / RMS error: 32^2 %.3e / %.3e, 64^2 %.3e / "
      "%.3e, 32^2 + 64^2 centre %.3e / %.3e, 64^2 + 128^2 centre %.3e / %.3e (orders %.2f / "
      "%.2f)\n",
      coarse.max, coarse.rms, fine.max, fine.rms, refined.max, refined.rms, refined2.max,
      refined2.rms, std::log2(refined.max / refined2.max), std::log2(refined.rms / refined2.rms));
  // Where the refined grid's error is largest (one rank): a coarse cell beside the
  // coarse-fine faces x = 1/4 or 3/4 near y = 1/2, in u, the component normal to them.
  std::printf(
      "32^2 + 64^2 centre: largest error in component %d of a level-%d cell at (%.4f, %.4f)\n",
      refined.worst_component, refined.worst_level, refined.worst_at.x, refined.worst_at.y);
  // Second order on the refined forest, interface included (measured 2.06
  // for the max, 2.07 for the RMS error).
  EXPECT_GT(std::log2(refined.max / refined2.max), 1.8);
  EXPECT_GT(std::log2(refined.rms / refined2.rms), 1.8);
  // Not better than the uniform coarse grid (issue #7, open). The
  // projection's face velocity is a face mean (face_mean), so a coarse face
  // taking the mean of the fine faces across agrees with the coarse cell's
  // other faces to higher order; with point values (the plain average of two
  // cells) they differed by O(h^2), an O(h) divergence in every coarse cell
  // along the interface, and the first projection changed the exact field
  // by 1.4e-3 there (now 1.2e-4). What remains is in the fluxes that are
  // still point values where a coarse face takes the fine mean: advection
  // and the gradient fluxes of the two multigrid operators (pressure and
  // viscosity). Measured 6.4x the coarse max error and 3.05x its RMS error
  // (7.5x and 3.4x with point values); these bounds hold the measurement so
  // that a regression shows, they are not a target.
  EXPECT_LT(refined.max, 7.0 * coarse.max);
  EXPECT_LT(refined.rms, 3.3 * coarse.rms);
  EXPECT_GT(refined.max, fine.max);
}

// NavierStokesOptions::level_matched_advection: the BCG face values of the coarse blocks
// take the finest level's leading error, so that it does not jump at the interface.
TEST(FlowRefinedNavierStokes, LevelMatchedAdvectionLeavesUniformGridsAndNarrowsTheInterfaceError) {
  // A uniform grid has no coarser block: the same run to the last bit.
  const TaylorGreenError uniform = taylor_green_error(4, 0, false);
  const TaylorGreenError uniform_matched = taylor_green_error(4, 0, false, true);
  EXPECT_EQ(uniform_matched.max, uniform.max);
  EXPECT_EQ(uniform_matched.rms, uniform.rms);
  const TaylorGreenError refined = taylor_green_error(4, 0, true);
  const TaylorGreenError matched = taylor_green_error(4, 0, true, true);   // 32^2, 64^2 centre
  const TaylorGreenError matched2 = taylor_green_error(8, 0, true, true);  // 64^2, 128^2 centre
  std::printf(
      "Taylor-Green, 32^2 + 64^2 centre, max / RMS error: %.3e / %.3e, level-matched %.3e / "
      "%.3e; 64^2 + 128^2 centre level-matched %.3e / %.3e (orders %.2f / %.2f)\n",
      refined.max, refined.rms, matched.max, matched.rms, matched2.max, matched2.rms,
      std::log2(matched.max / matched2.max), std::log2(matched.rms / matched2.rms));
  // Measured 9.29e-4 / 3.45e-4 against 1.395e-3 / 4.79e-4 (0.67x, 0.72x).
  EXPECT_LT(matched.max, 0.75 * refined.max);
  EXPECT_LT(matched.rms, 0.8 * refined.rms);
  // Still second order (measured 2.04 and 2.04).
  EXPECT_GT(std::log2(matched.max / matched2.max), 1.8);
  EXPECT_GT(std::log2(matched.rms / matched2.rms), 1.8);
  // Three levels (32^2, 64^2 centre, 128^2 central eighth): the middle level's blocks
  // take the term too, and those below a coarser block evaluate their upper faces
  // by the scalar kernel (bcg_face_value). Measured 9.46e-4 / 3.50e-4 against
  // 1.402e-3 / 4.86e-4 (0.67x, 0.72x).
  const TaylorGreenError three = taylor_green_error(4, 0, true, false, true);
  const TaylorGreenError three_matched = taylor_green_error(4, 0, true, true, true);
  std::printf("three levels: max / RMS error %.3e / %.3e, level-matched %.3e / %.3e\n", three.max,
              three.rms, three_matched.max, three_matched.rms);
  EXPECT_LT(three_matched.max, 0.8 * three.max);
  EXPECT_LT(three_matched.rms, 0.8 * three.rms);
}

/// The channel of test_navier_stokes.cpp (H = 1, 16 cells across, periodic
/// in x and z over 1/2) with its lower half refined: a coarse-fine face
/// across the flow at y = 1/2.
ForestSpec channel_spec() {
  ForestSpec spec;
  spec.trees = {1, 2, 1};
  spec.tree_length = 0.5;
  spec.periodic = {true, false, true};
  return spec;
}

void refine_lower_half(Forest& forest) {
  refine_where(forest, [](const Vec3& c) { return c.y < 0.5; });
}

/// The largest deviation of u_x from exact(y) and of u_y, u_z from 0 (all ranks).
template <typename Exact>
std::pair<double, double> profile_deviation(const Forest& forest, const NavierStokes& ns,
                                            Exact&& exact) {
  double worst = 0.0, cross = 0.0;
  const int b = forest.block_cells();
  for (int blk = 0; blk < forest.local_blocks(); ++blk)
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          const double y = cell_centre(forest, blk, i, j, k).y;
          worst = std::max(worst, std::abs(ns.velocity()[0](blk, i, j, k) - exact(y)));
          cross = std::max({cross, std::abs(ns.velocity()[1](blk, i, j, k)),
                            std::abs(ns.velocity()[2](blk, i, j, k))});
        }
  return {forest.max(worst), forest.max(cross)};
}

TEST(FlowRefinedNavierStokes, CouetteAcrossARefinedBandIsExactlyLinear) {
  Forest forest(channel_spec());
  refine_lower_half(forest);
  ASSERT_EQ(forest.max_level(), 1);
  const double U = 1.0, H = 1.0, rho = 1.0, mu = 100.0, dt = 1e-3;
  NavierStokesOptions options;
  options.pressure.tolerance = 1e-10;
  options.viscous.tolerance = 1e-10;
  NavierStokes ns(forest, channel(U), Fluid{rho, mu}, options);
  ns.set_velocity([](const Vec3&) { return Vec3{}; });
  for (int s = 0; s < 500; ++s) ns.step(dt);  // 50 diffusion times H^2 rho / mu
  const auto [worst, cross] = profile_deviation(forest, ns, [&](double y) { return U * y / H; });
  std::printf("Couette across a refined band: max deviation %.2e, cross flow %.2e\n", worst, cross);
  // A linear profile is a discrete steady state on both levels: the
  // quadratic ghost interpolation and the flux matching are exact for it.
  // The same bounds as the uniform test (viscous solves to 1e-10).
  EXPECT_LT(worst, 1e-9);
  EXPECT_LT(cross, 1e-10);
}

TEST(FlowRefinedNavierStokes, PoiseuilleFlowRateAcrossARefinedBand) {
  Forest forest(channel_spec());
  refine_lower_half(forest);
  const double G = 2.0, mu = 1.0, H = 1.0;
  NavierStokesOptions options;
  options.dt_max = 0.01;
  options.viscous.tolerance = 1e-10;
  NavierStokes ns(forest, channel(0.0), Fluid{1.0, mu}, options);
  ns.set_velocity([](const Vec3&) { return Vec3{}; });
  ns.set_body_force([G](const Vec3&) { return Vec3{G, 0.0, 0.0}; });
  for (int s = 0; s < 300; ++s) ns.step(ns.stable_dt());  // 3 diffusion times
  const int b = forest.block_cells();
  double flux = 0.0, worst = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const double h = forest.block(blk).length / b;
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          const double y = cell_centre(forest, blk, i, j, k).y;
          const double u = ns.velocity()[0](blk, i, j, k);
          flux += u * h * h * h;
          worst = std::max(worst, std::abs(u - G / (2 * mu) * y * (H - y)));
        }
  }
  const double flow_rate = forest.sum(flux) / (0.5 * 0.5);  // per unit width
  const double exact = G * H * H * H / (12 * mu);
  std::printf(
      "Poiseuille across a refined band: flow rate %.6f exact %.6f (rel. error %.2e), max "
      "profile error %.2e\n",
      flow_rate, exact, std::abs(flow_rate / exact - 1), forest.max(worst));
  // The parabola is a discrete steady state on both levels (the 3-point
  // Laplacian, the quadratic wall closure and the quadratic coarse-fine
  // interpolation are exact for it; measured 8e-12 after 3 diffusion times,
  // the decay of the start-up transient and the 1e-10 viscous tolerance).
  EXPECT_LT(forest.max(worst), 1e-10);
  // The flow rate from cell-centre values is then the midpoint rule, high
  // (the parabola is concave) by h^2/(2 H^2) relative: 1/512 on the coarse
  // half, 1/2048 on the fine half, 1.2207e-3 in all (measured 1.2207e-3;
  // the 1e-8 covers the 8e-12 profile error).
  EXPECT_NEAR(flow_rate / exact - 1.0, 0.5 * (1.0 / 512 + 1.0 / 2048), 1e-8);
  EXPECT_LT(ns.max_divergence(), 1e-8);
}

/// The channel with its lower half refined, lid U = 1, the viscosity mu(x),
/// run 400 steps to the steady state: profile_deviation from exact(y).
template <typename Viscosity, typename Exact>
std::pair<double, double> layered_couette(Viscosity&& mu, Exact&& exact) {
  Forest forest(channel_spec());
  refine_lower_half(forest);
  NavierStokesOptions options;
  options.dt_max = 0.01;
  options.pressure.tolerance = 1e-10;
  options.viscous.tolerance = 1e-10;
  NavierStokes ns(forest, channel(1.0), Fluid{1.0, 1.0}, options);
  ns.set_viscosity(mu);
  ns.set_velocity([](const Vec3&) { return Vec3{}; });
  for (int s = 0; s < 400; ++s) ns.step(ns.stable_dt());
  return profile_deviation(forest, ns, exact);
}

TEST(FlowRefinedNavierStokes, LayeredCouetteWithViscosityJumpsOnBothLevelsIsExact) {
  // mu = 1, 4, 2 in the layers y < 1/4 (fine cells), 1/4 < y < 3/4 (across
  // the coarse-fine face at y = 1/2), y > 3/4 (coarse cells); the jumps lie
  // on faces. Steady: one shear stress tau = U / sum(thickness / mu) = 2,
  // u piecewise linear: 2y, 1/2 + (y - 1/4)/2, y.
  const auto [worst, cross] = layered_couette(
      [](const Vec3& x) { return x.y < 0.25 ? 1.0 : (x.y < 0.75 ? 4.0 : 2.0); },
      [](double y) { return y < 0.25 ? 2.0 * y : (y < 0.75 ? 0.5 + (y - 0.25) / 2 : y); });
  std::printf("layered Couette across a refined band: max deviation %.2e, cross flow %.2e\n", worst,
              cross);
  // The harmonic face viscosity passes the stress exactly through a jump on
  // a face (as on the uniform grid) and the profile at the coarse-fine face
  // is linear: a discrete steady state on both levels.
  EXPECT_LT(worst, 1e-8);
  EXPECT_LT(cross, 1e-10);
}

TEST(FlowRefinedNavierStokes, AViscosityJumpBesideTheCoarseFineFaceStaysPositive) {
  // mu = 1 up to y = 9/16, 5 above: the jump lies on the face between the first
  // and second coarse cells above the coarse-fine face at y = 1/2. The fine
  // block's ghost there, the quadratic interpolant of the coarse cells 1, 5, 5,
  // would be -0.625 and the harmonic face viscosity -3.3 (anti-diffusion:
  // the viscous multigrid diverged to NaN in the first step). Clamped to the
  // field's range [1, 5] it is 1, the coarse cell's own value. The steady
  // profile, tau = U / (9/16 + (7/16) / 5), is then exact except for the
  // quadratic coarse-to-fine interpolation of the velocity across its kink
  // at y = 9/16, one coarse cell from the fine block: an O(h) error there,
  // measured 2.7e-3 (of u ~ 1).
  const double tau = 1.0 / (0.5625 + 0.4375 / 5.0);
  const auto [worst, cross] = layered_couette(
      [](const Vec3& x) { return x.y < 0.5625 ? 1.0 : 5.0; },
      [tau](double y) { return y < 0.5625 ? tau * y : tau * (0.5625 + (y - 0.5625) / 5.0); });
  std::printf("viscosity jump beside the coarse-fine face: max deviation %.2e, cross flow %.2e\n",
              worst, cross);
  EXPECT_LT(worst, 1e-2);
}

TEST(FlowRefinedNavierStokes, ViscousForceIntegratesToZeroOnAPeriodicRefinedForest) {
  // Periodic cube with two refined blocks, a rough velocity and mu varying in
  // all three directions across the coarse-fine faces: the viscous force
  // density is the divergence of face fluxes that the two sides of every
  // face share (the coarse face takes the fine faces' mean), so its volume
  // integral vanishes to round-off. This is the explicit part of the step
  // (the grad u^T stress, the Crank-Nicolson half).
  Forest forest(periodic_cube());
  refine_two_blocks(forest);
  NavierStokes ns(forest, all_periodic(), Fluid{1.0, 1.0});
  ns.set_viscosity([](const Vec3& x) {
    return 1.0 + 0.8 * std::sin(2 * kPi * x.x) * std::cos(2 * kPi * x.y) * std::cos(2 * kPi * x.z);
  });
  ns.set_velocity([](const Vec3& x) { return Vec3{rough(x, 1), rough(x, 2), rough(x, 3)}; });
  const VectorField force = ns.viscous_force_density();
  Vec3 integral, magnitude;
  const int b = forest.block_cells();
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const double h = forest.block(blk).length / b;
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i)
          for (int c = 0; c < 3; ++c) {
            integral[c] += force[static_cast<std::size_t>(c)](blk, i, j, k) * h * h * h;
            magnitude[c] += std::abs(force[static_cast<std::size_t>(c)](blk, i, j, k)) * h * h * h;
          }
  }
  const double worst = std::max({std::abs(integral.x), std::abs(integral.y), std::abs(integral.z)});
  const double scale = std::max({magnitude.x, magnitude.y, magnitude.z});
  std::printf("refined cube: integral of the viscous force %.2e against its |.| integral %.2e\n",
              worst, scale);
  ASSERT_GT(scale, 100.0);  // rough velocity on h = 1/32: large, cancelling forces
  // Measured 1.0e-14 against 1.8e3; with each block evaluating its own side
  // of the coarse-fine faces (fluxes not matched) the integral was 5.2.
  EXPECT_LT(worst, 1e-13 * scale);
}

/// Max and RMS velocity error of a steady shear flow u = (sin 2 pi y, 0, 0)
/// with mu = 1 + sin(2 pi x) / 2, held by the body force
/// f = -div(mu (grad u + grad u^T)) = (4 pi^2 mu sin 2 pi y, -mu' 2 pi cos 2 pi y, 0):
/// the grad u^T stress gives f_y, which is no gradient, so a solver without it
/// (or with it mismatched at coarse-fine faces) ends at another flow. Unit
/// square periodic, half a unit thick, blocks of 4^3 cells; the central
/// quarter refined once if asked.
TaylorGreenError variable_viscosity_shear_error(int level, bool refine_centre) {
  Forest forest(unit_square(2, level, 4));
  if (refine_centre) refine_central_quarter(forest);
  NavierStokesOptions options;
  options.dt_max = 0.02;
  options.pressure.tolerance = 1e-11;
  options.viscous.tolerance = 1e-11;
  NavierStokes ns(forest, all_periodic(), Fluid{1.0, 1.0}, options);
  const double k = 2 * kPi;
  ns.set_viscosity([k](const Vec3& x) { return 1.0 + 0.5 * std::sin(k * x.x); });
  ns.set_body_force([k](const Vec3& x) {
    const double mu = 1.0 + 0.5 * std::sin(k * x.x), dmu = 0.5 * k * std::cos(k * x.x);
    return Vec3{mu * k * k * std::sin(k * x.y), -dmu * k * std::cos(k * x.y), 0.0};
  });
  auto exact = [k](const Vec3& x) { return Vec3{std::sin(k * x.y), 0.0, 0.0}; };
  ns.set_velocity(exact);
  // From the exact field to the discrete steady state: the slowest mode
  // decays as exp(-4 pi^2 mu_min t), e^-30 by t = 1.5.
  for (int s = 0; s < 75; ++s) ns.step(0.02);
  return velocity_error(forest, ns, exact);
}

TEST(FlowRefinedNavierStokes, VariableViscosityShearFlowWithARefinedCentreConverges) {
  const auto coarse = variable_viscosity_shear_error(1, false);  // 16 x 16 x 8
  const auto refined = variable_viscosity_shear_error(1, true);
  const auto fine = variable_viscosity_shear_error(2, false);  // 32 x 32 x 16
  std::printf(
      "variable-mu shear flow: max / RMS error coarse %.3e / %.3e, refined centre %.3e / %.3e, "
      "fine %.3e / %.3e\n",
      coarse.max, coarse.rms, refined.max, refined.rms, fine.max, fine.rms);
  // Second order on the uniform grids.
  EXPECT_GT(coarse.max / fine.max, 3.5);
  EXPECT_GT(coarse.rms / fine.rms, 3.5);
  // The level jumps add no error of lower order: the refined centre stays
  // near the coarse grid it refines (measured 0.95x in the max norm, 1.19x
  // RMS; the largest errors sit at the refined square's corners, as in the
  // Taylor-Green test). The error of the steady state is global, so
  // refining a quarter does not buy a quarter's worth. With the grad u^T
  // fluxes evaluated by each block on its own side of the coarse-fine faces
  // (not matched), the refined run was 2.6x (max) and 5.7x (RMS) worse.
  // Before the projection took face means (face_mean) the ratios were 0.91x
  // and 1.02x: every error fell (coarse 3.95e-2 / 1.74e-2 -> 3.29e-2 /
  // 1.46e-2, refined 3.58e-2 / 1.78e-2 -> 3.13e-2 / 1.74e-2), the uniform
  // grid's most, and the viscous operator's point-valued fluxes at the
  // coarse-fine faces (issue #7, open) now show in the RMS ratio.
  EXPECT_LT(refined.max, 1.1 * coarse.max);
  EXPECT_LT(refined.rms, 1.25 * coarse.rms);
}

}  // namespace
}  // namespace sanguis::flow
