// Navier-Stokes on a forest that adapts during the run (issue #7):
// NavierStokes::regrid keeps the face velocity divergence-free, carries the
// state conservatively, follows a moving feature with the wavelet criterion
// (eq. 4.11) and gives the same bits on 1 and 2 threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "adapt_problems.hpp"
#include "flow/adapt_criterion.hpp"
#include "flow/navier_stokes.hpp"
#include "navier_stokes_problems.hpp"
#include "poisson_problems.hpp"

namespace sanguis::flow {
namespace {

using testing::all_periodic;
using testing::block_centre;
using testing::cell_centre;
using testing::kPi;
using testing::periodic_cube;
using testing::rough;
using testing::total;

/// One flag per local block from a predicate on the block.
template <typename Decide>
std::vector<AdaptFlag> flags_where(const Forest& forest, Decide&& decide) {
  std::vector<AdaptFlag> flags(static_cast<std::size_t>(forest.local_blocks()));
  for (int blk = 0; blk < forest.local_blocks(); ++blk)
    flags[static_cast<std::size_t>(blk)] = decide(forest.block(blk));
  return flags;
}

/// Largest difference between the two copies of a face shared by two local
/// blocks of one level (the upper face of one, the lower face of the other).
double shared_face_mismatch(const Forest& forest, const FaceField& uf) {
  const int b = forest.block_cells();
  double worst = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk)
    for (int d = 0; d < 3; ++d) {
      const Neighbour& nb = forest.block(blk).neighbours[face_neighbour_slot(d, 1)];
      if (nb.link != Link::Local || nb.jump != LevelJump::Same) continue;
      const auto dd = static_cast<std::size_t>(d);
      for (int t2 = 0; t2 < b; ++t2)
        for (int t1 = 0; t1 < b; ++t1) {
          std::array<int, 3> upper{}, lower{};
          upper[dd] = b;
          lower[dd] = 0;
          upper[(dd + 1) % 3] = lower[(dd + 1) % 3] = t1;
          upper[(dd + 2) % 3] = lower[(dd + 2) % 3] = t2;
          worst = std::max(worst, std::abs(uf[dd](blk, upper[0], upper[1], upper[2]) -
                                           uf[dd](nb.index, lower[0], lower[1], lower[2])));
        }
    }
  return worst;
}

bool in_octant(const Block& block, double x0, double y0, double z0) {
  const Vec3 c = block_centre(block);
  return c.x > x0 && c.x < x0 + 0.5 && c.y > y0 && c.y < y0 + 0.5 && c.z > z0 && c.z < z0 + 0.5;
}

TEST(FlowAdaptiveNavierStokes, RegridKeepsTheFaceVelocityDivergenceFreeAndTheMomentum) {
  Forest forest(periodic_cube());
  NavierStokesOptions options;
  options.pressure.tolerance = 1e-13;
  options.pressure.max_cycles = 100;
  NavierStokes ns(forest, all_periodic(), Fluid{1.0, 0.0}, options);
  ns.set_velocity([](const Vec3& x) { return Vec3{rough(x, 1), rough(x, 2), rough(x, 3)}; });
  auto momentum = [&]() {
    return Vec3{total(forest, ns.velocity()[0]), total(forest, ns.velocity()[1]),
                total(forest, ns.velocity()[2])};
  };
  Vec3 before = momentum();
  double divergence_before = ns.max_divergence();
  // 1. refine one octant; 2. refine the octant beside it, whose children meet
  // the first octant's at one level (their faces there took the coarse
  // face's value: the case that needs the neighbour's values and the local
  // projection in each group of children); 3. refine the first octant again:
  // the 2:1 balance refines every coarser block beside it, whose children's
  // faces toward it took their parent's coarse value where the coarse copy
  // must now be the mean of the new fine faces across; 4. coarsen the first
  // octant back.
  const std::vector<std::pair<const char*, std::function<AdaptFlag(const Block&)>>> changes = {
      {"refine octant A",
       [](const Block& b) { return in_octant(b, 0, 0, 0) ? AdaptFlag::Refine : AdaptFlag::Keep; }},
      {"refine octant B beside A",
       [](const Block& b) {
         return b.level == 1 && in_octant(b, 0.5, 0, 0) ? AdaptFlag::Refine : AdaptFlag::Keep;
       }},
      {"refine octant A again (the balance refines the blocks beside it)",
       [](const Block& b) { return in_octant(b, 0, 0, 0) ? AdaptFlag::Refine : AdaptFlag::Keep; }},
      {"coarsen octant A",
       [](const Block& b) { return in_octant(b, 0, 0, 0) ? AdaptFlag::Coarsen : AdaptFlag::Keep; }},
  };
  const std::int64_t expected_blocks[] = {15, 22, 120, 64};
  for (std::size_t n = 0; n < changes.size(); ++n) {
    const RegridReport r = ns.regrid(forest, flags_where(forest, changes[n].second));
    const double divergence = ns.max_divergence();
    const Vec3 now = momentum();
    std::printf(
        "%s: %lld -> %lld blocks, max |div uf| %.2e before, %.2e after (%d V-cycles), momentum "
        "change %.1e\n",
        changes[n].first, static_cast<long long>(r.blocks_before),
        static_cast<long long>(r.blocks_after), divergence_before, divergence, r.projection_cycles,
        norm(now - before));
    EXPECT_TRUE(r.changed);
    EXPECT_EQ(r.blocks_after, expected_blocks[n]);
    // The carried uf is divergence-free by construction: every child cell
    // has its parent's divergence (the residual the last projection left,
    // ~1e-9 here), a parent the mean of its children's, so the regrid's
    // projection has nothing to do and the largest |div uf| does not grow
    // (round-off apart). With the two copies averaged instead, step 2 left
    // |div uf| of 11 (|uf| ~ 1, h = 1/64) to a projection of 6 V-cycles;
    // without the coarse copies made the fine mean before the local
    // projection, step 3 left 5e-10 to one of 6 V-cycles.
    EXPECT_EQ(r.projection_cycles, 0);
    EXPECT_LT(divergence, divergence_before + 1e-12);
    EXPECT_LT(divergence, 1e-8);
    // Volume-average restriction and slope-limited prolongation keep each
    // parent cell's total: the momentum moves by round-off only.
    EXPECT_LT(norm(now - before), 1e-14);
    // Both copies of every face between blocks of one level agree again.
    EXPECT_EQ(shared_face_mismatch(forest, ns.face_velocity()), 0.0);
    // A step between regrids gives the fine faces values of their own (the
    // prolonged ones are constant across each coarse face), so that the next
    // refinement meets finer blocks with different face values. The step
    // keeps the momentum of this periodic, force-free flow up to the solver
    // tolerances.
    ns.step(0.2 * ns.stable_dt());
    before = momentum();
    divergence_before = ns.max_divergence();
  }
  // A regrid that changes nothing reports so and leaves the state alone.
  const auto keep = flags_where(forest, [](const Block&) { return AdaptFlag::Keep; });
  // (Interior cells and faces 0..b: the ghost layers are refilled before use.)
  auto state = [&]() {
    std::vector<double> values;
    const int b = forest.block_cells();
    for (int blk = 0; blk < forest.local_blocks(); ++blk)
      for (int k = 0; k <= b; ++k)
        for (int j = 0; j <= b; ++j)
          for (int i = 0; i <= b; ++i) {
            if (i < b && j < b && k < b) {
              for (const auto& u : ns.velocity()) values.push_back(u(blk, i, j, k));
              values.push_back(ns.pressure()(blk, i, j, k));
            }
            const std::array<int, 3> n{i, j, k};
            for (int d = 0; d < 3; ++d) {
              const bool face = n[static_cast<std::size_t>((d + 1) % 3)] < b &&
                                n[static_cast<std::size_t>((d + 2) % 3)] < b;
              if (face)
                values.push_back(ns.face_velocity()[static_cast<std::size_t>(d)](blk, i, j, k));
            }
          }
    return values;
  };
  const std::vector<double> before_keep = state();
  EXPECT_FALSE(ns.regrid(forest, keep).changed);
  EXPECT_EQ(state(), before_keep);
  // The solver runs on the adapted forest.
  for (int s = 0; s < 3; ++s) ns.step(0.2 * ns.stable_dt());
  EXPECT_LT(ns.max_divergence(), 1e-9);
}

/// A tracer blob carried by a uniform stream through the periodic cube while
/// the wavelet criterion on the tracer refines around it and coarsens behind.
struct FollowResult {
  double mass_drift = 0.0;  ///< |total / total_0 - 1| at the end
  double worst_divergence = 0.0;
  double blob_level = 0.0;          ///< level of the block holding the blob's centre at the end
  double start_level = 0.0;         ///< level of the block at the blob's starting point at the end
  std::int64_t most_blocks = 0;     ///< largest block count during the run
  std::vector<double> state;        ///< tracer and velocity values at the end
  double viscosity_mismatch = 0.0;  ///< largest |mu(cell) - mu(centre)| at the end
};

/// A viscosity jump (ratio 10) across x = 0.52, inside cells of the coarser
/// levels, for the runs that have one.
double layered_viscosity(const Vec3& x) {
  return x.x < 0.52 ? 1e-3 : 1e-2;
}

FollowResult follow_a_blob(int threads, int steps, bool viscosity_jump = false) {
  // 64 blocks of 4^3 cells (16^3), refined once around the blob (h = 1/32).
  ForestSpec spec = periodic_cube(threads);
  spec.level = 2;
  spec.block_cells = 4;
  Forest forest(spec);
  NavierStokesOptions options;
  options.pressure.tolerance = 1e-10;
  options.viscous.tolerance = 1e-10;
  NavierStokes ns(forest, all_periodic(), Fluid{1.0, 1e-3}, options);
  if (viscosity_jump) ns.set_viscosity(layered_viscosity);
  // A stream with a shear wave on it (divergence-free, decays slowly).
  const Vec3 stream{1.0, 0.5, 0.0};
  ns.set_velocity([&](const Vec3& x) {
    return stream + Vec3{0.2 * std::sin(2 * kPi * x.y), 0.0, 0.1 * std::sin(2 * kPi * x.x)};
  });
  BlockField tracer(forest.local_blocks(), forest.block_cells());
  const Vec3 start{0.3, 0.3, 0.5};
  testing::fill_cells(forest, tracer, [&](const Vec3& x) {
    const Vec3 r = x - start;
    return 1.0 + std::exp(-dot(r, r) / 0.01);
  });
  const WaveletCriterion criterion{{1e-2}, 2, 3};
  BlockField* scalars[] = {&tracer};
  auto adapt = [&]() {
    const auto flags = wavelet_flags(forest, scalars, criterion);
    return ns.regrid(forest, flags, scalars, criterion.max_level);
  };
  for (int n = 0; n < 2; ++n) adapt();  // the initial grid around the blob
  const double before = total(forest, tracer);
  FollowResult result;
  double time = 0.0;
  for (int s = 0; s < steps; ++s) {
    const double dt = ns.stable_dt();
    ns.step(dt);
    ns.advect_scalar(tracer, dt);
    time += dt;
    if (s % 2 == 1) result.most_blocks = std::max(result.most_blocks, adapt().blocks_after);
    result.worst_divergence = std::max(result.worst_divergence, ns.max_divergence());
  }
  result.mass_drift = std::abs(total(forest, tracer) / before - 1.0);
  // Where the blob is now (periodic) and where it started.
  Vec3 centre = start + time * stream;
  for (int d = 0; d < 3; ++d) centre[d] -= std::floor(centre[d]);
  auto level_at = [&](const Vec3& x) {
    double level = 0.0;
    for (int blk = 0; blk < forest.local_blocks(); ++blk) {
      const Block& block = forest.block(blk);
      bool inside = true;
      for (int d = 0; d < 3; ++d)
        inside = inside && x[d] >= block.lower[d] && x[d] < block.lower[d] + block.length;
      if (inside) level = block.level;
    }
    return forest.max(level);
  };
  result.blob_level = level_at(centre);
  result.start_level = level_at(start);
  result.state.assign(tracer.raw().begin(), tracer.raw().end());
  for (const auto& u : ns.velocity())
    result.state.insert(result.state.end(), u.raw().begin(), u.raw().end());
  const int b = forest.block_cells();
  const BlockField& mu = std::as_const(ns).viscosity();
  for (int blk = 0; blk < forest.local_blocks(); ++blk)
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          const double expected =
              viscosity_jump ? layered_viscosity(cell_centre(forest, blk, i, j, k)) : 1e-3;
          result.viscosity_mismatch =
              std::max(result.viscosity_mismatch, std::abs(mu(blk, i, j, k) - expected));
        }
  result.viscosity_mismatch = forest.max(result.viscosity_mismatch);
  return result;
}

