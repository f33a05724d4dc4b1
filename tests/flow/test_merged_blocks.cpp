// The multigrid's merged blocks (src/flow/merged_blocks.hpp): which forests
// merge, copies that put every value where it lies, and solves on the merged
// blocks that give the solves on the flow's blocks.
#include <gtest/gtest.h>

#include <cmath>

#include "adapt_poisson.hpp"
#include "flow/merged_blocks.hpp"
#include "flow/multigrid.hpp"
#include "flow/navier_stokes.hpp"
#include "navier_stokes_problems.hpp"
#include "poisson_problems.hpp"

namespace sanguis::flow {
namespace {

TEST(MergedBlocks, UniformForestsOfSmallBlocksMerge) {
  ForestSpec spec;
  spec.level = 2;  // 4^3 blocks of 8^3
  const Forest levels(spec);
  const auto by_level = merged_forest_spec(levels);
  ASSERT_TRUE(by_level.has_value());
  EXPECT_EQ(by_level->level, 1);
  EXPECT_EQ(by_level->block_cells, 16);
  EXPECT_EQ(by_level->trees, spec.trees);
  EXPECT_EQ(by_level->tree_length, spec.tree_length);

  ForestSpec brick;  // 8 x 4 x 4 trees at level 0 (the benchmark cavity's kind)
  brick.trees = {8, 4, 4};
  brick.tree_length = 0.125;
  brick.periodic = {true, false, false};
  const auto by_trees = merged_forest_spec(Forest(brick));
  ASSERT_TRUE(by_trees.has_value());
  EXPECT_EQ(by_trees->level, 0);
  EXPECT_EQ(by_trees->trees, (std::array<int, 3>{4, 2, 2}));
  EXPECT_EQ(by_trees->tree_length, 0.25);
  EXPECT_EQ(by_trees->periodic, brick.periodic);
  brick.trees = {8, 4, 2};  // one merged block along z: too few to coarsen further
  EXPECT_FALSE(merged_forest_spec(Forest(brick)).has_value());
  brick.trees = {8, 4, 3};  // odd: the families are not whole
  EXPECT_FALSE(merged_forest_spec(Forest(brick)).has_value());

  spec.block_cells = 16;  // already large
  EXPECT_FALSE(merged_forest_spec(Forest(spec)).has_value());
  spec.block_cells = 8;
  spec.level = 1;  // 2 blocks per direction would merge into 1
  EXPECT_FALSE(merged_forest_spec(Forest(spec)).has_value());

  spec.level = 2;
  Forest refined(spec);
  testing::refine_where(refined, testing::in_refined_octant);
  EXPECT_FALSE(merged_forest_spec(refined).has_value());
}

TEST(MergedBlocks, CopiesPutEveryValueWhereItLies) {
  ForestSpec spec;
  spec.trees = {2, 1, 1};
  spec.level = 2;
  spec.block_cells = 4;
  spec.tree_length = 0.5;
  const Forest fine(spec);
  const auto merged_spec = merged_forest_spec(fine);
  ASSERT_TRUE(merged_spec.has_value());
  const Forest merged(*merged_spec);
  const MergedBlocks copies(fine, merged);
  // A value that names its cell.
  const auto label = [](const Vec3& x) { return 1e6 * x.x + 1e3 * x.y + x.z; };
  const BlockField cells = testing::sample(fine, label);
  BlockField on_merged(merged.local_blocks(), merged.block_cells());
  copies.to_merged(cells, on_merged);
  const int m = merged.block_cells();
  for (int blk = 0; blk < merged.local_blocks(); ++blk)
    for (int k = 0; k < m; ++k)
      for (int j = 0; j < m; ++j)
        for (int i = 0; i < m; ++i)
          ASSERT_EQ(on_merged(blk, i, j, k), label(testing::cell_centre(merged, blk, i, j, k)));
  BlockField back(fine.local_blocks(), fine.block_cells());
  copies.to_fine(on_merged, back);
  for (int blk = 0; blk < fine.local_blocks(); ++blk)
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) ASSERT_EQ(back(blk, i, j, k), cells(blk, i, j, k));

