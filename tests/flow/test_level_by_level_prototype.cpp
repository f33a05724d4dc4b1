// Prototype (issue #7): the level-by-level multigrid hierarchy on a forest refined once,
// built from the public Multigrid calls of one process, to compare its rate per cycle with
// the block-by-block V-cycle the solver runs (scripts/composite_two_grid.py, the 2D model).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

#include "flow/forest.hpp"
#include "flow/multigrid.hpp"
#include "poisson_problems.hpp"

namespace sanguis::flow {
namespace {

using Coords = std::vector<std::array<std::int64_t, 3>>;

Coords scattered_blocks(std::int64_t n = 4) {
  Coords picked;
  for (std::int64_t k = 0; k < n; ++k)
    for (std::int64_t j = 0; j < n; ++j)
      for (std::int64_t i = 0; i < n; ++i)
        if (((i * 73856093) ^ (j * 19349663) ^ (k * 83492791)) % 10 < 4)
          picked.push_back({i, j, k});
  return picked;
}

double rms(const Forest& forest, const BlockField& f) {
  const int b = forest.block_cells();
  double s = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk)
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) s += f(blk, i, j, k) * f(blk, i, j, k);
  return std::sqrt(s / (forest.local_blocks() * b * b * b));
}

struct Rates {
  double block_by_block = 0.0, level_by_level = 0.0;
  int cycles_block = 0, cycles_level = 0;
  double seconds_block = 0.0, seconds_level = 0.0;  ///< of the solves, hierarchies built
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Rates compare(const Coords& refined, double relaxation, int base_level = 2) {
  ForestSpec spec;
  spec.level = base_level;
  spec.periodic = {true, true, true};
  Forest fine(spec);
  fine.adapt(
      [&](const Block& block) {
        for (const auto& c : refined)
          if (block.coord == c) return AdaptFlag::Refine;
        return AdaptFlag::Keep;
      },
      {});
  Forest coarse(spec);
  const int b = fine.block_cells();
  ScalarBoundary bc;
  bc.kind = uniform_kinds(fine, BcKind::Periodic);
  BlockField rhs = testing::sample(fine, testing::periodic_source);
  // Zero volume-weighted mean (the periodic problem's compatibility).
  double sum = 0.0, volume = 0.0;
  for (int blk = 0; blk < fine.local_blocks(); ++blk) {
    const double v = std::pow(fine.block(blk).length / b, 3);
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) sum += v * rhs(blk, i, j, k), volume += v;
  }
  for (int blk = 0; blk < fine.local_blocks(); ++blk)
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) rhs(blk, i, j, k) -= sum / volume;

  Rates rates;
  MultigridOptions options;
  options.tolerance = 1e-10;
  options.relaxation = relaxation;
  {
    Multigrid mg(fine, bc.kind);
    BlockField x(fine.local_blocks(), b);
    const auto start = std::chrono::steady_clock::now();
    const auto report = mg.solve(x, rhs, bc, options);
    rates.seconds_block = seconds_since(start);
    rates.block_by_block = report.mean_reduction();
    rates.cycles_block = report.cycles;
  }

  Multigrid mg_fine(fine, bc.kind), mg_coarse(coarse, bc.kind);
  std::map<std::array<std::int64_t, 3>, int> coarse_block;
  for (int blk = 0; blk < coarse.local_blocks(); ++blk) coarse_block[coarse.block(blk).coord] = blk;
  BlockField x(fine.local_blocks(), b), r(fine.local_blocks(), b);
  BlockField x1(coarse.local_blocks(), b), rhs1(coarse.local_blocks(), b);
  MultigridOptions one_cycle = options;
  one_cycle.tolerance = 0.0;
  one_cycle.max_cycles = 1;
  const auto clock_start = std::chrono::steady_clock::now();
  mg_fine.residual(x, rhs, bc, r);
  const double start = rms(fine, r), target = options.tolerance * rms(fine, rhs);
  double now = start;
  int cycles = 0;
  while (now > target && cycles < 50) {
    mg_fine.relax(x, rhs, bc, options.pre_sweeps, options);
    mg_fine.residual(x, rhs, bc, r);
    rhs1.fill(0.0);
    for (int blk = 0; blk < fine.local_blocks(); ++blk) {
      const Block& block = fine.block(blk);
      const bool refined_block = block.level > spec.level;
      std::array<std::int64_t, 3> parent = block.coord;
      std::array<int, 3> octant{};
      if (refined_block) {
        for (int d = 0; d < 3; ++d) {
          octant[d] = static_cast<int>(block.coord[d] & 1) * (b / 2);
          parent[d] = block.coord[d] >> 1;
        }
      }
      const int c = coarse_block.at(parent);
      for (int k = 0; k < b; ++k)
        for (int j = 0; j < b; ++j)
          for (int i = 0; i < b; ++i) {
            if (refined_block) {
              rhs1(c, octant[0] + i / 2, octant[1] + j / 2, octant[2] + k / 2) +=
                  r(blk, i, j, k) / 8.0;
            } else {
              rhs1(c, i, j, k) = r(blk, i, j, k);
            }
          }
    }
    x1.fill(0.0);
    mg_coarse.solve(x1, rhs1, bc, one_cycle);  // ghosts filled on return
    for (int blk = 0; blk < fine.local_blocks(); ++blk) {
      const Block& block = fine.block(blk);
      const bool refined_block = block.level > spec.level;
      std::array<std::int64_t, 3> parent = block.coord;
      std::array<int, 3> octant{};
      if (refined_block) {
        for (int d = 0; d < 3; ++d) {
          octant[d] = static_cast<int>(block.coord[d] & 1) * (b / 2);
          parent[d] = block.coord[d] >> 1;
        }
      }
      const int c = coarse_block.at(parent);
      for (int k = 0; k < b; ++k)
        for (int j = 0; j < b; ++j)
          for (int i = 0; i < b; ++i) {
            if (!refined_block) {
              x(blk, i, j, k) += x1(c, i, j, k);
              continue;
            }
            const int ci = octant[0] + i / 2, cj = octant[1] + j / 2, ck = octant[2] + k / 2;
            const int si = (i & 1) ? 1 : -1, sj = (j & 1) ? 1 : -1, sk = (k & 1) ? 1 : -1;
            double value = 0.0;
            for (int dk = 0; dk < 2; ++dk)
              for (int dj = 0; dj < 2; ++dj)
                for (int di = 0; di < 2; ++di) {
                  const double w = (di ? 0.25 : 0.75) * (dj ? 0.25 : 0.75) * (dk ? 0.25 : 0.75);
                  value += w * x1(c, ci + di * si, cj + dj * sj, ck + dk * sk);
                }
            x(blk, i, j, k) += value;
          }
    }
    mg_fine.relax(x, rhs, bc, options.post_sweeps, options);
    mg_fine.residual(x, rhs, bc, r);
    now = rms(fine, r);
    ++cycles;
  }
  rates.seconds_level = seconds_since(clock_start);
  rates.level_by_level = std::pow(start / now, 1.0 / cycles);
  rates.cycles_level = cycles;
  return rates;
}

