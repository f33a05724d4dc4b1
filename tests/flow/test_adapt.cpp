// Adaptive forest (issue #7): refinement with 2:1 balance, the neighbour
// table across levels, coarse-fine ghost filling, and the data transfer of
// adapt() (restriction by volume average, limited linear prolongation).
#include <gtest/gtest.h>

#include <cmath>

#include "adapt_problems.hpp"
#include "flow/forest.hpp"

namespace sanguis::flow {
namespace {

using testing::block_centre;
using testing::fill_cells;
using testing::fill_faces;
using testing::ghost_error;
using testing::refine_where;

double linear(const Vec3& x) {
  return 1.0 + 2.0 * x.x - 3.0 * x.y + 0.5 * x.z;
}
double quadratic(const Vec3& x) {
  return linear(x) + x.x * x.x - 2.0 * x.y * x.y + 3.0 * x.z * x.z + x.x * x.y - x.y * x.z;
}

ForestSpec small_spec(bool periodic) {
  ForestSpec spec;
  spec.level = 1;
  spec.block_cells = 4;
  spec.periodic = {periodic, periodic, periodic};
  return spec;
}

TEST(FlowAdapt, RefiningOneBlockLinksNeighboursAcrossLevels) {
  Forest forest(small_spec(false));
  refine_where(forest, [](const Vec3& c) { return c.x < 0.5 && c.y < 0.5 && c.z < 0.5; });
  EXPECT_EQ(forest.global_blocks(), 7 + 8);
  EXPECT_EQ(forest.min_level(), 1);
  EXPECT_EQ(forest.max_level(), 2);
  EXPECT_FALSE(forest.uniform());
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const Block& block = forest.block(blk);
    const Neighbour& right = block.neighbours[neighbour_slot(1, 0, 0)];
    if (block.level == 2 && block.coord[0] == 1) {
      // A child on the x = 1/2 face sees the coarse block beyond it.
      EXPECT_EQ(right.jump, LevelJump::Coarser);
      if (right.link == Link::Local) {
        EXPECT_EQ(forest.block(right.index).level, 1);
      }
    }
    if (block.level == 1 && block.coord == std::array<std::int64_t, 3>{1, 0, 0}) {
      // Across the face at x = 1/2: the 4 children with x-bit 1 are set.
      const Neighbour& left = block.neighbours[neighbour_slot(-1, 0, 0)];
      EXPECT_EQ(left.jump, LevelJump::Finer);
      for (int c = 0; c < 8; ++c) {
        EXPECT_EQ(left.children[static_cast<std::size_t>(c)].link != Link::Boundary, (c & 1) == 1);
      }
      // Across the edge towards (-x, +y): the y-bit must be 0 too.
      const Neighbour& edge = block.neighbours[neighbour_slot(-1, 1, 0)];
      EXPECT_EQ(edge.jump, LevelJump::Same);  // (0,1,0) is an unrefined level-1 block
    }
  }
}

TEST(FlowAdapt, FinerNeighboursListFourChildrenAcrossFacesTwoAcrossEdgesOneAcrossCorners) {
  Forest forest(small_spec(true));
  refine_where(forest, [](const Vec3& c) { return c.x < 0.5 && c.y < 0.5 && c.z < 0.5; });
  double seen = 0.0;  // summed over ranks below
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const Block& block = forest.block(blk);
    for (int oz = -1; oz <= 1; ++oz)
      for (int oy = -1; oy <= 1; ++oy)
        for (int ox = -1; ox <= 1; ++ox) {
          const Neighbour& nb = block.neighbours[neighbour_slot(ox, oy, oz)];
          if (nb.jump != LevelJump::Finer) continue;
          const int zeros = (ox == 0) + (oy == 0) + (oz == 0);  // 2 face, 1 edge, 0 corner
          int children = 0;
          for (const BlockRef& child : nb.children) {
            if (child.link == Link::Boundary) continue;
            ++children;
            if (child.link == Link::Local) {
              EXPECT_EQ(forest.block(child.index).level, block.level + 1);
            }
          }
          EXPECT_EQ(children, 1 << zeros);
          ++seen;
        }
  }
  // Periodic: each of the 7 coarse blocks sees the refined octant across
  // every offset that wraps onto it (26 in all, counted once per offset).
  EXPECT_EQ(forest.sum(seen), 26.0);
}

