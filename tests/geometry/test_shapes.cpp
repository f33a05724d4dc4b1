// Support functions against closed-form support values h(d) = max_x d.x
// (relative 1e-14) and membership of the returned point; graceful zero, tiny
// and huge directions; bounding radii and exact space-frame boxes; the crust
// cores (every supporting plane of a core + crust lies within the shape, and
// at face normals exactly on it, 1e-12); closed outward tessellations whose
// volume converges to the exact one.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <stdexcept>

#include "geometry/convex_hull.hpp"
#include "geometry/mass_properties.hpp"
#include "geometry/polytope.hpp"
#include "geometry/shapes.hpp"
#include "geometry_test_util.hpp"

namespace sanguis::geometry {
namespace {

using testing::random_rotation;
using testing::random_unit;
using testing::uniform;

ConvexPolyhedron octahedron(double r) {
  return make_convex_polyhedron(
      {{r, 0, 0}, {-r, 0, 0}, {0, r, 0}, {0, -r, 0}, {0, 0, r}, {0, 0, -r}});
}

std::vector<ConvexShape> all_shapes() {
  std::mt19937_64 rng(1);
  return {Sphere{0.7},
          Box{{0.5, 1.0, 1.5}},
          Cylinder{0.6, 1.1},
          Cone{0.8, 1.6},
          Ellipsoid{{0.4, 1.2, 0.9}},
          testing::random_polyhedron(rng, 25),
          Triangle{{0, 0, 0}, {1, 0.2, 0}, {0.3, 1, 0.4}}};
}

// Closed-form support value h(d) of each shape.
struct SupportValue {
  Vec3 d;
  double operator()(const Sphere& s) const { return s.radius * norm(d); }
  double operator()(const Box& b) const {
    return b.half_extents.x * std::abs(d.x) + b.half_extents.y * std::abs(d.y) +
           b.half_extents.z * std::abs(d.z);
  }
  double operator()(const Cylinder& c) const {
    return c.radius * std::hypot(d.x, d.y) + c.half_height * std::abs(d.z);
  }
  double operator()(const Cone& c) const {
    const double apex = (c.axial_offset + 0.75 * c.height) * d.z;
    const double rim = c.radius * std::hypot(d.x, d.y) + (c.axial_offset - 0.25 * c.height) * d.z;
    return std::max(apex, rim);
  }
  double operator()(const Ellipsoid& e) const {
    return norm(Vec3{e.semi_axes.x * d.x, e.semi_axes.y * d.y, e.semi_axes.z * d.z});
  }
  double operator()(const ConvexPolyhedron& p) const {
    double h = -1e300;
    for (const Vec3& v : p.vertices()) h = std::max(h, dot(v, d));
    return h;
  }
  double operator()(const Triangle& t) const {
    return std::max({dot(t.a, d), dot(t.b, d), dot(t.c, d)});
  }
};

double support_value(const ConvexShape& s, const Vec3& d) {
  return std::visit(SupportValue{d}, s);
}

// Whether x belongs to the shape (within tol).
struct Contains {
  Vec3 x;
  double tol;
  bool operator()(const Sphere& s) const { return norm(x) <= s.radius + tol; }
  bool operator()(const Box& b) const {
    return std::abs(x.x) <= b.half_extents.x + tol && std::abs(x.y) <= b.half_extents.y + tol &&
           std::abs(x.z) <= b.half_extents.z + tol;
  }
  bool operator()(const Cylinder& c) const {
    return std::hypot(x.x, x.y) <= c.radius + tol && std::abs(x.z) <= c.half_height + tol;
  }
  bool operator()(const Cone& c) const {
    const double base = c.axial_offset - 0.25 * c.height;
    const double up = x.z - base;
    return up >= -tol && up <= c.height + tol &&
           std::hypot(x.x, x.y) <= c.radius * (1.0 - up / c.height) + tol;
  }
  bool operator()(const Ellipsoid& e) const {
    const Vec3& a = e.semi_axes;
    return std::sqrt(x.x * x.x / (a.x * a.x) + x.y * x.y / (a.y * a.y) + x.z * x.z / (a.z * a.z)) <=
           1.0 + tol;
  }
  bool operator()(const ConvexPolyhedron& p) const {
    for (const Plane& plane : p.face_planes())
      if (dot(plane.normal, x) - plane.offset > tol) return false;
    return true;
  }
  bool operator()(const Triangle& t) const {
    return x == t.a || x == t.b || x == t.c;  // supports are corners
  }
};

bool contains(const ConvexShape& s, const Vec3& x, double tol = 1e-12) {
  return std::visit(Contains{x, tol}, s);
}

TEST(Shapes, SupportMatchesClosedFormSupportValues) {
  std::mt19937_64 rng(2);
  for (const ConvexShape& shape : all_shapes())
    for (int i = 0; i < 2000; ++i) {
      const Vec3 d = uniform(rng, 0.1, 10.0) * random_unit(rng);
      const Vec3 s = support(shape, d);
      EXPECT_NEAR(dot(s, d), support_value(shape, d), 1e-14 * norm(d) * bounding_radius(shape))
          << "shape " << shape.index();
      EXPECT_TRUE(contains(shape, s)) << "shape " << shape.index();
    }
}

TEST(Shapes, SupportAlongAxesAndTies) {
  const Box box{{1, 2, 3}};
  EXPECT_EQ(support(box, {1, -1, 1}), (Vec3{1, -2, 3}));
  const Cylinder cyl{1.0, 2.0};
  const Vec3 top = support(cyl, {0, 0, 1});  // the whole top disc ties: a rim point
  EXPECT_EQ(top.z, 2.0);
  EXPECT_NEAR(std::hypot(top.x, top.y), 1.0, 1e-15);
  const Cone cone{1.0, 4.0};  // base at z = -1, apex at z = 3
  EXPECT_EQ(support(cone, {0, 0, 1}), (Vec3{0, 0, 3}));
  EXPECT_EQ(support(cone, {0, 0, -1}).z, -1.0);
  EXPECT_EQ(support(cone, {1, 0, 0}), (Vec3{1, 0, -1}));
}

TEST(Shapes, ZeroTinyAndHugeDirectionsGiveFinitePointsOfTheShape) {
  for (const ConvexShape& shape : all_shapes())
    for (const Vec3& d : {Vec3{0, 0, 0}, Vec3{1e-200, 0, 0}, Vec3{0, -1e-170, 1e-170},
                          Vec3{1e200, 1e200, -1e200}, Vec3{-0.0, 0.0, -0.0}}) {
      const Vec3 s = support(shape, d);
      EXPECT_TRUE(std::isfinite(s.x) && std::isfinite(s.y) && std::isfinite(s.z));
      EXPECT_TRUE(contains(shape, s)) << "shape " << shape.index();
    }
  const Vec3 s = support(Sphere{2.0}, {0, -1e-170, 1e-170});
  EXPECT_NEAR(s.y, -std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(s.z, std::sqrt(2.0), 1e-15);
  const Vec3 e = support(Ellipsoid{{1, 2, 3}}, {1e200, 0, 0});
  EXPECT_EQ(e, (Vec3{1, 0, 0}));
}

TEST(Shapes, BoundingRadiusIsTheFarthestPoint) {
  EXPECT_DOUBLE_EQ(bounding_radius(Box{{1, 2, 2}}), 3.0);
  EXPECT_DOUBLE_EQ(bounding_radius(Cylinder{3, 4}), 5.0);
  EXPECT_DOUBLE_EQ(bounding_radius(Cone{1, 4}), 3.0);  // apex at 3 beats the rim at sqrt(2)
  EXPECT_DOUBLE_EQ(bounding_radius(Ellipsoid{{1, 5, 2}}), 5.0);
  std::mt19937_64 rng(3);
  for (const ConvexShape& shape : all_shapes()) {
    const double r = bounding_radius(shape);
    double farthest = 0.0;
    for (int i = 0; i < 20000; ++i) {
      const double h = norm(support(shape, random_unit(rng)));
      EXPECT_LE(h, r * (1 + 1e-14));
      farthest = std::max(farthest, h);
    }
    EXPECT_GT(farthest, r * (1 - 1e-3)) << "shape " << shape.index();
  }
}

TEST(Shapes, SpaceFrameBoundsAreExact) {
  std::mt19937_64 rng(4);
  for (int i = 0; i < 200; ++i) {
    const Quaternion q = random_rotation(rng);
    const Vec3 p{uniform(rng, -5, 5), uniform(rng, -5, 5), uniform(rng, -5, 5)};
    const Mat3 r = rotation_matrix(q);
    // Box: half extent along k is sum_j |R_kj| h_j.
    const Vec3 h{0.5, 1.0, 1.5};
    const Aabb box = bounds(Box{h}, p, q);
    // Cylinder of axis a = R e_z: hh |a_k| + r sqrt(1 - a_k^2).
    const Aabb cyl = bounds(Cylinder{0.6, 1.1}, p, q);
    // Ellipsoid: sqrt(sum_j (R_kj a_j)^2).
    const Vec3 a{0.4, 1.2, 0.9};
    const Aabb ell = bounds(Ellipsoid{a}, p, q);
    for (int k = 0; k < 3; ++k) {
      const double hb = std::abs(r(k, 0)) * h.x + std::abs(r(k, 1)) * h.y + std::abs(r(k, 2)) * h.z;
      EXPECT_NEAR(box.max[k] - p[k], hb, 1e-14);
      EXPECT_NEAR(p[k] - box.min[k], hb, 1e-14);
      const double hc = 1.1 * std::abs(r(k, 2)) + 0.6 * std::sqrt(1.0 - r(k, 2) * r(k, 2));
      EXPECT_NEAR(cyl.max[k] - p[k], hc, 1e-14);
      EXPECT_NEAR(p[k] - cyl.min[k], hc, 1e-14);
      const double he = std::hypot(r(k, 0) * a.x, r(k, 1) * a.y, r(k, 2) * a.z);
      EXPECT_NEAR(ell.max[k] - p[k], he, 1e-14);
    }
  }
  const Aabb local = local_bounds(Cone{1.0, 4.0});
  EXPECT_EQ(local.min, (Vec3{-1, -1, -1}));
  EXPECT_EQ(local.max, (Vec3{1, 1, 3}));
}

// The rounded core (core + ball of radius c) has support value h_core + c.
// It must lie within the shape (h_core + c <= h) with equality at the
// normals of the shape's flat faces, which keep their place.
void expect_core_inside(const ConvexShape& shape, double crust, double tol,
                        const std::vector<Vec3>& face_normals) {
  const ConvexShape core = shrunk(shape, crust);
  std::mt19937_64 rng(9);
  for (int i = 0; i < 5000; ++i) {
    const Vec3 u = random_unit(rng);
    EXPECT_LE(dot(support(core, u), u) + crust, dot(support(shape, u), u) + tol);
  }
  for (const Vec3& n : face_normals)
    EXPECT_NEAR(dot(support(core, n), n) + crust, dot(support(shape, n), n), tol);
}

TEST(Shapes, CoresOfSimpleShapes) {
  EXPECT_DOUBLE_EQ(std::get<Sphere>(shrunk(Sphere{1.0}, 0.1)).radius, 0.9);
  EXPECT_EQ(std::get<Box>(shrunk(Box{{1, 2, 3}}, 0.5)).half_extents, (Vec3{0.5, 1.5, 2.5}));
  const auto cyl = std::get<Cylinder>(shrunk(Cylinder{1.0, 2.0}, 0.25));
  EXPECT_DOUBLE_EQ(cyl.radius, 0.75);
  EXPECT_DOUBLE_EQ(cyl.half_height, 1.75);
  expect_core_inside(Box{{1, 2, 3}}, 0.3, 1e-14,
                     {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}});
  expect_core_inside(Cylinder{1.0, 2.0}, 0.3, 1e-14, {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}});
}

TEST(Shapes, ConeCoreIsTheInnerParallelBody) {
  const Cone cone{1.0, 3.0};
  const double crust = 0.1;
  const double slant = std::hypot(1.0, 3.0);
  std::vector<Vec3> normals = {{0, 0, -1}};
  for (int i = 0; i < 8; ++i) {  // lateral normals (h cos phi, h sin phi, r) / slant
    const double phi = i * std::numbers::pi / 4;
    normals.push_back({3.0 * std::cos(phi) / slant, 3.0 * std::sin(phi) / slant, 1.0 / slant});
  }
  expect_core_inside(cone, crust, 1e-14, normals);
  const auto core = std::get<Cone>(shrunk(cone, crust));
  EXPECT_NEAR(core.axial_offset - 0.25 * core.height, -0.75 + crust,
              1e-15);                  // base moved up by crust
  EXPECT_NO_THROW(shrunk(cone, 0.7));  // inradius 3/(1 + sqrt 10) = 0.72..
  EXPECT_THROW(shrunk(cone, 0.75), std::invalid_argument);
}

TEST(Shapes, EllipsoidCoreBulgeIsWithinTheStatedBound) {
  const Ellipsoid e{{1.0, 2.0, 0.5}};
  const double crust = 0.1;
  const ConvexShape core = shrunk(e, crust);
  const double k = (2.0 - crust) / (0.5 - crust);
  const double bound = crust * std::pow(std::sqrt(k) - 1.0, 2) / (k + 1.0);
  std::mt19937_64 rng(10);
  double worst = 0.0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3 u = random_unit(rng);
    const double excess = dot(support(core, u), u) + crust - dot(support(e, u), u);
    EXPECT_GE(excess, -1e-15);
    worst = std::max(worst, excess);
  }
  EXPECT_LE(worst, bound);
  EXPECT_GT(worst, 0.5 * bound);  // the bound is not loose
}

