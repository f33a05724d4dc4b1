// Navier-Stokes on a forest of blocks: Taylor-Green vortex (second-order
// convergence in space and time), plane Poiseuille (flow rate and profile),
// square duct (flow rate and profile against the series), Couette at Re = 0.01 with the
// implicit viscous step (exact linear profile, stable), exact divergence of
// the face velocity.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <vector>

#include "flow/navier_stokes.hpp"
#include "navier_stokes_problems.hpp"
#include "poisson_problems.hpp"

namespace sanguis::flow {
namespace {

using testing::all_periodic;
using testing::cell_centre;
using testing::channel;
using testing::kPi;
using testing::rough;
using testing::total;

/// The unit square with `cells` cells per side, periodic, one block thick in z.
Forest taylor_green_forest(int cells) {
  ForestSpec spec;
  spec.block_cells = 8;
  spec.trees = {cells / 8, cells / 8, 1};
  spec.tree_length = 1.0 / (cells / 8);
  spec.periodic = {true, true, true};
  return Forest(spec);
}

/// Taylor-Green vortex in the unit square (periodic, one block thick in z),
/// max velocity error at t_end with dt proportional to h.
double taylor_green_error(int cells, double nu, double t_end) {
  const Forest forest = taylor_green_forest(cells);
  NavierStokes ns(forest, all_periodic(), Fluid{1.0, nu}, testing::taylor_green_options());
  auto exact = [nu](const Vec3& x, double t) { return testing::taylor_green_velocity(x, nu, t); };
  ns.set_velocity([&](const Vec3& x) { return exact(x, 0.0); });
  const double h = 1.0 / cells;
  const int steps = static_cast<int>(std::lround(t_end / (0.25 * h)));
  const double dt = t_end / steps;
  for (int s = 0; s < steps; ++s) ns.step(dt);
  EXPECT_LT(ns.max_divergence(), 1e-7);
  double error = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk)
    for (int k = 0; k < 8; ++k)
      for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i) {
          const Vec3 e = exact(cell_centre(forest, blk, i, j, k), ns.time());
          for (int c = 0; c < 3; ++c)
            error = std::max(error, std::abs(ns.velocity()[c](blk, i, j, k) - e[c]));
        }
  return forest.max(error);
}

TEST(FlowNavierStokes, TaylorGreenVortexConvergesAtSecondOrder) {
  const double e16 = taylor_green_error(16, 0.01, 0.25);
  const double e32 = taylor_green_error(32, 0.01, 0.25);
  const double e64 = taylor_green_error(64, 0.01, 0.25);
  std::printf(
      "Taylor-Green (nu 0.01, t 0.25, dt = h/4): max error 16^2 %.3e, 32^2 %.3e, 64^2 %.3e, "
      "orders %.2f %.2f\n",
      e16, e32, e64, std::log2(e16 / e32), std::log2(e32 / e64));
  EXPECT_GT(std::log2(e32 / e64), 1.8);
}

/// The velocity components of every cell of the Taylor-Green vortex on a
/// `cells`^2 grid after t_end in `steps` equal steps.
std::vector<double> taylor_green_after(int cells, int steps, double nu, double t_end) {
  const Forest forest = taylor_green_forest(cells);
  NavierStokes ns(forest, all_periodic(), Fluid{1.0, nu}, testing::taylor_green_options());
  ns.set_velocity([nu](const Vec3& x) { return testing::taylor_green_velocity(x, nu, 0.0); });
  for (int s = 0; s < steps; ++s) ns.step(t_end / steps);
  std::vector<double> values;
  for (int blk = 0; blk < forest.local_blocks(); ++blk)
    for (int k = 0; k < 8; ++k)
      for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i)
          for (int c = 0; c < 2; ++c) values.push_back(ns.velocity()[c](blk, i, j, k));
  return values;
}

/// The largest difference between two runs' values (same grid).
double max_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double worst = 0.0;
  for (std::size_t n = 0; n < a.size(); ++n) worst = std::max(worst, std::abs(a[n] - b[n]));
  return worst;
}

