// Contact patches of flat-faced cores (contact_patch.hpp): the facing faces, the part of
// them within the crusts' reach, and the corners' overlaps and perimeter shares.
#include "geometry/contact_patch.hpp"

#include <gtest/gtest.h>

#include "geometry/convex_hull.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
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

// A patch of the given corners (in the plane z = 0.3 mm) and overlaps.
ContactPatch patch_of(std::initializer_list<std::array<double, 3>> corners) {
  ContactPatch p;
  for (const auto& [x, y, overlap] : corners) {
    p.point[p.count] = {x, y, 3e-4};
    p.overlap[p.count] = overlap;
    p.perimeter_share[p.count] = 1.0;
    ++p.count;
  }
  return p;
}

// <r^2> and <|r|> of the overlap over the rectangle [0, a] x [0, b] (overlap
// d0 + dx x + dy y) about (cx, cy), by the midpoint rule on a fine grid.
std::array<double, 2> fine_arms(double a, double b, double d0, double dx, double dy, double cx,
                                double cy) {
  const int n = 1000;
  double weight = 0.0, arm = 0.0, arm2 = 0.0;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const double x = (i + 0.5) * a / n, y = (j + 0.5) * b / n;
      const double w = d0 + dx * x + dy * y, r2 = (x - cx) * (x - cx) + (y - cy) * (y - cy);
      weight += w;
      arm += w * std::sqrt(r2);
      arm2 += w * r2;
    }
  }
  return {arm2 / weight, arm / weight};
}

TEST(ContactPatch, PressureArmsAreTheMomentsOfTheOverlapOverThePatch) {
  const Vec3 z{0.0, 0.0, 1.0};
  // An evenly pressed square of side s about its centre: <r^2> = s^2/6 (exact),
  // <|r|> = s (sqrt(2) + asinh(1))/6 = 0.3826 s.
  const double s = 2e-3;
  PatchArms arms = pressure_arms(patch_of({{0, 0, 1e-6}, {s, 0, 1e-6}, {s, s, 1e-6}, {0, s, 1e-6}}),
                                 {s / 2, s / 2, 3e-4}, z);
  EXPECT_NEAR(arms.second_moment, s * s / 6, 1e-12 * s * s);
  EXPECT_NEAR(arms.mean_arm, s * (std::sqrt(2.0) + std::asinh(1.0)) / 6, 0.002 * s);
  // The same about a corner, the normal pointing the other way (corners clockwise).
  arms = pressure_arms(patch_of({{0, 0, 1e-6}, {s, 0, 1e-6}, {s, s, 1e-6}, {0, s, 1e-6}}),
                       {0, 0, 3e-4}, -1.0 * z);
  EXPECT_NEAR(arms.second_moment, 2 * s * s / 3, 1e-12 * s * s);
  // A cross's arm face (27 x 2 mm) with the overlap tilted across and along it, about a
  // point off its centre.
  const double a = 27e-3, b = 2e-3, dx = 3e-5, dy = 4e-4;
  arms = pressure_arms(patch_of({{0, 0, 1e-6},
                                 {a, 0, 1e-6 + dx * a},
                                 {a, b, 1e-6 + dx * a + dy * b},
                                 {0, b, 1e-6 + dy * b}}),
                       {0.6 * a, 0.3 * b, 3e-4}, z);
  const auto fine = fine_arms(a, b, 1e-6, dx, dy, 0.6 * a, 0.3 * b);
  EXPECT_NEAR(arms.second_moment, fine[0], 1e-5 * fine[0]);
  EXPECT_NEAR(arms.mean_arm, fine[1], 0.01 * fine[1]);
  // An edge on a face: a sliver whose far side has no overlap tends to the line,
  // <r^2> = L^2/12 and <|r|> = L/4 about its middle for an even overlap along it.
  arms = pressure_arms(patch_of({{0, 0, 1e-6}, {a, 0, 1e-6}, {a, 1e-8, 0}, {0, 1e-8, 0}}),
                       {a / 2, 1e-8 / 3, 3e-4}, z);
  EXPECT_NEAR(arms.second_moment, a * a / 12, 1e-6 * a * a);
  EXPECT_NEAR(arms.mean_arm, a / 4, 0.0025 * a);
  // Corners on a line (no area): the same along the edges.
  arms = pressure_arms(patch_of({{0, 0, 1e-6}, {a, 0, 1e-6}}), {a / 2, 0, 3e-4}, z);
  EXPECT_NEAR(arms.second_moment, a * a / 12, 1e-9 * a * a);
  EXPECT_NEAR(arms.mean_arm, a / 4, 1e-9 * a);
  // Overlap at one end only, about the centre of pressure (a third of the way): L^2/18.
  arms = pressure_arms(patch_of({{0, 0, 1e-6}, {a, 0, 0}}), {a / 3, 0, 3e-4}, z);
  EXPECT_NEAR(arms.second_moment, a * a / 18, 1e-9 * a * a);
  // Nothing pressed, or a single corner: no arms.
  arms = pressure_arms(patch_of({{0, 0, 0}, {s, 0, 0}, {s, s, 0}}), {}, z);
  EXPECT_EQ(arms.second_moment, 0.0);
  EXPECT_EQ(pressure_arms(patch_of({{0, 0, 1e-6}}), {0, 0, 3e-4}, z).mean_arm, 0.0);
}

}  // namespace
}  // namespace sanguis::geometry
