// The storage sort (DemSetup::storage_sort_interval): particles re-sorted in memory along
// a Z-order curve give the same bits on any thread count, with the same checkpoint file,
// and differ from unsorted storage by round-off only; a pair whose storage order flips
// is turned round exactly (ContactMemory::as_oriented).
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
#include "falling_crosses.hpp"

namespace sanguis::dem {
namespace {

// Per-particle values rearranged into id order (storage order differs between runs).
std::vector<Vec3> by_id(const std::vector<Vec3>& values, const ParticleStore& p) {
  return in_id_order(values, p.id);
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
DemSetup crosses_and_spheres(int threads, std::int64_t sort_interval, IntegratorKind kind) {
  DemSetup s = testing::falling_crosses(threads, [](int n) { return (7 * n) % 36; });
  s.domain.periodic[0] = true;
  s.integrator = kind;
  s.storage_sort_interval = sort_interval;
  ContactParameters p = s.contacts.get(0, 0);
  p.rolling_stiffness = 3e-4;  // rolling memory in play too
  p.rolling_damping = 2e-8;
  p.rolling_friction = 0.05;
  s.contacts.set(0, 0, p);
  s.contacts.set(0, 1, p);
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

Outcome run(int threads, std::int64_t sort_interval, IntegratorKind kind) {
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
  EXPECT_EQ(a.d.particle_contacts, b.d.particle_contacts) << what;
  EXPECT_EQ(a.d.wall_contacts, b.d.wall_contacts) << what;
  EXPECT_EQ(a.storage, b.storage) << what << ": stored in another order";
  EXPECT_FALSE(a.checkpoint.empty()) << what;
  EXPECT_TRUE(a.checkpoint == b.checkpoint) << what << ": checkpoint files differ";
}

TEST(StorageSort, SortedRunsGiveIdenticalBitsOnOneTwoAndThreeThreads) {
  for (auto kind : {IntegratorKind::kLeapfrog, IntegratorKind::kAdamsBashforth3}) {
    const Outcome one = run(1, 100, kind);  // a sort at the first rebuild of every 100 steps
    for (int threads : {2, 3}) {
      expect_same(one, run(threads, 100, kind), std::to_string(threads) + " threads");
    }
  }
}

// A dense pack of 320 spheres (touching from the start, shuffled ids, springs loaded by
// small random velocities) with, if `crosses`, 9 crosses dropped onto it.
DemSetup dense_pack(std::int64_t sort_interval, IntegratorKind kind, bool crosses) {
  DemSetup s = crosses_and_spheres(1, sort_interval, kind);
  s.pour.clear();
  const ParticleShape& cross = s.shapes.back();
  const ParticleStore falling = s.particles;
  s.particles = ParticleStore{};
  std::vector<std::int64_t> ids(8 * 8 * 5);
  std::iota(ids.begin(), ids.end(), 100);
  std::shuffle(ids.begin(), ids.end(), std::mt19937_64(11));
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> noise(-1e-3, 1e-3);
  for (std::size_t n = 0; n < ids.size(); ++n) {
    const double d = 3e-3 - 1e-8;  // spacing: touching, about the overlap of their weight
    const Vec3 x{0.03 + d * static_cast<double>(n % 8), 0.03 + d * static_cast<double>((n / 8) % 8),
                 1.5e-3 + d * static_cast<double>(n / 64)};
    s.particles.add_sphere(ids[n], 0, 1.5e-3, 2500.0, x, {noise(rng), noise(rng), noise(rng)}, {});
  }
  for (std::size_t i = 0; crosses && i < falling.size(); i += 4) {
    s.particles.add_body(falling.id[i], 0, 0, cross.bounding_radius, falling.mass[i],
                         falling.inertia_body[i], falling.orientation[i],
                         falling.position[i] + Vec3{0.0, 0.0, 0.0175}, {0.0, 0.0, -0.5}, {});
  }
  return s;
}

TEST(StorageSort, SortedAndUnsortedRunsDifferByRoundOffOnly) {
  // Sorting changes the order of each particle's sum and turns pairs round: on a dense
  // pack of spheres (no GJK corners to amplify round-off) the runs must stay within
  // round-off of each other, per integrator (a multistep history or a half-step velocity
  // left behind by the sort, or a memory turned wrongly, gives differences of 1e-7 m or
  // more here; round-off stays below 1e-12 m).
  for (auto kind : {IntegratorKind::kLeapfrog, IntegratorKind::kAdamsBashforth3}) {
    DemSimulation plain(dense_pack(0, kind, false)), sorted(dense_pack(100, kind, false));
    for (int k = 0; k < 1000; ++k) {
      plain.step();
      sorted.step();
    }
    const ParticleStore& a = plain.particles();
    const ParticleStore& b = sorted.particles();
    EXPECT_NE(a.id, b.id) << to_string(kind);  // stored in another order
    double dx = 0.0, dv = 0.0;
    const std::vector<Vec3> xa = by_id(a.position, a), xb = by_id(b.position, b);
    const std::vector<Vec3> va = by_id(a.velocity, a), vb = by_id(b.velocity, b);
    for (std::size_t i = 0; i < xa.size(); ++i) {
      dx = std::max(dx, norm(xa[i] - xb[i]));
      dv = std::max(dv, norm(va[i] - vb[i]));
    }
    EXPECT_LT(dx, 1e-12) << to_string(kind);
    EXPECT_LT(dv, 1e-9) << to_string(kind);
    EXPECT_GT(plain.diagnostics().particle_contacts, 150) << to_string(kind);
  }
}

TEST(StorageSort, SortingKeepsEveryContactMemory) {
  // A pack loaded for a while, never sorted, then sorted by hand: each touching contact
  // must come out with its memory, turned round where the new storage order puts the
  // other particle first, and nothing else may change.
  DemSetup s = dense_pack(0, IntegratorKind::kLeapfrog, true);
  DemSimulation sim(std::move(s));
  for (int k = 0; k < 1500; ++k) sim.step();
  const auto touching = [](const ContactMemory& m) {
    return m.history.normal.x != 0.0 || m.history.normal.y != 0.0 || m.history.normal.z != 0.0;
  };
  const auto keyed = [](std::vector<ContactMemory> all) {
    std::sort(all.begin(), all.end(),
              [](const ContactMemory& a, const ContactMemory& b) { return a.key() < b.key(); });
    return all;
  };
  const std::vector<ContactMemory> before = keyed(sim.export_contacts());
  const ParticleStore p0 = sim.particles();
  sim.sort_storage();
  const std::vector<ContactMemory> after = keyed(sim.export_contacts());
  const ParticleStore& p1 = sim.particles();
  EXPECT_NE(p0.id, p1.id);  // reordered
  EXPECT_TRUE(same_bits(by_id(p0.position, p0), by_id(p1.position, p1)));
  EXPECT_TRUE(same_bits(by_id(p0.velocity, p0), by_id(p1.velocity, p1)));
  std::size_t carried = 0, turned = 0, touching_before = 0;
  for (const ContactMemory& m : before) {
    if (!touching(m)) continue;
    ++touching_before;
    const auto it = std::lower_bound(
        after.begin(), after.end(), m,
        [](const ContactMemory& a, const ContactMemory& b) { return a.key() < b.key(); });
    ASSERT_TRUE(it != after.end() && it->key() == m.key()) << "a touching contact was lost";
    turned += it->first_id != m.first_id;
    const ContactMemory back = it->as_oriented(m.first_id);
    EXPECT_EQ(back.history.tangential_displacement, m.history.tangential_displacement);
    EXPECT_EQ(back.history.rolling_spring_torque, m.history.rolling_spring_torque);
    EXPECT_EQ(back.history.normal, m.history.normal);
    ++carried;
  }
  EXPECT_GT(touching_before, 100u);
  EXPECT_EQ(carried, touching_before);
  EXPECT_GT(turned, 10u);  // the sort turned pairs round, and their memories with them
  EXPECT_EQ(std::count_if(after.begin(), after.end(), touching), touching_before);
}

TEST(StorageSort, TurningAContactRoundNegatesItsMemoryAndItsForce) {
  ContactParameters law;
  law.normal_stiffness = 1e5;
  law.normal_damping = 0.3;
  law.tangential_stiffness = 3e4;
  law.tangential_damping = 0.1;
  law.friction = 0.5;
  law.rolling_stiffness = 2e-3;
  law.rolling_damping = 1e-6;
  law.rolling_friction = 0.1;
  ContactKinematics c;
  c.normal = (1.0 / norm(Vec3{0.3, -0.2, 0.9})) * Vec3{0.3, -0.2, 0.9};
  c.overlap = 2e-5;
  c.relative_velocity = {0.01, 0.02, -0.003};
  c.relative_angular_velocity = {1.0, -2.0, 0.5};
  c.reduced_radius = 1e-3;
  ContactKinematics turned = c;  // the same contact seen from the other particle
  turned.normal = -c.normal;
  turned.relative_velocity = -c.relative_velocity;
  turned.relative_angular_velocity = -c.relative_angular_velocity;

  ContactMemory m;
  m.kind = ContactMemory::kBodyPair;
  m.first_id = 4;
  m.second_id = 9;
  m.element_first = 1;
  m.element_second = 3;
  m.history.normal = (1.0 / norm(Vec3{0.31, -0.19, 0.9})) * Vec3{0.31, -0.19, 0.9};  // last step
  m.history.tangential_displacement = {2e-6, 1e-6, -5e-7};
  m.history.rolling_spring_torque = {1e-6, 2e-6, 0.0};
  m.warm.size = 2;
  const ContactMemory r = m.as_oriented(9);
  EXPECT_EQ(r.first_id, 9);
  EXPECT_EQ(r.element_first, 3);
  EXPECT_EQ(r.element_second, 1);
  EXPECT_EQ(r.key(), m.key());  // one pair, whichever way round
  EXPECT_EQ(r.warm.size, 0);    // GJK starts cold
  const ContactMemory back = r.as_oriented(4);
  EXPECT_EQ(back.history.tangential_displacement, m.history.tangential_displacement);
  EXPECT_EQ(back.history.rolling_spring_torque, m.history.rolling_spring_torque);
  EXPECT_EQ(back.history.normal, m.history.normal);

  ContactHistory h = m.history, h_turned = r.history;
  for (int step = 0; step < 3; ++step) {
    const ContactResponse a = evaluate_contact(law, c, h, 1e-5);
    const ContactResponse b = evaluate_contact(law, turned, h_turned, 1e-5);
    EXPECT_EQ(b.force, -a.force);  // exact: every operation is mirrored
    EXPECT_EQ(b.rolling_torque, -a.rolling_torque);
    EXPECT_EQ(h_turned.tangential_displacement, -h.tangential_displacement);
    EXPECT_GT(norm(a.rolling_torque), 0.0);
  }
  // Walls are never turned round.
  ContactMemory wall = m;
  wall.kind = ContactMemory::kSphereWall;
  EXPECT_EQ(wall.as_oriented(9).first_id, 4);
}

TEST(StorageSort, SpaceKeysRunLayerByLayerAlongTheAxisAndInZOrderWithin) {
  Domain domain{{0.0, 0.0, 0.0}, {0.1, 0.1, 0.1}, {false, true, false}};
  NeighborSearch search(domain, 0.0, 0.005);  // cut-off 0.01: 10 x 10 x 10 cells
  ParticleStore p;
  const double h = 0.01;
  const Vec3 cells[] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},   {0, 0, 1},
                        {1, 1, 1}, {2, 0, 0}, {3, 3, 3}, {0, 10.4, 0}};  // the last wraps in y
  for (const Vec3& c : cells) {
    p.add_sphere(static_cast<std::int64_t>(p.size()), 0, 0.004, 1000.0,
                 {(c.x + 0.5) * h, (c.y + 0.5) * h, (c.z + 0.5) * h}, {}, {});
  }
  const std::uint64_t layer = std::uint64_t{1} << 42;
  // Layers along z, Z-order of (x, y) within.
  EXPECT_EQ(search.space_keys(p, 2),
            (std::vector<std::uint64_t>{0, 1, 2, 3, layer, layer + 3, 4, 3 * layer + 15, 0}));
  // Layers along x, Z-order of (y, z) within.
  EXPECT_EQ(search.space_keys(p, 0),
            (std::vector<std::uint64_t>{0, layer, 1, layer + 1, 2, layer + 3, 2 * layer,
                                        3 * layer + 15, 0}));
}

// The bytes of `sim`'s checkpoint in an older format: CK3 held the twists as angles in
// the place of today's moments; CK2 (before the contact patches) lacks the body
// contacts' twists, CK1 (before the storage sort) the sort keys as well; all were
// written in the same order, so CK2 and CK1 files are prefixes.
std::string older_checkpoint(const DemSimulation& sim, const char* magic, bool keep_sort_keys) {
  const auto file = std::filesystem::temp_directory_path() / "sanguis_ck4.ck";
  sim.save_checkpoint(file);
  std::string bytes = file_bytes(file);
  std::filesystem::remove(file);
  const bool keep_twists = std::string(magic) == "SANGUIS-DEM-CK3";
  const std::size_t twists =
      keep_twists ? 0
                  : 8 + 8 * sim.body_contacts().size() + 8 + 8 * sim.body_wall_contacts().size();
  const std::size_t keys = keep_sort_keys ? 0 : 8 + 8 * sim.particles().size();
  EXPECT_EQ(bytes.substr(0, 15), "SANGUIS-DEM-CK4");
  bytes.resize(bytes.size() - twists - keys);
  bytes.replace(0, 15, magic);
  return bytes;
}

// A run continued from an older-format copy of `original`'s checkpoint.
DemSimulation restarted_from(const DemSimulation& original, const char* magic,
                             bool keep_sort_keys) {
  const auto file = std::filesystem::temp_directory_path() / "sanguis_older.ck";
  std::ofstream(file, std::ios::binary) << older_checkpoint(original, magic, keep_sort_keys);
  DemSimulation restarted(crosses_and_spheres(1, 0, IntegratorKind::kLeapfrog));
  restarted.load_checkpoint(file);
  std::filesystem::remove(file);
  return restarted;
}

TEST(StorageSort, CheckpointsWrittenBeforeSortKeysStillLoad) {
  // The format before the storage sort (CK1) had no sort keys, the particles in the
  // order of their creation (here not id order): it loads with keys that keep that order
  // the (key, id) order (their ranks), and continues as the unsorted run it came from.
  // Both old formats lack the twists, so the CK1 run is compared with the run from the
  // CK2 copy, which has the written keys (CheckpointsWrittenBeforeContactPatches...).
  DemSimulation original(crosses_and_spheres(1, 0, IntegratorKind::kLeapfrog));
  for (int k = 0; k < 1500; ++k) original.step();
  DemSimulation from_ck1 = restarted_from(original, "SANGUIS-DEM-CK1", false);
  DemSimulation from_ck2 = restarted_from(original, "SANGUIS-DEM-CK2", true);
  const std::size_t n = original.particles().size();
  std::vector<std::uint64_t> ranks(n);
  std::iota(ranks.begin(), ranks.end(), std::uint64_t{0});
  EXPECT_EQ(from_ck1.particles().sort_key, ranks);
  EXPECT_NE(id_order(from_ck1.particles().id),
            std::vector<std::uint32_t>(ranks.begin(), ranks.end()));
  EXPECT_NE(from_ck2.particles().sort_key, ranks);
  for (int k = 0; k < 500; ++k) {
    from_ck1.step();
    from_ck2.step();
  }
  EXPECT_TRUE(same_bits(from_ck1.particles().position, from_ck2.particles().position));
}

TEST(StorageSort, CheckpointsWrittenBeforeTwistMomentsLoadWithZeroTwist) {
  // CK2 had no twist memory on body contacts, CK3 held it as an angle, from which no
  // moment can be formed without the patch: both load with every twist at zero and
  // everything else as written. Saved once a cross lies on the floor with a twist held,
  // the continued run is then another run, close to the original.
  for (const char* magic : {"SANGUIS-DEM-CK2", "SANGUIS-DEM-CK3"}) {
    SCOPED_TRACE(magic);
    DemSimulation original(crosses_and_spheres(1, 0, IntegratorKind::kLeapfrog));
    const auto twisted = [](const BodyContactList& list) {
      return std::any_of(list.twist.begin(), list.twist.end(), [](double t) { return t != 0.0; });
    };
    for (int k = 0; k < 40000 && !twisted(original.body_wall_contacts()); ++k) original.step();
    ASSERT_TRUE(twisted(original.body_wall_contacts()));
    DemSimulation restarted = restarted_from(original, magic, true);
    EXPECT_EQ(restarted.particles().sort_key, original.particles().sort_key);
    EXPECT_TRUE(same_bits(original.particles().position, restarted.particles().position));
    ASSERT_EQ(restarted.body_wall_contacts().size(), original.body_wall_contacts().size());
    for (double t : restarted.body_contacts().twist) EXPECT_EQ(t, 0.0);
    for (double t : restarted.body_wall_contacts().twist) EXPECT_EQ(t, 0.0);
    for (int k = 0; k < 100; ++k) {
      original.step();
      restarted.step();
    }
    for (std::size_t i = 0; i < original.particles().size(); ++i) {
      EXPECT_LT(norm(original.particles().position[i] - restarted.particles().position[i]), 1e-6);
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
  EXPECT_EQ(in_id_order(p.material, p.id), (std::vector<std::int32_t>{0, 1, 2, 3}));
}

}  // namespace
}  // namespace sanguis::dem
