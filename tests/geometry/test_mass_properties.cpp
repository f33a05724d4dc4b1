// Mass properties: closed forms of the primitives (1e-14) checked against
// fine inscribed polyhedra (relative 2e-3 at resolution 256, converging as
// resolution^-2), a polyhedral cube against Box (1e-13), the union of the
// thesis cross (312 mm^3, inertia from inclusion-exclusion of the three boxes'
// closed forms, 1e-12 relative), a three-box jack (triple intersection),
// overlapping spheres against the lens formula within the stated error bound,
// and principal axes of rotated boxes recovered (1e-12).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <stdexcept>

#include "geometry/convex_hull.hpp"
#include "geometry/mass_properties.hpp"
#include "geometry_test_util.hpp"

namespace sanguis::geometry {
namespace {

void expect_mat_near(const Mat3& a, const Mat3& b, double tol) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(a(i, j), b(i, j), tol) << "(" << i << "," << j << ")";
}

TEST(MassProperties, ClosedFormsOfThePrimitives) {
  MassProperties m = mass_properties(Sphere{2.0});
  EXPECT_NEAR(m.volume, 32.0 * std::numbers::pi / 3.0, 1e-13);
  EXPECT_NEAR(m.inertia_about_centroid(0, 0), 0.4 * m.volume * 4.0, 1e-12);

  m = mass_properties(Box{{1, 2, 3}});  // 2 x 4 x 6
  EXPECT_DOUBLE_EQ(m.volume, 48.0);
  expect_mat_near(m.inertia_about_centroid,
                  Mat3::diagonal({48.0 * 13 / 3, 48.0 * 10 / 3, 48.0 * 5 / 3}), 1e-12);

  m = mass_properties(Cylinder{1.0, 2.0});  // height 4
  EXPECT_NEAR(m.volume, 4.0 * std::numbers::pi, 1e-14);
  EXPECT_NEAR(m.inertia_about_centroid(2, 2), 2.0 * std::numbers::pi, 1e-14);
  EXPECT_NEAR(m.inertia_about_centroid(0, 0), 4.0 * std::numbers::pi * (0.25 + 16.0 / 12.0), 1e-13);

  m = mass_properties(Cone{1.0, 4.0});
  EXPECT_NEAR(m.volume, 4.0 * std::numbers::pi / 3.0, 1e-14);
  EXPECT_EQ(m.centroid, (Vec3{0, 0, 0}));
  EXPECT_NEAR(m.inertia_about_centroid(2, 2), 0.3 * m.volume, 1e-14);
  EXPECT_NEAR(m.inertia_about_centroid(1, 1), m.volume * (3.0 / 20.0 + 3.0 / 80.0 * 16.0), 1e-13);

  m = mass_properties(Ellipsoid{{1, 2, 3}});
  EXPECT_NEAR(m.volume, 8.0 * std::numbers::pi, 1e-13);
  EXPECT_NEAR(m.inertia_about_centroid(0, 0), 0.2 * m.volume * 13.0, 1e-12);
  EXPECT_THROW(mass_properties(Triangle{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}), std::invalid_argument);
}

// Independent check of the closed forms (and of the cone's centroid
// convention): polyhedra inscribed in the shapes converge to them.
TEST(MassProperties, ClosedFormsAgreeWithFineInscribedPolyhedra) {
  for (const ConvexShape& shape :
       {ConvexShape{Sphere{0.7}}, ConvexShape{Cylinder{0.6, 1.1}}, ConvexShape{Cone{0.8, 1.6}},
        ConvexShape{Ellipsoid{{0.4, 1.2, 0.9}}}}) {
    const MassProperties exact = mass_properties(shape);
    const MassProperties fine = mass_properties(convex_hull(tessellate(shape, 256).vertices));
    const double size = std::cbrt(exact.volume);
    EXPECT_NEAR(fine.volume / exact.volume, 1.0, 2e-3) << "shape " << shape.index();
    EXPECT_NEAR(norm(fine.centroid - exact.centroid) / size, 0.0, 1e-3)
        << "shape " << shape.index();
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(fine.inertia_about_centroid(i, i) / exact.inertia_about_centroid(i, i), 1.0, 3e-3)
          << "shape " << shape.index() << " axis " << i;
  }
}

TEST(MassProperties, PolyhedralCubeEqualsTheBox) {
  std::vector<Vec3> corners;
  for (int i = 0; i < 8; ++i)
    corners.push_back({i & 1 ? 1.0 : -1.0, i & 2 ? 2.0 : -2.0, i & 4 ? 3.0 : -3.0});
  const MassProperties poly = mass_properties(make_convex_polyhedron(corners));
  const MassProperties box = mass_properties(Box{{1, 2, 3}});
  EXPECT_NEAR(poly.volume, box.volume, 1e-13);
  EXPECT_NEAR(norm(poly.centroid), 0.0, 1e-14);
  expect_mat_near(poly.inertia_about_centroid, box.inertia_about_centroid, 1e-12);
}

// Inertia about the origin of an axis-aligned box of full sizes (a, b, c).
Mat3 box_inertia(double a, double b, double c) {
  const double v = a * b * c;
  return Mat3::diagonal(
      {v * (b * b + c * c) / 12, v * (a * a + c * c) / 12, v * (a * a + b * b) / 12});
}

TEST(MassProperties, ThesisCrossUnion) {
  // 27 x 2 x 3 mm: 2 * 27 * 2 * 3 - 2 * 2 * 3 = 312 mm^3 = 0.312 cm^3.
  const MassProperties cross = composite_mass_properties(cross_particle(27.0, 2.0, 3.0));
  EXPECT_NEAR(cross.volume, 312.0, 1e-10);
  EXPECT_NEAR(norm(cross.centroid), 0.0, 1e-12);
  const Mat3 expected =
      box_inertia(27, 2, 3) + box_inertia(2, 27, 3) - box_inertia(2, 2, 3);  // overlap once
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(cross.inertia_about_centroid(i, j), expected(i, j), 1e-12 * expected(2, 2));
  EXPECT_EQ(composite_volume_error_bound(cross_particle(27.0, 2.0, 3.0)), 0.0);
  const MassProperties in_cm = composite_mass_properties(cross_particle(2.7, 0.2, 0.3));
  EXPECT_NEAR(in_cm.volume, 0.312, 1e-14);
}

TEST(MassProperties, ThreeBoxJackCountsTheTripleOverlapOnce) {
  // Bars of L x w x w along x, y and z: V = 3 L w^2 - 3 w^3 + w^3.
  const double l = 5.0, w = 1.0;
  const Composite jack = {{Box{{l / 2, w / 2, w / 2}}, {}, {}},
                          {Box{{w / 2, l / 2, w / 2}}, {}, {}},
                          {Box{{w / 2, w / 2, l / 2}}, {}, {}}};
  const MassProperties m = composite_mass_properties(jack);
  EXPECT_NEAR(m.volume, 3 * l * w * w - 2 * w * w * w, 1e-12);
  // I_xx: bar x + bars y, z - 3 pairwise cubes + the triple cube.
  const Mat3 expected = box_inertia(l, w, w) + box_inertia(w, l, w) + box_inertia(w, w, l) -
                        2.0 * box_inertia(w, w, w);
  expect_mat_near(m.inertia_about_centroid, expected, 1e-11);
}

TEST(MassProperties, OverlappingSpheresWithinTheStatedBound) {
  // Two unit spheres d = 1 apart: union = 2 V - lens, lens = pi (4r + d)(2r - d)^2 / 12.
  const double d = 1.0;
  const Composite pair = {{Sphere{1.0}, {}, {}}, {Sphere{1.0}, {d, 0, 0}, {}}};
  const double exact = 2.0 * 4.0 / 3.0 * std::numbers::pi -
                       std::numbers::pi * (4.0 + d) * std::pow(2.0 - d, 2) / 12.0;
  double previous_bound = exact;
  for (const int resolution : {16, 32, 64}) {
    const MassProperties m = composite_mass_properties(pair, resolution);
    const double bound = composite_volume_error_bound(pair, resolution);
    std::printf(
        "[ mass     ] two overlapping unit spheres, resolution %3d: union volume error "
        "%.2e, stated bound %.2e\n",
        resolution, m.volume - exact, bound);
    EXPECT_LE(std::abs(m.volume - exact), bound) << "resolution " << resolution;
    EXPECT_LT(bound, 0.3 * previous_bound);  // about resolution^-2
    previous_bound = bound;
    EXPECT_GE(m.volume, exact);                 // inscribed lens: too small, union too large
    EXPECT_NEAR(m.centroid.x, 0.5 * d, 1e-12);  // symmetric either way
  }
  EXPECT_LT(composite_volume_error_bound(pair, 64) / exact, 0.01);
}

TEST(MassProperties, PrincipalAxesOfARotatedBoxAreRecovered) {
  std::mt19937_64 rng(13);
  for (int trial = 0; trial < 50; ++trial) {
    const Quaternion q = testing::random_rotation(rng);
    const Vec3 p{testing::uniform(rng, -2, 2), testing::uniform(rng, -2, 2), 1.0};
    const MassProperties m = composite_mass_properties({{Box{{1, 2, 3}}, p, q}});
    EXPECT_NEAR(norm(m.centroid - p), 0.0, 1e-12);
    // Moments 48/3 (1 + 4), 48/3 (1 + 9), 48/3 (4 + 9): ascending axes z, y, x.
    EXPECT_NEAR(m.principal_moments.x, 80.0, 1e-11);
    EXPECT_NEAR(m.principal_moments.y, 160.0, 1e-11);
    EXPECT_NEAR(m.principal_moments.z, 208.0, 1e-11);
    const Vec3 body_axis[3] = {{0, 0, 1}, {0, 1, 0}, {1, 0, 0}};
    const Vec3 unit[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(std::abs(dot(rotate(m.principal_axes, unit[k]), rotate(q, body_axis[k]))), 1.0,
                  1e-12);
    // R diag(moments) R^T gives the inertia back.
    const Mat3 r = rotation_matrix(m.principal_axes);
    expect_mat_near(r * Mat3::diagonal(m.principal_moments) * r.transposed(),
                    m.inertia_about_centroid, 1e-11);
  }
}

TEST(MassProperties, CompositeErrors) {
  EXPECT_THROW(composite_mass_properties({}), std::invalid_argument);
  EXPECT_THROW(composite_mass_properties({{Triangle{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {}, {}}}),
               std::invalid_argument);
  EXPECT_THROW(composite_mass_properties({{Sphere{1.0}, {}, {}}}, 2), std::invalid_argument);
  EXPECT_THROW(cross_particle(27.0, 0.0, 3.0), std::invalid_argument);
}

}  // namespace
}  // namespace sanguis::geometry
