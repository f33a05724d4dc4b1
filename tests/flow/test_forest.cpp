// Forest of blocks: brick geometry, neighbours, ghost exchange (periodic wrap
// included) and boundary ghost filling.
#include <gtest/gtest.h>

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "flow/boundary.hpp"
#include "flow/forest.hpp"

namespace sanguis::flow {
namespace {

/// A value that identifies a global cell (wrapped into the domain).
double cell_tag(std::int64_t gx, std::int64_t gy, std::int64_t gz) {
  return static_cast<double>(gx) + 1000.0 * static_cast<double>(gy) + 1e6 * static_cast<double>(gz);
}

/// A field whose cells hold their cell_tag and whose ghosts hold -1.
BlockField tagged_cells(const Forest& forest) {
  const int b = forest.block_cells();
  BlockField field(forest.local_blocks(), b);
  field.fill(-1.0);
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const auto& c = forest.block(blk).coord;
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i)
          field(blk, i, j, k) = cell_tag(c[0] * b + i, c[1] * b + j, c[2] * b + k);
  }
  return field;
}

TEST(FlowForest, BrickOfAnyAspectRatioHasTheRightBlocksAndExtent) {
  ForestSpec spec;
  spec.trees = {1, 2, 3};
  spec.level = 1;
  spec.block_cells = 4;
  spec.tree_length = 0.5;
  const Forest forest(spec);
  EXPECT_EQ(forest.global_blocks(), 6 * 8);
  EXPECT_EQ(forest.local_blocks() * forest.ranks(), forest.global_blocks());
  EXPECT_DOUBLE_EQ(forest.extent().z, 1.5);
  const auto n = forest.blocks_per_direction(1);
  EXPECT_EQ(n[0], 2);
  EXPECT_EQ(n[2], 6);
  for (int b = 0; b < forest.local_blocks(); ++b) {
    const Block& block = forest.block(b);
    EXPECT_DOUBLE_EQ(block.length, 0.25);
    EXPECT_DOUBLE_EQ(block.lower.y, 0.25 * static_cast<double>(block.coord[1]));
  }
}

/// Two trees along x, level 1, blocks of 4^3 cells, periodic in x and z with
/// walls along y: the forest of the single-block ghost tests below.
ForestSpec two_trees_walls_along_y() {
  ForestSpec spec;
  spec.trees = {2, 1, 1};
  spec.periodic = {true, false, true};
  spec.level = 1;
  spec.block_cells = 4;
  return spec;
}

TEST(FlowForest, GhostExchangeCopiesNeighbourCellsWithPeriodicWrap) {
  ForestSpec spec;
  spec.trees = {2, 1, 1};
  spec.periodic = {true, true, false};
  spec.level = 1;
  spec.block_cells = 4;
  const Forest forest(spec);
  const int b = spec.block_cells;
  const auto nb = forest.blocks_per_direction(spec.level);
  const std::array<std::int64_t, 3> n{nb[0] * b, nb[1] * b, nb[2] * b};
  BlockField field = tagged_cells(forest);
  forest.exchange(field, kGhost);
  int checked = 0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const auto& c = forest.block(blk).coord;
    for (int k = -kGhost; k < b + kGhost; ++k)
      for (int j = -kGhost; j < b + kGhost; ++j)
        for (int i = -kGhost; i < b + kGhost; ++i) {
          std::int64_t g[3] = {c[0] * b + i, c[1] * b + j, c[2] * b + k};
          bool outside = false;
          for (int d = 0; d < 3; ++d) {
            if (g[d] < 0 || g[d] >= n[static_cast<std::size_t>(d)]) {
              if (spec.periodic[static_cast<std::size_t>(d)]) {
                g[d] = (g[d] + n[static_cast<std::size_t>(d)]) % n[static_cast<std::size_t>(d)];
              } else {
                outside = true;
              }
            }
          }
          if (outside) {
            EXPECT_EQ(field(blk, i, j, k), -1.0);  // left for the boundary conditions
            continue;
          }
          ASSERT_EQ(field(blk, i, j, k), cell_tag(g[0], g[1], g[2]))
              << blk << ' ' << i << ' ' << j << ' ' << k;
          ++checked;
        }
  }
  EXPECT_GT(checked, 0);
}

