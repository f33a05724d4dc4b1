// The level-by-level multigrid hierarchy (src/flow/coarsened_blocks.hpp): the forest with
// its finest level coarsened, and transfers that are exact where they should be.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <vector>

#include "adapt_problems.hpp"
#include "flow/coarsened_blocks.hpp"
#include "poisson_problems.hpp"

namespace sanguis::flow {
namespace {

/// 4^3 blocks of 8^3 with a 2 x 2 x 2 region refined once and its centre block twice.
std::unique_ptr<Forest> three_level_forest() {
  ForestSpec spec;
  spec.level = 2;
  auto made = std::make_unique<Forest>(spec);
  Forest& forest = *made;
  const auto inside = [](const Vec3& c, double lo, double hi) {
    return c.x > lo && c.x < hi && c.y > lo && c.y < hi && c.z > lo && c.z < hi;
  };
  testing::refine_where(forest, [&](const Vec3& c) { return inside(c, 0.25, 0.75); });
  testing::refine_where(forest, [&](const Vec3& c) { return inside(c, 0.375, 0.625); });
  return made;
}

double linear(const Vec3& x) {
  return 1.0 + 2.0 * x.x - 3.0 * x.y + 0.5 * x.z;
}

TEST(CoarsenedBlocks, TheFinestLevelIsCoarsenedAndNothingElse) {
  const auto made = three_level_forest();
  const Forest& fine = *made;
  ASSERT_EQ(fine.max_level(), 4);
  const auto once = coarsen_finest_level(fine);
  EXPECT_EQ(once->max_level(), 3);
  EXPECT_EQ(once->min_level(), 2);
  // Each family of 8 finest blocks becomes one block (one process: every block is local).
  std::int64_t finest = 0;
  for (int b = 0; b < fine.local_blocks(); ++b) finest += fine.block(b).level == 4 ? 1 : 0;
  EXPECT_EQ(once->global_blocks(), fine.global_blocks() - finest + finest / 8);
  const auto twice = coarsen_finest_level(*once);
  EXPECT_TRUE(twice->uniform());
  EXPECT_EQ(twice->global_blocks(), 64);
  // A uniform forest coarsens too (the multigrid's hierarchy on many blocks), down to
  // its trees, and no further.
  std::unique_ptr<Forest> coarser = coarsen_finest_level(*twice);
  while (coarser->max_level() > 0) {
    EXPECT_TRUE(coarser->uniform());
    coarser = coarsen_finest_level(*coarser);
  }
  EXPECT_EQ(coarser->global_blocks(),
            std::int64_t{fine.spec().trees[0]} * fine.spec().trees[1] * fine.spec().trees[2]);
  EXPECT_THROW(coarsen_finest_level(*coarser), std::invalid_argument);
}

TEST(CoarsenedBlocks, ACoarsenedForestAdaptedInPlaceHasTheLeavesOfANewOne) {
  // What a regrid does (Multigrid::rebuild): the last coarsened forest takes the new fine
  // forest's coarsened leaves instead of a new forest being built.
  const auto made = three_level_forest();
  Forest& fine = *made;
  const auto reused = coarsen_finest_level(fine);
  const auto leaves = [](const Forest& forest) {
    std::vector<std::array<std::int64_t, 4>> out;
    for (int b = 0; b < forest.local_blocks(); ++b) {
      const Block& block = forest.block(b);
      out.push_back({block.level, block.coord[0], block.coord[1], block.coord[2]});
    }
    return out;
  };
  // Refined elsewhere (a corner twice), then back to one level of refinement.
  fine.adapt(
      [](const Block& block) { return block.level > 2 ? AdaptFlag::Coarsen : AdaptFlag::Keep; },
      {});
  fine.adapt(
      [](const Block& block) { return block.level == 3 ? AdaptFlag::Coarsen : AdaptFlag::Keep; },
      {});
  ASSERT_TRUE(fine.uniform());
  testing::refine_where(fine, [](const Vec3& c) { return c.x < 0.25 && c.y < 0.25; });
  testing::refine_where(fine,
                        [](const Vec3& c) { return c.x < 0.125 && c.y < 0.125 && c.z < 0.5; });
  ASSERT_EQ(fine.max_level(), 4);
  reused->assign_coarsened_finest_level(fine);
  EXPECT_EQ(leaves(*reused), leaves(*coarsen_finest_level(fine)));
  EXPECT_EQ(reused->max_level(), 3);
  testing::refine_where(fine, [](const Vec3& c) { return c.x > 0.75; });
  reused->assign_coarsened_finest_level(fine);
  EXPECT_EQ(leaves(*reused), leaves(*coarsen_finest_level(fine)));
}

TEST(CoarsenedBlocks, RestrictionAveragesAndCopies) {
  const auto made = three_level_forest();
  const Forest& fine = *made;
  const auto coarse = coarsen_finest_level(fine);
  const CoarsenedBlocks transfers(fine, *coarse);
  // The mean of 2^3 cells of a linear field is its value at the parent cell's centre.
  const BlockField f = testing::sample(fine, linear);
  BlockField c(coarse->local_blocks(), coarse->block_cells());
  transfers.restrict_cells(f, c);
  EXPECT_LT(testing::max_error(*coarse, c, linear), 1e-13);
  // Faces: beta 1 stays 1 on faces 0..b of every coarse block.
  const int b = fine.block_cells();
  for (int d = 0; d < 3; ++d) {
    BlockField one(fine.local_blocks(), b);
    one.fill(1.0);
    BlockField faces(coarse->local_blocks(), b, 1);
    faces.fill(-7.0);
    transfers.restrict_faces(one, d, faces);
    std::array<int, 3> hi{b, b, b};
    hi[static_cast<std::size_t>(d)] = b + 1;
    for (int blk = 0; blk < coarse->local_blocks(); ++blk)
      for (int k = 0; k < hi[2]; ++k)
        for (int j = 0; j < hi[1]; ++j)
          for (int i = 0; i < hi[0]; ++i) ASSERT_EQ(faces(blk, i, j, k), 1.0) << d;
  }
}

TEST(CoarsenedBlocks, ProlongationIsExactForLinearCorrections) {
  const auto made = three_level_forest();
  const Forest& fine = *made;
  const auto coarse = coarsen_finest_level(fine);
  const CoarsenedBlocks transfers(fine, *coarse);
  BlockField c = testing::sample(*coarse, linear);
  coarse->exchange(c, 1);  // the ring the trilinear weights read (inside the domain here)
  BlockField f(fine.local_blocks(), fine.block_cells());
  transfers.prolong_add(c, nullptr, f);
  // Shared blocks take the coarse cells as they are; the refined centre's cells the
  // trilinear interpolant, exact for a linear field.
  EXPECT_LT(testing::max_error(fine, f, linear), 1e-13);
  // Added, not written.
  transfers.prolong_add(c, nullptr, f);
  EXPECT_LT(testing::max_error(fine, f, [](const Vec3& x) { return 2.0 * linear(x); }), 1e-13);
}

}  // namespace
}  // namespace sanguis::flow