TEST(LevelByLevelPrototype, ReachesTheUniformRateWhereTheBlockByBlockCycleFallsShort) {
  // Issue #7 asks the composite V-cycle to converge per cycle as the uniform one does. The
  // solver's block-by-block hierarchy reaches 0.74-0.91 of the uniform rate at omega 1.15
  // and 0.43-0.49 at the pressure solves' 1.25 (CompositeCyclesConvergeNearlyAsFastAsUniformOnes).
  // The level-by-level one of this prototype, measured 2026-12-05: 0.96-1.06 of the uniform
  // rate at 1.15, 0.72-0.95 at 1.25, on the same grids (the results are the same bits on every
  // run, so the bounds only catch a regression).
  const Coords blob{{0, 1, 2}, {1, 0, 1}, {1, 0, 2}, {1, 1, 1}, {1, 1, 2}, {2, 1, 1}, {2, 1, 2}};
  const Coords corner{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  const Coords octant{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1},
                      {1, 1, 0}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  struct Grid {
    Coords refined;
    const char* name;
    int base_level;
  };
  const std::vector<Grid> grids{{octant, "octant", 2},
                                {blob, "blob", 2},
                                {corner, "corner", 2},
                                {scattered_blocks(4), "scattered", 2},
                                {scattered_blocks(8), "1898 blocks", 3}};
  for (const auto& [omega, share] : {std::pair{1.15, 0.9}, std::pair{1.25, 0.7}}) {
    for (const Grid& grid : grids) {
      const double uniform = compare({}, omega, grid.base_level).block_by_block;
      const Rates r = compare(grid.refined, omega, grid.base_level);
      std::printf(
          "omega %.2f %-12s uniform %5.1fx; block by block %5.1fx (%2d cycles, %.2f s), "
          "level by level %5.1fx (%2d cycles, %.2f s)\n",
          omega, grid.name, uniform, r.block_by_block, r.cycles_block, r.seconds_block,
          r.level_by_level, r.cycles_level, r.seconds_level);
      EXPECT_GT(r.level_by_level, share * uniform) << grid.name << ", omega " << omega;
      EXPECT_GT(r.level_by_level, r.block_by_block) << grid.name << ", omega " << omega;
    }
  }
}

}  // namespace
}  // namespace sanguis::flow
