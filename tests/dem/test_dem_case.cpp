// Tests for the DEM case reader (dem/dem_case.hpp): a small valid case resolves
// to the expected setup (time step Tc/20, §2.4 parameters), and each class of bad
// input is an InputError naming the file and the exact key path.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <variant>

#include "core/config.hpp"
#include "core/error.hpp"
#include "dem/dem_case.hpp"
#include "dem/parameter_procedure.hpp"

namespace sanguis::dem {
namespace {

// Three glass spheres (R = 1 mm) in a list, resting above a steel floor plane.
const std::string kValidCase = R"(
[simulation]
name = "unit"
end_time_s = 0.01
seed = 3

[domain]
min_m = [0.0, 0.0, 0.0]
max_m = [0.02, 0.02, 0.02]

[[material]]
name = "glass"
density_kg_m3 = 2500.0

[[material]]
name = "steel"

[[interaction]]
materials = ["glass", "glass"]
normal_restitution = 0.5
tangential_restitution = 0.4
max_overlap_ratio = 0.01
max_impact_velocity_m_s = 1.0
friction = 0.4
rolling_friction = 0.02

[[interaction]]
materials = ["glass", "steel"]
normal_restitution = 0.6
tangential_restitution = 0.3
max_overlap_ratio = 0.005
max_impact_velocity_m_s = 2.0

[[obstacle]]
name = "floor"
type = "plane"
material = "steel"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 2.0]

[[particles]]
material = "glass"
radius_m = 1e-3
arrangement = "list"
positions_m = [[0.005, 0.005, 0.005], [0.008, 0.005, 0.005], [0.005, 0.008, 0.005]]
velocities_m_s = [[0.0, 0.0, -0.1], [0.0, 0.0, 0.0], [0.1, 0.0, 0.0]]
)";

DemCase load(const std::string& text) {
  return load_dem_case(ConfigTable::parse_string(text, "case.toml"), "case.toml");
}

// `text` with the first occurrence of `from` replaced by `to` (which must exist).
std::string replaced(const std::string& text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  if (at == std::string::npos) {
    ADD_FAILURE() << "test case text lacks '" << from << "'";
    return text;
  }
  std::string out = text;
  out.replace(at, from.size(), to);
  return out;
}

// Loads `text`, which must fail with an InputError on `key` whose reason contains `reason_part`.
void expect_case_error(const std::string& text, const std::string& key,
                       const std::string& reason_part) {
  try {
    load(text);
    ADD_FAILURE() << "expected an InputError on '" << key << "', the case loaded";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "case.toml");
    EXPECT_EQ(e.key(), key) << e.what();
    EXPECT_NE(e.reason().find(reason_part), std::string::npos)
        << "reason '" << e.reason() << "' lacks '" << reason_part << "'";
  }
}

double sphere_mass(double r, double density) {
  return 4.0 / 3.0 * std::numbers::pi * r * r * r * density;
}

void expect_same_parameters(const ContactParameters& a, const ContactParameters& b) {
  EXPECT_EQ(a.normal_stiffness, b.normal_stiffness);
  EXPECT_EQ(a.normal_damping, b.normal_damping);
  EXPECT_EQ(a.tangential_stiffness, b.tangential_stiffness);
  EXPECT_EQ(a.tangential_damping, b.tangential_damping);
  EXPECT_EQ(a.friction, b.friction);
  EXPECT_EQ(a.rolling_stiffness, b.rolling_stiffness);
  EXPECT_EQ(a.rolling_damping, b.rolling_damping);
  EXPECT_EQ(a.rolling_friction, b.rolling_friction);
}

// --- A valid case -------------------------------------------------------------

