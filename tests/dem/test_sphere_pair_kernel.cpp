// The batched sphere-sphere kernel (src/dem/sphere_pair_kernel.hpp) gives, bit for bit,
// what the same law gives one contact at a time (the path of builds without AVX2). The
// spheres move between the steps, so contacts are made and broken and their normals turn;
// every lane kind is counted as it occurs (new, continuing with a turned normal, a memory
// whose normal points the other way, sticking, sliding, rolling free and saturated, broken
// with memory, across a periodic boundary), mixed in the same batches, with uniform and
// mixed materials. Equality with the code before the batches is shown end to end by
// byte-identical checkpoints (docs/performance.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

#include "dem/sphere_pair_kernel.hpp"

namespace sanguis::dem {
namespace {

// Bit equality (tells -0.0 from +0.0; a NaN equals the same NaN).
void expect_same_bits(const Vec3& a, const Vec3& b, const char* what, std::size_t k) {
  using Bits = std::array<std::uint64_t, 3>;
  EXPECT_EQ(std::bit_cast<Bits>(a), std::bit_cast<Bits>(b))
      << what << " of contact " << k << ": (" << a.x << ", " << a.y << ", " << a.z << ") vs ("
      << b.x << ", " << b.y << ", " << b.z << ")";
}

void expect_same_bits(double a, double b, const char* what, std::size_t k) {
  EXPECT_EQ(std::bit_cast<std::uint64_t>(a), std::bit_cast<std::uint64_t>(b))
      << what << " of contact " << k << ": " << a << " vs " << b;
}

struct Particles {
  std::vector<Vec3> x, v, w;
  std::vector<double> r;
  std::vector<std::int32_t> material;
  std::vector<std::uint32_t> first, second;
};

// A random cloud in a periodic box: near pairs of spheres, some overlapping, some apart,
// some across the periodic boundary, with velocities that make contacts slide, open and
// close. `only_material` >= 0 gives every sphere that material.
Particles make_particles(std::size_t pairs, int materials, int only_material,
                         std::mt19937_64& rng) {
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
      const auto m = static_cast<std::int32_t>(rng() % static_cast<unsigned>(materials));
      s.material.push_back(only_material >= 0 ? only_material : m);
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
      // With rolling resistance, material pairs with a + b odd still roll freely. The
      // rolling spring is stiff enough that some contacts saturate within a step.
      if (rolling && (a + b) % 2 == 0) {
        p.rolling_stiffness = 1.5;
        p.rolling_damping = 1e-6;
        p.rolling_friction = 0.1;
      }
      table[static_cast<std::size_t>(a * materials + b)] = p;
    }
  }
  return table;
}

struct Case {
  int materials = 1;
  bool rolling = false;
  std::size_t pairs = 203;
  bool shuffled = false;   // batches in a random contact order (as slabs are, threaded)
  int only_material = -1;  // every sphere of this material (a uniform, non-zero pair)
};

// Counts of what the steps went through, to show each lane kind occurred.
struct Seen {
  std::size_t touching = 0, apart = 0, sliding = 0, turned = 0, flipped = 0, forgot = 0;
  std::size_t rolling_saturated = 0, rolling_elastic = 0;
};

