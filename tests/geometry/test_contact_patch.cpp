// Contact patches of flat-faced cores (contact_patch.hpp): the facing faces, the part of
// them within the crusts' reach, and the corners' overlaps and perimeter shares.
#include "geometry/contact_patch.hpp"

#include <gtest/gtest.h>

#include "geometry/convex_hull.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace sanguis::geometry {
namespace {

double patch_largest_overlap(const ContactPatch& p) {
  double most = 0.0;
  for (int k = 0; k < p.count; ++k) most = std::max(most, p.overlap[k]);
  return most;
}

double patch_perimeter(const ContactPatch& p) {
  double sum = 0.0;
  for (int k = 0; k < p.count; ++k) sum += p.perimeter_share[k];
  return sum;
}

TEST(ContactPatch, FacingFaceOfABoxIsTheFaceMostAlongTheDirection) {
  const ConvexShape box = Box{{3.0, 2.0, 1.0}};
  const Pose pose{{10.0, 0.0, 0.0},
                  Quaternion::from_axis_angle({0.0, 0.0, 1.0}, 0.5 * std::numbers::pi)};
  SpaceFace f;
  // Body +x is space +y after the quarter turn about z.
  ASSERT_TRUE(facing_face(box, pose, {0.2, 1.0, 0.1}, f));
  EXPECT_EQ(f.count, 4);
  EXPECT_NEAR(f.normal.y, 1.0, 1e-15);
  EXPECT_NEAR(f.offset, 3.0, 1e-14);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(dot(f.normal, f.corner[k]), f.offset, 1e-14);
  EXPECT_FALSE(facing_face(ConvexShape{Sphere{1.0}}, pose, {0.0, 0.0, 1.0}, f));
}

TEST(ContactPatch, FacingFaceOfAPolyhedronHoldsTheSupportPoint) {
  // A unit cube as a hull: the face most along d among those at the support vertex.
  const ConvexShape cube = make_convex_polyhedron(
      {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}});
  SpaceFace f;
  ASSERT_TRUE(facing_face(cube, {}, {0.1, -0.2, -1.0}, f));
  EXPECT_EQ(f.count, 4);
  EXPECT_NEAR(f.normal.z, -1.0, 1e-14);
}

TEST(ContactPatch, ParallelFacesMeetOnTheIntersectionOfTheirOutlines) {
  // A 2 x 2 face under a 2 x 2 face moved by (1, 0.5): the patch is the 1 x 1.5
  // rectangle where they overlap, every corner with the overlap reach - gap.
  const ConvexShape lower = Box{{1.0, 1.0, 1.0}};
  const ConvexShape upper = Box{{1.0, 1.0, 1.0}};
  const double crust = 0.1, gap = 0.15;
  const Pose pose_lower{};
  const Pose pose_upper{{1.0, 0.5, 2.0 + gap}, {}};
  const Vec3 n{0.0, 0.0, 1.0};
  SpaceFace a, b;
  ASSERT_TRUE(facing_face(lower, pose_lower, n, a));
  ASSERT_TRUE(facing_face(upper, pose_upper, -n, b));
  ContactPatch p;
  ASSERT_TRUE(face_pair_patch(a, b, n, crust, crust, p));
  ASSERT_EQ(p.count, 4);
  Vec3 low{1e9, 1e9, 1e9}, high{-1e9, -1e9, -1e9};
  for (int k = 0; k < p.count; ++k) {
    EXPECT_NEAR(p.overlap[k], 2.0 * crust - gap, 1e-14);
    // Midway between the crust surfaces: z = 1 + crust - overlap / 2.
    EXPECT_NEAR(p.point[k].z, 1.0 + crust - 0.5 * (2.0 * crust - gap), 1e-14);
    low = {std::min(low.x, p.point[k].x), std::min(low.y, p.point[k].y), 0.0};
    high = {std::max(high.x, p.point[k].x), std::max(high.y, p.point[k].y), 0.0};
  }
  EXPECT_NEAR(low.x, 0.0, 1e-14);
  EXPECT_NEAR(high.x, 1.0, 1e-14);
  EXPECT_NEAR(low.y, -0.5, 1e-14);
  EXPECT_NEAR(high.y, 1.0, 1e-14);
  EXPECT_NEAR(patch_perimeter(p), 5.0, 1e-13);
  // Beyond reach: no patch.
  const Pose far{{1.0, 0.5, 2.0 + 2.0 * crust + 1e-9}, {}};
  ASSERT_TRUE(facing_face(upper, far, -n, b));
  EXPECT_FALSE(face_pair_patch(a, b, n, crust, crust, p));
}