TEST(FlowAdaptiveNavierStokes, TheGridFollowsATracerBlobAndKeepsItsMass) {
  const FollowResult r = follow_a_blob(1, 24);
  std::printf(
      "blob followed 24 steps: tracer total drift %.2e, max |div uf| %.2e, level at the blob %g, "
      "at its start %g, at most %lld blocks (512 at level 3)\n",
      r.mass_drift, r.worst_divergence, r.blob_level, r.start_level,
      static_cast<long long>(r.most_blocks));
  // Flux-form advection and conservative transfers: round-off only.
  EXPECT_LT(r.mass_drift, 1e-13);
  EXPECT_LT(r.worst_divergence, 1e-6);  // projection tolerance 1e-10 of |div| ~ 1/h
  EXPECT_EQ(r.blob_level, 3.0);         // refined where the blob is now
  EXPECT_EQ(r.start_level, 2.0);        // and coarsened where it was
  EXPECT_LT(r.most_blocks, 512);        // never the whole cube at the finest level
}

TEST(FlowAdaptiveNavierStokes, TwoThreadsGiveTheOneThreadAnswerBitForBit) {
  const FollowResult one = follow_a_blob(1, 6);
  const FollowResult two = follow_a_blob(2, 6);
  ASSERT_EQ(one.state.size(), two.state.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < one.state.size(); ++i) differ += one.state[i] != two.state[i] ? 1 : 0;
  EXPECT_EQ(differ, 0u);
}

