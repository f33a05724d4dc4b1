// Poisson on a statically refined forest (issue #7): the composite operator
// with flux matching at coarse-fine faces converges at second order across
// the interface, and the multigrid reduces the residual by a fixed factor
// per V-cycle.
#include <gtest/gtest.h>
#include <algorithm>

#include <cmath>
#include <cstdio>
#include <vector>

#include "adapt_poisson.hpp"

namespace sanguis::flow {
namespace {

using testing::RefinedPoissonResult;
using testing::solve_refined_manufactured;

void report(const char* name, const RefinedPoissonResult& coarse,
            const RefinedPoissonResult& fine) {
  std::printf(
      "%s: max error %.3e -> %.3e (order %.2f), beside coarse-fine faces %.3e -> %.3e (order "
      "%.2f); %.1fx / %.1fx per V-cycle (%d / %d cycles)\n",
      name, coarse.error, fine.error, std::log2(coarse.error / fine.error), coarse.interface_error,
      fine.interface_error, std::log2(coarse.interface_error / fine.interface_error),
      coarse.report.mean_reduction(), fine.report.mean_reduction(), coarse.report.cycles,
      fine.report.cycles);
}

/// Orders and rates shared by both boundary conditions.
void expect_second_order_and_fast(const RefinedPoissonResult& coarse,
                                  const RefinedPoissonResult& fine) {
  ASSERT_TRUE(coarse.report.converged);
  ASSERT_TRUE(fine.report.converged);
  // Second order: the error falls by 4 when h halves (measured 1.94 and 2.02
  // overall); 1.8 leaves room for the pre-asymptotic mix of two grid sizes.
  EXPECT_GT(std::log2(coarse.error / fine.error), 1.8);
  // The same at the cells beside the coarse-fine faces, where the quadratic
  // ghost interpolation and the flux matching act (first order would be 1).
  EXPECT_GT(std::log2(coarse.interface_error / fine.interface_error), 1.8);
  // The composite V(2,2) cycle: measured 15.7-19.7x per cycle (uniform
  // grids: 14-20x); 10x is the milestone's target.
  EXPECT_GT(coarse.report.mean_reduction(), 10.0);
  EXPECT_GT(fine.report.mean_reduction(), 10.0);
}

TEST(AdaptPoisson, PeriodicSecondOrderAcrossCoarseFineFaces) {
  // 16^3 with the octant at 32^3, then 32^3 with the octant at 64^3.
  const auto coarse = solve_refined_manufactured(true, 1);
  const auto fine = solve_refined_manufactured(true, 2);
  report("periodic", coarse, fine);
  expect_second_order_and_fast(coarse, fine);
}

TEST(AdaptPoisson, DirichletSecondOrderAcrossCoarseFineFaces) {
  const auto coarse = solve_refined_manufactured(false, 1);
  const auto fine = solve_refined_manufactured(false, 2);
  report("Dirichlet", coarse, fine);
  expect_second_order_and_fast(coarse, fine);
}

TEST(AdaptPoisson, HelmholtzWithVariableCoefficientOnTheRefinedOctant) {
  // alpha u - div(beta grad u) = f with beta = 1 + x/2 on faces, alpha = 3,
  // u = cos(pi x) cos(pi y) cos(pi z) + x + 2 y^2, Dirichlet (the uniform
  // test of test_multigrid.cpp, here with the octant refined once): beta
  // varies across the coarse-fine faces normal to x, where the fine side's
  // beta sets the matched flux.
  struct Result {
    double error, rate;
    int cycles;
  };
  auto run = [](int level, bool refined) {
    ForestSpec spec;
    spec.level = level;
    Forest forest(spec);
    if (refined) testing::refine_where(forest, testing::in_refined_octant);
    ScalarBoundary bc;
    bc.kind = uniform_kinds(forest, BcKind::Dirichlet);
    for (auto& v : bc.value) v = testing::dirichlet_exact;
    const double pi = testing::kPi;
    auto beta_at = [](const Vec3& x) { return 1.0 + 0.5 * x.x; };
    auto source = [&](const Vec3& x) {
      const double cx = std::cos(pi * x.x), cy = std::cos(pi * x.y), cz = std::cos(pi * x.z);
      const double u = cx * cy * cz + x.x + 2 * x.y * x.y;
      const double lap = -3 * pi * pi * cx * cy * cz + 4.0;
      const double ux = -pi * std::sin(pi * x.x) * cy * cz + 1.0;
      return 3.0 * u - (beta_at(x) * lap + 0.5 * ux);
    };
    const int b = forest.block_cells();
    BlockField alpha(forest.local_blocks(), b);
    alpha.fill(3.0);
    FaceField beta = make_vector_field(forest.local_blocks(), b);
    for (int blk = 0; blk < forest.local_blocks(); ++blk)
      for (int k = 0; k <= b; ++k)
        for (int j = 0; j <= b; ++j)
          for (int i = 0; i <= b; ++i) {
            const Vec3 c = testing::cell_centre(forest, blk, i, j, k);
            const double h = forest.block(blk).length / b;
            beta[0](blk, i, j, k) = beta_at({c.x - 0.5 * h, c.y, c.z});
            beta[1](blk, i, j, k) = beta_at(c);
            beta[2](blk, i, j, k) = beta_at(c);
          }
    Multigrid mg(forest, bc.kind);
    mg.set_coefficients(&alpha, &beta);
    BlockField x(forest.local_blocks(), b);
    MultigridOptions options;
    options.tolerance = 1e-10;
    const auto report = mg.solve(x, testing::sample(forest, source), bc, options);
    EXPECT_TRUE(report.converged);
    EXPECT_GT(report.mean_reduction(), 10.0);  // as for Poisson (measured above 10)
    std::printf("Helmholtz %s, base level %d: max error %.3e, %.1fx per V-cycle (%d cycles)\n",
                refined ? "on the refined octant" : "uniform", level,
                testing::max_error(forest, x, testing::dirichlet_exact), report.mean_reduction(),
                report.cycles);
    return Result{testing::max_error(forest, x, testing::dirichlet_exact), report.mean_reduction(),
                  report.cycles};
  };
  const Result coarse = run(1, true), fine = run(2, true);
  // Second order as for Poisson (1.8: pre-asymptotic mix of two grid sizes).
  EXPECT_GT(std::log2(coarse.error / fine.error), 1.8);
  // The viscous solver's rate per cycle against the uniform grid of the same finest cells
  // (see CompositeCyclesConvergeAsFastAsUniformOnes for why that grid).
  for (const auto& [composite, uniform] :
       {std::pair{coarse, run(2, false)}, {fine, run(3, false)}}) {
    EXPECT_GT(composite.rate, 0.95 * uniform.rate);
    EXPECT_LE(composite.cycles, uniform.cycles);
  }
}

/// Periodic Poisson on 4^3 blocks of 8^3 cells with the level-2 blocks at
/// `refined` refined once: V-cycles and reduction per cycle.
MultigridReport solve_with_refined_blocks(const std::vector<std::array<std::int64_t, 3>>& refined,
                                          const char* name, double relaxation = 1.15,
                                          bool level_by_level = true, int base_level = 2,
                                          double beside_finer = 1.0) {
  ForestSpec spec;
  spec.level = base_level;
  spec.periodic = {true, true, true};
  Forest forest(spec);
  forest.adapt(
      [&](const Block& block) {
        for (const auto& c : refined)
          if (block.coord == c) return AdaptFlag::Refine;
        return AdaptFlag::Keep;
      },
      {});
  EXPECT_EQ(forest.global_blocks(),
            static_cast<std::int64_t>((std::int64_t{1} << (3 * base_level)) + 7 * refined.size()));
  ScalarBoundary bc;
  bc.kind = uniform_kinds(forest, BcKind::Periodic);
  Multigrid mg(forest, bc.kind, true, level_by_level);
  BlockField x(forest.local_blocks(), forest.block_cells());
  MultigridOptions options;
  options.tolerance = 1e-10;
  options.relaxation = relaxation;
  options.beside_finer_relaxation = beside_finer;
  const auto r = mg.solve(x, testing::sample(forest, testing::periodic_source), bc, options);
  std::printf(
      "  %-30s %3zu blocks refined, omega %.2f (%.2f beside finer blocks), %s: %2d V-cycles, "
      "%.1fx per cycle, max error %.3e\n",
      name, refined.size(), relaxation, std::min(relaxation, beside_finer),
      level_by_level ? "level by level" : "block by block", r.cycles, r.mean_reduction(),
      testing::max_error(forest, x, testing::periodic_exact));
  return r;
}

/// The blocks of a level-2 forest (4^3 blocks) that a fixed hash picks, 4 in
/// 10 of them: refined regions of every shape, most blocks beside a
/// coarse-fine face.
std::vector<std::array<std::int64_t, 3>> scattered_blocks(std::int64_t n = 4) {
  std::vector<std::array<std::int64_t, 3>> picked;
  for (std::int64_t k = 0; k < n; ++k)
    for (std::int64_t j = 0; j < n; ++j)
      for (std::int64_t i = 0; i < n; ++i)
        if (((i * 73856093) ^ (j * 19349663) ^ (k * 83492791)) % 10 < 4)
          picked.push_back({i, j, k});
  return picked;
}

TEST(AdaptPoisson, CompositeCyclesConvergeAsFastAsUniformOnes) {
  // Issue #7 asks the composite V-cycle to converge as fast per cycle as the uniform one.
  // Refined regions with re-entrant edges and corners, as the wavelet criterion makes
  // around a moving blob (found by test_navier_stokes_adaptive): coarse blocks with finer
  // neighbours across two faces (the blob) or three (an octant of 2 x 2 x 2 blocks refined
  // but for one corner block), 22 blocks picked by a hash, and 8^3 blocks with 4 in 10
  // refined (1898 blocks). The block-by-block hierarchy (every block halving its own cells,
  // the solver's until 2026-12-05) reached 0.74-0.91 of the uniform rate at the smoother's
  // 1.15 and 0.43-0.49 at the pressure solves' 1.25 (measured before the rule below, which
  // by_block now runs with too); the level-by-level one (the finest
  // level coarsened first: coarsened_blocks.hpp) 0.96-1.06 and 0.72-0.95, and with plain
  // Gauss-Seidel in the cells beside finer blocks (MultigridOptions::beside_finer_relaxation)
  // 0.97-1.06 and 0.85-0.98 (measured 2026-12-05; the results are the same bits on every run
  // and thread count, so the bounds only catch a regression).
  // Those shares are taken against the uniform base grid, one level coarser than the
  // composite grid's finest. A uniform grid's own V-cycle converges more slowly the finer it
  // is (31.6x, 27.6x, 25.4x per cycle at 32^3, 64^3, 128^3 at 1.25), so the uniform grid the
  // composite one stands for, its finest resolution with the same depth of levels, is the
  // reference that holds the grid's size fixed: against it the composite cycles reach
  // 0.98-1.14 of the rate at both relaxations (docs/performance.md, "The composite V-cycle
  // against the uniform grid of its finest cells").
  std::printf("periodic Poisson, V(2,2), uniform against composite grids:\n");
  const std::vector<std::array<std::int64_t, 3>> blob{{0, 1, 2}, {1, 0, 1}, {1, 0, 2}, {1, 1, 1},
                                                      {1, 1, 2}, {2, 1, 1}, {2, 1, 2}};
  const std::vector<std::array<std::int64_t, 3>> corner{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0},
                                                        {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  const auto scattered = scattered_blocks();
  ASSERT_GE(scattered.size(), 16u);
  struct Grid {
    std::vector<std::array<std::int64_t, 3>> refined;
    const char* name;
    int base_level;
  };
  const std::vector<Grid> grids{{blob, "blob", 2},
                                {corner, "corner", 2},
                                {scattered, "scattered", 2},
                                {scattered_blocks(8), "1898 blocks", 3}};
  for (const auto& [omega, share] : {std::pair{1.15, 0.95}, std::pair{1.25, 0.8}}) {
    for (const Grid& grid : grids) {
      const auto uniform = solve_with_refined_blocks({}, "uniform", omega, true, grid.base_level);
      ASSERT_TRUE(uniform.converged);
      const auto uniform_finest = solve_with_refined_blocks({}, "uniform at the finest cells",
                                                            omega, true, grid.base_level + 1);
      ASSERT_TRUE(uniform_finest.converged);
      const auto by_block =
          solve_with_refined_blocks(grid.refined, grid.name, omega, false, grid.base_level);
      const auto by_level =
          solve_with_refined_blocks(grid.refined, grid.name, omega, true, grid.base_level);
      ASSERT_TRUE(by_block.converged);
      ASSERT_TRUE(by_level.converged);
      EXPECT_GT(by_level.mean_reduction(), share * uniform.mean_reduction()) << grid.name;
      EXPECT_GT(by_level.mean_reduction(), 0.95 * uniform_finest.mean_reduction()) << grid.name;
      EXPECT_LE(by_level.cycles, uniform_finest.cycles) << grid.name;
      EXPECT_GT(by_level.mean_reduction(), by_block.mean_reduction()) << grid.name;
      EXPECT_LE(by_level.cycles, uniform.cycles + 1) << grid.name;
      if (omega > 1.2) {  // the cells beside finer blocks over-relaxed as the rest: slower
        const auto over =
            solve_with_refined_blocks(grid.refined, grid.name, omega, true, grid.base_level, omega);
        EXPECT_GT(by_level.mean_reduction(), 1.02 * over.mean_reduction()) << grid.name;
      }
    }
  }
}

TEST(AdaptPoisson, ARebuiltMultigridSolvesAsANewOne) {
  // Multigrid::rebuild() after Forest::adapt reuses the old levels' storage
  // (what a regrid does); the solve must be the one a new Multigrid gives,
  // bit for bit, from a uniform forest to a refined one and back.
  ForestSpec spec;
  spec.level = 2;
  spec.periodic = {true, true, true};
  Forest forest(spec);
  ScalarBoundary bc;
  bc.kind = uniform_kinds(forest, BcKind::Periodic);
  Multigrid reused(forest, bc.kind);
  MultigridOptions options;
  options.tolerance = 1e-10;
  const auto solve_both = [&](const char* grid) {
    const BlockField rhs = testing::sample(forest, testing::periodic_source);
    Multigrid fresh(forest, bc.kind);
    BlockField a(forest.local_blocks(), forest.block_cells());
    BlockField b(forest.local_blocks(), forest.block_cells());
    const auto ra = reused.solve(a, rhs, bc, options);
    const auto rb = fresh.solve(b, rhs, bc, options);
    EXPECT_TRUE(ra.converged) << grid;
    EXPECT_EQ(ra.cycles, rb.cycles) << grid;
    EXPECT_EQ(a.raw(), b.raw()) << grid;
  };
  solve_both("uniform");
  reused.rebuild();  // the same uniform forest: the merged solver is kept
  solve_both("uniform, rebuilt");
  testing::refine_where(forest, testing::in_refined_octant);
  ASSERT_FALSE(forest.uniform());
  reused.rebuild();
  solve_both("octant refined");
  // Other composite forests: the coarsened forest is adapted in place, and its solver
  // rebuilt (three levels: a chain of two coarsened forests).
  forest.adapt(
      [](const Block& block) {
        return block.level == 3 && block.coord[0] == 0 && block.coord[1] == 0 ? AdaptFlag::Refine
                                                                              : AdaptFlag::Keep;
      },
      {});
  ASSERT_EQ(forest.max_level(), 4);
  reused.rebuild();
  solve_both("a corner refined twice");
  forest.adapt(
      [](const Block& block) { return block.level == 4 ? AdaptFlag::Coarsen : AdaptFlag::Keep; },
      {});
  ASSERT_EQ(forest.max_level(), 3);
  reused.rebuild();
  solve_both("back to the octant");
  forest.adapt(
      [](const Block& block) { return block.level > 2 ? AdaptFlag::Coarsen : AdaptFlag::Keep; },
      {});
  ASSERT_TRUE(forest.uniform());
  reused.rebuild();
  solve_both("coarsened back");
}

TEST(AdaptPoisson, TwoThreadsGiveTheOneThreadAnswerBitForBit) {
  // Blocks relax independently within a colour (ghosts are filled before),
  // so the thread count must not change a single bit.
  const auto one = solve_refined_manufactured(true, 1, MPI_COMM_WORLD, 1e-10, 50, 1);
  const auto two = solve_refined_manufactured(true, 1, MPI_COMM_WORLD, 1e-10, 50, 2);
  ASSERT_EQ(one.solution.raw().size(), two.solution.raw().size());
  EXPECT_EQ(one.solution.raw(), two.solution.raw());
  EXPECT_EQ(one.report.cycles, two.report.cycles);
}

}  // namespace
}  // namespace sanguis::flow