TEST(DemCase, ValidCaseResolves) {
  const DemCase c = load(kValidCase);
  EXPECT_EQ(c.name, "unit");
  EXPECT_EQ(c.seed, 3u);
  EXPECT_EQ(c.stop.end_time, 0.01);
  EXPECT_FALSE(c.stop.mean_velocity_below.has_value());
  const DemSetup& s = c.setup;
  EXPECT_EQ(s.integrator, IntegratorKind::kLeapfrog);
  EXPECT_EQ(s.gravity, (Vec3{0.0, 0.0, -9.81}));
  EXPECT_EQ(s.max_overlap_ratio, 0.5);
  EXPECT_EQ(s.domain.min, (Vec3{0.0, 0.0, 0.0}));
  EXPECT_EQ(s.domain.max, (Vec3{0.02, 0.02, 0.02}));
  EXPECT_EQ(s.domain.periodic, (std::array<bool, 3>{false, false, false}));
  EXPECT_EQ(s.material_names, (std::vector<std::string>{"glass", "steel"}));

  ASSERT_EQ(s.particles.size(), 3u);
  EXPECT_EQ(s.particles.position[1], (Vec3{0.008, 0.005, 0.005}));
  EXPECT_EQ(s.particles.velocity[2], (Vec3{0.1, 0.0, 0.0}));
  EXPECT_EQ(s.particles.radius[0], 1e-3);
  EXPECT_EQ(s.particles.material[0], 0);
  EXPECT_DOUBLE_EQ(s.particles.mass[0], sphere_mass(1e-3, 2500.0));

  ASSERT_EQ(s.obstacles.size(), 1u);
  EXPECT_EQ(s.obstacles[0].name, "floor");
  EXPECT_EQ(s.obstacles[0].material, 1);
  const auto* plane = std::get_if<PlaneShape>(&s.obstacles[0].shape);
  ASSERT_NE(plane, nullptr);
  EXPECT_EQ(plane->normal, (Vec3{0.0, 0.0, 1.0}));  // normalised
  EXPECT_TRUE(std::isinf(s.obstacles[0].remove_at));

  EXPECT_TRUE(s.contacts.defined(0, 0));
  EXPECT_TRUE(s.contacts.defined(0, 1));
  EXPECT_TRUE(s.contacts.defined(1, 0));
  EXPECT_FALSE(s.contacts.defined(1, 1));

  // Defaults of [output] when the table is absent.
  EXPECT_EQ(c.output.interval, 0.01 / 100.0);
  EXPECT_TRUE(c.output.vtk);
  EXPECT_EQ(c.output.checkpoint_interval, 0.0);
  EXPECT_FALSE(describe(c).empty());
}

TEST(DemCase, OmittedTimeStepIsTcOver20) {
  const DemCase c = load(kValidCase);
  ASSERT_EQ(c.interactions.size(), 2u);
  double smallest = std::numeric_limits<double>::infinity();
  for (const auto& r : c.interactions) {
    EXPECT_GT(r.contact_time, 0.0);
    smallest = std::min(smallest, r.contact_time);
  }
  EXPECT_EQ(c.smallest_contact_time, smallest);
  EXPECT_EQ(c.setup.time_step, c.smallest_contact_time / 20.0);
  // Both interactions are underdamped, so Tc is eq. 2.17 as the procedure reports it.
  for (const auto& r : c.interactions) {
    ASSERT_TRUE(r.procedure.has_value());
    EXPECT_NEAR(r.contact_time, r.procedure->contact_time, 1e-12 * r.contact_time);
  }
}

TEST(DemCase, ProcedureValuesAreThoseOfDeriveContactParameters) {
  const DemCase c = load(kValidCase);
  ASSERT_EQ(c.interactions.size(), 2u);
  const double r = 1e-3;
  const double m = sphere_mass(r, 2500.0);

  ProcedureInput pair;
  pair.reduced_mass = m * m / (m + m);
  pair.reduced_radius = r * r / (r + r);
  pair.inertia_factor = 2.5;
  pair.normal_restitution = 0.5;
  pair.tangential_restitution = 0.4;
  pair.max_overlap = 0.01 * r;
  pair.max_impact_velocity = 1.0;
  pair.friction = 0.4;
  pair.rolling_friction = 0.02;
  const ProcedureResult expected_pair = derive_contact_parameters(pair);

  ProcedureInput wall;
  wall.reduced_mass = m;
  wall.reduced_radius = r;
  wall.inertia_factor = 2.5;
  wall.normal_restitution = 0.6;
  wall.tangential_restitution = 0.3;
  wall.max_overlap = 0.005 * r;
  wall.max_impact_velocity = 2.0;
  wall.friction = 0.5;          // default
  wall.rolling_friction = 0.0;  // default
  const ProcedureResult expected_wall = derive_contact_parameters(wall);

  const ResolvedInteraction& gg = c.interactions[0];
  EXPECT_EQ(gg.first, "glass");
  EXPECT_EQ(gg.second, "glass");
  EXPECT_FALSE(gg.wall);
  EXPECT_DOUBLE_EQ(gg.reduced_mass, pair.reduced_mass);
  ASSERT_TRUE(gg.procedure.has_value());
  expect_same_parameters(gg.parameters, expected_pair.parameters);
  expect_same_parameters(c.setup.contacts.get(0, 0), expected_pair.parameters);
  EXPECT_EQ(gg.procedure->damping_ratio, expected_pair.damping_ratio);
  EXPECT_EQ(gg.procedure->contact_time, expected_pair.contact_time);
  EXPECT_GT(gg.parameters.rolling_stiffness, 0.0);

  const ResolvedInteraction& gs = c.interactions[1];
  EXPECT_EQ(gs.first, "glass");
  EXPECT_EQ(gs.second, "steel");
  EXPECT_TRUE(gs.wall);
  EXPECT_DOUBLE_EQ(gs.reduced_mass, m);
  ASSERT_TRUE(gs.procedure.has_value());
  expect_same_parameters(gs.parameters, expected_wall.parameters);
  expect_same_parameters(c.setup.contacts.get(0, 1), expected_wall.parameters);
  expect_same_parameters(c.setup.contacts.get(1, 0), expected_wall.parameters);
}