// The test above refines space and time together. Two runs on one grid with
// dt and dt/2 differ by the time error alone (the dt-independent O(h^2)
// error cancels; terms in both h and dt stay). At a fixed Courant number
// (0.8 at the peak speed 1, dt = 0.8 h) it shrinks at second order as the
// grid is refined. That cannot tell O(dt^2) from O(h dt), both h^2 there: at
// a fixed grid the order in time is below 2 and falls as dt shrinks (32^2:
// 1.59, 1.44, 1.18 from 10 to 160 steps; 64^2: 1.71, 1.54 from 20), a
// first-order part that shrinks about as h^2 (docs/validation/flow.md,
// "Taylor-Green: the time error"). The 64^2 grid's first pair is pinned.
TEST(FlowNavierStokes, TaylorGreenTimeErrorShrinksAtSecondOrderAtAFixedCourantNumber) {
  const double nu = 0.01, t_end = 0.25;
  const double e32 =
      max_difference(taylor_green_after(32, 10, nu, t_end), taylor_green_after(32, 20, nu, t_end));
  const auto u64_40 = taylor_green_after(64, 40, nu, t_end);
  const double e64 = max_difference(taylor_green_after(64, 20, nu, t_end), u64_40);
  const double e64_half = max_difference(u64_40, taylor_green_after(64, 80, nu, t_end));
  std::printf(
      "Taylor-Green (nu 0.01, t 0.25): time error max |u(dt) - u(dt/2)| at dt = 0.8 h: 32^2 "
      "%.3e, 64^2 %.3e, order %.2f; on 64^2 at dt = 0.4 h %.3e (order in time %.2f)\n",
      e32, e64, std::log2(e32 / e64), e64_half, std::log2(e64 / e64_half));
  EXPECT_GT(std::log2(e32 / e64), 1.8);
  EXPECT_GT(std::log2(e64 / e64_half), 1.5);
}

/// The 3D Arnold-Beltrami-Childress flow on the periodic unit cube, an exact
/// decaying Navier-Stokes solution (u x curl u = 0: the advection is a
/// pressure gradient): max velocity error at t_end with dt = h/5.
double abc_flow_error(int cells, double nu, double t_end) {
  ForestSpec spec;
  spec.level = cells == 16 ? 1 : 2;
  spec.periodic = {true, true, true};
  const Forest forest(spec);
  NavierStokesOptions options;
  options.viscous_theta = 0.5;
  options.pressure.tolerance = 1e-10;
  options.viscous.tolerance = 1e-10;
  NavierStokes ns(forest, all_periodic(), Fluid{1.0, nu}, options);
  auto exact = [nu](const Vec3& x, double t) {
    const double k = 2 * kPi, decay = std::exp(-k * k * nu * t);
    return Vec3{std::sin(k * x.z) + std::cos(k * x.y), std::sin(k * x.x) + std::cos(k * x.z),
                std::sin(k * x.y) + std::cos(k * x.x)} *
           decay;
  };
  ns.set_velocity([&](const Vec3& x) { return exact(x, 0.0); });
  const int steps = static_cast<int>(std::lround(t_end * cells * 5.0));
  for (int s = 0; s < steps; ++s) ns.step(t_end / steps);
  double error = 0.0;
  const int b = forest.block_cells();
  for (int blk = 0; blk < forest.local_blocks(); ++blk)
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          const Vec3 e = exact(cell_centre(forest, blk, i, j, k), ns.time());
          for (int c = 0; c < 3; ++c)
            error = std::max(error, std::abs(ns.velocity()[c](blk, i, j, k) - e[c]));
        }
  return forest.max(error);
}

TEST(FlowNavierStokes, ThreeDimensionalBeltramiFlowConvergesAtSecondOrder) {
  const double e16 = abc_flow_error(16, 0.05, 0.1);
  const double e32 = abc_flow_error(32, 0.05, 0.1);
  std::printf(
      "ABC (Beltrami) flow 3D (nu 0.05, t 0.1, dt = h/5): max error 16^3 %.3e, 32^3 %.3e, order "
      "%.2f\n",
      e16, e32, std::log2(e16 / e32));
  EXPECT_GT(std::log2(e16 / e32), 1.8);
}

/// Mean over x and z of u_x at cell row j of the channel (y cells = 16).
std::vector<double> profile(const Forest& forest, const NavierStokes& ns, int rows) {
  std::vector<double> sum(static_cast<std::size_t>(rows), 0.0),
      count(static_cast<std::size_t>(rows), 0.0);
  const int b = forest.block_cells();
  for (int blk = 0; blk < forest.local_blocks(); ++blk)
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          const auto row = static_cast<std::size_t>(forest.block(blk).coord[1] * b + j);
          sum[row] += ns.velocity()[0](blk, i, j, k);
          count[row] += 1.0;
        }
  for (std::size_t r = 0; r < sum.size(); ++r) sum[r] = forest.sum(sum[r]) / forest.sum(count[r]);
  return sum;
}