TEST(FlowAdapt, BalanceRefinesAcrossFacesEdgesAndCorners) {
  Forest forest(small_spec(false));
  refine_where(forest, [](const Vec3& c) { return c.x < 0.5 && c.y < 0.5 && c.z < 0.5; });
  // The level-2 block [1/4, 1/2]^3 touches all 7 other level-1 blocks (3 by
  // faces, 3 by edges, 1 by a corner): refining it forces all 7 to level 2.
  refine_where(forest, [](const Vec3& c) {
    return std::abs(c.x - 0.375) < 1e-12 && std::abs(c.y - 0.375) < 1e-12 &&
           std::abs(c.z - 0.375) < 1e-12;
  });
  EXPECT_EQ(forest.global_blocks(), 64 + 7);
  EXPECT_EQ(forest.min_level(), 2);
  EXPECT_EQ(forest.max_level(), 3);
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const Block& block = forest.block(blk);
    for (const Neighbour& nb : block.neighbours) {
      if (nb.link != Link::Local) continue;
      EXPECT_EQ(forest.block(nb.index).level, block.level + static_cast<int>(nb.jump));
    }
  }
}

TEST(FlowAdapt, CoarseningMergesFamiliesBack) {
  Forest forest(small_spec(true));
  refine_where(forest, [](const Vec3& c) { return c.x < 0.5; });
  EXPECT_EQ(forest.global_blocks(), 4 + 4 * 8);
  const bool changed = forest.adapt(
      [](const Block& b) { return b.level == 2 ? AdaptFlag::Coarsen : AdaptFlag::Keep; }, {});
  EXPECT_TRUE(changed);
  EXPECT_EQ(forest.global_blocks(), 8);
  EXPECT_TRUE(forest.uniform());
  EXPECT_FALSE(forest.adapt([](const Block&) { return AdaptFlag::Keep; }, {}));
}

TEST(FlowAdapt, FlagsThatChangeNothingLeaveTheForestAndTheFieldsAsTheyAre) {
  // A regrid of a settled grid (every step, say) must not exchange, copy or
  // rebuild anything: Keep everywhere, and Refine only at max_level.
  Forest forest(small_spec(false));
  refine_where(forest, [](const Vec3& c) { return c.x < 0.5; });
  BlockField field(forest.local_blocks(), 4);
  fill_cells(forest, field, linear);
  const double sentinel = -12345.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk) field(blk, -1, 0, 0) = sentinel;
  const double* storage = field.block(0);
  const std::int64_t blocks = forest.global_blocks();
  BlockField* fields[] = {&field};
  EXPECT_FALSE(forest.adapt(
      [](const Block& b) { return b.level == 2 ? AdaptFlag::Refine : AdaptFlag::Keep; }, fields, {},
      2));
  EXPECT_EQ(forest.global_blocks(), blocks);
  EXPECT_EQ(field.block(0), storage);  // not reallocated
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    EXPECT_EQ(field(blk, -1, 0, 0), sentinel);  // no exchange either
  }
  // Coarsen on 7 of a family's 8 blocks merges nothing either.
  int asked = 0;
  EXPECT_FALSE(forest.adapt(
      [&](const Block& b) {
        return b.level == 2 && asked++ < 7 ? AdaptFlag::Coarsen : AdaptFlag::Keep;
      },
      fields, {}, 2));
  ASSERT_GT(asked, 8);  // the first family's 8th block, and the others, kept
  EXPECT_EQ(forest.global_blocks(), blocks);
  EXPECT_EQ(field.block(0), storage);
  // One block asking for a split below max_level changes the forest again.
  EXPECT_TRUE(forest.adapt(
      [](const Block& b) {
        return b.level == 2 && b.coord == std::array<std::int64_t, 3>{0, 0, 0} ? AdaptFlag::Refine
                                                                               : AdaptFlag::Keep;
      },
      fields, {}, 3));
  EXPECT_GT(forest.global_blocks(), blocks);
}

