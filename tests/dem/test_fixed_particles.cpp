// Fixed (glued) particles: a rough floor of beads that touch the others but never
// move. Spheres dropped on the layer come to rest in its hollows; the layer keeps
// its exact positions; the diagnostics' means and `sanguis analyze` count only the
// mobile particles; a fixed group that is poured or given a velocity is an error.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>

#include "core/config.hpp"
#include "core/error.hpp"
#include "dem/analysis/run_output.hpp"
#include "dem/dem_run.hpp"

namespace sanguis::dem {
namespace {

constexpr double kBeadRadius = 1e-3;

// A 1 cm periodic cell: a square layer of 5 x 5 glued beads (spacing one diameter,
// centres at z = R) and four spheres released above it, off the hollows.
const std::string kRoughFloor = R"(
[simulation]
end_time_s = 0.6
[domain]
min_m = [0.0, 0.0, 0.0]
max_m = [0.01, 0.01, 0.02]
periodic = [true, true, false]
[[material]]
name = "glass"
density_kg_m3 = 2500.0
[[material]]
name = "wall"
[[interaction]]
materials = ["glass", "glass"]
normal_restitution = 0.3
tangential_restitution = 0.3
max_overlap_ratio = 0.01
max_impact_velocity_m_s = 0.5
friction = 0.5
rolling_friction = 0.1
[[interaction]]
materials = ["glass", "wall"]
normal_restitution = 0.3
tangential_restitution = 0.3
max_overlap_ratio = 0.01
max_impact_velocity_m_s = 0.5
[[obstacle]]
type = "plane"
material = "wall"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[particles]]
material = "glass"
radius_m = 1e-3
arrangement = "lattice"
fixed = true
region_min_m = [0.0, 0.0, 1e-7]
region_max_m = [0.01, 0.01, 0.0020001]
[[particles]]
material = "glass"
radius_m = 1e-3
arrangement = "list"
positions_m = [[0.0023, 0.0021, 0.005], [0.0061, 0.0024, 0.006], [0.0025, 0.0066, 0.007],
               [0.0067, 0.0063, 0.008]]
[output]
interval_s = 0.05
[stop]
mean_velocity_below_m_s = 1e-6
check_after_s = 0.2
)";

DemCase load_rough_floor(const std::string& text) {
  return load_dem_case(ConfigTable::parse_string(text, "rough.toml"), "rough.toml");
}

TEST(FixedParticles, SpheresRestInTheHollowsOfAGluedLayerThatNeverMoves) {
  const auto dir = std::filesystem::temp_directory_path() / "sanguis_test_fixed_particles";
  std::filesystem::remove_all(dir);
  const DemCase c = load_rough_floor(kRoughFloor);
  const ParticleStore& start = c.setup.particles;
  ASSERT_EQ(start.size(), 29u);
  for (std::size_t i = 0; i < 25; ++i) EXPECT_TRUE(start.is_fixed(i)) << i;
  for (std::size_t i = 25; i < 29; ++i) EXPECT_FALSE(start.is_fixed(i)) << i;

  DemSimulation sim(c.setup);
  sim.run_until(0.6);
  const ParticleStore& p = sim.particles();
  int mobile = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto k = static_cast<std::size_t>(p.id[i]);  // the store may be re-sorted
    if (k < 25) {
      EXPECT_EQ(p.position[i], start.position[k]) << "glued bead " << k << " moved";
      EXPECT_EQ(p.velocity[i], Vec3{});
      EXPECT_EQ(p.angular_velocity[i], Vec3{});
      continue;
    }
    ++mobile;
    // Resting on four beads of a square layer: the centre is sqrt(2) R above theirs (z = R).
    EXPECT_NEAR(p.position[i].z, kBeadRadius + std::sqrt(2.0) * kBeadRadius, 0.02 * kBeadRadius)
        << "sphere " << k;
    EXPECT_LT(norm(p.velocity[i]), 1e-4);
  }
  EXPECT_EQ(mobile, 4);
  EXPECT_EQ(sim.diagnostics().mobile_particles, 4);

  // Through the run driver: the diagnostics average over the four mobile spheres (it
  // settles), and the analysis reads the frames without the glued beads.
  RunOptions options;
  options.output_dir = dir;
  options.quiet = true;
  std::ostringstream console;
  const RunSummary summary = run_dem_case(c, options, console);
  EXPECT_TRUE(summary.settled);
  EXPECT_EQ(summary.last.mobile_particles, 4);
  const analysis::RunOutput out(dir);
  const analysis::ParticleFrame last = out.particles(out.frame_at(-1.0));
  ASSERT_EQ(last.size(), 4u);
  for (std::size_t k = 0; k < last.size(); ++k) EXPECT_GE(last.id[k], 25);
  std::filesystem::remove_all(dir);
}

TEST(FixedParticles, AFixedGroupCannotBePouredOrMoving) {
  const std::string lattice = "arrangement = \"lattice\"\nfixed = true";
  const auto expect_error = [&](const std::string& text, const std::string& key) {
    try {
      load_rough_floor(text);
      ADD_FAILURE() << "expected an InputError on " << key;
    } catch (const InputError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
    }
  };
  std::string moving = kRoughFloor;
  moving.replace(moving.find(lattice), lattice.size(),
                 lattice + "\nvelocity_m_s = [0.0, 0.0, -1.0]");
  expect_error(moving, "particles[0].velocity_m_s");
  std::string poured = kRoughFloor;
  poured.replace(poured.find(lattice), lattice.size(),
                 "arrangement = \"pour\"\nfixed = true\ncount = 3\nrate_per_s = 10.0");
  expect_error(poured, "particles[0].fixed");
}

TEST(FixedParticles, AGluedOnlyMaterialNeedsInteractionsOnlyWithMobileOnes) {
  // The glued layer gets its own material: it meets the mobile glass beads, never
  // itself nor the floor plane, so only the glass-base pair must be given.
  std::string without = kRoughFloor;
  const std::string glued_group =
      "[[particles]]\nmaterial = \"glass\"\nradius_m = 1e-3\n"
      "arrangement = \"lattice\"";
  without.replace(without.find(glued_group), glued_group.size(),
                  "[[particles]]\nmaterial = \"base\"\nradius_m = 1e-3\n"
                  "arrangement = \"lattice\"");
  without.insert(without.find("[[obstacle]]"),
                 "[[material]]\nname = \"base\"\ndensity_kg_m3 = 2500.0\n");
  try {
    load_rough_floor(without);
    ADD_FAILURE() << "expected an InputError on the glass-base pair";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "interaction");
    EXPECT_NE(std::string(e.what()).find("['glass', 'base']"), std::string::npos) << e.what();
  }

  std::string with = without;
  with.insert(with.find("[[obstacle]]"),
              "[[interaction]]\nmaterials = [\"glass\", \"base\"]\nnormal_restitution = 0.3\n"
              "tangential_restitution = 0.3\nmax_overlap_ratio = 0.01\n"
              "max_impact_velocity_m_s = 0.5\nfriction = 0.5\n");
  const DemCase c = load_rough_floor(with);  // no base-base, no base-wall pair needed
  ASSERT_EQ(c.setup.particles.size(), 29u);
  for (std::size_t i = 0; i < 25; ++i) EXPECT_TRUE(c.setup.particles.is_fixed(i)) << i;
  DemSimulation sim(c.setup);
  sim.run_until(0.05);  // the beads fall onto the layer: only defined pairs are met
  EXPECT_GT(sim.diagnostics().mobile_particles, 0);
}

}  // namespace
}  // namespace sanguis::dem