Forest make_channel_forest() {
  ForestSpec spec;
  spec.trees = {1, 2, 1};
  spec.tree_length = 0.5;  // H = 1, 16 cells across
  spec.periodic = {true, false, true};
  return Forest(spec);
}

TEST(FlowNavierStokes, PlanePoiseuilleFlowRateWithinHalfAPercentAt16CellsAcross) {
  const Forest forest = make_channel_forest();
  const double G = 2.0, mu = 1.0, H = 1.0;  // body force density (= -dp/dx), viscosity
  NavierStokesOptions options;
  options.dt_max = 0.01;
  options.viscous.tolerance = 1e-10;
  NavierStokes ns(forest, channel(0.0), Fluid{1.0, mu}, options);
  ns.set_velocity([](const Vec3&) { return Vec3{}; });
  ns.set_body_force([G](const Vec3&) { return Vec3{G, 0.0, 0.0}; });
  for (int s = 0; s < 300; ++s) ns.step(ns.stable_dt());  // 3 diffusion times H^2 rho/mu
  const auto u = profile(forest, ns, 16);
  const double h = H / 16;
  double flow_rate = 0.0, worst = 0.0;
  for (int j = 0; j < 16; ++j) {
    const double y = (j + 0.5) * h;
    flow_rate += u[static_cast<std::size_t>(j)] * h;
    worst = std::max(worst, std::abs(u[static_cast<std::size_t>(j)] - G / (2 * mu) * y * (H - y)));
  }
  const double exact = G * H * H * H / (12 * mu);
  std::printf("Poiseuille: flow rate %.6f exact %.6f (rel. error %.2e), max profile error %.2e\n",
              flow_rate, exact, std::abs(flow_rate / exact - 1), worst);
  EXPECT_LT(std::abs(flow_rate / exact - 1.0), 5e-3);  // the midpoint sum's O(h^2)
  // The cell-centred Laplacian with the walls' closure is exact for the
  // parabola: the steady profile matches it at every cell centre, to the
  // solvers' tolerance (the peak speed is G H^2 / 8 mu = 0.25).
  EXPECT_LT(worst, 1e-9);
  EXPECT_LT(ns.max_divergence(), 1e-8);
}

TEST(FlowNavierStokes, CouetteAtReynolds0p01IsExactlyLinearAndStable) {
  const Forest forest = make_channel_forest();
  const double U = 1.0, H = 1.0, rho = 1.0;
  const double mu = rho * U * H / 0.01;  // Re = rho U H / mu = 0.01
  const double dt = 1e-3 * H / U;        // shear rate x dt = 1e-3
  NavierStokesOptions options;
  options.pressure.tolerance = 1e-10;
  options.viscous.tolerance = 1e-10;
  NavierStokes ns(forest, channel(U), Fluid{rho, mu}, options);
  ns.set_velocity([](const Vec3&) { return Vec3{}; });
  // The diffusion time H^2 rho / mu = 0.01 = 10 dt: 500 steps reach steady
  // state, at a viscous number mu dt / (rho h^2) = 25.6 (explicit limit 1/6).
  double worst = 0.0;
  for (int s = 0; s < 500; ++s) ns.step(dt);
  const auto u = profile(forest, ns, 16);
  for (int j = 0; j < 16; ++j) {
    const double y = (j + 0.5) / 16.0 * H;
    worst = std::max(worst, std::abs(u[static_cast<std::size_t>(j)] - U * y / H));
  }
  double vmax = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk)
    for (int k = 0; k < 8; ++k)
      for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i)
          vmax = std::max({vmax, std::abs(ns.velocity()[1](blk, i, j, k)),
                           std::abs(ns.velocity()[2](blk, i, j, k))});
  std::printf(
      "Couette Re 0.01: max deviation from the linear profile %.2e (U = 1), cross flow %.2e\n",
      worst, vmax);
  EXPECT_LT(worst, 1e-9);
  EXPECT_LT(forest.max(vmax), 1e-10);
}

/// The flow rate of the series of square_duct_errors for a square duct of side 1.
double square_duct_series_rate(double G, double mu) {
  const double half = 0.5;
  double series = 0.0;
  for (int i = 1; i < 200; i += 2) series += std::tanh(i * kPi / 2.0) / std::pow(i, 5);
  return 4.0 * half * half * half * half * G / (3.0 * mu) *
         (1.0 - 192.0 / std::pow(kPi, 5) * series);
}

