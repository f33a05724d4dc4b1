// The separating-axis rejection of two boxes (geometry/separating_axes.hpp) against
// GJK: it never rejects a pair within the margin, it rejects most pairs of cross arms
// that only their bounding balls bring together, and the edge-edge axes matter.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "geometry/gjk.hpp"
#include "geometry/separating_axes.hpp"
#include "geometry_test_util.hpp"

namespace sanguis::geometry {
namespace {

using testing::random_rotation;
using testing::random_unit;
using testing::uniform;

TEST(SeparatingAxes, FaceGapAgainstTheMargin) {
  const Box box{{0.5, 0.5, 0.5}};
  const Pose a{{0.0, 0.0, 0.0}, {}};
  const Pose b{{1.3, 0.0, 0.0}, {}};  // faces 0.3 apart
  EXPECT_TRUE(boxes_apart_beyond(box, a, box, b, 0.29));
  EXPECT_FALSE(boxes_apart_beyond(box, a, box, b, 0.31));
}

TEST(SeparatingAxes, OnlyAnEdgeAxisSeparatesTwoCubesEdgeToEdge) {
  // A unit cube turned 45 degrees about x (an edge along x on top) under one turned 45
  // degrees about y (an edge along y below), the edges g apart: no face normal
  // separates them, the axis x cross y does.
  const Box cube{{0.5, 0.5, 0.5}};
  const double g = 0.05;
  const Pose a{{0.0, 0.0, 0.0},
               Quaternion::from_axis_angle({1.0, 0.0, 0.0}, 0.25 * std::numbers::pi)};
  const Pose b{{0.0, 0.0, std::sqrt(2.0) + g},
               Quaternion::from_axis_angle({0.0, 1.0, 0.0}, 0.25 * std::numbers::pi)};
  const DistanceResult d = gjk_distance(ConvexShape{cube}, a, ConvexShape{cube}, b);
  ASSERT_FALSE(d.intersecting);
  EXPECT_NEAR(d.distance, g, 1e-9);
  EXPECT_TRUE(boxes_apart_beyond(cube, a, cube, b, 0.99 * g));
  EXPECT_FALSE(boxes_apart_beyond(cube, a, cube, b, 1.01 * g));
}

TEST(SeparatingAxes, UnequalBoxesInEitherOrder) {
  // A flat plate under a long rod, both tilted: the test must not depend on which box
  // comes first, and must agree with GJK on the margin (the rod's extents enter as b's
  // when it comes second and as a's when it comes first).
  std::mt19937_64 rng(7);
  const Box plate{{0.02, 0.015, 0.001}};
  const Box rod{{0.0135, 0.001, 0.0015}};
  int rejected = 0;
  for (int n = 0; n < 5000; ++n) {
    const Pose a{{0.0, 0.0, 0.0}, random_rotation(rng)};
    const Pose b{uniform(rng, 0.0, 0.06) * random_unit(rng), random_rotation(rng)};
    const double margin = uniform(rng, 0.0, 0.003);  // crusts and a skin
    const bool ab = boxes_apart_beyond(plate, a, rod, b, margin);
    EXPECT_EQ(ab, boxes_apart_beyond(rod, b, plate, a, margin)) << n;
    const DistanceResult d = gjk_distance(ConvexShape{plate}, a, ConvexShape{rod}, b);
    if (d.intersecting || d.distance <= margin) {
      EXPECT_FALSE(ab) << n;
    }
    rejected += ab ? 1 : 0;
  }
  EXPECT_GT(rejected, 1000);
}

TEST(SeparatingAxes, NeverRejectsAPairWithinTheMarginAndRejectsMostFarOnes) {
  // Arms of the crosses of thesis §3.2.2 (27 x 2 x 3 mm boxes, 0.1 mm crusts) at random
  // poses with their bounding balls overlapping, as the element lists hand them over.
  std::mt19937_64 rng(2026);
  const Box arm{{0.0135, 0.001, 0.0015}};
  const double margin = 2e-4;
  const double reach = 2.0 * std::sqrt(0.0135 * 0.0135 + 0.001 * 0.001 + 0.0015 * 0.0015);
  int near = 0, far = 0, far_rejected = 0;
  for (int n = 0; n < 20000; ++n) {
    const Pose a{{0.0, 0.0, 0.0}, random_rotation(rng)};
    const Pose b{uniform(rng, 0.0, reach) * random_unit(rng), random_rotation(rng)};
    const DistanceResult d = gjk_distance(ConvexShape{arm}, a, ConvexShape{arm}, b);
    const bool rejected = boxes_apart_beyond(arm, a, arm, b, margin);
    if (d.intersecting || d.distance <= margin) {
      ++near;
      EXPECT_FALSE(rejected) << "pair " << n << " at distance " << d.distance;
    } else if (d.distance > 2.0 * margin) {
      ++far;
      far_rejected += rejected ? 1 : 0;
    }
  }
  EXPECT_GT(near, 500);
  EXPECT_GT(far, 5000);
  EXPECT_GT(far_rejected, 0.8 * far) << far_rejected << " of " << far;
}

}  // namespace
}  // namespace sanguis::geometry