TEST(Shapes, PolyhedronCoreMovesEveryFacePlaneByTheCrust) {
  std::mt19937_64 rng(12);
  std::vector<ConvexPolyhedron> polyhedra = {octahedron(1.0),
                                             convex_hull(tessellate(Box{{1, 2, 3}}, 3).vertices)};
  for (int i = 0; i < 10; ++i) polyhedra.push_back(testing::random_polyhedron(rng, 12));
  for (const ConvexPolyhedron& p : polyhedra) {
    const double crust = 0.02;
    std::vector<Vec3> normals;
    for (const Plane& plane : p.face_planes()) normals.push_back(plane.normal);
    expect_core_inside(p, crust, 1e-12, normals);
  }
  // The octahedron's apexes join 4 faces: the core is the octahedron of
  // inradius 1/sqrt(3) - crust, i.e. vertex distance scaled by the same ratio.
  const auto core = std::get<ConvexPolyhedron>(shrunk(octahedron(1.0), 0.1));
  EXPECT_EQ(core.vertices().size(), 6u);
  EXPECT_EQ(core.face_count(), 8u);
  const double scale = 1.0 - 0.1 * std::sqrt(3.0);
  for (const Vec3& v : core.vertices()) EXPECT_NEAR(norm(v), scale, 1e-13);
  EXPECT_THROW(shrunk(octahedron(1.0), 0.6), std::invalid_argument);  // inradius 0.577
}

