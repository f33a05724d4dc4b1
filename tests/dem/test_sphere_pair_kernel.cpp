// The batched sphere-sphere kernel (src/dem/sphere_pair_kernel.hpp) gives, bit for bit,
// what the same law gives one contact at a time (the path builds without AVX take): every lane kind
// (new, continuing, sticking, sliding, rolling free and saturated, apart with and without memory,
// across a periodic boundary) mixed in the same batches, with uniform and mixed materials.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include "dem/sphere_pair_kernel.hpp"

namespace sanguis::dem {
namespace {

void expect_same_bits(const Vec3& a, const Vec3& b, const char* what, std::size_t k) {
  EXPECT_TRUE(a == b) << what << " of contact " << k << ": (" << a.x << ", " << a.y << ", " << a.z
                      << ") vs (" << b.x << ", " << b.y << ", " << b.z << ")";
}

struct Particles {
  std::vector<Vec3> x, v, w;
  std::vector<double> r;
  std::vector<std::int32_t> material;
  std::vector<std::uint32_t> first, second;
};

// A random cloud in a periodic box: near pairs of spheres, some overlapping, some apart,
// some across the periodic boundary, with velocities that make some contacts slide.
Particles make_particles(std::size_t pairs, int materials, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Particles s;
  for (std::size_t k = 0; k < pairs; ++k) {
    const double ri = 1e-3 * (0.8 + 0.4 * unit(rng)), rj = 1e-3 * (0.8 + 0.4 * unit(rng));
    const Vec3 xi{0.01 * unit(rng), 0.01 * unit(rng), 0.01 * unit(rng)};
    Vec3 dir{unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5};
    dir = (1.0 / norm(dir)) * dir;
    const double gap = (ri + rj) * (0.97 + 0.05 * unit(rng));  // about 60 % touching
    Vec3 xj = xi + gap * dir;
    if (k % 7 == 0) xj.x += 0.01;  // same contact, seen through the periodic boundary in x
    for (const auto& [x, r] : {std::pair{xi, ri}, std::pair{xj, rj}}) {
      s.x.push_back(x);
      s.r.push_back(r);
      s.v.push_back({4.0 * (unit(rng) - 0.5), 4.0 * (unit(rng) - 0.5), 4.0 * (unit(rng) - 0.5)});
      s.w.push_back({50.0 * (unit(rng) - 0.5), 50.0 * (unit(rng) - 0.5), 50.0 * (unit(rng) - 0.5)});
      s.material.push_back(static_cast<std::int32_t>(rng() % static_cast<unsigned>(materials)));
    }
    s.first.push_back(static_cast<std::uint32_t>(2 * k));
    s.second.push_back(static_cast<std::uint32_t>(2 * k + 1));
  }
  return s;
}

std::vector<ContactParameters> make_table(int materials, bool rolling) {
  std::vector<ContactParameters> table(static_cast<std::size_t>(materials * materials));
  for (int a = 0; a < materials; ++a) {
    for (int b = 0; b < materials; ++b) {
      ContactParameters p;
      p.normal_stiffness = 7.34e5 * (1.0 + 0.1 * (a + b));
      p.normal_damping = 0.3 + 0.01 * (a + b);
      p.tangential_stiffness = 2.26e5;
      p.tangential_damping = 0.1;
      p.friction = 0.3 + 0.1 * (a + b);
      // With rolling resistance, material pairs with a + b odd still roll freely.
      if (rolling && (a + b) % 2 == 0) {
        p.rolling_stiffness = 0.05;
        p.rolling_damping = 1e-6;
        p.rolling_friction = 0.1;
      }
      table[static_cast<std::size_t>(a * materials + b)] = p;
    }
  }
  return table;
}

// Four evaluations of every contact by both paths, each carrying its own memories,
// compared output by output and memory by memory; `shuffled` batches the contacts in a
// random order (as the threaded loop does, by slab).
void compare_paths(int materials, bool rolling, std::size_t pairs, bool shuffled) {
  std::mt19937_64 rng(1234u + static_cast<unsigned>(materials));
  const Particles s = make_particles(pairs, materials, rng);
  const std::vector<ContactParameters> table = make_table(materials, rolling);
  Domain domain;
  domain.min = {0.0, 0.0, 0.0};
  domain.max = {0.01, 0.01, 0.01};
  domain.periodic = {true, false, false};
  std::vector<ContactHistory> batched(pairs), scalar(pairs);
  const auto inputs = [&](std::vector<ContactHistory>& history) {
    return SpherePairInputs{s.x.data(),
                            s.v.data(),
                            s.w.data(),
                            s.r.data(),
                            s.material.data(),
                            table.data(),
                            static_cast<std::size_t>(materials),
                            s.first.data(),
                            s.second.data(),
                            history.data(),
                            &domain,
                            true,
                            1e-5};
  };
  std::vector<std::uint32_t> order(pairs);
  std::iota(order.begin(), order.end(), 0u);
  if (shuffled) std::shuffle(order.begin(), order.end(), rng);

  std::size_t touching = 0, sliding = 0, continuing = 0;
  SpherePairLanes lanes;
  for (int step = 0; step < 4; ++step) {
    for (std::size_t e0 = 0; e0 < pairs; e0 += SpherePairLanes::kLanes) {
      const int n = static_cast<int>(std::min<std::size_t>(SpherePairLanes::kLanes, pairs - e0));
      const auto index = [&order, e0](int l) {
        return std::size_t{order[e0 + static_cast<std::size_t>(l)]};
      };
      for (int l = 0; l < n; ++l) continuing += batched[index(l)].normal == Vec3{} ? 0 : 1;
      std::vector<std::size_t> used, used_ref;
      std::vector<ContactOutcome> outcomes, outcomes_ref;
      evaluate_sphere_pairs_batched(inputs(batched), index, n, lanes,
                                    [&](std::size_t k, const ContactOutcome& o) {
                                      used.push_back(k);
                                      outcomes.push_back(o);
                                    });
      evaluate_sphere_pairs_one_by_one(inputs(scalar), index, n,
                                       [&](std::size_t k, const ContactOutcome& o) {
                                         used_ref.push_back(k);
                                         outcomes_ref.push_back(o);
                                       });
      ASSERT_EQ(used.size(), static_cast<std::size_t>(n));
      ASSERT_EQ(used, used_ref);  // every contact handed over once, in batch order
      for (int l = 0; l < n; ++l) {
        const std::size_t k = index(l);
        EXPECT_EQ(used[static_cast<std::size_t>(l)], k);
        const ContactOutcome& o = outcomes[static_cast<std::size_t>(l)];
        const ContactOutcome& ref = outcomes_ref[static_cast<std::size_t>(l)];
        ASSERT_EQ(o.touching, ref.touching) << "contact " << k;
        if (ref.touching) {
          ++touching;
          expect_same_bits(o.force, ref.force, "force", k);
          expect_same_bits(o.torque_first, ref.torque_first, "first torque", k);
          expect_same_bits(o.torque_second, ref.torque_second, "second torque", k);
          EXPECT_EQ(o.overlap_ratio, ref.overlap_ratio) << "contact " << k;
          // Sliding: the tangential force is at the Coulomb bound.
          const ContactParameters& p = table[static_cast<std::size_t>(
              s.material[s.first[k]] * materials + s.material[s.second[k]])];
          const Vec3& n_k = scalar[k].normal;
          const double fn = -dot(o.force, n_k);
          const Vec3 ft = o.force + fn * n_k;
          if (fn > 0.0 && norm(ft) >= 0.999 * p.friction * fn) ++sliding;
        }
        expect_same_bits(batched[k].tangential_displacement, scalar[k].tangential_displacement,
                         "tangential memory", k);
        expect_same_bits(batched[k].rolling_spring_torque, scalar[k].rolling_spring_torque,
                         "rolling memory", k);
        expect_same_bits(batched[k].normal, scalar[k].normal, "normal memory", k);
      }
    }
  }
  // The cases were all exercised.
  EXPECT_GT(touching, pairs);         // over 4 steps
  EXPECT_LT(touching, 4 * pairs);     // some apart
  EXPECT_GT(sliding, touching / 10);  // some sliding
  EXPECT_LT(sliding, touching);       // some sticking
  EXPECT_GT(continuing, pairs);       // memories carried
}

// Each test takes one of the four compiled variants of evaluate_sphere_lanes on most
// batches: with or without rolling, one or several material pairs.
TEST(SpherePairKernel, SameBitsAsOneContactAtATimeWithOneMaterial) {
  compare_paths(1, false, 203, false);
}

TEST(SpherePairKernel, SameBitsWithOneMaterialThatResistsRolling) {
  compare_paths(1, true, 203, false);
}

TEST(SpherePairKernel, SameBitsWithMixedMaterialsAndRollingInOneBatch) {
  compare_paths(3, true, 517, false);
}

TEST(SpherePairKernel, SameBitsWithContactsInAnyOrder) {
  compare_paths(2, false, 300, true);
}

}  // namespace
}  // namespace sanguis::dem
