// Torque-free rotation of an asymmetric rigid body (eq. 2.33-2.34): conservation
// of energy and angular momentum, the intermediate-axis flip, and the order of
// the two rotational schemes.
#include <gtest/gtest.h>

#include <cmath>

#include "dem/time_integrator.hpp"

namespace sanguis::dem {
namespace {

const Vec3 kInertia{1.0, 2.0, 3.0};  // principal moments [kg m^2]

ParticleStore spinning_body(const Vec3& omega_body) {
  ParticleStore p;
  const Quaternion q = Quaternion::from_axis_angle({0.3, -0.5, 0.8}, 0.7);
  p.add_body(0, 0, 0, 1.0, 1.0, kInertia, q, {}, {}, rotate(q, omega_body));
  return p;
}

double energy(const ParticleStore& p) {
  const Vec3 wb = rotate_inverse(p.orientation[0], p.angular_velocity[0]);
  return 0.5 * (kInertia.x * wb.x * wb.x + kInertia.y * wb.y * wb.y + kInertia.z * wb.z * wb.z);
}

Vec3 angular_momentum(const ParticleStore& p) {
  const Quaternion& q = p.orientation[0];
  const Vec3 wb = rotate_inverse(q, p.angular_velocity[0]);
  return rotate(q, {kInertia.x * wb.x, kInertia.y * wb.y, kInertia.z * wb.z});
}

void step(TimeIntegrator& integrator, ParticleStore& p, double dt) {
  integrator.advance(p, {}, dt);
  integrator.finish(p, {}, dt);
}

TEST(RigidBodyRotation, LeapfrogConservesAngularMomentumAndEnergy) {
  ParticleStore p = spinning_body({0.1, 2.0, 0.1});
  TimeIntegrator integrator(IntegratorKind::kLeapfrog);
  const double e0 = energy(p);
  const Vec3 l0 = angular_momentum(p);
  double worst_energy = 0.0;
  for (int n = 0; n < 20000; ++n) {  // 20 s, several flips
    step(integrator, p, 1e-3);
    worst_energy = std::max(worst_energy, std::abs(energy(p) / e0 - 1.0));
  }
  EXPECT_LT(norm(angular_momentum(p) - l0), 1e-11 * norm(l0));  // exact up to round-off
  EXPECT_LT(worst_energy, 1e-5);  // bounded O(dt^2) oscillation, no drift
  EXPECT_NEAR(std::sqrt(p.orientation[0].w * p.orientation[0].w + norm2(p.orientation[0].vector())),
              1.0, 1e-14);
}

TEST(RigidBodyRotation, IntermediateAxisFlips) {
  // Spin about the intermediate axis (J_y) with a small perturbation: unstable, the body
  // periodically turns over (Dzhanibekov effect), so omega_y changes sign.
  ParticleStore p = spinning_body({1e-3, 2.0, 1e-3});
  TimeIntegrator integrator(IntegratorKind::kLeapfrog);
  int flips = 0;
  double previous = rotate_inverse(p.orientation[0], p.angular_velocity[0]).y;
  for (int n = 0; n < 40000; ++n) {
    step(integrator, p, 1e-3);
    const double wy = rotate_inverse(p.orientation[0], p.angular_velocity[0]).y;
    flips += (wy < 0.0) != (previous < 0.0);
    previous = wy;
  }
  EXPECT_GE(flips, 2);
  // Spin about the major axis is stable: no flip.
  ParticleStore stable = spinning_body({1e-3, 1e-3, 2.0});
  TimeIntegrator integrator2(IntegratorKind::kLeapfrog);
  for (int n = 0; n < 40000; ++n) {
    step(integrator2, stable, 1e-3);
    ASSERT_GT(rotate_inverse(stable.orientation[0], stable.angular_velocity[0]).z, 1.9);
  }
}

double energy_error_after(IntegratorKind kind, double dt) {
  ParticleStore p = spinning_body({0.5, 1.0, 0.3});
  TimeIntegrator integrator(kind);
  const double e0 = energy(p);
  const int steps = static_cast<int>(std::lround(2.0 / dt));
  for (int n = 0; n < steps; ++n) step(integrator, p, dt);
  return std::abs(energy(p) / e0 - 1.0);
}

TEST(RigidBodyRotation, FirstOrderSchemeOfTheThesisConvergesAtFirstOrder) {
  const double e1 = energy_error_after(IntegratorKind::kForwardEuler, 1e-3);
  const double e2 = energy_error_after(IntegratorKind::kForwardEuler, 5e-4);
  EXPECT_NEAR(std::log2(e1 / e2), 1.0, 0.2);
  // and the leapfrog splitting at second order
  const double l1 = energy_error_after(IntegratorKind::kLeapfrog, 4e-2);
  const double l2 = energy_error_after(IntegratorKind::kLeapfrog, 2e-2);
  EXPECT_NEAR(std::log2(l1 / l2), 2.0, 0.3);
}

}  // namespace
}  // namespace sanguis::dem
