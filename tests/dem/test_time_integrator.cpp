// Each scheme on motions with known solutions: free flight under gravity (exact for
// leapfrog and the Adams-Bashforth schemes once started) and a constant torque.
#include <gtest/gtest.h>

#include "dem/time_integrator.hpp"

namespace sanguis::dem {
namespace {

TEST(TimeIntegrator, ParsesNamesAndOrders) {
  EXPECT_EQ(parse_integrator("leapfrog"), IntegratorKind::kLeapfrog);
  EXPECT_EQ(order_of(parse_integrator("adams_bashforth_3")), 3);
  EXPECT_THROW(parse_integrator("rk4"), std::invalid_argument);
}

TEST(TimeIntegrator, LeapfrogIsExactForConstantAcceleration) {
  ParticleStore p;
  p.add_sphere(0, 0, 1e-3, 1000.0, {0, 0, 0}, {1.0, 0.0, 2.0}, {});
  TimeIntegrator integrator(IntegratorKind::kLeapfrog);
  const Vec3 g{0.0, 0.0, -9.81};
  const double dt = 1e-3;
  for (int n = 0; n < 1000; ++n) {
    integrator.advance(p, g, dt);
    integrator.finish(p, g, dt);
  }
  EXPECT_NEAR(p.position[0].z, 2.0 * 1.0 - 0.5 * 9.81, 1e-12);
  EXPECT_NEAR(p.velocity[0].z, 2.0 - 9.81, 1e-12);
  EXPECT_NEAR(p.position[0].x, 1.0, 1e-12);
}

TEST(TimeIntegrator, EulerHasItsFirstOrderErrorUnderGravity) {
  ParticleStore p;
  p.add_sphere(0, 0, 1e-3, 1000.0, {0, 0, 0}, {}, {});
  TimeIntegrator integrator(IntegratorKind::kForwardEuler);
  const double dt = 1e-3;
  for (int n = 0; n < 1000; ++n) integrator.advance(p, {0, 0, -1.0}, dt);
  // x_N = -dt^2 N(N-1)/2 exactly: error 0.5 dt t against -t^2/2.
  EXPECT_NEAR(p.position[0].z, -0.5 + 0.5 * dt, 1e-12);
}

TEST(TimeIntegrator, AdamsBashforthSchemesIntegrateConstantTorque) {
  for (auto kind : {IntegratorKind::kAdamsBashforth2, IntegratorKind::kAdamsBashforth3}) {
    ParticleStore p;
    p.add_sphere(0, 0, 1e-3, 1000.0, {0, 0, 0}, {}, {});
    p.torque[0] = {0.0, 0.0, 1e-9};
    TimeIntegrator integrator(kind);
    for (int n = 0; n < 100; ++n) integrator.advance(p, {}, 1e-3);
    EXPECT_NEAR(p.angular_velocity[0].z, 0.1 * 1e-9 * p.inverse_inertia_body[0].x, 1e-9)
        << to_string(kind);
    EXPECT_EQ(integrator.history().depth, 2);
  }
}

}  // namespace
}  // namespace sanguis::dem