  // Faces 0..b along d (slot b in the ghost layer) land on faces 0..2b.
  for (int d = 0; d < 3; ++d) {
    const auto face_label = [&](const Forest& forest, int blk, int i, int j, int k) {
      Vec3 x = testing::cell_centre(forest, blk, i, j, k);
      const double h = forest.block(blk).length / forest.block_cells();
      (d == 0 ? x.x : (d == 1 ? x.y : x.z)) -= 0.5 * h;  // the lower d-face
      return label(x);
    };
    BlockField faces(fine.local_blocks(), 4);
    for (int blk = 0; blk < fine.local_blocks(); ++blk)
      for (int k = 0; k <= 4; ++k)
        for (int j = 0; j <= 4; ++j)
          for (int i = 0; i <= 4; ++i) faces(blk, i, j, k) = face_label(fine, blk, i, j, k);
    BlockField merged_faces(merged.local_blocks(), m);
    copies.faces_to_merged(faces, d, merged_faces);
    for (int blk = 0; blk < merged.local_blocks(); ++blk)
      for (int k = 0; k < m + (d == 2); ++k)
        for (int j = 0; j < m + (d == 1); ++j)
          for (int i = 0; i < m + (d == 0); ++i)
            ASSERT_EQ(merged_faces(blk, i, j, k), face_label(merged, blk, i, j, k))
                << "direction " << d;
  }
}

/// -div(beta grad x) + alpha x = rhs with varying alpha and beta and
/// Dirichlet walls on 32^3 cells (4^3 blocks of 8^3), on the flow's blocks or
/// on the merged ones.
MultigridReport solve_helmholtz(bool merge, BlockField& x) {
  ForestSpec spec;
  spec.level = 2;
  const Forest forest(spec);
  ScalarBoundary bc;
  bc.kind = uniform_kinds(forest, BcKind::Dirichlet);
  for (auto& v : bc.value) v = testing::dirichlet_exact;
  Multigrid mg(forest, bc.kind, merge);
  EXPECT_EQ(mg.merged(), merge);
  const BlockField alpha = testing::sample(forest, [](const Vec3& p) { return 1.0 + p.x; });
  // beta on the lower d-face of each cell, taken at that cell's centre (so
  // the same value where two blocks share a face): faces 0..b, slot b too.
  FaceField beta;
  for (BlockField& f : beta) {
    f = BlockField(forest.local_blocks(), 8);
    for (int blk = 0; blk < forest.local_blocks(); ++blk)
      for (int k = 0; k <= 8; ++k)
        for (int j = 0; j <= 8; ++j)
          for (int i = 0; i <= 8; ++i) {
            const Vec3 p = testing::cell_centre(forest, blk, i, j, k);
            f(blk, i, j, k) = 1.0 + p.y * p.z;
          }
  }
  mg.set_coefficients(&alpha, &beta);
  x = BlockField(forest.local_blocks(), 8);
  MultigridOptions options;
  options.tolerance = 1e-12;
  return mg.solve(x, testing::sample(forest, testing::dirichlet_source), bc, options);
}

/// Largest difference between two fields' interior cells, and of |b|; with
/// `solid`, over the cells where it is 0 only.
std::pair<double, double> interior_difference(const BlockField& a, const BlockField& b,
                                              const BlockField* solid = nullptr) {
  double diff = 0.0, scale = 0.0;
  const int n = a.cells();
  for (int blk = 0; blk < a.blocks(); ++blk)
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          if (solid && (*solid)(blk, i, j, k) != 0.0) continue;
          diff = std::max(diff, std::abs(a(blk, i, j, k) - b(blk, i, j, k)));
          scale = std::max(scale, std::abs(b(blk, i, j, k)));
        }
  return {diff, scale};
}

TEST(MergedBlocks, MultigridOnMergedBlocksGivesTheSameSolution) {
  BlockField merged, own;
  const auto on_merged = solve_helmholtz(true, merged);
  const auto on_own = solve_helmholtz(false, own);
  ASSERT_TRUE(on_merged.converged);
  ASSERT_TRUE(on_own.converged);
  const auto [diff, scale] = interior_difference(merged, own);
  std::printf(
      "Helmholtz 32^3, 8^3 blocks: merged %d V-cycles (%.1fx per cycle), own blocks %d (%.1fx); "
      "max difference %.2e of %.2f\n",
      on_merged.cycles, on_merged.mean_reduction(), on_own.cycles, on_own.mean_reduction(), diff,
      scale);
  // Both solved to 1e-12 of the rhs: the same answer to about that.
  EXPECT_LT(diff, 1e-9 * scale);
  // The merged hierarchy has one level more inside the blocks and a smaller
  // bottom grid; its rate per cycle must not be worse by much.
  EXPECT_GT(on_merged.mean_reduction(), 0.8 * on_own.mean_reduction());
  EXPECT_LE(on_merged.cycles, on_own.cycles + 1);
}

TEST(MergedBlocks, NavierStokesStepsTheSameOnMergedSolverBlocks) {
  // Ten steps of the Re = 100 cavity at 32^3 (4^3 blocks of 8^3) with the
  // multigrids on merged blocks and on the flow's: the same flow to the
  // solvers' tolerance. Then with a solid box (masked cells: closed faces in
  // the pressure's beta, the viscous solves' walls) and a viscosity that
  // varies (beta from cell to cell).
  for (const bool obstructed : {false, true}) {
    auto run = [&](bool merge) {
      ForestSpec spec;
      spec.level = 2;
      const Forest forest(spec);
      NavierStokesOptions options;
      options.pressure.tolerance = 1e-10;
      options.viscous.tolerance = 1e-10;
      options.merge_solver_blocks = merge;
      NavierStokes ns(forest, testing::lid_driven_cavity(), Fluid{1.0, 0.01}, options);
      ns.set_velocity([](const Vec3&) { return Vec3{}; });
      if (obstructed) {
        ns.set_solid([](const Vec3& x) {
          return x.x > 0.25 && x.x < 0.5 && x.y > 0.25 && x.y < 0.5 && x.z < 0.75;
        });
        ns.set_viscosity([](const Vec3& x) { return 0.01 * (1.0 + x.y); });
      }
      for (int s = 0; s < 10; ++s) ns.step(0.01);
      return std::array<BlockField, 3>{ns.velocity()[0], ns.pressure(), ns.solid()};
    };
    const auto merged = run(true), own = run(false);
    for (std::size_t f = 0; f < 2; ++f) {
      // In solid cells the pressure is no part of the solution: the solver
      // leaves them out of its rows, and the prolongation adds each hierarchy's
      // corrections there (1e-3 apart here), which nothing reads.
      const auto [diff, scale] = interior_difference(merged[f], own[f], &own[2]);
      std::printf("cavity 32^3%s, 10 steps, %s: max difference %.2e of %.3f\n",
                  obstructed ? " with a solid box and varying viscosity" : "", f == 0 ? "u" : "p",
                  diff, scale);
      EXPECT_LT(diff, 1e-7 * scale);
    }
  }
}

}  // namespace
}  // namespace sanguis::flow
