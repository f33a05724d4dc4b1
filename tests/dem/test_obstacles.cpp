// Analytic sphere-obstacle gaps (planes and axis-aligned boxes).
#include <gtest/gtest.h>

#include <cmath>

#include "dem/obstacles.hpp"

namespace sanguis::dem {
namespace {

TEST(Obstacles, PlaneGapAndNormal) {
  const PlaneShape plane{{0.0, 0.0, 1.0}, {0.0, 0.0, 1.0}};
  const auto g = sphere_gap(plane, {3.0, -2.0, 1.5}, 0.6);
  EXPECT_NEAR(g.overlap, 0.1, 1e-15);
  EXPECT_EQ(g.normal.z, -1.0);  // from the sphere towards the plane
}

TEST(Obstacles, BoxGapOnFaceEdgeAndCorner) {
  const AxisAlignedBoxShape box{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}};
  auto g = sphere_gap(box, {0.5, 0.5, 1.2}, 0.3);  // above the top face
  EXPECT_NEAR(g.overlap, 0.1, 1e-15);
  EXPECT_NEAR(g.normal.z, -1.0, 1e-15);
  g = sphere_gap(box, {1.1, 0.5, 1.1}, 0.2);  // next to an edge
  EXPECT_NEAR(g.overlap, 0.2 - std::sqrt(0.02), 1e-15);
  EXPECT_NEAR(g.normal.x, -std::sqrt(0.5), 1e-15);
  g = sphere_gap(box, {-0.1, -0.1, -0.1}, 0.1);  // off a corner, not touching
  EXPECT_NEAR(g.overlap, 0.1 - std::sqrt(0.03), 1e-15);
  EXPECT_LT(g.overlap, 0.0);
}

TEST(Obstacles, CentreInsideABoxIsPushedOutThroughTheNearestFace) {
  const AxisAlignedBoxShape box{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}};
  const auto g = sphere_gap(box, {0.9, 0.5, 0.5}, 0.2);
  EXPECT_NEAR(g.overlap, 0.3, 1e-15);
  EXPECT_EQ(g.normal.x, -1.0);  // the box lies on the -x side: the force pushes +x
}

TEST(Obstacles, RemovalTime) {
  Obstacle gate;
  gate.remove_at = 0.25;
  EXPECT_TRUE(gate.active(0.2499));
  EXPECT_FALSE(gate.active(0.25));
}

}  // namespace
}  // namespace sanguis::dem