/// Steady flow in a square duct of side 1 (walls at y, z = 0 and 1),
/// periodic along x, driven by a body force G, with `cells` cells across:
/// the flow rate's relative error and the largest error of the cell-centre
/// profile relative to the peak speed, both against the series solution of
/// White (Viscous Fluid Flow, eq. 3-48) for the half-sides b = c = 1/2:
///   u = 16 c^2 G / (mu pi^3) sum_{i odd} (-1)^((i-1)/2)
///       [1 - cosh(i pi y'/2c) / cosh(i pi b/2c)] cos(i pi z'/2c) / i^3,
///   Q = 4 b c^3 G / (3 mu) [1 - 192 c / (pi^5 b) sum_{i odd} tanh(i pi b/2c) / i^5],
/// y', z' from the duct's axis.
std::array<double, 2> square_duct_errors(int cells) {
  ForestSpec spec;
  spec.trees = {1, cells / 8, cells / 8};
  spec.tree_length = 8.0 / cells;  // blocks of 8 cells: one block along x
  spec.periodic = {true, false, false};
  const Forest forest(spec);
  std::array<FlowBoundary, 6> bcs{};
  bcs[face_index(0, 0)].kind = bcs[face_index(0, 1)].kind = FlowBoundaryKind::Periodic;
  const double G = 2.0, mu = 1.0, half = 0.5;
  NavierStokesOptions options;
  options.dt_max = 0.01;
  options.viscous.tolerance = 1e-10;
  options.pressure.tolerance = 1e-10;
  NavierStokes ns(forest, bcs, Fluid{1.0, mu}, options);
  ns.set_velocity([](const Vec3&) { return Vec3{}; });
  ns.set_body_force([G](const Vec3&) { return Vec3{G, 0.0, 0.0}; });
  for (int s = 0; s < 200; ++s) ns.step(ns.stable_dt());  // 2 diffusion times a^2 rho / mu
  const int b = forest.block_cells();
  const double h = 1.0 / cells, length = spec.tree_length;
  double volume_flux = 0.0;
  std::vector<double> sum(static_cast<std::size_t>(cells * cells), 0.0);
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const auto& coord = forest.block(blk).coord;
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          const double u = ns.velocity()[0](blk, i, j, k);
          volume_flux += u * h * h * h;
          sum[static_cast<std::size_t>((coord[2] * b + k) * cells + coord[1] * b + j)] += u;
        }
  }
  const double rate = forest.sum(volume_flux) / length;
  const double exact_rate = square_duct_series_rate(G, mu);
  auto exact_u = [&](double y, double z) {  // from the axis, |y|, |z| <= 1/2
    double u = 0.0;
    for (int i = 1; i < 200; i += 2) {
      const double a = i * kPi * std::abs(y) / (2 * half), w = i * kPi / 2.0;
      // cosh(a) / cosh(w) for a <= w, without overflow
      const double ratio = (std::exp(a - w) + std::exp(-a - w)) / (1.0 + std::exp(-2.0 * w));
      u += ((i / 2) % 2 == 0 ? 1.0 : -1.0) * (1.0 - ratio) * std::cos(i * kPi * z / (2 * half)) /
           (i * i * i);
    }
    return 16.0 * half * half * G / (mu * kPi * kPi * kPi) * u;
  };
  const double peak = exact_u(0.0, 0.0);
  const double cells_along_x = std::lround(length / h);
  double worst = 0.0;
  for (int k = 0; k < cells; ++k)
    for (int j = 0; j < cells; ++j) {
      const double u = forest.sum(sum[static_cast<std::size_t>(k * cells + j)]) / cells_along_x;
      worst = std::max(worst, std::abs(u - exact_u((j + 0.5) * h - half, (k + 0.5) * h - half)));
    }
  return {rate / exact_rate - 1.0, worst / peak};
}

TEST(FlowNavierStokes, SquareDuctFlowRateAndProfileMatchTheSeriesSolution) {
  const auto [rate16, profile16] = square_duct_errors(16);
  const auto [rate32, profile32] = square_duct_errors(32);
  std::printf(
      "square duct: flow rate relative error 16 x 16 cells %.2e, 32 x 32 %.2e; profile max "
      "error / peak speed %.2e, %.2e (order %.2f)\n",
      rate16, rate32, profile16, profile32, std::log2(profile16 / profile32));
  EXPECT_LT(std::abs(rate16), 5e-3);  // issue #6: within 0.5 % at 16 cells across
  EXPECT_LT(profile16, 5e-3);         // measured 2.5e-3 of the peak speed
  EXPECT_GT(std::log2(profile16 / profile32), 1.8);
}

