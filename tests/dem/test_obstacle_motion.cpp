// Prescribed obstacle kinematics: the speed laws and their integrals, a conveyor
// belt driving a sphere to the rolling speed 2/7 U, and the case-file keys.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/config.hpp"
#include "dem/dem_case.hpp"
#include "dem/obstacle_motion.hpp"
#include "dem/simulation.hpp"

namespace sanguis::dem {
namespace {

double integrate(const SpeedLaw& law, double t) {
  const int n = 200000;
  double sum = 0.0;
  for (int k = 0; k < n; ++k) sum += law.speed_at((k + 0.5) * t / n) * t / n;
  return sum;
}

TEST(ObstacleMotion, DamBreakGateRampOfSection321) {
  SpeedLaw gate;
  gate.kind = SpeedLaw::Kind::kRamp;
  gate.speed = 3.0;          // m/s
  gate.acceleration = 43.0;  // m/s^2
  gate.start = 0.5;
  EXPECT_EQ(gate.speed_at(0.4), 0.0);
  EXPECT_NEAR(gate.speed_at(0.55), 43.0 * 0.05, 1e-12);
  EXPECT_EQ(gate.speed_at(0.6), 3.0);
  const double t_ramp = 3.0 / 43.0;
  EXPECT_NEAR(gate.distance_at(0.6), 0.5 * 43.0 * t_ramp * t_ramp + 3.0 * (0.1 - t_ramp), 1e-12);
  for (double t : {0.3, 0.52, 0.56, 0.8})
    EXPECT_NEAR(gate.distance_at(t), integrate(gate, t), 1e-9);
}

TEST(ObstacleMotion, PiecewiseAndConstantLawsIntegrateExactly) {
  SpeedLaw piecewise;
  piecewise.kind = SpeedLaw::Kind::kPiecewise;
  piecewise.points = {{0.1, 0.5}, {0.3, 2.0}, {0.4, -1.0}};
  SpeedLaw constant;
  constant.kind = SpeedLaw::Kind::kConstant;
  constant.speed = 0.7;
  constant.start = 0.2;
  for (double t : {0.05, 0.2, 0.35, 0.6}) {
    EXPECT_NEAR(piecewise.distance_at(t), integrate(piecewise, t), 1e-9) << t;
    // The constant law jumps at its start: the midpoint quadrature itself is then off by
    // up to speed x (quadrature step) / 2 = 1e-6.
    EXPECT_NEAR(constant.distance_at(t), integrate(constant, t), 1.1e-6) << t;
  }
}

TEST(ObstacleMotion, ConveyorBeltBringsASphereToTwoSeventhsOfItsSpeed) {
  // A sphere at rest on a belt starting at speed U: friction accelerates and spins it until
  // it rolls without slipping; angular momentum about the contact line is conserved, so
  // v = 2/7 U (and omega = -5/7 U / R relative to ... the belt frame).
  const double u = 0.2, r = 1e-3;
  DemSetup s;
  s.domain = {{-1.0, -0.01, -0.01}, {1.0, 0.01, 0.01}, {false, false, false}};
  s.gravity = {0.0, 0.0, -9.81};
  s.time_step = 2e-7;
  s.material_names = {"glass", "belt"};
  ContactParameters p;
  p.normal_stiffness = 1e5;
  p.normal_damping = 0.02;
  p.tangential_stiffness = 3e4;
  p.tangential_damping = 0.01;
  p.friction = 0.3;
  s.contacts = ContactTable(2);
  s.contacts.set(0, 0, p);
  s.contacts.set(0, 1, p);
  Obstacle belt;
  belt.material = 1;
  belt.shape = PlaneShape{{0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}};
  belt.motion.direction = {1.0, 0.0, 0.0};
  belt.motion.translation.kind = SpeedLaw::Kind::kConstant;
  belt.motion.translation.speed = u;
  s.obstacles.push_back(belt);
  const double m = 4.0 / 3.0 * std::numbers::pi * r * r * r * 2500.0;
  s.particles.add_sphere(0, 0, r, 2500.0, {0.0, 0.0, r - m * 9.81 / 1e5}, {}, {});
  DemSimulation sim(std::move(s));
  sim.run_until(0.1);  // slipping ends after 2U/(7 mu g) = 20 ms
  EXPECT_NEAR(sim.particles().velocity[0].x / (2.0 / 7.0 * u), 1.0, 0.01);
  // rolling without slip on the belt: v + omega x (-R z) = U
  const Vec3 contact_speed =
      sim.particles().velocity[0] + cross(sim.particles().angular_velocity[0], Vec3{0, 0, -r});
  EXPECT_NEAR(contact_speed.x, u, 1e-3 * u);
}

TEST(ObstacleMotion, CaseFileKeys) {
  const char* text = R"(
[simulation]
end_time_s = 0.1
[domain]
min_m = [0.0, 0.0, 0.0]
max_m = [0.1, 0.1, 0.1]
[[material]]
name = "glass"
density_kg_m3 = 2500.0
[[material]]
name = "steel"
[[interaction]]
materials = ["glass", "glass"]
mode = "explicit"
normal_stiffness_N_m = 1e4
[[interaction]]
materials = ["glass", "steel"]
mode = "explicit"
normal_stiffness_N_m = 1e4
[[obstacle]]
name = "gate"
type = "box"
material = "steel"
min_m = [0.05, 0.0, 0.0]
max_m = [0.055, 0.1, 0.1]
translation = { direction = [0.0, 0.0, 2.0], law = "ramp", speed_m_s = 3.0, acceleration_m_s2 = 43.0, start_s = 0.02 }
[[obstacle]]
name = "paddle"
type = "box"
material = "steel"
min_m = [0.08, 0.04, 0.0]
max_m = [0.09, 0.06, 0.02]
rotation = { axis = [0.0, 0.0, 1.0], centre_m = [0.085, 0.05, 0.0], law = "piecewise", points_s_rad_s = [[0.0, 0.0], [0.05, 10.0]] }
[[particles]]
material = "glass"
radius_m = 1e-3
arrangement = "list"
positions_m = [[0.02, 0.05, 0.01]]
)";
  const DemCase c = load_dem_case(ConfigTable::parse_string(text, "gate.toml"), "gate.toml");
  const ObstacleMotion& gate = c.setup.obstacles[0].motion;
  EXPECT_EQ(gate.direction.z, 1.0);  // normalised
  EXPECT_EQ(gate.translation.kind, SpeedLaw::Kind::kRamp);
  EXPECT_EQ(gate.translation.acceleration, 43.0);
  const ObstacleMotion& paddle = c.setup.obstacles[1].motion;
  EXPECT_EQ(paddle.rotation.points.size(), 2u);
  EXPECT_NEAR(paddle.rotation.speed_at(0.025), 5.0, 1e-12);
  std::string bad = text;
  bad.replace(bad.find("law = \"ramp\""), 12, "law = \"jump\"");
  try {
    load_dem_case(ConfigTable::parse_string(bad, "gate.toml"), "gate.toml");
    ADD_FAILURE() << "bad law accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "obstacle[0].translation.law");
  }
}

}  // namespace
}  // namespace sanguis::dem