TEST(DemCase, ExplicitInteractionKeepsTheGivenValues) {
  const std::string text = replaced(kValidCase, R"([[interaction]]
materials = ["glass", "steel"]
normal_restitution = 0.6
tangential_restitution = 0.3
max_overlap_ratio = 0.005
max_impact_velocity_m_s = 2.0)",
                                    R"([[interaction]]
materials = ["steel", "glass"]
mode = "explicit"
normal_stiffness_N_m = 2.0e5
normal_damping_N_s_m = 0.5
tangential_stiffness_N_m = 6.0e4
friction = 0.3
rolling_friction = 0.1
rolling_stiffness_N_m_rad = 1e-3)");
  const DemCase c = load(text);
  ASSERT_EQ(c.interactions.size(), 2u);
  const ResolvedInteraction& gs = c.interactions[1];
  EXPECT_EQ(gs.first, "glass");  // the particle material comes first
  EXPECT_EQ(gs.second, "steel");
  EXPECT_FALSE(gs.procedure.has_value());
  const ContactParameters& p = c.setup.contacts.get(0, 1);
  EXPECT_EQ(p.normal_stiffness, 2.0e5);
  EXPECT_EQ(p.normal_damping, 0.5);
  EXPECT_EQ(p.tangential_stiffness, 6.0e4);
  EXPECT_EQ(p.tangential_damping, 0.0);
  EXPECT_EQ(p.friction, 0.3);
  EXPECT_EQ(p.rolling_friction, 0.1);
  EXPECT_EQ(p.rolling_stiffness, 1e-3);
  EXPECT_EQ(p.rolling_damping, 0.0);
  // eq. 2.17 with the particle mass for a wall.
  const double m = sphere_mass(1e-3, 2500.0);
  const double omega0 = std::sqrt(2.0e5 / m);
  const double ratio = 0.5 / (2.0 * m) / omega0;
  EXPECT_NEAR(gs.contact_time, std::numbers::pi / (omega0 * std::sqrt(1.0 - ratio * ratio)),
              1e-12 * gs.contact_time);
}

TEST(DemCase, OptionalSimulationKeysAndTables) {
  std::string text = replaced(kValidCase, "seed = 3", R"(seed = 3
integrator = "adams_bashforth_3"
gravity_m_s2 = [0.0, -1.0, 0.0]
skin_m = 2e-4
abort_overlap_ratio = 0.2
storage_sort_steps = 0
flat_contacts = "point"
element_contacts = "mean"
forget_contact_memory_at_s = 0.004)");
  text += R"(
[output]
interval_s = 0.002
vtk = false
checkpoint_interval_s = 0.005

[stop]
mean_velocity_below_m_s = 0.01
check_after_s = 0.003
)";
  const DemCase c = load(text);
  EXPECT_EQ(c.setup.integrator, IntegratorKind::kAdamsBashforth3);
  EXPECT_EQ(c.setup.gravity, (Vec3{0.0, -1.0, 0.0}));
  EXPECT_EQ(c.setup.skin, 2e-4);
  EXPECT_EQ(c.setup.max_overlap_ratio, 0.2);
  EXPECT_EQ(c.setup.storage_sort_interval, 0);
  EXPECT_EQ(load(kValidCase).setup.storage_sort_interval, 2000);  // the default
  EXPECT_FALSE(c.setup.contact_patches);
  EXPECT_TRUE(load(kValidCase).setup.contact_patches);  // the default
  EXPECT_TRUE(c.setup.mean_element_contacts);
  EXPECT_FALSE(load(kValidCase).setup.mean_element_contacts);  // the default: the sum
  EXPECT_EQ(c.setup.forget_contact_memory_at, 0.004);
  EXPECT_NE(describe(c).find("contact memory  forgotten at t = 0.004 s"), std::string::npos);
  EXPECT_TRUE(std::isinf(load(kValidCase).setup.forget_contact_memory_at));  // never
  EXPECT_EQ(describe(load(kValidCase)).find("contact memory"), std::string::npos);
  EXPECT_EQ(c.output.interval, 0.002);
  EXPECT_FALSE(c.output.vtk);
  EXPECT_EQ(c.output.checkpoint_interval, 0.005);
  ASSERT_TRUE(c.stop.mean_velocity_below.has_value());
  EXPECT_EQ(*c.stop.mean_velocity_below, 0.01);
  EXPECT_EQ(c.stop.settle_check_after, 0.003);
}

