// analysis/top_view: the top-view raster, run-out distance and pile height of
// thesis §3.2.3 (Fig. 3.2), and the repose angle of a heap.
#include "dem/analysis/top_view.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace sanguis::dem::analysis {
namespace {

TEST(TopViewRaster, SphereCoversItsDiskAndKnowsItsTop) {
  TopViewRaster raster(-1.0, 1.0, -1.0, 1.0, 0.005);
  raster.add_sphere({0.1, -0.2, 0.3}, 0.5);
  double covered = 0.0, highest = -1.0;
  for (std::size_t j = 0; j < raster.ny(); ++j) {
    for (std::size_t i = 0; i < raster.nx(); ++i) {
      if (raster.covered(i, j)) covered += 1.0;
      highest = std::max(highest, raster.top(i, j));
    }
  }
  const double area = covered * raster.pixel() * raster.pixel();
  EXPECT_NEAR(area, std::numbers::pi * 0.25, 0.01 * std::numbers::pi * 0.25);
  EXPECT_NEAR(highest, 0.8, 1e-4);
}

TEST(TopViewRaster, TriangleCoverageAndInterpolatedHeight) {
  TopViewRaster raster(0.0, 1.0, 0.0, 1.0, 0.01);
  raster.add_triangle({0, 0, 0}, {1, 0, 1}, {0, 1, 0});  // z = x over the lower-left half
  double covered = 0.0;
  for (std::size_t j = 0; j < raster.ny(); ++j) {
    for (std::size_t i = 0; i < raster.nx(); ++i) {
      if (!raster.covered(i, j)) continue;
      covered += 1.0;
      EXPECT_NEAR(raster.top(i, j), (static_cast<double>(i) + 0.5) * 0.01, 1e-12);
    }
  }
  EXPECT_NEAR(covered * 1e-4, 0.5, 0.01);
}

// A uniform slab of touching spheres from the wall to x = 0.2: every column up to
// the slab's end is fully covered, so L = 0.2 whatever the threshold; H is the top.
TEST(TopViewRaster, RunoutAndHeightOfASlab) {
  const double r = 0.005;
  TopViewRaster raster(0.0, 0.5, 0.0, 0.04, r / 4);
  for (double x = r; x < 0.2; x += r) {
    for (double y = r; y < 0.04; y += r) raster.add_sphere({x, y, 0.05}, r);
  }
  const RunoutMeasure l = measure_runout(raster);
  EXPECT_NEAR(l.length, 0.2, 2 * raster.pixel());
  EXPECT_LE(l.length_lower, l.length);
  EXPECT_GE(l.length_upper, l.length);
  // Each pixel row sees the top of the spheres whose centres are nearest in y; the
  // nearest pixel centre in x is half a pixel off a sphere centre (r = 4 pixels).
  const double dx = 0.5 * raster.pixel();
  double expected = 0.0;
  for (std::size_t j = 0; j < raster.ny(); ++j) {
    const double y = (static_cast<double>(j) + 0.5) * raster.pixel();
    double dy = 1.0;
    for (double yc = r; yc < 0.04; yc += r) dy = std::min(dy, std::abs(y - yc));
    expected += 0.05 + std::sqrt(r * r - dy * dy - dx * dx);
  }
  expected /= static_cast<double>(raster.ny());
  const HeightMeasure h = measure_height(raster, 0.0);
  EXPECT_NEAR(h.mean, expected, 1e-9);
  EXPECT_LT(h.third_quartile, 0.055 + 1e-12);
  EXPECT_LE(h.first_quartile, h.third_quartile);
}

// A front of decreasing density: L moves with the threshold as in Fig. 3.2a.
TEST(TopViewRaster, ThresholdsBracketTheRunout) {
  TopViewRaster raster(0.0, 1.0, 0.0, 1.0, 0.01);
  // Column i covered over a fraction 1 - i/100 of the width.
  for (std::size_t i = 0; i < 100; ++i) {
    const double x = (static_cast<double>(i) + 0.5) * 0.01;
    const double covered_width = 1.0 - static_cast<double>(i) / 100.0;
    raster.add_triangle({x - 0.004, 0, 0}, {x + 0.004, 0, 0}, {x, covered_width - 0.005, 0});
    raster.add_triangle({x - 0.004, 0, 0}, {x, covered_width - 0.005, 0},
                        {x - 0.004, covered_width - 0.005, 0});
    raster.add_triangle({x + 0.004, 0, 0}, {x + 0.004, covered_width - 0.005, 0},
                        {x, covered_width - 0.005, 0});
  }
  EXPECT_NEAR(runout_distance(raster, 0.2), 0.80, 0.015);
  EXPECT_NEAR(runout_distance(raster, 0.1), 0.90, 0.015);
  EXPECT_NEAR(runout_distance(raster, 0.01), 0.99, 0.015);
}

TEST(TopViewRaster, ReposeAngleOfAConeOfSpheres) {
  // A cone of slope 30 degrees built of small spheres on a floor.
  const double slope = std::tan(30.0 * std::numbers::pi / 180.0);
  const double r = 0.001, base = 0.05;
  TopViewRaster raster(-0.06, 0.06, -0.06, 0.06, r / 2);
  for (double x = -base; x <= base; x += r) {
    for (double y = -base; y <= base; y += r) {
      const double rho = std::hypot(x, y);
      if (rho > base) continue;
      raster.add_sphere({x, y, (base - rho) * slope}, r);
    }
  }
  const ReposeMeasure m = measure_repose_angle(raster, 0.0);
  EXPECT_NEAR(m.angle_deg, 30.0, 1.0);
  EXPECT_GT(m.fitted_rings, 10u);
  EXPECT_NEAR(m.cone_angle_deg, 30.0, 1.0);
  EXPECT_GT(m.cone_pixels, 1000u);
  EXPECT_GT(m.cone_r_squared, 0.9);
}

// A heap of spheres h = h0 - sqrt((s1 x)^2 + (s2 y)^2) on a floor: slope s1 along x,
// s2 along y. Optionally one loose sphere resting on the slope 3 mm off the apex, its
// top the highest point of the heap (the apex the envelope takes).
TopViewRaster elliptic_heap(double s1, double s2, bool loose_sphere) {
  const double r = 0.001, h0 = 0.02;
  TopViewRaster raster(-0.08, 0.08, -0.08, 0.08, r / 2);
  for (double x = -0.075; x <= 0.075; x += r) {
    for (double y = -0.075; y <= 0.075; y += r) {
      const double h = h0 - std::hypot(s1 * x, s2 * y);
      if (h > 0) raster.add_sphere({x, y, h}, r);
    }
  }
  if (loose_sphere) raster.add_sphere({0.003, 0.0, h0 - 0.003 * s1 + 2 * r}, r);
  return raster;
}

double degrees(double slope) {
  return std::atan(slope) * 180.0 / std::numbers::pi;
}

TEST(TopViewRaster, ReposeAngleIgnoresALooseSphereNearTheApex) {
  const ReposeMeasure m = measure_repose_angle(elliptic_heap(0.6, 0.6, true), 0.0);
  EXPECT_NEAR(m.angle_deg, degrees(0.6), 1.0);
  EXPECT_NEAR(m.cone_angle_deg, degrees(0.6), 1.0);
}

// On a heap that is not a cone the envelope reads the shallowest profile (the
// highest at each radius), the cone fit a slope between the shallowest and the
// steepest.
TEST(TopViewRaster, ReposeReadingsOfAnEllipticHeap) {
  const double s1 = 0.5, s2 = 0.9;
  const ReposeMeasure m = measure_repose_angle(elliptic_heap(s1, s2, false), 0.0);
  EXPECT_NEAR(m.angle_deg, degrees(s1), 1.0);
  EXPECT_GT(m.cone_angle_deg, degrees(s1) + 3.0);
  EXPECT_LT(m.cone_angle_deg, degrees(s2) - 3.0);
}

// A layer of spheres spread flat, 0.2 mm higher in the middle than at the rim: no
// heap, and neither reading makes one of it (the spheres' own caps swamp the dome,
// so the cone fit's radius hardly depends on the height: fitted anyway, its slope
// would tend to zero and its angle to 90°).
TEST(TopViewRaster, ReposeReadingsOfAFlatLayer) {
  const double r = 0.001;
  TopViewRaster raster(-0.05, 0.05, -0.05, 0.05, r / 8);  // fine: caps of every height
  for (double x = -0.04; x <= 0.04; x += 2 * r) {
    for (double y = -0.04; y <= 0.04; y += 2 * r) {
      const double rho = std::hypot(x, y);
      if (rho < 0.04) raster.add_sphere({x, y, r + 2e-4 * (1.0 - rho / 0.04)}, r);
    }
  }
  const ReposeMeasure m = measure_repose_angle(raster, 0.0);
  EXPECT_LT(m.angle_deg, 2.0);
  EXPECT_LT(m.cone_r_squared, 0.1);
  EXPECT_EQ(m.cone_angle_deg, 0.0);
}

TEST(Quantile, InterpolatesOrderStatistics) {
  EXPECT_DOUBLE_EQ(quantile({4, 1, 3, 2, 5}, 0.25), 2.0);
  EXPECT_DOUBLE_EQ(quantile({1, 2}, 0.5), 1.5);
  EXPECT_DOUBLE_EQ(quantile({}, 0.5), 0.0);
}

}  // namespace
}  // namespace sanguis::dem::analysis