TEST(Shapes, CrustErrors) {
  EXPECT_THROW(shrunk(Sphere{1.0}, 1.0), std::invalid_argument);
  EXPECT_THROW(shrunk(Box{{1, 0.2, 1}}, 0.2), std::invalid_argument);
  EXPECT_THROW(shrunk(Cylinder{1.0, 0.1}, 0.2), std::invalid_argument);
  EXPECT_THROW(shrunk(Sphere{1.0}, -0.1), std::invalid_argument);
  EXPECT_THROW(shrunk(Triangle{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, 0.1), std::invalid_argument);
  EXPECT_NO_THROW(shrunk(Triangle{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, 0.0));
}

double mesh_volume(const TriangleMesh& mesh) {
  double six_v = 0.0;
  for (const auto& t : mesh.triangles)
    six_v += dot(mesh.vertices[t[0]], cross(mesh.vertices[t[1]], mesh.vertices[t[2]]));
  return six_v / 6.0;
}

TEST(Shapes, TessellationsAreClosedOutwardAndConverge) {
  for (const ConvexShape& shape : all_shapes()) {
    if (std::holds_alternative<Triangle>(shape)) continue;
    const double exact = mass_properties(shape).volume;
    double previous_error = 1.0;
    for (const int n : {16, 64, 256}) {
      const TriangleMesh mesh = tessellate(shape, n);
      std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
      for (const auto& t : mesh.triangles)
        for (int e = 0; e < 3; ++e) ++directed[{t[e], t[(e + 1) % 3]}];
      for (const auto& [edge, count] : directed) {
        ASSERT_EQ(count, 1);
        ASSERT_EQ(directed.count({edge.second, edge.first}), 1u);
      }
      for (const Vec3& v : mesh.vertices) EXPECT_TRUE(contains(shape, v, 1e-12));
      const double error = (exact - mesh_volume(mesh)) / exact;  // inscribed: >= 0
      EXPECT_GE(error, -1e-14);
      EXPECT_LE(error, previous_error + 1e-14);
      previous_error = error;
    }
    EXPECT_LT(previous_error, 3e-4) << "shape " << shape.index();
  }
  EXPECT_THROW(tessellate(Sphere{1.0}, 2), std::invalid_argument);
}

}  // namespace
}  // namespace sanguis::geometry