// Six steps of every contact by both paths, each carrying its own memories, compared output
// by output and memory by memory; the spheres move between steps.
void compare_paths(const Case& cs) {
  std::mt19937_64 rng(1234u + static_cast<unsigned>(cs.materials));
  Particles s = make_particles(cs.pairs, cs.materials, cs.only_material, rng);
  const std::vector<ContactParameters> table = make_table(cs.materials, cs.rolling);
  Domain domain;
  domain.min = {0.0, 0.0, 0.0};
  domain.max = {0.01, 0.01, 0.01};
  domain.periodic = {true, false, false};
  const double dt = 1e-5;
  std::vector<ContactHistory> batched(cs.pairs), scalar(cs.pairs);
  const auto inputs = [&](std::vector<ContactHistory>& history) {
    return SpherePairInputs{s.x.data(),
                            s.v.data(),
                            s.w.data(),
                            s.r.data(),
                            s.material.data(),
                            table.data(),
                            static_cast<std::size_t>(cs.materials),
                            s.first.data(),
                            s.second.data(),
                            history.data(),
                            &domain,
                            true,
                            dt};
  };
  std::vector<std::uint32_t> order(cs.pairs);
  std::iota(order.begin(), order.end(), 0u);
  if (cs.shuffled) std::shuffle(order.begin(), order.end(), rng);

  Seen seen;
  SpherePairLanes lanes;
  for (int step = 0; step < 6; ++step) {
    if (step == 3) {
      // A memory whose normal points the other way (a contact seen from its other side):
      // the rotation of eq. 2.8 gives up and the memory restarts.
      for (std::size_t k = 0; k < cs.pairs; k += 5) {
        if (batched[k].normal == Vec3{}) continue;
        batched[k].normal = -batched[k].normal;
        scalar[k].normal = -scalar[k].normal;
        ++seen.flipped;
      }
    }
    const std::vector<ContactHistory> before = batched;
    for (std::size_t e0 = 0; e0 < cs.pairs; e0 += SpherePairLanes::kLanes) {
      const int n = static_cast<int>(std::min<std::size_t>(SpherePairLanes::kLanes, cs.pairs - e0));
      const auto index = [&order, e0](int l) {
        return std::size_t{order[e0 + static_cast<std::size_t>(l)]};
      };
      std::vector<std::size_t> used, used_ref;
      std::vector<ContactOutcome> outcomes, outcomes_ref;
      evaluate_sphere_pairs_batched(inputs(batched), index, n, lanes,
                                    [&](std::size_t k, const ContactOutcome& o) {
                                      used.push_back(k);
                                      outcomes.push_back(o);
                                    });
      evaluate_sphere_pairs_one_by_one(
          inputs(scalar), [&index](std::size_t e) { return index(static_cast<int>(e)); },
          static_cast<std::size_t>(n),
          [&](std::size_t k, const ContactOutcome& o) {
            used_ref.push_back(k);
            outcomes_ref.push_back(o);
          });
      ASSERT_EQ(used.size(), static_cast<std::size_t>(n));
      ASSERT_EQ(used, used_ref);  // every contact handed over once, in batch order
      for (int l = 0; l < n; ++l) {
        const std::size_t k = index(l);
        ASSERT_EQ(used[static_cast<std::size_t>(l)], k);
        const ContactOutcome& o = outcomes[static_cast<std::size_t>(l)];
        const ContactOutcome& ref = outcomes_ref[static_cast<std::size_t>(l)];
        ASSERT_EQ(o.touching, ref.touching) << "contact " << k;
        expect_same_bits(o.force, ref.force, "force", k);
        expect_same_bits(o.torque_first, ref.torque_first, "first torque", k);
        expect_same_bits(o.torque_second, ref.torque_second, "second torque", k);
        expect_same_bits(o.overlap_ratio, ref.overlap_ratio, "overlap ratio", k);
        expect_same_bits(batched[k].tangential_displacement, scalar[k].tangential_displacement,
                         "tangential memory", k);
        expect_same_bits(batched[k].rolling_spring_torque, scalar[k].rolling_spring_torque,
                         "rolling memory", k);
        expect_same_bits(batched[k].normal, scalar[k].normal, "normal memory", k);

        const Vec3& old_normal = before[k].normal;
        if (!ref.touching) {
          ++seen.apart;
          if (!(old_normal == Vec3{})) ++seen.forgot;
          continue;
        }
        ++seen.touching;
        const Vec3& n_k = scalar[k].normal;
        if (!(old_normal == Vec3{}) && dot(old_normal, n_k) < 1.0 - 1e-12 &&
            dot(old_normal, n_k) > -0.999999) {
          ++seen.turned;
        }
        const ContactParameters& p = table[static_cast<std::size_t>(
            s.material[s.first[k]] * cs.materials + s.material[s.second[k]])];
        const double fn = -dot(o.force, n_k);
        const Vec3 ft = o.force + fn * n_k;
        if (fn > 0.0 && norm(ft) >= 0.999 * p.friction * fn) ++seen.sliding;
        const double ri = s.r[s.first[k]], rj = s.r[s.second[k]];
        const double m_max = p.rolling_friction * ri * rj / (ri + rj) * fn;
        if (p.rolling_friction > 0.0 && fn > 0.0) {
          if (norm(scalar[k].rolling_spring_torque) >= 0.999 * m_max) {
            ++seen.rolling_saturated;
          } else {
            ++seen.rolling_elastic;
          }
        }
      }
    }
    // Move the spheres: contacts open, close and turn.
    for (std::size_t i = 0; i < s.x.size(); ++i) s.x[i] += 2e-5 * s.v[i];
  }
  // Every lane kind occurred.
  EXPECT_GT(seen.touching, cs.pairs);           // over 6 steps
  EXPECT_GT(seen.apart, cs.pairs / 2);          // some apart
  EXPECT_GT(seen.forgot, cs.pairs / 50);        // broken contacts that had a memory
  EXPECT_GT(seen.turned, seen.touching / 4);    // continuing contacts whose normal turned
  EXPECT_GT(seen.flipped, 0u);                  // memories pointing the other way
  EXPECT_GT(seen.sliding, seen.touching / 20);  // some sliding
  EXPECT_LT(seen.sliding, seen.touching);       // some sticking
  if (cs.rolling) {
    EXPECT_GT(seen.rolling_saturated, seen.touching / 20);
    EXPECT_GT(seen.rolling_elastic, seen.touching / 20);
  }
}