// The Navier-Stokes loops fill each block's ghosts right before they read them on a
// uniform one-process forest: fill_same_level_ghosts must write, block by block and in any
// order, every ghost exchange() writes (faces, edges, corners, both layers, periodic wrap)
// with the same value, and nothing else; a refined forest is not uniform_local().
TEST(FlowForest, OneBlocksGhostsFilledAloneMatchTheExchange) {
  const ForestSpec spec = two_trees_walls_along_y();
  Forest forest(spec);
  if (forest.ranks() > 1) GTEST_SKIP() << "needs one rank";
  ASSERT_TRUE(forest.uniform_local());
  BlockField exchanged = tagged_cells(forest), second = tagged_cells(forest);
  BlockField alone = exchanged, alone_second = second;
  BlockField* both[] = {&exchanged, &second};
  forest.exchange(both, kGhost);
  BlockField* both_alone[] = {&alone, &alone_second};
  for (int blk = forest.local_blocks() - 1; blk >= 0; --blk) {  // backwards: order is free
    forest.fill_same_level_ghosts(both_alone, blk, kGhost);
  }
  std::size_t filled = 0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const int b = spec.block_cells;
    for (int k = -kGhost; k < b + kGhost; ++k)
      for (int j = -kGhost; j < b + kGhost; ++j)
        for (int i = -kGhost; i < b + kGhost; ++i) {
          ASSERT_EQ(alone(blk, i, j, k), exchanged(blk, i, j, k)) << blk << ' ' << i << j << k;
          ASSERT_EQ(alone_second(blk, i, j, k), second(blk, i, j, k)) << blk << ' ' << i << j << k;
          const bool ghost = i < 0 || i >= b || j < 0 || j >= b || k < 0 || k >= b;
          filled += ghost && exchanged(blk, i, j, k) != -1.0;
        }
  }
  EXPECT_GT(filled, 0u);
  // One block refined: two levels, so ghosts may come from interpolation.
  forest.adapt(
      [](const Block& block) {
        return block.coord == std::array<std::int64_t, 3>{0, 0, 0} ? AdaptFlag::Refine
                                                                   : AdaptFlag::Keep;
      },
      {});
  EXPECT_FALSE(forest.uniform_local());
}

TEST(FlowForest, StencilGhostsAreTheFacesTwoDeepAndTheEdgesOneDeep) {
  // fill_same_level_ghosts(..., stencil_only) for the face prediction and the
  // face average: the face ghosts (both layers) and the first layer of the
  // edge ghosts as the exchange fills them; the second edge layer and the
  // corners untouched (still -1, as tagged_cells leaves every ghost).
  const ForestSpec spec = two_trees_walls_along_y();
  const Forest forest(spec);
  if (forest.ranks() > 1) GTEST_SKIP() << "needs one rank";
  ASSERT_TRUE(forest.uniform_local());
  BlockField exchanged = tagged_cells(forest);
  BlockField stencil = exchanged;
  forest.exchange(exchanged, kGhost);
  BlockField* one[] = {&stencil};
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    forest.fill_same_level_ghosts(one, blk, kGhost, /*stencil_only=*/true);
  }
  const int b = spec.block_cells;
  const auto beyond = [b](int n) { return n < 0 ? -n : (n >= b ? n - b + 1 : 0); };
  std::size_t edges = 0, untouched = 0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    for (int k = -kGhost; k < b + kGhost; ++k)
      for (int j = -kGhost; j < b + kGhost; ++j)
        for (int i = -kGhost; i < b + kGhost; ++i) {
          const int out[] = {beyond(i), beyond(j), beyond(k)};
          const int across = (out[0] > 0) + (out[1] > 0) + (out[2] > 0);
          const int deepest = std::max({out[0], out[1], out[2]});
          // Beyond a domain wall (y here) nothing is exchanged: -1 in both.
          const bool wanted = across <= 1 || (across == 2 && deepest == 1);
          if (wanted) {
            ASSERT_EQ(stencil(blk, i, j, k), exchanged(blk, i, j, k)) << blk << ' ' << i << j << k;
            edges += across == 2 && exchanged(blk, i, j, k) != -1.0;
          } else {
            ASSERT_EQ(stencil(blk, i, j, k), -1.0) << blk << ' ' << i << j << k;
            untouched += exchanged(blk, i, j, k) != -1.0;
          }
        }
  }
  EXPECT_GT(edges, 0u);      // some first-layer edge ghosts were copied
  EXPECT_GT(untouched, 0u);  // and some that the exchange fills were left alone
}

