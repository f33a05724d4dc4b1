// The wavelet refinement criterion (thesis eq. 4.11) on analytic fields:
// zero for linear fields, the exact O(h^3) value for a cubic, flags that
// follow a front within the level limits, and the forced-finest tag.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "adapt_problems.hpp"
#include "flow/adapt_criterion.hpp"

namespace sanguis::flow {
namespace {

using testing::block_centre;
using testing::fill_cells;

ForestSpec spec_at(int level) {
  ForestSpec spec;
  spec.level = level;
  spec.block_cells = 8;
  return spec;
}

TEST(FlowAdaptCriterion, LinearFieldsHaveNoWaveletAndCoarsenToTheMinimumLevel) {
  const Forest forest(spec_at(2));
  BlockField u(forest.local_blocks(), 8);
  fill_cells(forest, u, [](const Vec3& x) { return 3.0 - x.x + 2.0 * x.y + 0.5 * x.z; });
  for (const double e : wavelet_estimate(forest, u))
    EXPECT_LT(e, 1e-14);  // round-off of O(1) values
  WaveletCriterion criterion{{1e-6}, 1, 3};
  BlockField* fields[] = {&u};
  for (const AdaptFlag flag : wavelet_flags(forest, fields, criterion)) {
    EXPECT_EQ(flag, AdaptFlag::Coarsen);
  }
  criterion.min_level = 2;
  for (const AdaptFlag flag : wavelet_flags(forest, fields, criterion)) {
    EXPECT_EQ(flag, AdaptFlag::Keep);
  }
}

TEST(FlowAdaptCriterion, PerBlockFloorsRefineBelowThemAndNeverCoarsenAtThem) {
  // A front along x = 0.5 on level-2 blocks; the blocks with x < 0.25 get a
  // floor of 3 (a refinement region), those with x > 0.75 a floor of 2.
  const Forest forest(spec_at(2));
  BlockField u(forest.local_blocks(), 8);
  fill_cells(forest, u, [](const Vec3& x) { return std::tanh((x.x - 0.5) / 0.01); });
  WaveletCriterion criterion{{1e-3}, 1, 3};
  criterion.block_min_level.resize(static_cast<std::size_t>(forest.local_blocks()), 1);
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const double x = block_centre(forest.block(blk)).x;
    if (x < 0.25) criterion.block_min_level[static_cast<std::size_t>(blk)] = 3;
    if (x > 0.75) criterion.block_min_level[static_cast<std::size_t>(blk)] = 2;
  }
  BlockField* fields[] = {&u};
  const auto flags = wavelet_flags(forest, fields, criterion);
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const double x = block_centre(forest.block(blk)).x;
    const AdaptFlag flag = flags[static_cast<std::size_t>(blk)];
    if (x < 0.25) {
      EXPECT_EQ(flag, AdaptFlag::Refine);  // below its floor, although the field is flat there
    } else if (x > 0.75) {
      EXPECT_EQ(flag, AdaptFlag::Keep);  // flat, but at its floor
    } else if (std::abs(x - 0.5) < 0.2) {
      EXPECT_EQ(flag, AdaptFlag::Refine);  // the front
    }
  }
  // Without floors the flat blocks on both sides would coarsen.
  criterion.block_min_level.clear();
  const auto free = wavelet_flags(forest, fields, criterion);
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const double x = block_centre(forest.block(blk)).x;
    if (x < 0.25 || x > 0.75) {
      EXPECT_EQ(free[static_cast<std::size_t>(blk)], AdaptFlag::Coarsen);
    }
  }
  criterion.block_min_level.resize(3);
  EXPECT_THROW(wavelet_flags(forest, fields, criterion), std::invalid_argument);
}

