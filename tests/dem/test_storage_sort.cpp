// The storage sort (DemSetup::storage_sort_interval): particles re-sorted in memory along
// space give the same bits as particles left in id order, on any thread count, with the
// same checkpoint file; the sort itself is a permutation layered along the cut axis.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "core/config.hpp"
#include "dem/dem_case.hpp"
#include "geometry/mass_properties.hpp"

namespace sanguis::dem {
namespace {

// Per-particle values rearranged into id order (storage order differs between runs).
std::vector<Vec3> by_id(const std::vector<Vec3>& values, const ParticleStore& p) {
  std::vector<Vec3> out;
  for (const std::uint32_t i : id_order(p.id)) out.push_back(values[i]);
  return out;
}

bool same_bits(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0;
}

std::string file_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// 36 crosses (element contacts by GJK, body-wall contacts) on a floor, their ids a
// permutation that does not follow space, and 300 spheres poured over them.
DemSetup crosses_and_spheres(int threads, int sort_interval, IntegratorKind kind) {
  DemSetup s;
  s.shapes.push_back(
      make_particle_shape("cross", geometry::cross_particle(0.027, 0.002, 0.003), 1e-4));
  const ParticleShape& cross = s.shapes.back();
  s.domain = {{0.0, 0.0, 0.0}, {0.09, 0.09, 0.1}, {true, false, false}};
  s.gravity = {0.0, 0.0, -9.81};
  s.time_step = 2.5e-6;
  s.integrator = kind;
  s.threads = threads;
  s.particles_per_thread = 1;  // threads on this small system
  s.storage_sort_interval = sort_interval;
  ContactParameters p;
  p.normal_stiffness = 4.5e5;
  p.normal_damping = 0.05;
  p.tangential_stiffness = 3e2;
  p.tangential_damping = 0.02;
  p.friction = 0.5;
  p.rolling_stiffness = 3e-4;  // rolling memory in play too
  p.rolling_damping = 2e-8;
  p.rolling_friction = 0.05;
  s.contacts = ContactTable(2);
  s.contacts.set(0, 0, p);
  s.contacts.set(0, 1, p);
  Obstacle floor;
  floor.material = 1;
  floor.shape = PlaneShape{{0, 0, 0}, {0, 0, 1}};
  s.obstacles.push_back(floor);
  const Quaternion axes =
      geometry::composite_mass_properties(geometry::cross_particle(0.027, 0.002, 0.003))
          .principal_axes;
  for (int n = 0; n < 36; ++n) {
    const Vec3 x{0.015 + 0.03 * (n % 3), 0.015 + 0.03 * ((n / 3) % 3), 0.002 + 0.0035 * (n / 9)};
    const Quaternion q = Quaternion::from_axis_angle({0.0, 0.0, 1.0}, 0.7 * n) * axes;
    s.particles.add_body((7 * n) % 36, 0, 0, cross.bounding_radius, 770.0 * cross.volume,
                         770.0 * cross.inertia_per_density, normalized(q), x, {0.0, 0.0, -0.3},
                         {0.0, 0.0, 0.5 * (n % 5)});
  }
  PourSource rain;
  rain.radius = 1.5e-3;
  rain.density = 2500.0;
  rain.region_min = {0.0, 0.0, 0.03};
  rain.region_max = {0.09, 0.09, 0.1};
  rain.velocity = {0.05, 0.0, -0.5};
  rain.rate = 1e5;
  rain.count = 300;
  s.pour.push_back(rain);
  s.pour_seed = 5;
  return s;
}

struct Outcome {
  std::vector<Vec3> x, v, w, f, t;
  DemDiagnostics d;
  std::string checkpoint;
  std::vector<std::int64_t> storage;  // ids in storage order at the end
};

Outcome run(int threads, int sort_interval, IntegratorKind kind) {
  DemSimulation sim(crosses_and_spheres(threads, sort_interval, kind));
  std::int64_t contacts_seen = 0;
  for (int k = 0; k < 4000; ++k) {
    sim.step();
    if (k % 20 == 0) {
      contacts_seen += sim.diagnostics().particle_contacts + sim.diagnostics().wall_contacts;
    }
  }
  EXPECT_GT(contacts_seen, 100);
  EXPECT_EQ(sim.particles().size(), 336u);
  EXPECT_GT(sim.neighbor_search().rebuild_count(), 10);
  const ParticleStore& p = sim.particles();
  Outcome o{by_id(p.position, p),
            by_id(p.velocity, p),
            by_id(p.angular_velocity, p),
            by_id(p.force, p),
            by_id(p.torque, p),
            sim.diagnostics(),
            {},
            p.id};
  const auto file =
      std::filesystem::temp_directory_path() / ("sanguis_storage_sort_" + std::to_string(threads) +
                                                "_" + std::to_string(sort_interval) + ".ck");
  sim.save_checkpoint(file);
  o.checkpoint = file_bytes(file);
  std::filesystem::remove(file);
  return o;
}

void expect_same(const Outcome& a, const Outcome& b, const std::string& what) {
  EXPECT_TRUE(same_bits(a.x, b.x)) << what;
  EXPECT_TRUE(same_bits(a.v, b.v)) << what;
  EXPECT_TRUE(same_bits(a.w, b.w)) << what;
  EXPECT_TRUE(same_bits(a.f, b.f)) << what;
  EXPECT_TRUE(same_bits(a.t, b.t)) << what;
  EXPECT_EQ(a.d.kinetic_energy_translational, b.d.kinetic_energy_translational) << what;
  EXPECT_EQ(a.d.kinetic_energy_rotational, b.d.kinetic_energy_rotational) << what;
  EXPECT_EQ(a.d.mean_velocity, b.d.mean_velocity) << what;
  EXPECT_EQ(a.d.particle_contacts, b.d.particle_contacts) << what;
  EXPECT_EQ(a.d.wall_contacts, b.d.wall_contacts) << what;
  EXPECT_FALSE(a.checkpoint.empty()) << what;
  EXPECT_TRUE(a.checkpoint == b.checkpoint) << what << ": checkpoint files differ";
}

TEST(StorageSort, SortedStorageGivesTheBitsOfIdOrderOnOneAndTwoThreads) {
  for (auto kind : {IntegratorKind::kLeapfrog, IntegratorKind::kAdamsBashforth3}) {
    const Outcome plain = run(1, 0, kind);
    for (int threads : {1, 2}) {
      const Outcome sorted = run(threads, 1, kind);
      EXPECT_NE(plain.storage, sorted.storage);  // the sort did reorder the particles
      expect_same(plain, sorted, std::to_string(threads) + " threads, " + to_string(kind));
    }
  }
}

TEST(StorageSort, SpaceOrderIsAPermutationInLayersAlongTheAxis) {
  Domain domain{{0.0, 0.0, 0.0}, {0.1, 0.05, 0.2}, {false, true, false}};
  const double radius = 1e-3;
  NeighborSearch search(domain, 2e-4, radius);
  ParticleStore p;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<std::int64_t> ids(2000);
  std::iota(ids.begin(), ids.end(), 0);
  std::shuffle(ids.begin(), ids.end(), rng);
  for (std::int64_t id : ids) {
    p.add_sphere(id, 0, radius, 1000.0, {0.1 * unit(rng), 0.05 * unit(rng), 0.2 * unit(rng)}, {},
                 {});
  }
  for (int axis = 0; axis < 3; ++axis) {
    const std::vector<std::uint32_t> order = search.space_order(p, axis);
    std::vector<std::uint32_t> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    std::vector<std::uint32_t> all(p.size());
    std::iota(all.begin(), all.end(), 0u);
    ASSERT_EQ(sorted, all) << "not a permutation, axis " << axis;
    // Cells at least one cut-off (2 R + skin) wide: a particle's layer never decreases.
    const double length = domain.max[axis] - domain.min[axis];
    const double cell = length / std::floor(length / (2.0 * radius + 2e-4));
    double last = -1.0;
    for (std::uint32_t i : order) {
      const double layer = std::floor(p.position[i][axis] / cell);
      EXPECT_GE(layer, last) << "axis " << axis;
      last = layer;
    }
  }
}

TEST(StorageSort, PermuteMovesEveryFieldOfAParticleTogether) {
  ParticleStore p;
  for (int n = 0; n < 4; ++n) {
    p.add_sphere(10 + n, n, 1e-3 * (n + 1), 1000.0, {1.0 * n, 0.0, 0.0}, {0.0, 1.0 * n, 0.0},
                 {0.0, 0.0, 1.0 * n});
  }
  p.fix(2);
  const std::vector<std::uint32_t> order{2, 0, 3, 1};
  p.permute(order);
  for (std::size_t k = 0; k < 4; ++k) {
    const auto n = static_cast<double>(order[k]);
    EXPECT_EQ(p.id[k], 10 + static_cast<std::int64_t>(order[k]));
    EXPECT_EQ(p.material[k], static_cast<std::int32_t>(order[k]));
    EXPECT_DOUBLE_EQ(p.radius[k], 1e-3 * (n + 1));
    EXPECT_DOUBLE_EQ(p.position[k].x, n);
    EXPECT_DOUBLE_EQ(p.velocity[k].y, order[k] == 2 ? 0.0 : n);  // fix() stops it
    EXPECT_DOUBLE_EQ(p.angular_velocity[k].z, order[k] == 2 ? 0.0 : n);
  }
  EXPECT_TRUE(p.is_fixed(0));  // old particle 2
  EXPECT_EQ(id_order(p.id), (std::vector<std::uint32_t>{1, 3, 0, 2}));
}

}  // namespace
}  // namespace sanguis::dem