TEST(DemCase, LatticeAndRandomArrangements) {
  const std::string lattice = replaced(kValidCase, R"(arrangement = "list"
positions_m = [[0.005, 0.005, 0.005], [0.008, 0.005, 0.005], [0.005, 0.008, 0.005]]
velocities_m_s = [[0.0, 0.0, -0.1], [0.0, 0.0, 0.0], [0.1, 0.0, 0.0]])",
                                       R"(arrangement = "lattice"
region_min_m = [0.0, 0.0, 0.0]
region_max_m = [0.0081, 0.0061, 0.0066]
spacing_m = 2.5e-3
velocity_m_s = [0.0, 0.0, -0.5])");
  const DemCase l = load(lattice);
  // Sites at R + k spacing up to region_max - R: 3 x 2 x 2.
  ASSERT_EQ(l.setup.particles.size(), 12u);
  EXPECT_EQ(l.setup.particles.position[0], (Vec3{1e-3, 1e-3, 1e-3}));
  EXPECT_EQ(l.setup.particles.velocity[5], (Vec3{0.0, 0.0, -0.5}));

  const std::string random = replaced(kValidCase, R"(radius_m = 1e-3
arrangement = "list"
positions_m = [[0.005, 0.005, 0.005], [0.008, 0.005, 0.005], [0.005, 0.008, 0.005]]
velocities_m_s = [[0.0, 0.0, -0.1], [0.0, 0.0, 0.0], [0.1, 0.0, 0.0]])",
                                      R"(radius_min_m = 0.8e-3
radius_max_m = 1.2e-3
arrangement = "random"
count = 40
region_min_m = [0.0, 0.0, 0.0]
region_max_m = [0.02, 0.02, 0.02])");
  const DemCase r1 = load(random);
  const DemCase r2 = load(random);
  ASSERT_EQ(r1.setup.particles.size(), 40u);
  for (std::size_t i = 0; i < 40; ++i) {
    EXPECT_GE(r1.setup.particles.radius[i], 0.8e-3);
    EXPECT_LE(r1.setup.particles.radius[i], 1.2e-3);
    EXPECT_GE(r1.setup.particles.position[i].z, r1.setup.particles.radius[i]);
    EXPECT_EQ(r1.setup.particles.position[i], r2.setup.particles.position[i]);  // seeded
  }
  const DemCase other_seed = load(replaced(random, "seed = 3", "seed = 4"));
  EXPECT_FALSE(other_seed.setup.particles.position[0] == r1.setup.particles.position[0]);
}

TEST(DemCase, SmallerRadiiGiveASmallerContactTime) {
  // With a size distribution, Tc (and so dt) is checked for the smallest particles.
  const std::string poly = replaced(kValidCase, R"(radius_m = 1e-3
arrangement = "list"
positions_m = [[0.005, 0.005, 0.005], [0.008, 0.005, 0.005], [0.005, 0.008, 0.005]]
velocities_m_s = [[0.0, 0.0, -0.1], [0.0, 0.0, 0.0], [0.1, 0.0, 0.0]])",
                                    R"(radius_min_m = 0.5e-3
radius_max_m = 1.5e-3
arrangement = "random"
count = 5
region_min_m = [0.0, 0.0, 0.0]
region_max_m = [0.02, 0.02, 0.02])");
  const DemCase c = load(poly);
  const ResolvedInteraction& gg = c.interactions[0];
  const double m_min = sphere_mass(0.5e-3, 2500.0);
  EXPECT_DOUBLE_EQ(gg.reduced_mass, m_min * m_min / (m_min + m_min));
  ASSERT_TRUE(gg.procedure.has_value());
  EXPECT_LT(gg.contact_time, gg.procedure->contact_time);  // procedure uses the mean radius
}

