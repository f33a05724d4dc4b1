// Quickhull: exact face structure for a cube (coplanar points merged into 6
// quadrilaterals), containment and face-plane checks for random clouds
// (every point behind every face plane within the hull tolerance, 1e-10 of
// the box diagonal), Euler's formula V - E + F = 2, clear errors for
// degenerate input, and the convexity check of meshes.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <set>
#include <stdexcept>
#include <string>

#include "geometry/convex_hull.hpp"
#include "geometry/polytope.hpp"
#include "geometry_test_util.hpp"

namespace sanguis::geometry {
namespace {

using testing::random_unit;
using testing::uniform;

std::vector<Vec3> cube_corners(double h) {
  std::vector<Vec3> c;
  for (int i = 0; i < 8; ++i) c.push_back({i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h});
  return c;
}

// Every input point behind every face plane, every face planar and outward,
// and the surface a closed sphere (V - E + F = 2, each edge in two faces).
void expect_valid_hull(const ConvexPolyhedron& hull, const std::vector<Vec3>& points,
                       double tolerance) {
  const auto& planes = hull.face_planes();
  ASSERT_EQ(planes.size(), hull.face_count());
  for (const Vec3& p : points)
    for (const Plane& plane : planes) ASSERT_LE(dot(plane.normal, p) - plane.offset, tolerance);
  Vec3 mean;
  for (const Vec3& v : hull.vertices()) mean += v;
  mean = mean / static_cast<double>(hull.vertices().size());
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (std::size_t f = 0; f < hull.face_count(); ++f) {
    const auto loop = hull.face(f);
    ASSERT_GE(loop.size(), 3u);
    for (std::size_t k = 0; k < loop.size(); ++k) {
      EXPECT_NEAR(dot(planes[f].normal, hull.vertices()[loop[k]]), planes[f].offset, tolerance);
      ++directed[{loop[k], loop[(k + 1) % loop.size()]}];
    }
    EXPECT_GT(planes[f].offset - dot(planes[f].normal, mean), 0.0);  // outward
  }
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1);
    EXPECT_EQ(directed.count({edge.second, edge.first}), 1u);
  }
  const long v = static_cast<long>(hull.vertices().size());
  const long e = static_cast<long>(directed.size() / 2);
  const long f = static_cast<long>(hull.face_count());
  EXPECT_EQ(v - e + f, 2);
}

TEST(ConvexHull, CubeHasSixQuadFacesAndEightVertices) {
  const ConvexPolyhedron cube = convex_hull(cube_corners(0.5));
  EXPECT_EQ(cube.vertices().size(), 8u);
  ASSERT_EQ(cube.face_count(), 6u);
  for (std::size_t f = 0; f < 6; ++f) {
    EXPECT_EQ(cube.face(f).size(), 4u);
    const Plane& p = cube.face_planes()[f];
    EXPECT_NEAR(std::abs(p.normal.x) + std::abs(p.normal.y) + std::abs(p.normal.z), 1.0, 1e-15);
    EXPECT_NEAR(p.offset, 0.5, 1e-15);
  }
  expect_valid_hull(cube, cube_corners(0.5), 1e-15);
}

TEST(ConvexHull, GridOfCoplanarAndDuplicatePointsStillGivesTheCube) {
  std::vector<Vec3> points;
  for (int i = 0; i <= 4; ++i)
    for (int j = 0; j <= 4; ++j)
      for (int k = 0; k <= 4; ++k) points.push_back({i * 0.25, j * 0.25, k * 0.25});
  for (int i = 0; i < 30; ++i) points.push_back(points[i * 3]);  // duplicates
  const ConvexPolyhedron hull = convex_hull(points);
  EXPECT_EQ(hull.vertices().size(), 8u);
  ASSERT_EQ(hull.face_count(), 6u);
  for (std::size_t f = 0; f < 6; ++f) EXPECT_EQ(hull.face(f).size(), 4u);
  expect_valid_hull(hull, points, 1e-12);
}

TEST(ConvexHull, RandomPointsInABallLieInsideEveryFacePlane) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<Vec3> points;
    const int n = 4 + trial * 20;
    for (int i = 0; i < n; ++i)
      points.push_back(std::cbrt(uniform(rng, 0.0, 1.0)) * random_unit(rng) + Vec3{3.0, -2.0, 1.0});
    const ConvexPolyhedron hull = convex_hull(points);
    expect_valid_hull(hull, points, 1e-10 * 2.0 * std::sqrt(3.0));
    for (const Vec3& v : hull.vertices())  // vertices are input points, unchanged
      EXPECT_TRUE(std::find(points.begin(), points.end(), v) != points.end());
  }
}

TEST(ConvexHull, PointsOnASphereAreAllVertices) {
  std::mt19937_64 rng(11);
  std::vector<Vec3> points;
  for (int i = 0; i < 400; ++i) points.push_back(random_unit(rng));
  const ConvexPolyhedron hull = convex_hull(points);
  EXPECT_EQ(hull.vertices().size(), points.size());
  expect_valid_hull(hull, points, 1e-12);
}

