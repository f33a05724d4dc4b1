// One sphere on a plane under gravity: static friction with memory (§2.3.1),
// sliding and rolling with their analytic accelerations, and rolling resistance
// (§2.3.2) bringing a rolling sphere to rest at the predicted distance.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>

#include "dem/parameter_procedure.hpp"
#include "dem/simulation.hpp"

namespace sanguis::dem {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRadius = 1e-3, kDensity = 2500.0, kG = 9.81;

struct PlaneCase {
  double incline_deg = 0.0;  // gravity tilted from -z towards +x
  double friction = 0.5;
  double rolling_friction = 0.0;
  bool memory = true;  // false: kt = kr = 0 (dashpots only)
  Vec3 velocity, angular_velocity;
  double forget_memory_at = std::numeric_limits<double>::infinity();  // [s]
};

DemSimulation make_sphere_on_plane(const PlaneCase& pc) {
  const double mass = 4.0 / 3.0 * kPi * std::pow(kRadius, 3) * kDensity;
  ProcedureInput in;
  in.reduced_mass = mass;
  in.reduced_radius = kRadius;
  in.normal_restitution = 0.45;
  in.tangential_restitution = 0.3;
  in.max_overlap = 0.005 * kRadius;
  in.max_impact_velocity = 2.62;
  in.friction = pc.friction;
  in.rolling_friction = pc.rolling_friction;
  const ProcedureResult r = derive_contact_parameters(in);
  ContactParameters p = r.parameters;
  if (!pc.memory) {
    p.tangential_stiffness = 0.0;
    p.rolling_stiffness = 0.0;
  }
  DemSetup s;
  s.domain.min = {-1.0, -0.01, -0.01};
  s.domain.max = {1.0, 0.01, 0.01};
  const double theta = pc.incline_deg * kPi / 180.0;
  s.gravity = {kG * std::sin(theta), 0.0, -kG * std::cos(theta)};
  s.time_step = r.recommended_time_step;
  s.forget_contact_memory_at = pc.forget_memory_at;
  s.material_names = {"sphere", "plane"};
  s.contacts = ContactTable(2);
  s.contacts.set(0, 0, p);
  s.contacts.set(0, 1, p);
  Obstacle plane;
  plane.material = 1;
  plane.shape = PlaneShape{{0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}};
  s.obstacles.push_back(plane);
  // Start at the static normal overlap so that the normal transient is small.
  const double overlap = mass * kG * std::cos(theta) / p.normal_stiffness;
  s.particles.add_sphere(0, 0, kRadius, kDensity, {0.0, 0.0, kRadius - overlap}, pc.velocity,
                         pc.angular_velocity);
  return DemSimulation(std::move(s));
}

TEST(SphereOnPlane, StaysStillBelowTheFrictionAngleWithMemory) {
  // tan(20 deg) = 0.36 is below mu_c = 0.5 and below mu_r = 0.45 (eq. 2.29: mu_r = tan beta).
  DemSimulation sim = make_sphere_on_plane({20.0, 0.5, 0.45, true, {}, {}});
  const Vec3 start = sim.particles().position[0];
  sim.run_until(1.0);
  const double drift = norm(sim.particles().position[0] - start);
  EXPECT_LT(drift, 1e-9) << "drift " << drift << " m over 1 s";
  EXPECT_LT(norm(sim.particles().velocity[0]), 1e-10);
}

TEST(SphereOnPlane, CreepsWithoutMemory) {
  DemSimulation sim = make_sphere_on_plane({20.0, 0.5, 0.45, false, {}, {}});
  const Vec3 start = sim.particles().position[0];
  sim.run_until(1.0);
  EXPECT_GT(norm(sim.particles().position[0] - start), 1e-6);
}

// DemSetup::forget_contact_memory_at: the sphere at rest on the incline holds its weight's
// slope component in its tangential spring (and rolling spring). Forgetting the memory
// empties both, so the sphere gives way until the springs carry the load again, and then
// rests again with the same spring loads.
TEST(SphereOnPlane, ForgettingTheMemoryEmptiesTheSpringsAndTheSphereGivesWayUntilTheyReload) {
  PlaneCase pc{20.0, 0.5, 0.45, true, {}, {}};
  pc.forget_memory_at = 0.5;
  DemSimulation sim = make_sphere_on_plane(pc);
  sim.run_until(0.5);
  ASSERT_EQ(sim.wall_contacts().size(), 1u);
  const ContactHistory loaded = sim.wall_contacts().history[0];
  const double spring = norm(loaded.tangential_displacement);
  ASSERT_GT(spring, 0.0);
  ASSERT_GT(norm(loaded.rolling_spring_torque), 0.0);
  const Vec3 rest = sim.particles().position[0];
  EXPECT_LT(norm(sim.particles().velocity[0]), 1e-10);

  sim.step();  // the step from t = 0.5 s starts by forgetting
  const ContactHistory emptied = sim.wall_contacts().history[0];
  EXPECT_LT(norm(emptied.tangential_displacement), 1e-3 * spring);
  EXPECT_LT(norm(emptied.rolling_spring_torque), 1e-3 * norm(loaded.rolling_spring_torque));

  sim.run_until(1.5);
  const ContactHistory reloaded = sim.wall_contacts().history[0];
  EXPECT_NEAR(norm(reloaded.tangential_displacement) / spring, 1.0, 0.01);
  EXPECT_LT(norm(sim.particles().velocity[0]), 1e-10);
  // It gave way by about the spring's stretch (the contact point moved by that much).
  const double moved = norm(sim.particles().position[0] - rest);
  EXPECT_GT(moved, 0.3 * spring);
  EXPECT_LT(moved, 3.0 * spring);
}

// The forgetting is tied to the step grid, so a restart from the step it falls on
// forgets and one from a later step does not forget again: a run stopped and restarted
// there gives the bits of the run that went through.
TEST(SphereOnPlane, ARestartForgetsTheMemoryAtTheSameStepOnly) {
  PlaneCase pc{20.0, 0.5, 0.45, true, {}, {}};
  pc.forget_memory_at = 0.2;
  DemSimulation through = make_sphere_on_plane(pc);
  through.run_until(0.4);
  for (const double stop : {0.2, 0.3}) {
    DemSimulation first = make_sphere_on_plane(pc);
    first.run_until(stop);
    const auto file = std::filesystem::temp_directory_path() / "sanguis_forget_memory_ck.bin";
    first.save_checkpoint(file);
    DemSimulation second = make_sphere_on_plane(pc);
    second.load_checkpoint(file);
    second.run_until(0.4);
    std::filesystem::remove(file);
    EXPECT_EQ(second.particles().position[0], through.particles().position[0])
        << "restarted at " << stop << " s";
    EXPECT_EQ(second.wall_contacts().history[0].tangential_displacement,
              through.wall_contacts().history[0].tangential_displacement);
  }
}

TEST(SphereOnPlane, SlidesWithTheCoulombAcceleration) {
  // tan(45 deg) = 1 > 7/2 mu_c = 0.7: the sphere slides (and spins up) with
  // a = g (sin theta - mu_c cos theta).
  const double mu = 0.2, theta = 45.0 * kPi / 180.0;
  DemSimulation sim = make_sphere_on_plane({45.0, mu, 0.0, true, {}, {}});
  sim.run_until(0.05);
  const double v0 = sim.particles().velocity[0].x, t0 = sim.time();
  sim.run_until(0.25);
  const double a = (sim.particles().velocity[0].x - v0) / (sim.time() - t0);
  EXPECT_NEAR(a / (kG * (std::sin(theta) - mu * std::cos(theta))), 1.0, 0.005);
}

TEST(SphereOnPlane, RollsWithoutSlippingAtFiveSeventhsGSinTheta) {
  // tan(20 deg) < 7/2 mu_c: rolling without slipping, a = 5/7 g sin theta (I = 2/5 m R^2).
  const double theta = 20.0 * kPi / 180.0;
  DemSimulation sim = make_sphere_on_plane({20.0, 0.5, 0.0, true, {}, {}});
  sim.run_until(0.05);
  const double v0 = sim.particles().velocity[0].x, t0 = sim.time();
  sim.run_until(0.25);
  const Vec3 v = sim.particles().velocity[0];
  const double a = (v.x - v0) / (sim.time() - t0);
  EXPECT_NEAR(a / (5.0 / 7.0 * kG * std::sin(theta)), 1.0, 0.005);
  // No slip: contact point velocity v + omega x (-R z) ~ 0.
  const Vec3 slip = v + cross(sim.particles().angular_velocity[0], Vec3{0.0, 0.0, -kRadius});
  EXPECT_LT(norm(slip), 1e-3 * norm(v));
}

TEST(SphereOnPlane, RollingResistanceStopsARollingSphereAtThePredictedDistance) {
  // M_max = mu_r R m g (eq. 2.13, R_ij = R on a wall) decelerates a rolling sphere at
  // a = 5/7 mu_r g: it stops after v0^2 / (2 a) in v0 / a, then stays at rest.
  const double mu_r = 0.1, v0 = 0.1;
  DemSimulation sim =
      make_sphere_on_plane({0.0, 0.5, mu_r, true, {v0, 0.0, 0.0}, {0.0, v0 / kRadius, 0.0}});
  const double a = 5.0 / 7.0 * mu_r * kG;
  double stop_time = -1.0;
  while (sim.time() < 2.0 * v0 / a) {
    sim.step();
    if (stop_time < 0 && sim.particles().velocity[0].x <= 0.0) stop_time = sim.time();
  }
  ASSERT_GT(stop_time, 0.0) << "the sphere never stopped";
  EXPECT_NEAR(stop_time / (v0 / a), 1.0, 0.01);
  const Vec3 rest = sim.particles().position[0];
  EXPECT_NEAR(rest.x / (v0 * v0 / (2.0 * a)), 1.0, 0.01);
  sim.run_until(sim.time() + 0.5);
  EXPECT_LT(norm(sim.particles().position[0] - rest), 1e-9);
}

}  // namespace
}  // namespace sanguis::dem