// Well-balancing: the body force lives on faces (as in the thesis' solver),
// where the projection's pressure gradient lives, and the cell velocity is
// corrected by the mean of (force - pressure gradient) / rho over its faces.
// Water (rho = 1000) at rest in a closed box under a force density that jumps
// from 0 to -rho g stays at rest to round-off, with the hydrostatic pressure
// (rho g per metre above the jump). On faces any force that depends on z alone
// is balanced exactly; the jump lies on a plane of cell centres, where a
// force taken at cell centres instead would leave those cells g/2 of
// imbalance (their faces' pressure gradients average to rho g / 2).
TEST(FlowNavierStokes, AFluidAtRestUnderAJumpingBodyForceStaysAtRest) {
  ForestSpec spec;
  spec.level = 1;  // 16^3 cells, walls on every face
  const Forest forest(spec);
  const double rho = 1000.0, g = 9.81, h = 1.0 / 16, z_jump = 8.5 * h;  // a plane of centres
  NavierStokesOptions options;
  options.pressure.tolerance = 1e-12;
  options.viscous.tolerance = 1e-12;
  NavierStokes ns(forest, std::array<FlowBoundary, 6>{}, Fluid{rho, 0.1}, options);
  ns.set_velocity([](const Vec3&) { return Vec3{}; });
  ns.set_body_force([=](const Vec3& x) { return Vec3{0.0, 0.0, x.z > z_jump ? -rho * g : 0.0}; });
  for (int s = 0; s < 20; ++s) ns.step(0.01);
  const int b = forest.block_cells();
  double speed = 0.0, p_top = 0.0, p_bottom = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk)
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          for (int c = 0; c < 3; ++c)
            speed = std::max(speed, std::abs(ns.velocity()[c](blk, i, j, k)));
          const Vec3 x = cell_centre(forest, blk, i, j, k);
          if (x.z > 1.0 - h) p_top += ns.pressure()(blk, i, j, k);
          if (x.z < h) p_bottom += ns.pressure()(blk, i, j, k);
        }
  speed = forest.max(speed);
  const double drop = (forest.sum(p_top) - forest.sum(p_bottom)) / 256.0;  // 16^2 cells a layer
  const double hydrostatic = -rho * g * (15.5 * h - z_jump);
  std::printf(
      "water at rest under a jumping body force: max speed %.1e m/s, pressure drop %.9f Pa "
      "(hydrostatic %.9f)\n",
      speed, drop, hydrostatic);
  EXPECT_LT(speed, 1e-12);
  EXPECT_NEAR(drop, hydrostatic, 1e-9 * rho);
}

TEST(FlowNavierStokes, OpenMpThreadsOverBlocksGiveTheSameResultBitForBit) {
  auto run = [](int threads) {
    ForestSpec spec;
    spec.level = 1;  // 16^3 cells in 8 blocks
    spec.threads = threads;
    const Forest forest(spec);
    const auto bcs = testing::lid_driven_cavity();
    NavierStokes ns(forest, bcs, Fluid{1.0, 0.01});
    ns.set_velocity([](const Vec3&) { return Vec3{}; });
    for (int s = 0; s < 5; ++s) ns.step(0.02);
    return std::array<FieldStorage, 2>{ns.velocity()[0].raw(), ns.pressure().raw()};
  };
  const auto one = run(1), two = run(2);
  EXPECT_EQ(one[0], two[0]);
  EXPECT_EQ(one[1], two[1]);
}

