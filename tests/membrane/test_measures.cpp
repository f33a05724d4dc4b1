// Global measures: area and volume of the sphere converge to 4 pi R^2 and
// 4/3 pi R^3 at second order; the inertia ellipsoid of a triangulated
// ellipsoid recovers its semi-axes (0.5 % at 5120 triangles) and axes;
// Taylor deformation both ways; largest-tension statistics.
#include "membrane/measures.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

using namespace sanguis;
using namespace sanguis::membrane;

TEST(MembraneMeasures, SphereAreaAndVolumeConverge) {
  constexpr double kPi = std::numbers::pi;
  double previous_area_error = 1.0, previous_volume_error = 1.0;
  for (int k = 2; k <= 5; ++k) {
    TriangleMesh m = icosphere(k);
    map_to_sphere(m, {2.0});
    const double area_error = std::fabs(surface_area(m.triangles, m.positions) / (16 * kPi) - 1);
    const double volume_error =
        std::fabs(enclosed_volume(m.triangles, m.positions) / (32.0 / 3.0 * kPi) - 1);
    EXPECT_GT(std::log2(previous_area_error / area_error), k == 2 ? -10.0 : 1.9);
    EXPECT_GT(std::log2(previous_volume_error / volume_error), k == 2 ? -10.0 : 1.9);
    previous_area_error = area_error;
    previous_volume_error = volume_error;
  }
  EXPECT_LT(previous_area_error, 1e-3);
}

TEST(MembraneMeasures, InertiaEllipsoidAndTaylorDeformation) {
  TriangleMesh m = icosphere(4);
  map_to_ellipsoid(m, {{1.0, 1.0, 2.0}});
  const Quaternion q = normalized(Quaternion::from_axis_angle({1, 0, 0}, 0.5 * std::numbers::pi));
  place(m.positions, q, {3, 4, 5});  // long axis now along -y
  const InertiaEllipsoid e = inertia_ellipsoid(m.triangles, m.positions);
  EXPECT_NEAR(e.centroid.x, 3.0, 1e-12);
  EXPECT_NEAR(e.centroid.y, 4.0, 1e-12);
  EXPECT_NEAR(e.centroid.z, 5.0, 1e-12);
  EXPECT_NEAR(e.semi_axes[0], 1.0, 5e-3);
  EXPECT_NEAR(e.semi_axes[2], 2.0, 1e-2);
  EXPECT_NEAR(std::fabs(e.axes[2].y), 1.0, 1e-9);
  EXPECT_NEAR(taylor_deformation(e), 1.0 / 3.0, 3e-3);
  // Nodes on the poles (r = 2) and on the equator (r = 1): D = 1/3 exactly.
  EXPECT_NEAR(taylor_deformation_from_radii(m.positions, {3, 4, 5}), 1.0 / 3.0, 1e-14);
  std::reverse(m.triangles.begin(), m.triangles.end());
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  EXPECT_THROW(inertia_ellipsoid(m.triangles, m.positions), std::invalid_argument);
}

TEST(MembraneMeasures, LargestTensionStatistics) {
  TriangleMesh m = icosphere(3);
  const auto reference = make_reference(m);
  const ElasticLaw law = NeoHookeanLaw{1.0, NeoHookeanConvention::kChapter4};
  auto x = m.positions;
  EXPECT_NEAR(largest_tension_statistics(law, reference, m.triangles, x).max_largest, 0.0, 1e-13);
  // Isotropic inflation by s: sigma = Es/3 (1 - 1/s^6) in both directions (eq. 4.5, 4.6).
  const double s = 1.1;
  for (auto& p : x) p = s * p;
  const auto stats = largest_tension_statistics(law, reference, m.triangles, x);
  const double exact = (1.0 - std::pow(s, -6.0)) / 3.0;
  EXPECT_NEAR(stats.max_largest, exact, 1e-12);
  EXPECT_NEAR(stats.mean_largest, exact, 1e-12);
}