TEST(FlowAdapt, GhostsReproduceLinearFunctionsAcrossLevels) {
  Forest forest(small_spec(false));
  refine_where(forest, [](const Vec3& c) { return c.x < 0.5 && c.y < 0.5; });
  ASSERT_GT(testing::blocks_with(forest, LevelJump::Coarser), 0.0);
  ASSERT_GT(testing::blocks_with(forest, LevelJump::Finer), 0.0);
  BlockField field(forest.local_blocks(), 4);
  fill_cells(forest, field, linear);
  forest.exchange(field, kGhost);
  // Values of order 1-5: round-off only (interpolation weights sum to 1).
  for (const LevelJump jump : {LevelJump::Same, LevelJump::Coarser, LevelJump::Finer}) {
    EXPECT_LT(ghost_error(forest, field, linear, jump, kGhost), 1e-13);
  }
}

TEST(FlowAdapt, FineGhostsReproduceQuadraticsAndCoarseGhostsAverageThem) {
  Forest forest(small_spec(false));
  refine_where(forest, [](const Vec3& c) { return c.x < 0.5 && c.y < 0.5; });
  BlockField field(forest.local_blocks(), 4);
  fill_cells(forest, field, quadratic);
  forest.exchange(field, kGhost);
  // Tensor-quadratic interpolation of the coarse interior: exact.
  EXPECT_LT(ghost_error(forest, field, quadratic, LevelJump::Coarser, kGhost), 1e-13);
  // Coarse ghosts are the mean of the 8 fine cells: for a x^2 + b y^2 + c z^2
  // + cross terms the mean exceeds the centre value by (a + b + c) (h_f/2)^2,
  // exactly (the cross terms average out): (1 - 2 + 3) / 4 * (1/16)^2 here.
  const double h_fine = 0.25 / 4;
  const double excess = (1.0 - 2.0 + 3.0) * 0.25 * h_fine * h_fine;
  const double restricted = ghost_error(forest, field, quadratic, LevelJump::Finer, kGhost);
  EXPECT_NEAR(restricted, excess, 1e-13);
}

TEST(FlowAdapt, CompositeFaceGhostsReproduceQuadraticsToo) {
  // The multigrid's composite rule (CoarseGhosts::Composite: the first layer
  // across a face from the coarse layer and the block's own two cells, the
  // rest interpolated) is exact for quadratics like the interpolation, and
  // it is a different rule: on a cubic the two first layers differ.
  Forest forest(small_spec(false));
  refine_where(forest, [](const Vec3& c) { return c.x < 0.5 && c.y < 0.5; });
  BlockField field(forest.local_blocks(), 4);
  fill_cells(forest, field, quadratic);
  forest.exchange(field, kGhost, false, CoarseGhosts::Composite);
  EXPECT_LT(ghost_error(forest, field, quadratic, LevelJump::Coarser, kGhost), 1e-13);
  const auto cubic = [](const Vec3& x) { return quadratic(x) + x.x * x.x * x.x; };
  BlockField composite(forest.local_blocks(), 4), interpolated(forest.local_blocks(), 4);
  fill_cells(forest, composite, cubic);
  fill_cells(forest, interpolated, cubic);
  forest.exchange(composite, kGhost, true, CoarseGhosts::Composite);
  forest.exchange(interpolated, kGhost, true);
  double apart = 0.0;
  for (std::size_t n = 0; n < composite.raw().size(); ++n) {
    apart = std::max(apart, std::abs(composite.raw()[n] - interpolated.raw()[n]));
  }
  // Across the faces normal to x the quadratic's remainder on x^3 is the
  // product of the distances to its nodes, in h_f from the ghost: the
  // interpolation's nodes are the coarse centres 0.5, 2.5, 4.5 beyond it
  // (-5.625 h_f^3), the composite rule's the coarse centre 0.5 beyond and
  // the fine cells 1 and 2 behind (-1 h_f^3): 4.625 h_f^3 apart, h_f = 1/16.
  // (Faces normal to y differ only by 7/15 of the transverse error.)
  const double h_fine = 0.25 / 4;
  EXPECT_NEAR(apart, 4.625 * h_fine * h_fine * h_fine, 1e-12);
}