// The block size is a layout choice: the lid-driven cavity at 32^3 gives the
// same flow with 8^3, 16^3 and 32^3 blocks, to the solvers' tolerance (only the
// multigrid hierarchy differs). From a smooth initial field: an impulsive start
// from rest amplifies the solvers' round-off differences (1.8e-8 after 5 steps,
// 1e-11 from a smooth field).
TEST(FlowNavierStokes, TheBlockSizeDoesNotChangeTheFlow) {
  constexpr int kCells = 32;
  auto run = [](int block_cells) {
    ForestSpec spec;
    spec.block_cells = block_cells;
    const int trees = kCells / block_cells;
    spec.trees = {trees, trees, trees};
    spec.tree_length = 1.0 / trees;
    const Forest forest(spec);
    const auto bcs = testing::lid_driven_cavity();
    NavierStokesOptions options;
    options.pressure.tolerance = 1e-12;
    options.viscous.tolerance = 1e-12;
    NavierStokes ns(forest, bcs, Fluid{1.0, 0.01}, options);
    ns.set_velocity([](const Vec3& x) {
      return Vec3{std::sin(kPi * x.y) * x.z, std::sin(kPi * x.x) * x.y * x.y, 0.3 * x.x * x.y};
    });
    for (int s = 0; s < 5; ++s) ns.step(0.02);
    // Every velocity component by global cell index.
    std::vector<double> u(3 * static_cast<std::size_t>(kCells) * kCells * kCells, 0.0);
    const auto global = [](double c) { return static_cast<std::size_t>(c * kCells); };
    const int b = block_cells;
    for (int blk = 0; blk < forest.local_blocks(); ++blk)
      for (int k = 0; k < b; ++k)
        for (int j = 0; j < b; ++j)
          for (int i = 0; i < b; ++i) {
            const Vec3 x = cell_centre(forest, blk, i, j, k);
            const std::size_t cell = (global(x.z) * kCells + global(x.y)) * kCells + global(x.x);
            for (int c = 0; c < 3; ++c) u[3 * cell + c] = ns.velocity()[c](blk, i, j, k);
          }
    return u;
  };
  const std::vector<double> reference = run(8);
  double largest = 0.0;
  for (double v : reference) largest = std::max(largest, std::abs(v));
  EXPECT_GT(largest, 0.5);
  for (int b : {16, 32}) {
    const std::vector<double> other = run(b);
    double worst = 0.0;
    for (std::size_t c = 0; c < other.size(); ++c) {
      worst = std::max(worst, std::abs(other[c] - reference[c]));
    }
    std::printf("cavity 32^3, blocks of %d^3 against 8^3: max |du| = %.2e\n", b, worst);
    EXPECT_LT(worst, 1e-10) << b;
  }
}

TEST(FlowNavierStokes, TwoLayerCouetteWithAViscosityJumpIsExact) {
  // mu = 1 below y = 0.5, 4 above (the jump on a face); lid U = 1 at y = 1.
  // Steady: uniform shear stress tau = U / (0.5/1 + 0.5/4) = 1.6, u piecewise linear.
  const Forest forest = make_channel_forest();
  NavierStokesOptions options;
  options.dt_max = 0.01;
  options.pressure.tolerance = 1e-10;
  options.viscous.tolerance = 1e-10;
  NavierStokes ns(forest, channel(1.0), Fluid{1.0, 1.0}, options);
  ns.set_viscosity([](const Vec3& x) { return x.y < 0.5 ? 1.0 : 4.0; });
  ns.set_velocity([](const Vec3&) { return Vec3{}; });
  for (int s = 0; s < 400; ++s) ns.step(ns.stable_dt());
  const auto u = profile(forest, ns, 16);
  const double tau = 1.6;
  double worst = 0.0;
  for (int j = 0; j < 16; ++j) {
    const double y = (j + 0.5) / 16.0;
    const double exact = y < 0.5 ? tau * y : tau * 0.5 + tau * (y - 0.5) / 4.0;
    worst = std::max(worst, std::abs(u[static_cast<std::size_t>(j)] - exact));
  }
  std::printf("two-layer Couette (viscosity ratio 4): max deviation %.2e\n", worst);
  EXPECT_LT(worst, 1e-8);
}

/// Flow through solid cell masks in a periodic box of `trees` trees of 0.5
/// at `level`, solid where `solid` says, driven along x by a body force
/// G = 2 N/m^3 (rho = mu = 1) for `steps` steps: the fluid's volume integral
/// of u over the box length (the flow rate times the depth along z for a
/// channel, the flow rate for a duct), and the largest velocity component in
/// the solids.
std::pair<double, double> masked_flow(const std::array<int, 3>& trees, int level,
                                      const std::function<bool(const Vec3&)>& solid, int steps) {
  ForestSpec spec;
  spec.trees = trees;
  spec.tree_length = 0.5;
  spec.level = level;
  spec.periodic = {true, true, true};
  const Forest forest(spec);
  NavierStokesOptions options;
  options.dt_max = 0.01;
  options.viscous.tolerance = 1e-10;
  options.pressure.tolerance = 1e-10;
  NavierStokes ns(forest, all_periodic(), Fluid{1.0, 1.0}, options);
  ns.set_solid(solid);
  ns.set_velocity([](const Vec3&) { return Vec3{}; });
  ns.set_body_force([](const Vec3&) { return Vec3{2.0, 0.0, 0.0}; });
  for (int s = 0; s < steps; ++s) ns.step(ns.stable_dt());
  const int b = forest.block_cells();
  const double h = forest.block(0).length / b;
  double flux = 0.0, inside = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk)
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          if (solid(cell_centre(forest, blk, i, j, k))) {
            for (int c = 0; c < 3; ++c)
              inside = std::max(inside, std::abs(ns.velocity()[c](blk, i, j, k)));
          } else {
            flux += ns.velocity()[0](blk, i, j, k) * h * h * h;
          }
        }
  EXPECT_LT(ns.max_divergence(), 1e-7);
  return {forest.sum(flux) / (0.5 * trees[0]), forest.max(inside)};
}