TEST(FlowAdaptCriterion, PerBlockCapsStopRefinementTheFloorAndTheTagOverrideThem) {
  // The front along x = 0.5 on level-2 blocks (centres x = 0.125 .. 0.875):
  // the blocks beside it (0.375, 0.625) would refine. Caps: 2 at 0.375 (it
  // stays), 1 at 0.625 (it is above its cap: it coarsens, although the
  // front wants it finer), 2 with a floor of 3 at 0.125 (the floor wins).
  const Forest forest(spec_at(2));
  BlockField u(forest.local_blocks(), 8);
  fill_cells(forest, u, [](const Vec3& x) { return std::tanh((x.x - 0.5) / 0.01); });
  WaveletCriterion criterion{{1e-3}, 1, 3};
  const auto blocks = static_cast<std::size_t>(forest.local_blocks());
  criterion.block_min_level.assign(blocks, 1);
  criterion.block_max_level.assign(blocks, 3);
  auto column = [&](int blk) { return static_cast<int>(block_centre(forest.block(blk)).x * 4); };
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const auto at = static_cast<std::size_t>(blk);
    if (column(blk) == 0) criterion.block_min_level[at] = 3;
    if (column(blk) == 0 || column(blk) == 1) criterion.block_max_level[at] = 2;
    if (column(blk) == 2) criterion.block_max_level[at] = 1;
  }
  BlockField* fields[] = {&u};
  const auto flags = wavelet_flags(forest, fields, criterion);
  const AdaptFlag expected[] = {AdaptFlag::Refine, AdaptFlag::Keep, AdaptFlag::Coarsen,
                                AdaptFlag::Coarsen};  // the last column: flat, no cap
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    EXPECT_EQ(flags[static_cast<std::size_t>(blk)], expected[column(blk)])
        << "column " << column(blk);
  }
  // Forced-finest cells take their block to max_level through its cap.
  BlockField tag(forest.local_blocks(), 8);
  fill_cells(forest, tag, [](const Vec3& x) { return x.x > 0.25 && x.x < 0.75 ? 1.0 : 0.0; });
  const auto tagged = wavelet_flags(forest, fields, criterion, &tag);
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    if (column(blk) == 1 || column(blk) == 2) {
      EXPECT_EQ(tagged[static_cast<std::size_t>(blk)], AdaptFlag::Refine);
    }
  }
  criterion.block_max_level.resize(3);
  EXPECT_THROW(wavelet_flags(forest, fields, criterion), std::invalid_argument);
}

TEST(FlowAdaptCriterion, CubicGivesTheThirdOrderWaveletExactly) {
  // u = x^3: R(u) = X^3 + 3 X h^2 / 4 per coarse cell (h the fine cell), the
  // central slope over one coarse cell 6 X^2 h + 9.5 h^3, so P(R(u)) differs
  // from u at the fine centres X +- h/2 by +-(2.375 - 0.125) h^3 = +-2.25 h^3
  // in every cell of a block whose x-faces are not domain faces.
  for (const int level : {2, 3}) {
    const Forest forest(spec_at(level));
    BlockField u(forest.local_blocks(), 8);
    fill_cells(forest, u, [](const Vec3& x) { return x.x * x.x * x.x; });
    const auto e = wavelet_estimate(forest, u);
    const double h = forest.spec().tree_length / (8 << level);
    const auto n = forest.blocks_per_direction(level);
    for (int blk = 0; blk < forest.local_blocks(); ++blk) {
      const auto x = forest.block(blk).coord[0];
      if (x == 0 || x == n[0] - 1) continue;
      // Round-off of sums of values |u| <= 1 (about 1e-16 each) against a
      // wavelet of 6.9e-5 (level 2) and 8.6e-6 (level 3).
      EXPECT_NEAR(e[static_cast<std::size_t>(blk)], 2.25 * h * h * h, 1e-15);
    }
  }
}

double front(const Vec3& x) {
  return std::tanh((x.x - 0.53) / 0.02);
}