// --- Bad input, one class per test ----------------------------------------------

TEST(DemCaseErrors, UnknownKey) {
  expect_case_error(replaced(kValidCase, "end_time_s = 0.01", "end_time_s = 0.01\nend_tme_s = 1"),
                    "simulation.end_tme_s", "unknown key");
  expect_case_error(replaced(kValidCase, "radius_m = 1e-3", "radius_m = 1e-3\nraduis_m = 1e-3"),
                    "particles[0].raduis_m", "unknown key");
  expect_case_error(replaced(kValidCase, "name = \"floor\"", "name = \"floor\"\nremove_at = 1.0"),
                    "obstacle[0].remove_at", "unknown key");
  expect_case_error(kValidCase + "\n[outputs]\ninterval_s = 0.001\n", "outputs", "unknown key");
  // Keys of another arrangement or mode are unknown here too.
  expect_case_error(
      replaced(kValidCase, "radius_m = 1e-3", "radius_m = 1e-3\nregion_min_m = [0.0, 0.0, 0.0]"),
      "particles[0].region_min_m", "unknown key");
  expect_case_error(
      replaced(kValidCase, "friction = 0.4", "friction = 0.4\nnormal_stiffness_N_m = 1e5"),
      "interaction[0].normal_stiffness_N_m", "unknown key");
}

TEST(DemCaseErrors, WrongType) {
  expect_case_error(replaced(kValidCase, "end_time_s = 0.01", "end_time_s = \"0.01\""),
                    "simulation.end_time_s", "expected a number, got a string");
  expect_case_error(replaced(kValidCase, "seed = 3", "seed = 3.5"), "simulation.seed",
                    "expected an integer");
  expect_case_error(replaced(kValidCase, "max_m = [0.02, 0.02, 0.02]", "max_m = [0.02, 0.02]"),
                    "domain.max_m", "expected an array of 3 numbers");
  expect_case_error(replaced(kValidCase, "[domain]", "[domain]\nperiodic = [true, false]"),
                    "domain.periodic", "3 booleans");
}

TEST(DemCaseErrors, MissingRequiredKey) {
  expect_case_error(replaced(kValidCase, "end_time_s = 0.01\n", ""), "simulation.end_time_s",
                    "required key is missing");
  expect_case_error(replaced(kValidCase, "arrangement = \"list\"\n", ""),
                    "particles[0].arrangement", "required key is missing");
  expect_case_error(replaced(kValidCase, "max_impact_velocity_m_s = 1.0\n", ""),
                    "interaction[0].max_impact_velocity_m_s", "required key is missing");
  expect_case_error(replaced(kValidCase, "[domain]", "[domainn]"), "domain",
                    "required table is missing");
}

TEST(DemCaseErrors, NegativeStorageSortInterval) {
  expect_case_error(replaced(kValidCase, "seed = 3", "seed = 3\nstorage_sort_steps = -5"),
                    "simulation.storage_sort_steps", "must be >= 0");
}

TEST(DemCaseErrors, UnknownFlatContactModel) {
  expect_case_error(replaced(kValidCase, "seed = 3", "seed = 3\nflat_contacts = \"manifold\""),
                    "simulation.flat_contacts", "patch");
}

TEST(DemCaseErrors, UnknownElementContactRule) {
  expect_case_error(replaced(kValidCase, "seed = 3", "seed = 3\nelement_contacts = \"average\""),
                    "simulation.element_contacts", "mean");
}

TEST(DemCaseErrors, NegativeTimeToForgetTheContactMemory) {
  expect_case_error(replaced(kValidCase, "seed = 3", "seed = 3\nforget_contact_memory_at_s = -1.0"),
                    "simulation.forget_contact_memory_at_s", "must be >= 0");
}

TEST(DemCaseErrors, NegativeOrZeroRadius) {
  expect_case_error(replaced(kValidCase, "radius_m = 1e-3", "radius_m = -1e-3"),
                    "particles[0].radius_m", "must be > 0");
  expect_case_error(replaced(kValidCase, "radius_m = 1e-3", "radius_m = 0"),
                    "particles[0].radius_m", "must be > 0");
}