TEST(FlowAdapt, RefinementAndCoarseningCarryLinearFieldsExactly) {
  ForestSpec spec = small_spec(false);
  spec.block_cells = 8;
  Forest forest(spec);
  BlockField field(forest.local_blocks(), 8), other(forest.local_blocks(), 8, 1);
  fill_cells(forest, field, linear);
  fill_cells(forest, other, quadratic);
  BlockField* fields[] = {&field, &other};
  refine_where(
      forest, [](const Vec3& c) { return c.x < 0.5; }, fields);
  ASSERT_EQ(forest.global_blocks(), 4 + 32);
  ASSERT_EQ(field.blocks(), forest.local_blocks());
  ASSERT_EQ(other.layout().ghost, 1);
  BlockField expected(forest.local_blocks(), 8);
  fill_cells(forest, expected, linear);
  double error = 0.0;
  for (std::size_t n = 0; n < field.raw().size(); ++n) {
    error = std::max(error, std::abs(field.raw()[n] - expected.raw()[n]));
  }
  // minmod of two equal differences is that difference: exact to round-off,
  // boundary cells (one-sided slopes) included.
  EXPECT_LT(error, 1e-13);
  forest.adapt([](const Block& b) { return b.level == 2 ? AdaptFlag::Coarsen : AdaptFlag::Keep; },
               fields);
  ASSERT_TRUE(forest.uniform());
  expected = BlockField(forest.local_blocks(), 8);
  fill_cells(forest, expected, linear);
  error = 0.0;
  for (std::size_t n = 0; n < field.raw().size(); ++n) {
    error = std::max(error, std::abs(field.raw()[n] - expected.raw()[n]));
  }
  EXPECT_LT(error, 1e-13);
}