TEST(ContactPatch, ATiltedFaceIsCutWhereItsOverlapVanishes) {
  // A 2 x 2 face tilted by a about y over a plane, its lowest edge 0.02 into a crust
  // of 0.05: the part within reach is a strip along that edge whose far corners have
  // zero overlap, and the deepest corners have the exact overlap of the lowest edge.
  const ConvexShape box = Box{{1.0, 1.0, 0.5}};
  const double a = 0.1, crust = 0.05, depth = 0.02;
  const Quaternion q = Quaternion::from_axis_angle({0.0, 1.0, 0.0}, a);
  // Lowest point of the bottom face: body (-1 or 1, y, -0.5) rotated.
  const Vec3 lowest = rotate(q, Vec3{1.0, 0.0, -0.5});
  const Pose pose{{0.0, 0.0, crust - depth - lowest.z}, q};
  SpaceFace f;
  ASSERT_TRUE(facing_face(box, pose, {0.0, 0.0, -1.0}, f));
  ContactPatch p;
  ASSERT_TRUE(face_plane_patch(f, {0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, crust, p));
  ASSERT_EQ(p.count, 4);
  EXPECT_NEAR(patch_largest_overlap(p), depth, 1e-15);
  int cut = 0;
  for (int k = 0; k < p.count; ++k) cut += p.overlap[k] < 1e-15;
  EXPECT_EQ(cut, 2);
  // Measured in the plane normal to n: the strip is depth / tan a wide.
  EXPECT_NEAR(patch_perimeter(p), 2.0 * 2.0 + 2.0 * depth / std::tan(a), 1e-12);
}

TEST(ContactPatch, CrossingEdgesGiveASliverWhoseApexIsTheClosestPoint) {
  // Two boxes turned 45 degrees about two crossing horizontal axes: their ridges cross
  // at right angles, 0.01 apart with crusts 0.05 each. The patch's deepest corner is the
  // crossing point, with overlap 0.1 - 0.01; the other corners have none.
  const ConvexShape box = Box{{1.0, 1.0, 1.0}};
  const double s = std::sqrt(2.0);
  const Pose lower{{0.0, 0.0, 0.0},
                   Quaternion::from_axis_angle({1.0, 0.0, 0.0}, 0.25 * std::numbers::pi)};
  const Pose upper{{0.0, 0.0, 2.0 * s + 0.01},
                   Quaternion::from_axis_angle({0.0, 1.0, 0.0}, 0.25 * std::numbers::pi)};
  const Vec3 n{0.0, 0.0, 1.0};
  SpaceFace a, b;
  ASSERT_TRUE(facing_face(box, lower, n, a));
  ASSERT_TRUE(facing_face(box, upper, -n, b));
  ContactPatch p;
  ASSERT_TRUE(face_pair_patch(a, b, n, 0.05, 0.05, p));
  int deepest = 0;
  for (int k = 1; k < p.count; ++k) {
    if (p.overlap[k] > p.overlap[deepest]) deepest = k;
  }
  EXPECT_NEAR(p.overlap[deepest], 0.09, 1e-13);
  EXPECT_NEAR(p.point[deepest].x, 0.0, 1e-13);
  EXPECT_NEAR(p.point[deepest].y, 0.0, 1e-13);
  EXPECT_NEAR(p.point[deepest].z, s + 0.005, 1e-13);
  for (int k = 0; k < p.count; ++k) {
    if (k != deepest) {
      EXPECT_LT(p.overlap[k], 1e-13);
    }
  }
}

TEST(ContactPatch, PerimeterSharesCarryOnWhenACornerCrossesAnEdge) {
  // The upper face slides in small steps until one of its corners passes over an edge
  // of the lower face: that corner of the patch splits into two. The overlap-weighted
  // perimeter shares must not jump there (the DEM's force comes from them).
  const ConvexShape box = Box{{1.0, 1.0, 1.0}};
  const Quaternion q = Quaternion::from_axis_angle({0.0, 0.0, 1.0}, 0.4) *
                       Quaternion::from_axis_angle({1.0, 0.0, 0.0}, 0.01);
  const Vec3 n{0.0, 0.0, 1.0};
  SpaceFace a, b;
  ASSERT_TRUE(facing_face(box, {}, n, a));
  double previous_sum = -1.0;
  int previous_count = 0, changes = 0;
  for (int step = 0; step <= 400; ++step) {
    const double x = 0.5 + 1.5 * step / 400.0;
    const Vec3 lowest = rotate(q, support(box, rotate_inverse(q, -n)));
    const Pose pose{{x, 0.2, 1.0 + 0.1 - 0.03 - lowest.z}, q};
    ASSERT_TRUE(facing_face(box, pose, -n, b));
    ContactPatch p;
    ASSERT_TRUE(face_pair_patch(a, b, n, 0.05, 0.05, p));
    double sum = 0.0;
    for (int k = 0; k < p.count; ++k) sum += p.overlap[k] * p.perimeter_share[k];
    if (previous_sum >= 0.0) {
      changes += p.count != previous_count;
      EXPECT_LT(std::abs(sum - previous_sum), 0.02 * previous_sum) << "step " << step;
    }
    previous_sum = sum;
    previous_count = p.count;
  }
  EXPECT_GT(changes, 0) << "no corner crossed an edge";
}

}  // namespace
}  // namespace sanguis::geometry