// The fused smoother fills one block's face ghosts at a time: copy_face_ghosts
// must put there what exchange(field, 1, faces only) does (periodic wrap and
// boundary faces included), and a colour must copy that colour and no other.
TEST(FlowForest, OneBlocksFaceGhostsMatchTheExchangeColourByColour) {
  const ForestSpec spec = two_trees_walls_along_y();
  const Forest forest(spec);
  ASSERT_TRUE(forest.faces_local_same_level() || forest.ranks() > 1);
  if (!forest.faces_local_same_level()) GTEST_SKIP() << "needs one rank";
  const int b = spec.block_cells;
  BlockField exchanged = tagged_cells(forest);
  BlockField whole = exchanged, red = exchanged;
  forest.exchange(exchanged, 1, true);
  int face_ghosts = 0, red_ghosts = 0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    forest.copy_face_ghosts(whole, blk);
    forest.copy_face_ghosts(red, blk, 0);
    const auto& c = forest.block(blk).coord;
    for (int k = -1; k <= b; ++k)
      for (int j = -1; j <= b; ++j)
        for (int i = -1; i <= b; ++i) {
          const int outside = (i < 0 || i >= b) + (j < 0 || j >= b) + (k < 0 || k >= b);
          if (outside != 1) continue;  // interior, edge and corner ghosts: not face ghosts
          ASSERT_EQ(whole(blk, i, j, k), exchanged(blk, i, j, k)) << blk << ' ' << i << j << k;
          const bool is_red = ((c[0] + c[1] + c[2]) * b + i + j + k) % 2 == 0;
          EXPECT_EQ(red(blk, i, j, k), is_red ? exchanged(blk, i, j, k) : -1.0);
          face_ghosts += exchanged(blk, i, j, k) != -1.0;
          red_ghosts += is_red && exchanged(blk, i, j, k) != -1.0;
        }
  }
  // 4 x 2 x 2 blocks of 4^3: each has a wall at one of its y faces, 5 faces of 16 ghosts left.
  EXPECT_EQ(face_ghosts, forest.local_blocks() * 5 * b * b);
  EXPECT_EQ(2 * red_ghosts, face_ghosts);
}

TEST(FlowForest, DirichletAndNeumannGhostsReproduceTheFaceValue) {
  ForestSpec spec;
  spec.level = 1;
  spec.block_cells = 4;
  const Forest forest(spec);
  BlockField field(forest.local_blocks(), 4);
  field.fill(1.0);
  ScalarBoundary bc;
  bc.kind = uniform_kinds(forest, BcKind::Dirichlet);
  bc.kind[face_index(2, 1)] = BcKind::Neumann;
  bc.value[face_index(0, 0)] = [](const Vec3& x) { return 3.0 + x.y; };
  forest.exchange(field, 2);
  fill_boundary_ghosts(forest, field, bc, 2);
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const Block& block = forest.block(blk);
    if (block.coord[0] == 0) {
      const double y = block.lower.y + 1.5 * block.length / 4;
      // Quadratic closure: the face value from the ghost and two interior cells.
      EXPECT_DOUBLE_EQ(
          (3 * field(blk, -1, 1, 1) + 6 * field(blk, 0, 1, 1) - field(blk, 1, 1, 1)) / 8, 3.0 + y);
      EXPECT_DOUBLE_EQ(0.5 * (field(blk, -2, 1, 1) + field(blk, 1, 1, 1)), 3.0 + y);
    }
    if (block.coord[0] == 1) {
      EXPECT_DOUBLE_EQ(field(blk, 4, 1, 1), -5.0 / 3.0);
    }
    if (block.coord[2] == 1) {
      EXPECT_DOUBLE_EQ(field(blk, 1, 1, 5), 1.0);
    }
  }
}

