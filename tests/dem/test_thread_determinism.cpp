// The same case gives bitwise identical results on 1, 2 and 3 threads: every particle
// sums its contacts in the serial loop's order, in its thread's slab or through the
// gather of shared particles, never with atomics.
#include <gtest/gtest.h>

#include <omp.h>

#include <algorithm>
#include <cstring>
#include <vector>

#include "core/config.hpp"
#include "dem/dem_case.hpp"
#include "thrown_pile.hpp"

namespace sanguis::dem {
namespace {

const char* const kPile = testing::kThrownPile;

struct Snapshot {
  std::vector<Vec3> x, v, w, f;
};

Snapshot run(int threads, IntegratorKind kind) {
  DemCase c = load_dem_case(ConfigTable::parse_string(kPile, "pile.toml"), "pile.toml");
  c.setup.threads = threads;
  c.setup.particles_per_thread = 1;  // force threads on this small system
  c.setup.integrator = kind;
  DemSimulation sim(c.setup);
  EXPECT_EQ(sim.threads(), threads);
  std::int64_t contacts_seen = 0;  // the run must exercise contacts, pairs and walls
  for (int n = 0; n < 3000; ++n) {
    sim.step();
    if (n % 50 == 0) {
      contacts_seen += sim.diagnostics().particle_contacts + sim.diagnostics().wall_contacts;
    }
  }
  EXPECT_GT(contacts_seen, 200);
  EXPECT_GT(sim.neighbor_search().rebuild_count(), 5);
  if (threads > 1) {  // both ways of walking a slab's sphere pairs are exercised
    const std::vector<PairRun>& runs = sim.pair_runs();
    const auto direct =
        std::count_if(runs.begin(), runs.end(), [](const PairRun& r) { return r.direct; });
    EXPECT_GT(direct, 0) << threads << " threads";
    EXPECT_LT(direct, static_cast<std::ptrdiff_t>(runs.size())) << threads << " threads";
    std::size_t covered = 0;  // the runs cover every sphere pair once
    for (const PairRun& r : runs) {
      EXPECT_LT(r.begin, r.end);
      if (r.direct) {
        EXPECT_GE(r.end - r.begin, 32u);
      }
      covered += r.end - r.begin;
    }
    EXPECT_EQ(covered, sim.particle_contacts().size()) << threads << " threads";
  }
  const ParticleStore& p = sim.particles();
  return {p.position, p.velocity, p.angular_velocity, p.force};
}

bool bitwise_equal(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0;
}

TEST(ThreadDeterminism, OneTwoAndThreeThreadsGiveIdenticalBits) {
  for (auto kind : {IntegratorKind::kLeapfrog, IntegratorKind::kAdamsBashforth3}) {
    const Snapshot one = run(1, kind);
    for (int threads : {2, 3}) {
      const Snapshot many = run(threads, kind);
      EXPECT_TRUE(bitwise_equal(one.x, many.x)) << threads << " threads, " << to_string(kind);
      EXPECT_TRUE(bitwise_equal(one.v, many.v)) << threads << " threads";
      EXPECT_TRUE(bitwise_equal(one.w, many.w)) << threads << " threads";
      EXPECT_TRUE(bitwise_equal(one.f, many.f)) << threads << " threads";
    }
  }
}

TEST(SlabQueue, EachThreadWalksItsOwnRunThenTakesTheLastOfTheBusiest) {
  SlabQueue q;
  q.start(8, 2);  // thread 0 owns slabs 0-3, thread 1 slabs 4-7
  EXPECT_EQ(q.take(0), 0);
  EXPECT_EQ(q.take(1), 4);
  EXPECT_EQ(q.take(0), 1);
  EXPECT_EQ(q.take(0), 2);
  EXPECT_EQ(q.take(0), 3);
  EXPECT_EQ(q.take(0), 7);  // its own run done: the last of thread 1's
  EXPECT_EQ(q.take(1), 5);
  EXPECT_EQ(q.take(0), 6);
  EXPECT_EQ(q.take(1), -1);
  EXPECT_EQ(q.take(0), -1);
  q.start(7, 3);  // runs 0-1, 2-3, 4-6: every slab exactly once
  std::vector<int> seen(7, 0);
  for (int round = 0; round < 10; ++round) {
    for (int thread : {2, 2, 0}) {
      const std::ptrdiff_t b = q.take(thread);
      if (b >= 0) ++seen[static_cast<std::size_t>(b)];
    }
  }
  EXPECT_EQ(seen, std::vector<int>(7, 1));
}

TEST(ThreadDeterminism, FewerThreadsGrantedThanSlabsStillGiveTheSerialBits) {
  // Inside an active parallel region OpenMP grants the simulation's regions a single
  // thread: its three slabs then run one after the other on that thread.
  const Snapshot one = run(1, IntegratorKind::kLeapfrog);
  const int levels = omp_get_max_active_levels();
  omp_set_max_active_levels(1);
  Snapshot starved;
#pragma omp parallel num_threads(2)
  {
#pragma omp single
    starved = run(3, IntegratorKind::kLeapfrog);
  }
  omp_set_max_active_levels(levels);
  ASSERT_EQ(starved.x.size(), 500u);
  EXPECT_TRUE(bitwise_equal(one.x, starved.x));
  EXPECT_TRUE(bitwise_equal(one.v, starved.v));
  EXPECT_TRUE(bitwise_equal(one.f, starved.f));
}

}  // namespace
}  // namespace sanguis::dem