TEST(FlowAdaptiveNavierStokes, AViscosityJumpStaysSharpThroughRegridsOnAnyThreadCount) {
  // The blob's grid moves across a viscosity jump (ratio 10, set_viscosity)
  // that lies inside coarse cells: each regrid samples mu again on the new
  // cells. Carrying it (prolongation of the coarse cell's value) left cells
  // 9e-3 off. The grad u^T stress and the matched viscous fluxes keep the run
  // conservative and divergence-free.
  const FollowResult one = follow_a_blob(1, 12, true);
  std::printf(
      "blob across a viscosity jump, 12 steps: tracer drift %.2e, max |div uf| %.2e, mu off "
      "its function by %.1e, at most %lld blocks\n",
      one.mass_drift, one.worst_divergence, one.viscosity_mismatch,
      static_cast<long long>(one.most_blocks));
  EXPECT_EQ(one.viscosity_mismatch, 0.0);
  EXPECT_LT(one.mass_drift, 1e-13);
  EXPECT_LT(one.worst_divergence, 1e-6);
  EXPECT_GT(one.most_blocks, 64);  // the grid did refine
  const FollowResult two = follow_a_blob(2, 12, true);
  ASSERT_EQ(one.state.size(), two.state.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < one.state.size(); ++i) differ += one.state[i] != two.state[i] ? 1 : 0;
  EXPECT_EQ(differ, 0u);
}