/// Channel of height 1 between two solid slabs (cell masks) in a periodic box
/// 0.5 x 1.5 x 0.5: the flow rate's relative error against G H^3 / 12 mu and
/// the largest velocity inside the solids.
std::pair<double, double> masked_channel(int level) {
  const auto [rate_depth, inside] = masked_flow(
      {1, 3, 1}, level, [](const Vec3& x) { return x.y < 0.25 || x.y > 1.25; }, 300);
  return {rate_depth / 0.5 / (2.0 / 12.0) - 1.0, inside};
}

/// The checks of a flow through solid masks, (flow rate error, largest
/// velocity in the solids) at 16 and 32 cells across: the error at 16 within
/// `bound`, second order, nothing moving in the solids.
void expect_second_order_through_masks(const char* name, const std::pair<double, double>& at16,
                                       const std::pair<double, double>& at32, double bound) {
  const auto [e16, inside16] = at16;
  const auto [e32, inside32] = at32;
  std::printf(
      "%s: flow rate error %.3e (16 across), %.3e (32), order %.2f; max velocity in solids "
      "%.1e\n",
      name, e16, e32, std::log2(std::abs(e16 / e32)), std::max(inside16, inside32));
  EXPECT_LT(std::abs(e16), bound);
  EXPECT_GT(std::log2(std::abs(e16 / e32)), 1.8);
  EXPECT_EQ(inside16, 0.0);
  EXPECT_EQ(inside32, 0.0);
}

TEST(FlowNavierStokes, SolidCellMasksActAsNoSlipWallsAtSecondOrder) {
  expect_second_order_through_masks("channel between solid masks", masked_channel(0),
                                    masked_channel(1), 0.01);
}

/// The square duct of square_duct_errors made of solid cell masks: the
/// fluid in 0.25 < y, z < 1.25 of a periodic 0.5 x 1.5 x 1.5 box, the rest
/// solid, so the duct's four edges are corners of the masks. The flow rate's
/// relative error against the series, and the largest velocity in the solids.
std::pair<double, double> masked_square_duct(int level) {
  const auto [rate, inside] = masked_flow(
      {1, 3, 3}, level,
      [](const Vec3& x) { return x.y < 0.25 || x.y > 1.25 || x.z < 0.25 || x.z > 1.25; },
      200);  // 2 diffusion times a^2 rho / mu
  return {rate / square_duct_series_rate(2.0, 1.0) - 1.0, inside};
}

// Solid masks with corners: the duct's edges, where two masked faces meet.
TEST(FlowNavierStokes, SquareDuctOfSolidMasksConvergesToTheSeriesAtSecondOrder) {
  expect_second_order_through_masks("square duct of solid masks", masked_square_duct(0),
                                    masked_square_duct(1), 0.02);
}