TEST(FlowAdaptCriterion, FlagsFollowAFrontWithinTheLevelLimits) {
  const Forest forest(spec_at(2));
  BlockField u(forest.local_blocks(), 8), tag(forest.local_blocks(), 8);
  fill_cells(forest, u, front);
  // Tag one cell of the block at the origin: it must go to the finest level.
  fill_cells(forest, tag, [](const Vec3& x) { return x.x < 0.03 && x.y < 0.03 && x.z < 0.03; });
  BlockField* fields[] = {&u};
  const WaveletCriterion criterion{{1e-3}, 1, 3};
  const auto flags = wavelet_flags(forest, fields, criterion, &tag);
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const Vec3 c = block_centre(forest.block(blk));
    const AdaptFlag flag = flags[static_cast<std::size_t>(blk)];
    if (c.x < 0.25 && c.y < 0.25 && c.z < 0.25) {
      EXPECT_EQ(flag, AdaptFlag::Refine);  // tagged
    } else if (std::abs(c.x - 0.625) < 0.01) {
      EXPECT_EQ(flag, AdaptFlag::Refine);  // holds the front (x in [0.5, 0.75])
    } else if (c.x < 0.25 || c.x > 0.75) {
      // tanh is within 1e-5 of +-1 (e ~ 0) more than 0.2 away from the front.
      EXPECT_EQ(flag, AdaptFlag::Coarsen);
    }
  }
  // At the maximum level nothing is refined; above it, blocks coarsen.
  const WaveletCriterion capped{{1e-3}, 0, 2};
  for (const AdaptFlag flag : wavelet_flags(forest, fields, capped, &tag)) {
    EXPECT_NE(flag, AdaptFlag::Refine);
  }
  const WaveletCriterion below{{1e-3}, 0, 1};
  for (const AdaptFlag flag : wavelet_flags(forest, fields, below, &tag)) {
    EXPECT_EQ(flag, AdaptFlag::Coarsen);
  }
}

// Each field is held to its own threshold, in its own units: a front in u
// (order 1) near x = 0.53 and one in p, 1000 times larger, near x = 0.2. A
// block is refined where either field asks, coarsened only where both allow.
TEST(FlowAdaptCriterion, EachFieldIsHeldToItsOwnThreshold) {
  const Forest forest(spec_at(2));
  BlockField u(forest.local_blocks(), 8), p(forest.local_blocks(), 8);
  fill_cells(forest, u, front);
  fill_cells(forest, p, [](const Vec3& x) { return 1e3 * std::tanh((x.x - 0.2) / 0.02); });
  BlockField* fields[] = {&u, &p};
  // (blocks flagged Refine, blocks) among those centred in x_lo < x < x_hi.
  const auto refined_in = [&](const WaveletCriterion& criterion, double x_lo, double x_hi) {
    const auto flags = wavelet_flags(forest, fields, criterion);
    std::array<int, 2> count{};
    for (int blk = 0; blk < forest.local_blocks(); ++blk) {
      const double x = block_centre(forest.block(blk)).x;
      if (x > x_lo && x < x_hi) {
        count[0] += flags[static_cast<std::size_t>(blk)] == AdaptFlag::Refine ? 1 : 0;
        ++count[1];
      }
    }
    return count;
  };
  const auto refined = [&](const WaveletCriterion& criterion, double x_lo, double x_hi) {
    const auto [flagged, blocks] = refined_in(criterion, x_lo, x_hi);
    return blocks > 0 && flagged == blocks;
  };
  const auto any_refined = [&](const WaveletCriterion& criterion, double x_lo, double x_hi) {
    return refined_in(criterion, x_lo, x_hi)[0] > 0;
  };
  // Blocks of 1/4: the p front lies in x in [0, 0.25], the u front in [0.5, 0.75].
  const WaveletCriterion both{{1e-3, 1.0}, 1, 3};  // zeta 1e-3 on u, 1 on p
  EXPECT_TRUE(refined(both, 0.0, 0.25));
  EXPECT_TRUE(refined(both, 0.5, 0.75));
  // p's threshold 1e6 (beyond any estimate of p): only the u front refines.
  const WaveletCriterion u_only{{1e-3, 1e6}, 1, 3};
  EXPECT_FALSE(any_refined(u_only, 0.0, 0.25));
  EXPECT_TRUE(refined(u_only, 0.5, 0.75));
  // u's threshold 1e6: only the p front refines.
  const WaveletCriterion p_only{{1e6, 1.0}, 1, 3};
  EXPECT_TRUE(refined(p_only, 0.0, 0.25));
  EXPECT_FALSE(any_refined(p_only, 0.5, 0.75));
  // Far from both fronts both estimates vanish: those blocks coarsen.
  const auto flags = wavelet_flags(forest, fields, both);
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const double x = block_centre(forest.block(blk)).x;
    if (x > 0.75) {
      EXPECT_EQ(flags[static_cast<std::size_t>(blk)], AdaptFlag::Coarsen);
    }
  }
}

