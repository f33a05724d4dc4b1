// Verlet lists from linked cells against brute force, with periodic images, and
// contact histories carried across rebuilds.
#include <gtest/gtest.h>

#include <random>
#include <set>
#include <utility>

#include "dem/neighbor_search.hpp"

namespace sanguis::dem {
namespace {

ParticleStore random_particles(std::size_t n, const Domain& d, std::uint64_t seed) {
  ParticleStore p;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 x{d.min.x + u(rng) * (d.max.x - d.min.x), d.min.y + u(rng) * (d.max.y - d.min.y),
                 d.min.z + u(rng) * (d.max.z - d.min.z)};
    p.add_sphere(static_cast<std::int64_t>(i), 0, 0.8e-3 + 0.4e-3 * u(rng), 2500.0, x, {}, {});
  }
  return p;
}

std::set<std::pair<std::uint32_t, std::uint32_t>> brute_force(const ParticleStore& p,
                                                              const Domain& d, double skin) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> pairs;
  for (std::uint32_t i = 0; i < p.size(); ++i)
    for (std::uint32_t j = i + 1; j < p.size(); ++j) {
      const double cut = p.radius[i] + p.radius[j] + skin;
      if (norm2(d.minimum_image(p.position[j] - p.position[i])) < cut * cut) pairs.insert({i, j});
    }
  return pairs;
}

TEST(NeighborSearch, FindsExactlyThePairsWithinCutoffWithPeriodicImages) {
  for (auto periodic :
       {std::array<bool, 3>{false, false, false}, std::array<bool, 3>{true, false, true},
        std::array<bool, 3>{true, true, true}}) {
    Domain d{{0.0, 0.0, 0.0}, {0.02, 0.015, 0.03}, periodic};
    ParticleStore p = random_particles(1500, d, 11);
    const double skin = 0.3e-3;
    NeighborSearch search(d, skin, 1.2e-3);
    ContactList pairs, walls;
    search.rebuild(p, {}, 0.0, pairs, walls);
    std::set<std::pair<std::uint32_t, std::uint32_t>> found;
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      ASSERT_LT(pairs.first[k], pairs.second[k]);
      if (k > 0) {  // sorted by (first, second)
        ASSERT_TRUE(pairs.first[k - 1] < pairs.first[k] || (pairs.first[k - 1] == pairs.first[k] &&
                                                            pairs.second[k - 1] < pairs.second[k]));
      }
      found.insert({pairs.first[k], pairs.second[k]});
    }
    EXPECT_EQ(found, brute_force(p, d, skin));
    EXPECT_EQ(found.size(), pairs.size());
  }
}

TEST(NeighborSearch, CarriesHistoriesAcrossRebuildsAndRebuildsOnlyWhenNeeded) {
  Domain d{{0.0, 0.0, 0.0}, {0.02, 0.02, 0.02}, {true, true, true}};
  ParticleStore p = random_particles(800, d, 5);
  const double skin = 0.4e-3;
  NeighborSearch search(d, skin, 1.2e-3);
  ContactList pairs, walls;
  search.rebuild(p, {}, 0.0, pairs, walls);
  ASSERT_GT(pairs.size(), 10u);
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    pairs.history[k].tangential_displacement = {double(pairs.first[k]), double(pairs.second[k]),
                                                1.0};
  }
  EXPECT_FALSE(search.needs_rebuild(p));
  // Move one particle by less than half the skin: no rebuild needed; more: rebuild.
  p.position[3].x += 0.4 * skin;
  EXPECT_FALSE(search.needs_rebuild(p));
  p.position[3].x += 0.2 * skin;
  EXPECT_TRUE(search.needs_rebuild(p));
  search.rebuild(p, {}, 0.0, pairs, walls);
  std::size_t carried = 0;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const Vec3& h = pairs.history[k].tangential_displacement;
    if (h.z == 1.0) {
      EXPECT_EQ(h.x, double(pairs.first[k]));
      EXPECT_EQ(h.y, double(pairs.second[k]));
      ++carried;
    }
  }
  EXPECT_GT(carried, pairs.size() - 20);  // all but the pairs of particle 3 that changed
}