// Many exactly coplanar and cocircular points: cylinders, box surfaces with
// lattice points, and slightly jittered copies (near-degenerate).
TEST(ConvexHull, NearDegenerateCloudsGiveValidHulls) {
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 60; ++trial) {
    std::vector<Vec3> points;
    const double jitter = trial % 3 == 0 ? 0.0 : (trial % 3 == 1 ? 1e-13 : 1e-9);
    for (int i = 0; i < 24; ++i)
      for (int z = 0; z < 3; ++z) {
        const double phi = 2.0 * std::numbers::pi * i / 24;
        points.push_back({std::cos(phi), std::sin(phi), 0.5 * z});
      }
    for (int i = 0; i < 100; ++i) {  // lattice points on the faces of a box
      const int axis = i % 3;
      Vec3 p{std::floor(uniform(rng, 0, 5)) / 4, std::floor(uniform(rng, 0, 5)) / 4,
             std::floor(uniform(rng, 0, 5)) / 4};
      p[axis] = i % 2 ? 1.5 : -0.5;
      points.push_back(p);
    }
    for (Vec3& p : points) p += jitter * random_unit(rng);
    const ConvexPolyhedron hull = convex_hull(points);
    expect_valid_hull(hull, points, 1e-9);
  }
}

TEST(ConvexHull, DegenerateInputThrowsClearErrors) {
  const auto message = [](const std::vector<Vec3>& points) {
    try {
      convex_hull(points);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  std::vector<Vec3> flat;
  for (int i = 0; i < 20; ++i) flat.push_back({std::cos(i * 0.3), std::sin(i * 0.7), 2.0});
  EXPECT_NE(message(flat).find("coplanar"), std::string::npos) << message(flat);
  EXPECT_NE(message({{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}}).find("collinear"),
            std::string::npos);
  EXPECT_NE(message({{1, 2, 3}, {1, 2, 3}, {1, 2, 3}, {1, 2, 3}}).find("coincident"),
            std::string::npos);
  EXPECT_NE(message({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}).find("at least 4"), std::string::npos);
  EXPECT_NE(message({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, NAN}}).find("non-finite"),
            std::string::npos);
}

TEST(ConvexHull, MakeConvexPolyhedronRecentresAtTheCentroid) {
  std::vector<Vec3> points = cube_corners(1.0);
  points.push_back({0.0, 0.0, 3.0});  // a pyramid on top: centroid above the cube's centre
  for (Vec3& p : points) p += Vec3{10.0, -4.0, 2.0};
  Vec3 centroid;
  const ConvexPolyhedron p = make_convex_polyhedron(points, &centroid);
  // Cube volume 8 centred at z = 0; pyramid volume 4 * 2 / 3 with centroid
  // a quarter of its height above its base (z = 1 + 0.5).
  const double zc = (8.0 * 0.0 + 8.0 / 3.0 * 1.5) / (8.0 + 8.0 / 3.0);
  EXPECT_NEAR(centroid.x, 10.0, 1e-13);
  EXPECT_NEAR(centroid.y, -4.0, 1e-13);
  EXPECT_NEAR(centroid.z, 2.0 + zc, 1e-13);
  const VolumeMoments m = volume_moments(to_polytope(p));
  EXPECT_NEAR(norm(m.first), 0.0, 1e-12);
  EXPECT_EQ(p.face_count(), 9u);  // 5 cube faces + 4 pyramid triangles
}

// Support by hill climbing on a many-vertex polyhedron equals the scan.
TEST(ConvexHull, HillClimbingSupportMatchesTheFullScan) {
  std::mt19937_64 rng(5);
  std::vector<Vec3> points;
  for (int i = 0; i < 600; ++i) {
    const Vec3 u = random_unit(rng);
    points.push_back({2.0 * u.x, 0.7 * u.y, 1.1 * u.z});
  }
  const ConvexPolyhedron p = make_convex_polyhedron(points);
  ASSERT_GT(p.vertices().size(), ConvexPolyhedron::kHillClimbThreshold);
  for (int i = 0; i < 2000; ++i) {
    const Vec3 d = random_unit(rng);
    double best = -1e300;
    for (const Vec3& v : p.vertices()) best = std::max(best, dot(v, d));
    EXPECT_NEAR(dot(support(p, d), d), best, 1e-14);
  }
}

TEST(ConvexHull, ConvexMeshCheck) {
  for (const ConvexShape& shape :
       {ConvexShape{Sphere{1.0}}, ConvexShape{Box{{1, 2, 3}}}, ConvexShape{Cylinder{0.5, 2.0}},
        ConvexShape{Cone{1.0, 2.0}}, ConvexShape{Ellipsoid{{1, 2, 0.5}}}}) {
    TriangleMesh mesh = tessellate(shape, 24);
    EXPECT_TRUE(is_convex_mesh(mesh));
    for (auto& t : mesh.triangles) std::swap(t[1], t[2]);  // inward orientation: still convex
    EXPECT_TRUE(is_convex_mesh(mesh));
  }
  TriangleMesh dented = tessellate(Box{{1, 1, 1}}, 3);
  dented.vertices[7] = {0.2, 0.2, 0.2};  // push the (+,+,+) corner in
  EXPECT_FALSE(is_convex_mesh(dented));
  TriangleMesh open = tessellate(Sphere{1.0}, 16);
  open.triangles.pop_back();
  EXPECT_FALSE(is_convex_mesh(open));
  // Two disjoint cubes: closed, every edge convex, but not one convex solid.
  TriangleMesh two = tessellate(Box{{1, 1, 1}}, 3);
  const TriangleMesh second = tessellate(Box{{1, 1, 1}}, 3);
  for (const auto& t : second.triangles) two.triangles.push_back({t[0] + 8, t[1] + 8, t[2] + 8});
  for (const Vec3& v : second.vertices) two.vertices.push_back(v + Vec3{5, 0, 0});
  EXPECT_FALSE(is_convex_mesh(two));
}

}  // namespace
}  // namespace sanguis::geometry