/// The slabs y < 0.25 and y > 1.25 of the periodic box 0.5 x 1.5 x 0.5 of the
/// uniform solid-mask test (test_navier_stokes.cpp): a channel of height 1.
bool channel_slabs(const Vec3& x) {
  return x.y < 0.25 || x.y > 1.25;
}

ForestSpec slab_box(int level) {
  ForestSpec spec;
  spec.trees = {1, 3, 1};
  spec.tree_length = 0.5;
  spec.level = level;
  spec.periodic = {true, true, true};
  return spec;
}

/// Blocks with a solid cell centre within 2 of their cells beyond their
/// faces, edges or corners (the test's own reading of the rule) below `level`.
int blocks_near_slabs_below(const Forest& forest, int level) {
  const int b = forest.block_cells();
  int count = 0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const Block& block = forest.block(blk);
    const double h = block.length / b;
    bool near = false;
    for (int j = -2; j < b + 2; ++j) {
      double y = block.lower.y + (j + 0.5) * h;
      y = y < 0.0 ? y + 1.5 : (y >= 1.5 ? y - 1.5 : y);
      near = near || channel_slabs({0.0, y, 0.0});
    }
    count += near && block.level < level ? 1 : 0;
  }
  return count;
}

TEST(FlowAdaptiveNavierStokes, SolidWallsOnAForestWithTwoLevels) {
  // The channel between solid slabs on 16 cells across (level 0), then
  // regridded with max_level 1: the blocks near the slabs go to 32 across,
  // the middle of the channel stays at 16. Steady Poiseuille flow: the flow
  // rate of the exact profile, and the force of the fluid on the slabs equals
  // the body force on the fluid (the wall shear balances it; p is uniform).
  Forest forest(slab_box(0));
  const double G = 2.0, mu = 1.0;
  NavierStokesOptions options;
  options.dt_max = 0.05;  // backward Euler: the slowest mode decays 1.5x per step
  options.viscous.tolerance = 1e-10;
  options.pressure.tolerance = 1e-10;
  NavierStokes ns(forest, all_periodic(), Fluid{1.0, mu}, options);
  ns.set_solid(channel_slabs);
  ns.set_velocity([](const Vec3&) { return Vec3{}; });
  ns.set_body_force([G](const Vec3&) { return Vec3{G, 0.0, 0.0}; });
  EXPECT_THROW(ns.regrid(forest, std::vector<AdaptFlag>(3, AdaptFlag::Keep)),
               std::invalid_argument);  // solids need an explicit max_level
  const RegridReport report =
      ns.regrid(forest, std::vector<AdaptFlag>(3, AdaptFlag::Keep), {}, /*max_level=*/1);
  EXPECT_TRUE(report.changed);
  EXPECT_EQ(report.blocks_after, 17);  // the two slab trees refined, the middle one kept
  EXPECT_EQ(forest.min_level(), 0);
  EXPECT_EQ(blocks_near_slabs_below(forest, 1), 0);
  // Asked to coarsen everywhere, the blocks near the slabs stay.
  ns.regrid(forest, std::vector<AdaptFlag>(17, AdaptFlag::Coarsen), {}, 1);
  EXPECT_EQ(forest.global_blocks(), 17);

  for (int s = 0; s < 80; ++s) ns.step(ns.stable_dt());
  const int b = forest.block_cells();
  double flux = 0.0, inside = 0.0, fluid_volume = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const double h = forest.block(blk).length / b;
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          const double u = ns.velocity()[0](blk, i, j, k);
          if (channel_slabs(cell_centre(forest, blk, i, j, k))) {
            inside = std::max({inside, std::abs(u), std::abs(ns.velocity()[1](blk, i, j, k))});
          } else {
            flux += u * h * h * h;
            fluid_volume += h * h * h;
          }
        }
  }
  const double rate = forest.sum(flux) / (0.5 * 0.5);
  const double error = rate / (G / (12 * mu)) - 1.0;
  const Vec3 force = ns.solid_force();
  const double body = G * forest.sum(fluid_volume);
  std::printf(
      "channel between solid slabs, 32 across at the walls, 16 in the middle: flow rate error "
      "%.3e, force on the slabs %.9f (body force on the fluid %.9f), |F_y| + |F_z| %.1e, max "
      "|div uf| %.1e\n",
      error, force.x, body, std::abs(force.y) + std::abs(force.z), ns.max_divergence());
  EXPECT_LT(std::abs(error), 0.01);  // the uniform 16-across grid: 0.6 %
  EXPECT_EQ(forest.max(inside), 0.0);
  EXPECT_LT(std::abs(force.x / body - 1.0), 1e-6);
  EXPECT_LT(std::abs(force.y) + std::abs(force.z), 1e-8 * body);
  EXPECT_LT(ns.max_divergence(), 1e-7);
}