// Each test takes one of the four compiled variants of evaluate_sphere_lanes on most
// batches: with or without rolling, one or several material pairs.
TEST(SpherePairKernel, SameBitsAsOneContactAtATimeWithOneMaterial) {
  compare_paths({});
}

TEST(SpherePairKernel, SameBitsWithOneMaterialThatResistsRolling) {
  compare_paths({.materials = 1, .rolling = true});
}

TEST(SpherePairKernel, SameBitsWhenEverySphereHasTheSecondOfTwoMaterials) {
  // Uniform batches whose material pair is not the first entry of the table.
  compare_paths({.materials = 2, .rolling = true, .only_material = 1});
}

TEST(SpherePairKernel, SameBitsWithMixedMaterialsAndRollingInOneBatch) {
  compare_paths({.materials = 3, .rolling = true, .pairs = 517});
}

TEST(SpherePairKernel, SameBitsWithContactsInAnyOrder) {
  compare_paths({.materials = 2, .pairs = 300, .shuffled = true});
}

// What compute_forces calls: any count of contacts, cut into batches by the kernel.
TEST(SpherePairKernel, TheDispatcherCutsAnyCountIntoBatchesInOrder) {
  std::mt19937_64 rng(99u);
  const std::size_t pairs = 3 * SpherePairLanes::kLanes + 5;
  const Particles s = make_particles(pairs, 2, -1, rng);
  const std::vector<ContactParameters> table = make_table(2, true);
  Domain domain;
  domain.max = {0.01, 0.01, 0.01};
  domain.periodic = {true, false, false};
  std::vector<ContactHistory> history(pairs), reference(pairs);
  const auto inputs = [&](std::vector<ContactHistory>& h) {
    return SpherePairInputs{
        s.x.data(), s.v.data(),     s.w.data(),      s.r.data(), s.material.data(), table.data(),
        2,          s.first.data(), s.second.data(), h.data(),   &domain,           true,
        1e-5};
  };
  for (int step = 0; step < 2; ++step) {
    std::vector<std::size_t> used, used_ref;
    std::vector<ContactOutcome> outcomes, outcomes_ref;
    SpherePairLanes lanes;
    evaluate_sphere_pairs(
        inputs(history), [](std::size_t e) { return pairs - 1 - e; }, pairs, lanes,
        [&](std::size_t k, const ContactOutcome& o) {
          used.push_back(k);
          outcomes.push_back(o);
        });
    evaluate_sphere_pairs_one_by_one(
        inputs(reference), [](std::size_t e) { return pairs - 1 - e; }, pairs,
        [&](std::size_t k, const ContactOutcome& o) {
          used_ref.push_back(k);
          outcomes_ref.push_back(o);
        });
    ASSERT_EQ(used, used_ref);
    for (std::size_t e = 0; e < pairs; ++e) {
      ASSERT_EQ(used[e], pairs - 1 - e);
      expect_same_bits(outcomes[e].force, outcomes_ref[e].force, "force", used[e]);
      expect_same_bits(outcomes[e].torque_first, outcomes_ref[e].torque_first, "torque", used[e]);
      expect_same_bits(history[e].tangential_displacement, reference[e].tangential_displacement,
                       "tangential memory", e);
    }
  }
}

}  // namespace
}  // namespace sanguis::dem