TEST(DemCaseErrors, NormalRestitutionOutsideZeroOne) {
  expect_case_error(replaced(kValidCase, "normal_restitution = 0.5", "normal_restitution = 0"),
                    "interaction[0].normal_restitution", "must be in (0, 1]");
  expect_case_error(replaced(kValidCase, "normal_restitution = 0.5", "normal_restitution = 1.5"),
                    "interaction[0].normal_restitution", "must be in (0, 1]");
  expect_case_error(
      replaced(kValidCase, "tangential_restitution = 0.3", "tangential_restitution = -0.3"),
      "interaction[1].tangential_restitution", "must be in (0, 1]");
  // 1 itself is allowed (elastic).
  EXPECT_NO_THROW(load(replaced(kValidCase, "normal_restitution = 0.5", "normal_restitution = 1")));
}

TEST(DemCaseErrors, TimeStepAboveTcOver10) {
  const double tc = load(kValidCase).smallest_contact_time;
  const auto with_dt = [&](double dt, bool allow) {
    std::ostringstream s;
    s.precision(17);
    s << "seed = 3\ntime_step_s = " << dt << (allow ? "\nallow_large_time_step = true" : "");
    return replaced(kValidCase, "seed = 3", s.str());
  };
  expect_case_error(with_dt(tc / 5.0, false), "simulation.time_step_s", "exceeds Tc/10");
  expect_case_error(with_dt(5.0 * tc, false), "simulation.time_step_s",
                    "allow_large_time_step = true");
  // Below the limit, or with the explicit override, the given step is used as is.
  EXPECT_EQ(load(with_dt(tc / 15.0, false)).setup.time_step, tc / 15.0);
  EXPECT_EQ(load(with_dt(5.0 * tc, true)).setup.time_step, 5.0 * tc);
  expect_case_error(with_dt(-1e-6, true), "simulation.time_step_s", "must be > 0");
}

TEST(DemCaseErrors, OverlappingParticlesInAList) {
  expect_case_error(replaced(kValidCase, "[0.008, 0.005, 0.005], [0.005, 0.008",
                             "[0.0065, 0.005, 0.005], [0.005, 0.008"),
                    "particles", "initial particles overlap");
  // A sphere cutting the floor overlaps too.
  expect_case_error(replaced(kValidCase, "[[0.005, 0.005, 0.005]", "[[0.005, 0.005, 0.0005]"),
                    "particles", "overlaps obstacle 'floor'");
}

TEST(DemCaseErrors, UnknownMaterialName) {
  expect_case_error(replaced(kValidCase, "material = \"glass\"", "material = \"glas\""),
                    "particles[0].material", "unknown material 'glas'");
  expect_case_error(replaced(kValidCase, "material = \"steel\"", "material = \"iron\""),
                    "obstacle[0].material", "unknown material 'iron'");
  expect_case_error(replaced(kValidCase, "materials = [\"glass\", \"steel\"]",
                             "materials = [\"glass\", \"stee\"]"),
                    "interaction[1].materials", "unknown material 'stee'");
}

TEST(DemCaseErrors, MaterialUsedByParticlesAndObstacles) {
  expect_case_error(replaced(kValidCase, "material = \"steel\"", "material = \"glass\""),
                    "material", "'glass' is used by particles and obstacles");
}

TEST(DemCaseErrors, MissingInteractionForAPairThatCanTouch) {
  const std::string no_wall = replaced(kValidCase, R"([[interaction]]
materials = ["glass", "steel"]
normal_restitution = 0.6
tangential_restitution = 0.3
max_overlap_ratio = 0.005
max_impact_velocity_m_s = 2.0)",
                                       "");
  expect_case_error(no_wall, "interaction", "no [[interaction]] for materials ['glass', 'steel']");
  expect_case_error(replaced(kValidCase, "materials = [\"glass\", \"glass\"]",
                             "materials = [\"steel\", \"glass\"]"),
                    "interaction[1].materials", "defined twice");
}