TEST(FlowAdaptiveNavierStokes, BlocksNearSolidsGainingTwoLevelsKeepTheFaceVelocityDivergenceFree) {
  // The settling passes of a regrid raise the blocks near the slabs two
  // levels (0 -> 2) and the 2:1 balance the middle ones one: blocks that
  // were all at the finest level, so no neighbour holds finer faces and the
  // carried uf needs no solve (the slabs lie on the coarse cells' faces, so
  // no face closes anew).
  Forest forest(slab_box(0));
  NavierStokesOptions options;
  options.pressure.tolerance = 1e-13;
  options.pressure.max_cycles = 100;
  NavierStokes ns(forest, all_periodic(), Fluid{1.0, 0.01}, options);
  ns.set_solid(channel_slabs);
  ns.set_velocity([](const Vec3& x) { return Vec3{rough(x, 1), rough(x, 2), rough(x, 3)}; });
  ns.step(0.2 * ns.stable_dt());
  const double before = ns.max_divergence();
  const RegridReport r =
      ns.regrid(forest, std::vector<AdaptFlag>(3, AdaptFlag::Keep), {}, /*max_level=*/2);
  const double after = ns.max_divergence();
  std::printf(
      "near-slab blocks raised two levels: %lld -> %lld blocks, max |div uf| %.2e -> %.2e "
      "(%d V-cycles)\n",
      static_cast<long long>(r.blocks_before), static_cast<long long>(r.blocks_after), before,
      after, r.projection_cycles);
  EXPECT_EQ(blocks_near_slabs_below(forest, 2), 0);
  EXPECT_EQ(forest.min_level(), 1);  // the middle tree, raised by the balance
  EXPECT_EQ(r.projection_cycles, 0);
  EXPECT_LT(after, before + 1e-12);
}

TEST(FlowAdaptiveNavierStokes, SolidsBesideCoarserBlocksAreRefused) {
  // A forest already refined away from the slabs: their blocks are coarse.
  Forest forest(slab_box(0));
  forest.adapt(
      [](const Block& b) { return b.lower.y == 0.5 ? AdaptFlag::Refine : AdaptFlag::Keep; }, {});
  NavierStokes ns(forest, all_periodic(), Fluid{1.0, 1.0});
  EXPECT_THROW(ns.set_solid(channel_slabs), std::invalid_argument);
}

}  // namespace
}  // namespace sanguis::flow
