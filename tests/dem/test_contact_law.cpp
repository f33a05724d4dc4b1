// The per-contact kernel of eq. 2.5-2.13 on hand-built contacts.
#include <gtest/gtest.h>

#include <cmath>

#include "dem/contact_law.hpp"

namespace sanguis::dem {
namespace {

ContactParameters parameters() {
  ContactParameters p;
  p.normal_stiffness = 1e5;
  p.normal_damping = 0.5;
  p.tangential_stiffness = 3e4;
  p.tangential_damping = 0.2;
  p.friction = 0.5;
  p.rolling_stiffness = 1e-3;
  p.rolling_damping = 1e-6;
  p.rolling_friction = 0.1;
  return p;
}

ContactKinematics contact(double overlap, const Vec3& v, const Vec3& w = {}) {
  ContactKinematics c;
  c.normal = {0.0, 0.0, 1.0};
  c.overlap = overlap;
  c.relative_velocity = v;
  c.relative_angular_velocity = w;
  c.reduced_radius = 1e-3;
  return c;
}

TEST(ContactLaw, NormalForceIsTheViscoelasticSpringAndNeverAttractive) {
  const ContactParameters p = parameters();
  ContactHistory h;
  // Approaching (first body moves along +n): kn d + eta_n d', pushing the first body back.
  auto r = evaluate_contact(p, contact(1e-6, {0.0, 0.0, 0.1}), h, 1e-6);
  EXPECT_DOUBLE_EQ(r.normal_force, 1e5 * 1e-6 + 0.5 * 0.1);
  EXPECT_DOUBLE_EQ(r.force.z, -r.normal_force);
  // Separating fast: kn d + eta_n d' < 0 is clamped to 0 (eq. 2.5).
  ContactHistory h2;
  r = evaluate_contact(p, contact(1e-6, {0.0, 0.0, -1.0}), h2, 1e-6);
  EXPECT_EQ(r.normal_force, 0.0);
  EXPECT_EQ(r.force.z, 0.0);
}

TEST(ContactLaw, StickingContactAccumulatesTheTangentialDisplacement) {
  const ContactParameters p = parameters();
  ContactHistory h;
  const double dt = 1e-6;
  const Vec3 vt{1e-3, 0.0, 0.0};
  for (int k = 1; k <= 10; ++k) {
    const auto r = evaluate_contact(p, contact(1e-5, vt), h, dt);
    EXPECT_NEAR(h.tangential_displacement.x, k * dt * vt.x, 1e-20);
    EXPECT_NEAR(r.force.x, -p.tangential_stiffness * k * dt * vt.x - p.tangential_damping * vt.x,
                1e-15);
  }
}

TEST(ContactLaw, SlidingSaturatesAtCoulombAndStaysContinuousThroughDesaturation) {
  const ContactParameters p = parameters();
  ContactHistory h;
  const double dt = 1e-6, overlap = 1e-5;
  const double fn = p.normal_stiffness * overlap;
  // Drive the contact far into sliding.
  ContactResponse r;
  for (int k = 0; k < 2000; ++k) r = evaluate_contact(p, contact(overlap, {0.01, 0.0, 0.0}), h, dt);
  EXPECT_NEAR(std::hypot(r.force.x, r.force.y), p.friction * fn, 1e-12);
  EXPECT_LT(r.force.x, 0.0);
  // eq. 2.8 (second line): the spring holds the saturated force plus the damping.
  EXPECT_NEAR(-p.tangential_stiffness * h.tangential_displacement.x - p.tangential_damping * 0.01,
              r.force.x, 1e-12);
  // The contact stops sliding: the force changes only by the vanished damping term and the
  // one-step spring increment, instead of dropping to zero as a fresh path integral would.
  const auto stuck = evaluate_contact(p, contact(overlap, {0.0, 0.0, 0.0}), h, dt);
  EXPECT_NEAR(stuck.force.x, r.force.x + p.tangential_damping * 0.01, 1e-12);
  EXPECT_GT(std::abs(stuck.force.x), 0.9 * p.friction * fn - p.tangential_damping * 0.01);
}

TEST(ContactLaw, HistoryRotatesWithTheTangentPlaneKeepingItsLength) {
  const Vec3 old_n{0.0, 0.0, 1.0};
  const double a = 0.3;
  const Vec3 new_n{std::sin(a), 0.0, std::cos(a)};
  const Vec3 delta{2.0, 1.0, 0.0};
  const Vec3 rotated = rotate_into_new_plane(delta, old_n, new_n);
  EXPECT_NEAR(dot(rotated, new_n), 0.0, 1e-15);
  EXPECT_NEAR(norm(rotated), norm(delta), 1e-14);
  // Rotation about y by a: x component turns, y is the axis and stays.
  EXPECT_NEAR(rotated.x, 2.0 * std::cos(a), 1e-14);
  EXPECT_NEAR(rotated.y, 1.0, 1e-14);
  EXPECT_NEAR(rotated.z, -2.0 * std::sin(a), 1e-14);
}

TEST(ContactLaw, RollingTorqueHasMemoryAndSaturatesAtMuRRFn) {
  const ContactParameters p = parameters();
  ContactHistory h;
  const double dt = 1e-6, overlap = 1e-5;
  const double fn = p.normal_stiffness * overlap;
  const Vec3 w{0.0, 10.0, 0.0};
  // Below saturation: M = -kr theta - eta_r omega (eq. 2.10-2.11).
  auto r = evaluate_contact(p, contact(overlap, {}, w), h, dt);
  EXPECT_NEAR(r.rolling_torque.y, -p.rolling_stiffness * 10.0 * dt - p.rolling_damping * 10.0,
              1e-18);
  // Keep rolling until saturation: |M| = mu_r R_ij Fn, damping off (eq. 2.11, 2.13).
  for (int k = 0; k < 100000; ++k) r = evaluate_contact(p, contact(overlap, {}, w), h, dt);
  EXPECT_NEAR(r.rolling_torque.y, -p.rolling_friction * 1e-3 * fn, 1e-15);
  // Stop rotating: the spring keeps its torque (memory), no jump.
  const auto held = evaluate_contact(p, contact(overlap, {}, {}), h, dt);
  EXPECT_NEAR(held.rolling_torque.y, r.rolling_torque.y, 1e-15);
}

TEST(ContactLaw, NewContactStartsWithoutMemory) {
  const ContactParameters p = parameters();
  ContactHistory h;                             // zero normal: no previous contact
  h.tangential_displacement = {1.0, 1.0, 0.0};  // stale values must be ignored
  const auto r = evaluate_contact(p, contact(1e-6, {}), h, 1e-6);
  EXPECT_EQ(r.force.x, 0.0);
  EXPECT_EQ(r.force.y, 0.0);
  EXPECT_EQ(h.normal.z, 1.0);
}

}  // namespace
}  // namespace sanguis::dem
