// The contact-parameter procedure of thesis §2.4 against Table 2.1, and the
// closed forms of the clamped spring-dashpot against direct integration.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "dem/parameter_procedure.hpp"

namespace sanguis::dem {
namespace {

constexpr double kPi = std::numbers::pi;

// Table 2.1 (hopper discharge): R = 1 mm, rho = 2500 kg/m3, en = 0.45, delta_max = 0.005 R,
// giving kn ~ 7.34e5 N/m, kt ~ 2.26e5 N/m, gamma_t ~ 4.0e4 1/s for particle pairs. The
// thesis does not state v_max and et: v_max = 2.62 m/s (a drop of 0.35 m) and et = 0.3
// reproduce all three values.
TEST(ParameterProcedure, ReproducesTable21WithinTwoPercent) {
  const double mass = 4.0 / 3.0 * kPi * 1e-9 * 2500.0;
  ProcedureInput in;
  in.reduced_mass = 0.5 * mass;
  in.reduced_radius = 0.5e-3;
  in.normal_restitution = 0.45;
  in.tangential_restitution = 0.3;
  in.max_overlap = 0.005 * 1e-3;
  in.max_impact_velocity = 2.62;
  in.friction = 0.5;
  in.rolling_friction = 0.45;
  const ProcedureResult r = derive_contact_parameters(in);
  EXPECT_NEAR(r.parameters.normal_stiffness / 7.34e5, 1.0, 0.02);
  EXPECT_NEAR(r.parameters.tangential_stiffness / 2.26e5, 1.0, 0.02);
  EXPECT_NEAR(r.tangential_damping_rate / 4.0e4, 1.0, 0.02);
  // dt = 5e-7 s of Table 2.1 is about Tc/17; the procedure recommends Tc/20.
  EXPECT_NEAR(r.recommended_time_step, r.contact_time / 20.0, 1e-18);
  EXPECT_GT(r.contact_time / 5e-7, 15.0);
  // eq. 2.28 with R_ij.
  EXPECT_DOUBLE_EQ(r.parameters.rolling_stiffness,
                   3.0 * r.parameters.normal_stiffness * 0.45 * 0.45 * 0.25e-6);
}

TEST(ParameterProcedure, ThesisDampingMatchesEq216) {
  // eq. 2.16: en = exp(-gamma_n pi / sqrt(omega0^2 - gamma_n^2)) for the unclamped oscillator.
  ProcedureInput in;
  in.reduced_mass = 1e-5;
  in.reduced_radius = 1e-3;
  in.max_overlap = 1e-6;
  in.max_impact_velocity = 1.0;
  for (double en : {0.1, 0.45, 0.9, 1.0}) {
    in.normal_restitution = en;
    const ProcedureResult r = derive_contact_parameters(in);
    const double omega0 = std::sqrt(r.parameters.normal_stiffness / in.reduced_mass);
    const double gamma = r.parameters.normal_damping / (2.0 * in.reduced_mass);
    EXPECT_NEAR(std::exp(-gamma * kPi / std::sqrt(omega0 * omega0 - gamma * gamma)), en, 1e-12);
    // eq. 2.18: the maximum overlap at v_max is delta_max.
    const double omega = std::sqrt(omega0 * omega0 - gamma * gamma);
    const double t_max = std::atan(omega / std::max(gamma, 1e-300)) / omega;
    EXPECT_NEAR(in.max_impact_velocity / omega * std::exp(-gamma * t_max) * std::sin(omega * t_max),
                in.max_overlap, 1e-15);
  }
}

// Integrates m x'' = -max(kn x + eta x', 0) with RK4 on a fine step and returns the
// rebound ratio and the maximum overlap.
std::pair<double, double> integrate_clamped(double damping_ratio) {
  const double omega0 = 1.0, dt = 1e-5;
  double x = 0.0, v = 1.0, x_max = 0.0;
  const auto acc = [&](double xx, double vv) {
    return -std::fmax(omega0 * omega0 * xx + 2.0 * damping_ratio * omega0 * vv, 0.0);
  };
  for (int it = 0; it < 10000000 && x >= 0.0; ++it) {
    const double k1x = v, k1v = acc(x, v);
    const double k2x = v + 0.5 * dt * k1v, k2v = acc(x + 0.5 * dt * k1x, v + 0.5 * dt * k1v);
    const double k3x = v + 0.5 * dt * k2v, k3v = acc(x + 0.5 * dt * k2x, v + 0.5 * dt * k2v);
    const double k4x = v + dt * k3v, k4v = acc(x + dt * k3x, v + dt * k3v);
    x += dt / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
    v += dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    x_max = std::max(x_max, x);
  }
  return {-v, x_max};
}

TEST(ClampedSpringDashpot, ClosedFormsMatchDirectIntegration) {
  for (double d : {0.05, 0.2463, 0.7, 0.999, 1.0, 1.5, 4.0}) {
    const auto [rebound, overlap] = integrate_clamped(d);
    EXPECT_NEAR(clamped_restitution(d), rebound, 2e-4) << "damping ratio " << d;
    EXPECT_NEAR(scaled_max_overlap(d), overlap, 2e-4) << "damping ratio " << d;
  }
  // The clamped law cannot rebound below e^-2 while underdamped (Schwager & Poeschel).
  EXPECT_NEAR(clamped_restitution(0.999999), std::exp(-2.0), 1e-4);
}

TEST(ClampedSpringDashpot, InverseRecoversTheDampingRatio) {
  for (double en : {0.05, 0.1, 0.45, 0.9, 0.999}) {
    const double d = damping_ratio_for_clamped_restitution(en);
    EXPECT_NEAR(clamped_restitution(d), en, 1e-12);
  }
  EXPECT_EQ(damping_ratio_for_clamped_restitution(1.0), 0.0);
}

TEST(ParameterProcedure, RejectsNonPhysicalInput) {
  ProcedureInput in;
  in.reduced_mass = 1e-5;
  in.reduced_radius = 1e-3;
  in.max_overlap = 1e-6;
  in.max_impact_velocity = 1.0;
  in.normal_restitution = 0.0;
  EXPECT_THROW(derive_contact_parameters(in), std::invalid_argument);
  in.normal_restitution = 1.2;
  EXPECT_THROW(derive_contact_parameters(in), std::invalid_argument);
  in.normal_restitution = 0.5;
  in.max_overlap = -1.0;
  EXPECT_THROW(derive_contact_parameters(in), std::invalid_argument);
}

}  // namespace
}  // namespace sanguis::dem