/// Channel 2 x 1 (x 0.5, periodic in z), walls at y = 0 and 1, parabolic
/// inflow of mean velocity 1 at x = 0, outflow at x = 2; mu = rho = 1.
/// Steady state: the same parabola everywhere, p = 12 mu U (2 - x) / H^2.
/// Returns the largest velocity and pressure errors at t = 1.5 (steady).
std::pair<double, double> inflow_outflow_errors(int level) {
  ForestSpec spec;
  spec.trees = {4, 2, 1};
  spec.tree_length = 0.5;
  spec.level = level;
  spec.periodic = {false, false, true};
  const Forest forest(spec);
  std::array<FlowBoundary, 6> bcs{};
  bcs[face_index(0, 0)].kind = FlowBoundaryKind::Inflow;
  bcs[face_index(0, 0)].inflow = [](const Vec3& x, double) {
    return Vec3{6.0 * x.y * (1.0 - x.y), 0.0, 0.0};
  };
  bcs[face_index(0, 1)].kind = FlowBoundaryKind::Outflow;
  bcs[face_index(2, 0)].kind = bcs[face_index(2, 1)].kind = FlowBoundaryKind::Periodic;
  NavierStokesOptions options;
  options.dt_max = 0.02;
  options.pressure.tolerance = 1e-8;
  options.viscous.tolerance = 1e-8;
  NavierStokes ns(forest, bcs, Fluid{1.0, 1.0}, options);
  ns.set_velocity([](const Vec3&) { return Vec3{}; });
  while (ns.time() < 1.5) ns.step(ns.stable_dt());  // 1.5 diffusion times: steady to 4e-7
  EXPECT_LT(ns.max_divergence(), 1e-6);
  const int b = forest.block_cells();
  double velocity_error = 0.0, pressure_error = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk)
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          const Vec3 x = cell_centre(forest, blk, i, j, k);
          const double u = ns.velocity()[0](blk, i, j, k), v = ns.velocity()[1](blk, i, j, k);
          velocity_error =
              std::max({velocity_error, std::abs(u - 6.0 * x.y * (1.0 - x.y)), std::abs(v)});
          pressure_error =
              std::max(pressure_error, std::abs(ns.pressure()(blk, i, j, k) - 12.0 * (2.0 - x.x)));
        }
  return {forest.max(velocity_error), forest.max(pressure_error)};
}

TEST(FlowNavierStokes, ParabolicInflowAndOutflowKeepFullyDevelopedChannelFlow) {
  const auto [u16, p16] = inflow_outflow_errors(0);
  const auto [u32, p32] = inflow_outflow_errors(1);
  std::printf(
      "inflow/outflow channel, 16 / 32 cells across: max velocity error %.2e / %.2e (U = 1, "
      "order %.2f), max pressure error %.2e / %.2e (p_in = 24)\n",
      u16, u32, std::log2(u16 / u32), p16, p32);
  EXPECT_LT(u16, 5e-3);                  // 0.5 % of the mean velocity, at the inlet
  EXPECT_LT(p16, 0.24);                  // 1 % of the inlet pressure
  EXPECT_GT(std::log2(u16 / u32), 0.9);  // the inlet error shrinks with h
}

/// The inflow faces take the mean of the profile over the face
/// (inflow_face_mean), which reads the profile beside the face centre; it
/// must read it only inside the domain: not beyond the walls, and across the
/// periodic seam one period over. A profile that is NaN outside the channel
/// would otherwise poison the run.
TEST(FlowNavierStokes, InflowFaceMeanReadsTheProfileOnlyInsideTheDomain) {
  ForestSpec spec;
  spec.trees = {2, 2, 1};
  spec.tree_length = 0.5;
  spec.periodic = {false, false, true};
  const Forest forest(spec);
  std::array<FlowBoundary, 6> bcs{};
  bcs[face_index(0, 0)].kind = FlowBoundaryKind::Inflow;
  int outside = 0;
  bcs[face_index(0, 0)].inflow = [&outside](const Vec3& x, double) {
    const bool inside = x.y >= 0.0 && x.y <= 1.0 && x.z >= 0.0 && x.z <= 0.5;
    if (!inside) ++outside;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return inside
               ? Vec3{6.0 * x.y * (1.0 - x.y) * (1.0 + 0.1 * std::sin(4.0 * kPi * x.z)), 0.0, 0.0}
               : Vec3{nan, nan, nan};
  };
  bcs[face_index(0, 1)].kind = FlowBoundaryKind::Outflow;
  bcs[face_index(2, 0)].kind = bcs[face_index(2, 1)].kind = FlowBoundaryKind::Periodic;
  NavierStokesOptions options;
  options.dt_max = 0.01;
  NavierStokes ns(forest, bcs, Fluid{1.0, 1.0}, options);
  ns.set_velocity([](const Vec3&) { return Vec3{}; });
  for (int s = 0; s < 3; ++s) ns.step(0.01);
  EXPECT_EQ(outside, 0);
  bool finite = true;
  const int b = forest.block_cells();
  for (int blk = 0; blk < forest.local_blocks(); ++blk)
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i)
          for (int c = 0; c < 3; ++c)
            finite =
                finite && std::isfinite(ns.velocity()[static_cast<std::size_t>(c)](blk, i, j, k));
  EXPECT_TRUE(finite);
}

}  // namespace
}  // namespace sanguis::flow
