// Exact geometry of axisymmetric profiles (biconcave_profile.hpp), checked on
// shapes with known curvatures: P = 2 gives the sphere of radius R (kappa =
// 1/R, kappa_g = 1/R^2, Delta_s kappa = 0), P = 1 the oblate spheroid with
// semi-axes R, R/2 (at the pole both curvatures c/a^2; on the equator
// a/c^2 and 1/a). Tolerance 1e-7 relative (the nested finite differences).
#include "membrane/biconcave_profile.hpp"

#include <gtest/gtest.h>

#include <numbers>

using namespace sanguis;
using namespace sanguis::membrane;

TEST(BiconcaveProfile, SphereLimit) {
  const BiconcaveShape sphere{2.0, 2.0, 0.0, 0.0};
  for (const double phi : {-1.2, 0.0, 0.3, 1.0, 1.5, 0.5 * std::numbers::pi}) {
    const auto c = biconcave_curvatures(sphere, phi);
    EXPECT_NEAR(c.mean, 0.5, 1e-7);
    EXPECT_NEAR(c.gaussian, 0.25, 1e-7);
    EXPECT_NEAR(c.laplace_beltrami, 0.0, 1e-6);
  }
}

TEST(BiconcaveProfile, OblateSpheroidCurvatures) {
  const double a = 1.0, c = 0.5;
  const BiconcaveShape spheroid{a, 1.0, 0.0, 0.0};  // z = (R/2) sin(phi)
  const auto pole = biconcave_curvatures(spheroid, 0.5 * std::numbers::pi);
  EXPECT_NEAR(pole.mean, c / (a * a), 1e-5);  // evaluated 1e-3 off the axis
  const auto equator = biconcave_curvatures(spheroid, 0.0);
  EXPECT_NEAR(equator.mean, 0.5 * (a / (c * c) + 1.0 / a), 1e-7);
  EXPECT_NEAR(equator.gaussian, a / (c * c) / a, 1e-7);
}

TEST(BiconcaveProfile, LatitudeInvertsTheMapAndPolarAngleFoldsHalves) {
  const BiconcaveShape rbc{3.91, 0.207, 2.003, -1.123};
  for (const double phi : {-1.4, -0.5, 0.0, 0.01, 0.7, 1.5}) {
    const double r = rbc.radius * std::cos(phi), y = std::cos(phi) * std::cos(phi);
    const Vec3 x{r * 0.6, r * 0.8,
                 0.5 * rbc.radius * std::sin(phi) * (0.207 + 2.003 * y - 1.123 * y * y)};
    EXPECT_NEAR(biconcave_latitude(rbc, x), phi, 1e-12);
  }
  EXPECT_NEAR(polar_angle({0, 0, -1}), 0.0, 1e-15);
  EXPECT_NEAR(polar_angle({1, 0, 0}), 0.5 * std::numbers::pi, 1e-15);
  EXPECT_NEAR(polar_angle({1, 0, -1}), 0.25 * std::numbers::pi, 1e-15);
}