TEST(DemCaseErrors, RandomInsertionThatCannotFit) {
  const std::string base = replaced(kValidCase, R"(arrangement = "list"
positions_m = [[0.005, 0.005, 0.005], [0.008, 0.005, 0.005], [0.005, 0.008, 0.005]]
velocities_m_s = [[0.0, 0.0, -0.1], [0.0, 0.0, 0.0], [0.1, 0.0, 0.0]])",
                                    R"(arrangement = "random"
count = COUNT
region_min_m = [0.0, 0.0, 0.0]
region_max_m = [0.006, 0.006, 0.006])");
  // At most 27 spheres of diameter 2 mm fit in a 6 mm cube.
  expect_case_error(replaced(base, "COUNT", "60"), "particles[0].count", "could place only");
  expect_case_error(replaced(base, "COUNT", "0"), "particles[0].count", "positive integer");
  expect_case_error(
      replaced(replaced(base, "COUNT", "1"), "[0.006, 0.006, 0.006]", "[0.006, 0.006, 0.0015]"),
      "particles[0].count", "thinner than one particle diameter");
}

TEST(DemCaseErrors, PeriodicAxisTooShort) {
  // 3 x (2 R + skin) with the default skin 0.2 R = 6.6 mm; x is 6 mm long.
  const std::string short_x =
      replaced(replaced(kValidCase, "max_m = [0.02, 0.02, 0.02]",
                        "max_m = [0.006, 0.02, 0.02]\nperiodic = [true, false, false]"),
               "[[0.005, 0.005, 0.005], [0.008, 0.005, 0.005], [0.005, 0.008, 0.005]]",
               "[[0.003, 0.005, 0.005], [0.003, 0.008, 0.005], [0.003, 0.011, 0.005]]");
  expect_case_error(short_x, "domain.periodic", "at least 3 x (largest diameter + skin)");
  // 7 mm is enough.
  const DemCase c = load(replaced(short_x, "max_m = [0.006", "max_m = [0.007"));
  EXPECT_TRUE(c.setup.domain.periodic[0]);
}

// --- Other checks -------------------------------------------------------------------

TEST(DemCaseErrors, OtherRangeAndConsistencyChecks) {
  expect_case_error(replaced(kValidCase, "end_time_s = 0.01", "end_time_s = 0"),
                    "simulation.end_time_s", "must be > 0");
  expect_case_error(replaced(kValidCase, "seed = 3", "seed = -1"), "simulation.seed", ">= 0");
  expect_case_error(replaced(kValidCase, "seed = 3", "seed = 3\nintegrator = \"rk4\""),
                    "simulation.integrator", "is not one of");
  expect_case_error(replaced(kValidCase, "max_m = [0.02, 0.02, 0.02]", "max_m = [0.02, 0.0, 0.02]"),
                    "domain.max_m", "greater than the minimum corner");
  expect_case_error(replaced(kValidCase, "name = \"steel\"", "name = \"glass\""),
                    "material[1].name", "defined twice");
  expect_case_error(replaced(kValidCase, "normal = [0.0, 0.0, 2.0]", "normal = [0.0, 0.0, 0.0]"),
                    "obstacle[0].normal", "non-zero");
  expect_case_error(replaced(kValidCase, "type = \"plane\"", "type = \"sphere\""),
                    "obstacle[0].type", "is not one of 'plane', 'box'");
  expect_case_error(replaced(kValidCase, "max_overlap_ratio = 0.01", "max_overlap_ratio = 0.5"),
                    "interaction[0].max_overlap_ratio", "well below 1");
  expect_case_error(replaced(kValidCase, "friction = 0.4", "friction = -0.4"),
                    "interaction[0].friction", "must be >= 0");
  expect_case_error(replaced(kValidCase, "radius_m = 1e-3", "radius_m = 1e-3\nradius_max_m = 2e-3"),
                    "particles[0].radius_m", "not both");
  expect_case_error(kValidCase + "\n[output]\ninterval_s = 1e-9\n", "output.interval_s",
                    "shorter than the time step");
  expect_case_error(
      replaced(kValidCase, "velocities_m_s = [[0.0, 0.0, -0.1], ", "velocities_m_s = ["),
      "particles[0].velocities_m_s", "as many entries as positions_m");
  expect_case_error(replaced(kValidCase, "[[material]]\nname = \"glass\"\ndensity_kg_m3 = 2500.0",
                             "[[material]]\nname = \"glass\""),
                    "particles[0].material", "has no density_kg_m3");
  expect_case_error(
      replaced(kValidCase, "materials = [\"glass\", \"glass\"]", "materials = [\"glass\"]"),
      "interaction[0].materials", "exactly two materials");
  expect_case_error(replaced(kValidCase, "materials = [\"glass\", \"glass\"]",
                             "materials = [\"glass\", \"glass\"]\nmode = \"guess\""),
                    "interaction[0].mode", "'procedure', 'explicit'");
}