TEST(FlowForest, BoundaryGhostsOfOneColourAreTheFullFillsFaceGhostsOfThatColour) {
  // The smoother's per-block fill (fill_block_boundary_ghosts with a colour):
  // every face ghost of that colour gets the value of the full fill, bit for
  // bit, for each kind of closure (Dirichlet with a given value, at rest,
  // homogeneous; Neumann), and no other ghost is written.
  ForestSpec spec;
  spec.trees = {2, 1, 1};
  spec.level = 1;
  spec.block_cells = 4;
  const Forest forest(spec);
  const int b = spec.block_cells;
  std::array<BcKind, 6> kinds = uniform_kinds(forest, BcKind::Dirichlet);
  kinds[face_index(2, 1)] = BcKind::Neumann;
  std::array<FaceValue, 6> values{};
  values[face_index(0, 0)] = [](const Vec3& x) { return 3.0 + x.y * x.z; };
  values[face_index(1, 1)] = [](const Vec3& x) { return -x.x; };
  for (const bool homogeneous : {false, true}) {
    const std::array<FaceValue, 6>* given = homogeneous ? nullptr : &values;
    BlockField full = tagged_cells(forest);
    for (int blk = 0; blk < forest.local_blocks(); ++blk)
      fill_block_boundary_ghosts(forest, full, blk, kinds, given, 1);
    int checked = 0;
    for (int colour = 0; colour < 2; ++colour) {
      BlockField one = tagged_cells(forest);
      for (int blk = 0; blk < forest.local_blocks(); ++blk)
        fill_block_boundary_ghosts(forest, one, blk, kinds, given, 1, colour);
      for (int blk = 0; blk < forest.local_blocks(); ++blk) {
        const auto& c = forest.block(blk).coord;
        for (int k = -1; k <= b; ++k)
          for (int j = -1; j <= b; ++j)
            for (int i = -1; i <= b; ++i) {
              const int outside = (i < 0 || i >= b) + (j < 0 || j >= b) + (k < 0 || k >= b);
              if (outside == 0) continue;
              const bool of_colour = (((c[0] + c[1] + c[2]) * b + i + j + k) & 1) == colour;
              if (outside == 1 && of_colour) {
                ASSERT_EQ(one(blk, i, j, k), full(blk, i, j, k)) << blk << ' ' << i << j << k;
                const int n[3] = {i, j, k};
                for (int d = 0; d < 3; ++d) {
                  if (n[d] >= 0 && n[d] < b) continue;
                  const int side = n[d] < 0 ? 0 : 1;
                  checked += forest.block(blk).neighbours[face_neighbour_slot(d, side)].link ==
                             Link::Boundary;
                }
              } else {
                ASSERT_EQ(one(blk, i, j, k), -1.0) << blk << ' ' << i << j << k;
              }
            }
      }
    }
    // The two colours together: every face ghost on the boundary.
    int boundary_face_ghosts = 0;
    for (int blk = 0; blk < forest.local_blocks(); ++blk)
      for (int d = 0; d < 3; ++d)
        for (int side = 0; side < 2; ++side)
          boundary_face_ghosts +=
              forest.block(blk).neighbours[face_neighbour_slot(d, side)].link == Link::Boundary
                  ? b * b
                  : 0;
    EXPECT_GT(boundary_face_ghosts, 0);
    EXPECT_EQ(checked, boundary_face_ghosts);
  }
}

/// The blocks each thread visits, in its order of visit (each thread appends
/// to its own list only).
template <typename Loop>
std::vector<std::vector<int>> visits_per_thread(int threads, Loop&& loop) {
  std::vector<std::vector<int>> visits(static_cast<std::size_t>(threads));
  loop([&](int b) { visits[static_cast<std::size_t>(omp_get_thread_num())].push_back(b); });
  return visits;
}

// The smoother's second half-sweep goes backwards so that it starts on the
// blocks still in cache; the cache it reuses is the one of the thread that
// last touched them, so each thread must keep its share of the blocks.
TEST(FlowForest, BackwardLoopGivesEachThreadItsForwardShareReversed) {
  struct Case {
    std::array<int, 3> trees;
    int level, threads;
  };
  // 40 blocks on 1, 2 and 3 threads (40 % 3 = 1: uneven shares), and 2 blocks
  // on 3 threads (a thread with none).
  for (const Case& c : {Case{{1, 1, 5}, 1, 1}, Case{{1, 1, 5}, 1, 2}, Case{{1, 1, 5}, 1, 3},
                        Case{{1, 1, 2}, 0, 3}}) {
    ForestSpec spec;
    spec.trees = c.trees;
    spec.level = c.level;
    spec.block_cells = 4;
    spec.threads = c.threads;
    const Forest forest(spec);
    const int n = forest.local_blocks();
    const auto forward =
        visits_per_thread(c.threads, [&](auto&& body) { forest.for_each_block(body); });
    const auto backward =
        visits_per_thread(c.threads, [&](auto&& body) { forest.for_each_block_backward(body); });
    // Forward: thread t takes the t-th contiguous share, in increasing order,
    // one block more for the first n % T; so every block exactly once, and
    // every thread with a share of its own (the team really has T threads).
    int next = 0;
    for (int t = 0; t < c.threads; ++t) {
      const auto& mine = forward[static_cast<std::size_t>(t)];
      const int expected = n / c.threads + (t < n % c.threads ? 1 : 0);
      ASSERT_EQ(static_cast<int>(mine.size()), expected) << c.threads << " threads, thread " << t;
      for (const int b : mine) EXPECT_EQ(b, next++);
      auto reversed = mine;
      std::reverse(reversed.begin(), reversed.end());
      EXPECT_EQ(backward[static_cast<std::size_t>(t)], reversed)
          << c.threads << " threads, thread " << t;
    }
    EXPECT_EQ(next, n);
  }
}

}  // namespace
}  // namespace sanguis::flow