TEST(FlowAdaptCriterion, RepeatedAdaptationResolvesTheFrontAtTheFinestLevel) {
  Forest forest(spec_at(1));
  BlockField u(forest.local_blocks(), 8);
  fill_cells(forest, u, front);
  const WaveletCriterion criterion{{1e-3}, 1, 4};
  for (int pass = 0; pass < 4; ++pass) {
    BlockField* fields[] = {&u};
    const auto flags = wavelet_flags(forest, fields, criterion);
    if (!forest.adapt(flags, {})) break;
    u = BlockField(forest.local_blocks(), 8);
    fill_cells(forest, u, front);  // the analytic field on the new blocks
  }
  EXPECT_EQ(forest.max_level(), 4);
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const Block& block = forest.block(blk);
    const bool holds_front = block.lower.x <= 0.53 && 0.53 <= block.lower.x + block.length;
    if (holds_front) {
      EXPECT_EQ(block.level, 4);
    }
    // Far from the front (tanh flat to 1e-5), only the 2:1 grading keeps blocks fine.
    if (block.lower.x > 0.8 || block.lower.x + block.length < 0.25) {
      EXPECT_LE(block.level, 2);
    }
  }
}

double bump(const Vec3& x) {
  const double r2 =
      (x.x - 0.45) * (x.x - 0.45) + (x.y - 0.5) * (x.y - 0.5) + (x.z - 0.55) * (x.z - 0.55);
  return std::exp(-r2 / 0.02);
}

TEST(FlowAdaptCriterion, ASmoothFieldSettlesInsteadOfFlipFlopping) {
  // A smooth field's estimate grows about 8x per coarser level, so blocks
  // whose own estimate lies between zeta/8 and 2 zeta/3 would coarsen and be
  // refined again at every pass. With the parent's estimate checked, the grid
  // reaches a fixed point, and every block is either resolved (estimate
  // <= zeta) or at the finest level.
  Forest forest(spec_at(1));
  BlockField u(forest.local_blocks(), 8);
  fill_cells(forest, u, bump);
  const WaveletCriterion criterion{{2e-3}, 1, 3};
  std::vector<std::int64_t> counts;
  bool settled = false;
  for (int pass = 0; pass < 8 && !settled; ++pass) {
    BlockField* fields[] = {&u};
    settled = !forest.adapt(wavelet_flags(forest, fields, criterion), {});
    u = BlockField(forest.local_blocks(), 8);
    fill_cells(forest, u, bump);
    counts.push_back(forest.global_blocks());
  }
  EXPECT_TRUE(settled) << "blocks per pass: " << ::testing::PrintToString(counts);
  EXPECT_EQ(forest.max_level(), 3);
  EXPECT_GT(counts.back(), 8);    // refined where the bump is curved
  EXPECT_LT(counts.back(), 512);  // and coarser than the uniform finest grid elsewhere
  const auto e = wavelet_estimate(forest, u);
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    if (forest.block(blk).level < 3) {
      EXPECT_LE(e[static_cast<std::size_t>(blk)], 2e-3);
    }
  }
}

}  // namespace
}  // namespace sanguis::flow
