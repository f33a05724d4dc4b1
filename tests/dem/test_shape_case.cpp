// Case files with [[shape]] species: parsing, mass properties of the particles made from
// them, and the errors of bad shape input.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/config.hpp"
#include "dem/dem_case.hpp"

namespace sanguis::dem {
namespace {

const std::string kCrosses = R"(
[simulation]
end_time_s = 0.01
seed = 5
[domain]
min_m = [0.0, 0.0, 0.0]
max_m = [0.2, 0.2, 0.2]
[[shape]]
name = "cross"
type = "cross"
length_m = 0.027
width_m = 0.002
thickness_m = 0.003
crust_m = 1e-4
[[shape]]
name = "pebble"
type = "composite"
[[shape.element]]
type = "box"
size_m = [0.004, 0.002, 0.002]
[[shape.element]]
type = "sphere"
radius_m = 0.0012
position_m = [0.002, 0.0, 0.0]
[[material]]
name = "plastic"
density_kg_m3 = 770.0
[[material]]
name = "wall"
[[interaction]]
materials = ["plastic", "plastic"]
mode = "explicit"
normal_stiffness_N_m = 4.5e5
normal_restitution = 0.85
tangential_stiffness_N_m = 3e2
tangential_damping_rate_1_s = 1e3
friction = 0.46
[[interaction]]
materials = ["plastic", "wall"]
mode = "explicit"
normal_stiffness_N_m = 4.5e5
normal_restitution = 0.85
tangential_stiffness_N_m = 3e2
tangential_damping_rate_1_s = 1e3
friction = 0.62
[[obstacle]]
type = "plane"
material = "wall"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[particles]]
material = "plastic"
shape = "cross"
arrangement = "random"
count = 20
region_min_m = [0.0, 0.0, 0.0]
region_max_m = [0.2, 0.2, 0.2]
[[particles]]
material = "plastic"
shape = "pebble"
orientation = "fixed"
orientation_axis = [0.0, 1.0, 0.0]
orientation_angle_deg = 90.0
arrangement = "list"
positions_m = [[0.1, 0.1, 0.19]]
)";

DemCase load(const std::string& text) {
  return load_dem_case(ConfigTable::parse_string(text, "shapes.toml"), "shapes.toml");
}

TEST(ShapeCase, CrossesAndCompositesBecomeBodiesWithTheirMassProperties) {
  const DemCase c = load(kCrosses);
  const ParticleStore& p = c.setup.particles;
  ASSERT_EQ(p.size(), 21u);
  ASSERT_EQ(c.setup.shapes.size(), 2u);
  EXPECT_NEAR(c.setup.shapes[0].volume, 312e-9, 1e-15);  // thesis §3.2.2: 0.312 cm3
  for (std::size_t i = 0; i < 20; ++i) {
    EXPECT_EQ(p.spherical[i], 0);
    EXPECT_EQ(p.species[i], 0);
    EXPECT_NEAR(p.mass[i], 770.0 * 312e-9, 1e-15);
    EXPECT_NEAR(p.radius[i], c.setup.shapes[0].bounding_radius, 0.0);
  }
  // Random orientations differ; the fixed one is as asked.
  EXPECT_NE(p.orientation[0].w, p.orientation[1].w);
  EXPECT_EQ(p.species[20], 1);
  // Explicit damping from en and gamma_t with the pair's reduced mass (Table 3.1 style);
  // the material's reference size is the mean volume-equivalent radius of its species.
  const double r =
      0.5 * (c.setup.shapes[0].equivalent_radius + c.setup.shapes[1].equivalent_radius);
  const double m = 0.5 * 770.0 * 4.0 / 3.0 * 3.141592653589793 * r * r * r;
  EXPECT_NEAR(c.interactions[0].parameters.tangential_damping, 2.0 * m * 1e3, 1e-12);
  // A short run: the bodies fall, nothing blows up.
  DemSimulation sim(c.setup);
  sim.run_until(c.stop.end_time);
  EXPECT_LT(sim.diagnostics().max_overlap_ratio, 0.01);
}

void expect_error(const std::string& text, const std::string& key, const std::string& part) {
  try {
    load(text);
    ADD_FAILURE() << "accepted; expected an error on " << key;
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), key) << e.what();
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  text.replace(text.find(from), from.size(), to);
  return text;
}

TEST(ShapeCase, BadShapeInputIsAnErrorNamingTheKey) {
  expect_error(
      replaced(kCrosses, "shape = \"cross\"\narrangement", "shape = \"star\"\narrangement"),
      "particles[0].shape", "unknown shape");
  expect_error(replaced(kCrosses, "crust_m = 1e-4", "crust_m = 0.005"), "shape[0].crust_m",
               "does not fit");
  expect_error(replaced(kCrosses, "size_m = [0.004, 0.002, 0.002]", "size_m = [0.004, 0.0, 0.002]"),
               "shape[1].element[0].size_m", "> 0");
  expect_error(replaced(kCrosses, "type = \"cross\"", "type = \"star\""), "shape[0].type",
               "not one of");
}

}  // namespace
}  // namespace sanguis::dem