TEST(NeighborSearch, ListsObstaclesWithinTheSkinAndSkipsRemovedOnes) {
  Domain d{{0.0, 0.0, 0.0}, {0.01, 0.01, 0.01}, {false, false, false}};
  ParticleStore p;
  p.add_sphere(0, 0, 1e-3, 2500.0, {0.005, 0.005, 1.05e-3}, {}, {});  // near the floor
  p.add_sphere(1, 0, 1e-3, 2500.0, {0.005, 0.005, 5e-3}, {}, {});     // far from it
  std::vector<Obstacle> obstacles(2);
  obstacles[0].shape = PlaneShape{{0, 0, 0}, {0, 0, 1}};
  obstacles[1].shape = PlaneShape{{0, 0, 0}, {0, 0, 1}};
  obstacles[1].remove_at = 0.5;
  NeighborSearch search(d, 0.2e-3, 1e-3);
  ContactList pairs, walls;
  search.rebuild(p, obstacles, 0.0, pairs, walls);
  ASSERT_EQ(walls.size(), 2u);
  EXPECT_EQ(walls.first[0], 0u);
  search.rebuild(p, obstacles, 1.0, pairs, walls);
  ASSERT_EQ(walls.size(), 1u);
  EXPECT_EQ(walls.second[0], 0u);
}

// Every field of two lists equal (histories compared component by component).
void expect_same_list(const ContactList& a, const ContactList& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  EXPECT_EQ(a.first, b.first) << what;
  EXPECT_EQ(a.second, b.second) << what;
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a.history[k].tangential_displacement, b.history[k].tangential_displacement)
        << what << " entry " << k;
    ASSERT_EQ(a.history[k].normal, b.history[k].normal) << what << " entry " << k;
  }
}

TEST(NeighborSearch, ListsAndCarriedHistoriesAreTheSameOnOneTwoAndThreeThreads) {
  // Enough particles for several ranges per thread; glued particles (no pair between two of
  // them, no wall entry), ghosts (no pair of two ghosts), a periodic axis, two obstacles.
  Domain d{{0.0, 0.0, 0.0}, {0.03, 0.02, 0.02}, {true, false, false}};
  std::vector<Obstacle> obstacles(2);
  obstacles[0].shape = PlaneShape{{0, 0, 0}, {0, 0, 1}};
  obstacles[1].shape = PlaneShape{{0, 0.02, 0}, {0, -1, 0}};
  const double skin = 0.3e-3;
  std::vector<std::uint8_t> ghost(6000);
  for (std::size_t i = 0; i < ghost.size(); i += 7) ghost[i] = 1;
  ContactList reference_pairs, reference_walls;
  for (const int threads : {1, 2, 3}) {
    ParticleStore p = random_particles(ghost.size(), d, 21);
    for (std::size_t i = 0; i < p.size(); i += 5) p.fix(i);
    NeighborSearch search(d, skin, 1.2e-3);
    ContactList pairs, walls;
    search.rebuild(p, obstacles, 0.0, pairs, walls, ghost.data(), threads);
    ASSERT_GT(pairs.size(), 5000u);
    ASSERT_GT(walls.size(), 100u);
    // Memories named after their pair, then a move that keeps most pairs and changes some.
    for (ContactList* list : {&pairs, &walls}) {
      for (std::size_t k = 0; k < list->size(); ++k) {
        list->history[k].tangential_displacement = {double(list->first[k]), double(list->second[k]),
                                                    1.0};
        list->history[k].normal = {0.0, 0.0, 1.0};
      }
    }
    for (std::size_t i = 0; i < p.size(); i += 3) p.position[i].x += 0.8 * skin;
    search.rebuild(p, obstacles, 0.0, pairs, walls, ghost.data(), threads);
    if (threads == 1) {
      reference_pairs = pairs;
      reference_walls = walls;
      std::size_t carried = 0;
      for (std::size_t k = 0; k < pairs.size(); ++k) carried += pairs.history[k].normal.z == 1.0;
      EXPECT_GT(carried, pairs.size() / 2);
      EXPECT_LT(carried, pairs.size());
      continue;
    }
    expect_same_list(pairs, reference_pairs, "pairs");
    expect_same_list(walls, reference_walls, "walls");
  }
}

}  // namespace
}  // namespace sanguis::dem