TEST(FlowAdapt, FaceFieldsKeepTheDivergenceOfEveryParentCell) {
  Forest forest(small_spec(false));
  const int b = 4;
  // u = (x^2, y^2, z^2) on faces: the discrete divergence of a cell is
  // 2 (x_c + y_c + z_c) at its centre, exactly. After refinement every child
  // must carry its parent cell's divergence (the prolongation keeps the
  // fluxes and the divergence, it does not add detail).
  auto square = [](const Vec3& x) { return Vec3{x.x * x.x, x.y * x.y, x.z * x.z}; };
  auto normal_linear = [](const Vec3& x) { return Vec3{1.0 + x.x, 2.0 * x.y, -3.0 * x.z}; };
  FaceField uf = make_vector_field(forest.local_blocks(), b);
  FaceField linear_faces = make_vector_field(forest.local_blocks(), b);
  fill_faces(forest, uf, square);
  fill_faces(forest, linear_faces, normal_linear);
  FaceField* faces[] = {&uf, &linear_faces};
  forest.adapt(
      [](const Block& block) {
        return block_centre(block).x < 0.5 ? AdaptFlag::Refine : AdaptFlag::Keep;
      },
      {}, faces);
  ASSERT_EQ(forest.global_blocks(), 4 + 32);
  double divergence_error = 0.0, linear_error = 0.0;
  FaceField expected = make_vector_field(forest.local_blocks(), b);
  fill_faces(forest, expected, normal_linear);
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const Block& block = forest.block(blk);
    const double h = block.length / b;
    for (int d = 0; d < 3; ++d) {
      std::array<int, 3> end{b, b, b};
      end[static_cast<std::size_t>(d)] = b + 1;
      for (int k = 0; k < end[2]; ++k)
        for (int j = 0; j < end[1]; ++j)
          for (int i = 0; i < end[0]; ++i) {
            const auto c = static_cast<std::size_t>(d);
            linear_error = std::max(
                linear_error, std::abs(linear_faces[c](blk, i, j, k) - expected[c](blk, i, j, k)));
          }
    }
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          const double div =
              (uf[0](blk, i + 1, j, k) - uf[0](blk, i, j, k) + uf[1](blk, i, j + 1, k) -
               uf[1](blk, i, j, k) + uf[2](blk, i, j, k + 1) - uf[2](blk, i, j, k)) /
              h;
          // The centre of the cell of the original (level-1) grid holding this cell.
          const double H = 0.5 / b;
          const Vec3 x{block.lower.x + (i + 0.5) * h, block.lower.y + (j + 0.5) * h,
                       block.lower.z + (k + 0.5) * h};
          double centres = 0.0;
          for (int d = 0; d < 3; ++d) centres += (std::floor(x[d] / H) + 0.5) * H;
          divergence_error = std::max(divergence_error, std::abs(div - 2.0 * centres));
        }
  }
  // Differences of values <= 1 divided by h = 1/16: round-off times 16.
  EXPECT_LT(divergence_error, 1e-13);
  // Components linear along their own direction: exact.
  EXPECT_LT(linear_error, 1e-14);
  // Coarsening back restores the original faces (the mean of 4 equal values).
  forest.adapt(
      [](const Block& block) { return block.level == 2 ? AdaptFlag::Coarsen : AdaptFlag::Keep; },
      {}, faces);
  FaceField original = make_vector_field(forest.local_blocks(), b);
  fill_faces(forest, original, square);
  double round_trip = 0.0;
  for (std::size_t c = 0; c < 3; ++c)
    for (int blk = 0; blk < forest.local_blocks(); ++blk)
      for (int k = 0; k <= b; ++k)
        for (int j = 0; j <= b; ++j)
          for (int i = 0; i <= b; ++i) {
            std::array<int, 3> f{i, j, k};
            bool valid = true;
            for (std::size_t x = 0; x < 3; ++x) valid = valid && (x == c ? f[x] <= b : f[x] < b);
            if (valid)
              round_trip =
                  std::max(round_trip, std::abs(uf[c](blk, i, j, k) - original[c](blk, i, j, k)));
          }
  EXPECT_LT(round_trip, 1e-15);
}

/// Sum of cell value times cell volume over all ranks.
double integral(const Forest& forest, const BlockField& field) {
  const int b = field.cells();
  double sum = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const double h = forest.block(blk).length / b;
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) sum += field(blk, i, j, k) * h * h * h;
  }
  return forest.sum(sum);
}

TEST(FlowAdapt, TransferConservesTheIntegralAndCreatesNoNewExtrema) {
  ForestSpec spec = small_spec(true);
  Forest forest(spec);
  BlockField wave(forest.local_blocks(), 4), step(forest.local_blocks(), 4);
  fill_cells(forest, wave, [](const Vec3& x) { return std::sin(6.0 * x.x) * std::cos(4.0 * x.y); });
  fill_cells(forest, step, [](const Vec3& x) { return x.x + 0.3 * x.y < 0.6 ? 1.0 : -1.0; });
  const double before = integral(forest, wave), step_before = integral(forest, step);
  BlockField* fields[] = {&wave, &step};
  refine_where(
      forest, [](const Vec3& c) { return c.y < 0.5; }, fields);
  // The child offsets +-h/4 cancel in pairs: the parent's mean is kept, to round-off.
  EXPECT_NEAR(integral(forest, wave), before, 1e-15);
  EXPECT_NEAR(integral(forest, step), step_before, 1e-15);
  double lo = 0.0, hi = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk)
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
          lo = std::min(lo, step(blk, i, j, k));
          hi = std::max(hi, step(blk, i, j, k));
        }
  // minmod: a step stays within its two values.
  EXPECT_GE(lo, -1.0);
  EXPECT_LE(hi, 1.0);
}

}  // namespace
}  // namespace sanguis::flow