#include "falling_crosses.hpp"

namespace sanguis::dem {
namespace {

// Crosses (element contacts by GJK, body-wall contacts) give the same bits too.
// most_shared_fraction 1: every thread owns four slabs and takes others when done.
std::vector<Vec3> crosses_after(int threads, double most_shared_fraction = 0.15,
                                bool mean_element_contacts = false) {
  DemSetup s = testing::falling_crosses(threads, [](int n) { return n; });
  s.most_shared_fraction = most_shared_fraction;
  s.mean_element_contacts = mean_element_contacts;
  DemSimulation sim(std::move(s));
  std::int64_t contacts_seen = 0;  // element-pair and element-floor contacts
  for (int k = 0; k < 3000; ++k) {
    sim.step();
    if (k % 20 == 0) {
      contacts_seen += sim.diagnostics().particle_contacts + sim.diagnostics().wall_contacts;
    }
  }
  EXPECT_GT(contacts_seen, 100);
  if (threads > 1 && most_shared_fraction >= 1.0) {
    EXPECT_EQ(sim.slab_pairs().offset.size(), static_cast<std::size_t>(4 * threads + 1));
  }
  std::vector<Vec3> state = sim.particles().position;
  state.insert(state.end(), sim.particles().angular_velocity.begin(),
               sim.particles().angular_velocity.end());
  return state;
}

TEST(ThreadDeterminism, CrossesGiveIdenticalBitsOnOneTwoAndThreeThreads) {
  // With bodies each thread may take several slabs, its own and then others' (SlabQueue):
  // which thread sums which slab changes from step to step, the bits must not.
  const std::vector<Vec3> one = crosses_after(1);
  for (int threads : {2, 3}) {
    EXPECT_TRUE(bitwise_equal(one, crosses_after(threads))) << threads << " threads";
    EXPECT_TRUE(bitwise_equal(one, crosses_after(threads, 1.0)))
        << threads << " threads, four slabs each";
  }
}

TEST(ThreadDeterminism, CrossesWithTheMeanOfTheirElementContactsGiveIdenticalBits) {
  // element_contacts = "mean": the element contacts of a pair of bodies are summed as a
  // group before they reach the particles, on one thread as on several.
  const std::vector<Vec3> one = crosses_after(1, 0.15, true);
  EXPECT_FALSE(bitwise_equal(one, crosses_after(1))) << "the mean changed nothing";
  for (int threads : {2, 3}) {
    EXPECT_TRUE(bitwise_equal(one, crosses_after(threads, 0.15, true))) << threads << " threads";
    EXPECT_TRUE(bitwise_equal(one, crosses_after(threads, 1.0, true)))
        << threads << " threads, four slabs each";
  }
}

}  // namespace
}  // namespace sanguis::dem