TEST(DemCaseErrors, BoxObstacleAndLatticeChecks) {
  const std::string box = replaced(kValidCase, R"(type = "plane"
material = "steel"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 2.0])",
                                   R"(type = "box"
material = "steel"
min_m = [0.0, 0.0, 0.0]
max_m = [0.02, 0.02, 0.001]
remove_at_s = 0.004)");
  const DemCase c = load(box);
  ASSERT_EQ(c.setup.obstacles.size(), 1u);
  EXPECT_EQ(c.setup.obstacles[0].remove_at, 0.004);
  EXPECT_TRUE(std::holds_alternative<AxisAlignedBoxShape>(c.setup.obstacles[0].shape));
  expect_case_error(replaced(box, "max_m = [0.02, 0.02, 0.001]", "max_m = [0.02, 0.02, 0.0]"),
                    "obstacle[0].max_m", "greater than the minimum corner");
  expect_case_error(replaced(box, "remove_at_s = 0.004", "remove_at_s = -1"),
                    "obstacle[0].remove_at_s", "must be >= 0");

  const std::string lattice = replaced(kValidCase, R"(arrangement = "list"
positions_m = [[0.005, 0.005, 0.005], [0.008, 0.005, 0.005], [0.005, 0.008, 0.005]]
velocities_m_s = [[0.0, 0.0, -0.1], [0.0, 0.0, 0.0], [0.1, 0.0, 0.0]])",
                                       R"(arrangement = "lattice"
region_min_m = [0.0, 0.0, 0.0]
region_max_m = [0.01, 0.01, 0.01]
spacing_m = SPACING
count = COUNT)");
  expect_case_error(replaced(replaced(lattice, "SPACING", "1.5e-3"), "COUNT", "0"),
                    "particles[0].spacing_m", "at least one diameter");
  expect_case_error(replaced(replaced(lattice, "SPACING", "2.5e-3"), "COUNT", "100"),
                    "particles[0].count", "fewer than count = 100");
  expect_case_error(replaced(replaced(lattice, "SPACING", "2.5e-3"), "COUNT", "-1"),
                    "particles[0].count", "must be >= 0");
  EXPECT_EQ(
      load(replaced(replaced(lattice, "SPACING", "2.5e-3"), "COUNT", "0")).setup.particles.size(),
      64u);  // 4 x 4 x 4 sites fill the region
  EXPECT_EQ(
      load(replaced(replaced(lattice, "SPACING", "2.5e-3"), "COUNT", "10")).setup.particles.size(),
      10u);
}

// --- The documentation's example -------------------------------------------------

TEST(DemCase, MinimalExampleOfTheDocsLoads) {
  std::ifstream in(std::string(SANGUIS_SOURCE_DIR) + "/docs/case-file.md");
  ASSERT_TRUE(in) << "cannot read docs/case-file.md";
  const std::string doc{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const std::size_t marker = doc.find("<!-- example: minimal");
  ASSERT_NE(marker, std::string::npos);
  const std::size_t begin = doc.find("```toml\n", marker);
  ASSERT_NE(begin, std::string::npos);
  const std::size_t end = doc.find("```", begin + 8);
  ASSERT_NE(end, std::string::npos);
  const DemCase c = load(doc.substr(begin + 8, end - begin - 8));
  EXPECT_EQ(c.name, "minimal");
  EXPECT_EQ(c.setup.particles.size(), 30u);
  EXPECT_EQ(c.setup.obstacles.size(), 1u);
  EXPECT_EQ(c.setup.time_step, c.smallest_contact_time / 20.0);
}

}  // namespace
}  // namespace sanguis::dem

namespace sanguis::dem {
namespace {

TEST(DemCase, InteractionWithAnUnusedMaterialIsAnError) {
  std::string text = kValidCase;
  text += R"(
[[material]]
name = "rubber"
density_kg_m3 = 1100.0

[[interaction]]
materials = ["glass", "rubber"]
mode = "explicit"
normal_stiffness_N_m = 1e5
)";
  expect_case_error(text, "interaction[2].materials", "used by no");
}

}  // namespace
}  // namespace sanguis::dem
