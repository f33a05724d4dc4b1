// GJK distances against closed forms (sphere-sphere, sphere-box face/edge/
// corner, box-box incl. 45-degree rotations, cylinder and cone on a plane;
// 1e-12 relative), and 5000 random pairs of convex polyhedra in random poses
// against a brute-force closest-feature distance (1e-9 relative, absolute
// floor 1e-12 for size ~1) or, when GJK reports an intersection, against the
// separating-axis test. EPA depths against closed forms (1e-9) and against
// the exact polytope penetration depth min_u h_{A-B}(u) over the
// separating-axis candidates (1e-8). Timings are printed, not asserted.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "geometry/gjk.hpp"
#include "geometry_test_util.hpp"

namespace sanguis::geometry {
namespace {

using testing::random_rotation;
using testing::random_unit;
using testing::uniform;

constexpr double kPi = std::numbers::pi;

Pose at(const Vec3& p, const Quaternion& q = {}) {
  return {p, q};
}
Quaternion about(const Vec3& axis, double angle) {
  return Quaternion::from_axis_angle(axis, angle);
}

// Distance of the pair, and the same pair moved rigidly by a random motion
// (the result must not depend on the frame).
double distance(const ConvexShape& a, const Pose& pa, const ConvexShape& b, const Pose& pb) {
  const DistanceResult r = gjk_distance(a, pa, b, pb);
  EXPECT_FALSE(r.intersecting);
  EXPECT_NEAR(norm(r.point_a - r.point_b), r.distance, 1e-12 * (1.0 + r.distance));
  std::mt19937_64 rng(17);
  const Quaternion q = random_rotation(rng);
  const Vec3 shift{uniform(rng, -3, 3), uniform(rng, -3, 3), uniform(rng, -3, 3)};
  const Pose ma{shift + rotate(q, pa.position), q * pa.orientation};
  const Pose mb{shift + rotate(q, pb.position), q * pb.orientation};
  const DistanceResult moved = gjk_distance(a, ma, b, mb);
  EXPECT_NEAR(moved.distance, r.distance, 1e-12 * (1.0 + r.distance));
  return r.distance;
}

TEST(Gjk, SphereSphere) {
  const Vec3 c{3.0, 1.0, 2.0};
  const DistanceResult r = gjk_distance(Sphere{1.0}, at({}), Sphere{0.5}, at(c));
  EXPECT_NEAR(r.distance, norm(c) - 1.5, 1e-13);
  const Vec3 u = c / norm(c);
  EXPECT_NEAR(norm(r.point_a - u), 0.0, 1e-13);
  EXPECT_NEAR(norm(r.point_b - (c - 0.5 * u)), 0.0, 1e-13);
  EXPECT_NEAR(distance(Sphere{1.0}, at({}), Sphere{0.5}, at(c)), norm(c) - 1.5, 1e-13);
}

TEST(Gjk, SphereBoxFaceEdgeCorner) {
  const Box box{{1, 1, 1}};
  EXPECT_NEAR(distance(box, at({}), Sphere{0.3}, at({0.5, 0.5, 1.5})), 0.2, 1e-13);
  EXPECT_NEAR(distance(box, at({}), Sphere{0.1}, at({1.2, 0.5, 1.2})), std::sqrt(0.08) - 0.1,
              1e-13);
  EXPECT_NEAR(distance(box, at({}), Sphere{0.2}, at({1.3, 1.3, 1.3})), std::sqrt(0.27) - 0.2,
              1e-13);
  // Sphere as A, rotated box as B.
  const Quaternion q = about({0, 0, 1}, 0.3);
  const Vec3 corner = rotate(q, Vec3{1, 1, 1});
  EXPECT_NEAR(distance(Sphere{0.2}, at(1.5 * corner), box, at({}, q)), 0.5 * std::sqrt(3.0) - 0.2,
              1e-13);
}

TEST(Gjk, BoxBoxKnownPoses) {
  const Box unit{{1, 1, 1}};
  EXPECT_NEAR(distance(unit, at({}), unit, at({3.0, 0.5, 0.2})), 1.0, 1e-13);  // face-face
  // B turned 45 degrees about z: its vertical edge points at A's face.
  EXPECT_NEAR(distance(unit, at({}), unit, at({4.0, 0.3, 0.0}, about({0, 0, 1}, kPi / 4))),
              3.0 - std::sqrt(2.0), 1e-13);
  // B's body diagonal turned onto -x: a corner points at A's face.
  const Vec3 diagonal{1, 1, 1};
  const Quaternion corner_first =
      about(cross(diagonal, {-1, 0, 0}), std::acos(-1.0 / std::sqrt(3.0)));
  EXPECT_NEAR(distance(unit, at({}), unit, at({4.0, 0.1, -0.2}, corner_first)),
              3.0 - std::sqrt(3.0), 1e-13);
  // Crossed edges: A turned 45 degrees about x (top edge along x at z = sqrt 2),
  // B about y (bottom edge along y at z0 - sqrt 2).
  EXPECT_NEAR(distance(unit, at({}, about({1, 0, 0}, kPi / 4)), unit,
                       at({0.2, -0.3, 3.5}, about({0, 1, 0}, kPi / 4))),
              3.5 - 2.0 * std::sqrt(2.0), 1e-13);
}

TEST(Gjk, CylinderAboveABigThinBox) {
  const Box ground{{100, 100, 0.5}};  // top face at z = 0 when centred at z = -0.5
  const Cylinder cylinder{1.0, 2.0};
  for (const double theta : {0.0, 0.1, kPi / 4, 1.2, kPi / 2}) {
    const double height = 3.0;
    const double lowest = 2.0 * std::cos(theta) + 1.0 * std::sin(theta);
    EXPECT_NEAR(distance(ground, at({0, 0, -0.5}), cylinder,
                         at({0.3, -0.2, height}, about({1, 0, 0}, theta))),
                height - lowest, 1e-12)
        << "theta " << theta;
  }
}

TEST(Gjk, ConeApexTowardsAPlane) {
  const Box ground{{100, 100, 0.5}};
  const Cone cone{1.0, 4.0};  // apex 3 above the centroid, base 1 below
  EXPECT_NEAR(distance(ground, at({0, 0, -0.5}), cone, at({0.1, 0.2, 5.0}, about({1, 0, 0}, kPi))),
              5.0 - 3.0, 1e-12);
  EXPECT_NEAR(distance(ground, at({0, 0, -0.5}), cone, at({0.1, 0.2, 5.0})), 5.0 - 1.0, 1e-12);
  // Tilted by t about x: the lowest point is on the base rim, at
  // -(r sin t + (h/4) cos t) below the centroid.
  const double t = 0.2;
  EXPECT_NEAR(distance(ground, at({0, 0, -0.5}), cone, at({0, 0, 5.0}, about({1, 0, 0}, t))),
              5.0 - (std::sin(t) + std::cos(t)), 1e-12);
}

struct RandomPairStats {
  int separated = 0, intersecting = 0;
  double worst_relative = 0.0;
  long iterations = 0;
};

TEST(Gjk, RandomPolyhedraAgainstBruteForce) {
  std::mt19937_64 rng(2024);
  RandomPairStats stats;
  for (int pair = 0; pair < 5000; ++pair) {
    const ConvexPolyhedron a = testing::random_polyhedron(rng, 4 + pair % 27);
    const ConvexPolyhedron b = testing::random_polyhedron(rng, 4 + (pair * 7) % 27);
    const Pose pa =
        at({uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1)}, random_rotation(rng));
    const Pose pb =
        at(pa.position + uniform(rng, 0.3, 3.5) * random_unit(rng), random_rotation(rng));
    const DistanceResult r = gjk_distance(a, pa, b, pb);
    stats.iterations += r.iterations;
    const auto ma = testing::place(a, pa.position, pa.orientation);
    const auto mb = testing::place(b, pb.position, pb.orientation);
    ASSERT_TRUE(std::isfinite(r.distance));
    if (r.intersecting) {
      ++stats.intersecting;
      EXPECT_LE(testing::max_separation(ma, mb), 1e-12) << "pair " << pair;
      continue;
    }
    ++stats.separated;
    const double exact = testing::feature_distance(ma, mb);
    const double error = std::abs(r.distance - exact);
    EXPECT_LE(error, 1e-9 * exact + 1e-12) << "pair " << pair << " exact " << exact;
    stats.worst_relative = std::max(stats.worst_relative, error / exact);
    EXPECT_NEAR(norm(r.point_a - r.point_b), r.distance, 1e-12);
    // The witness points lie on their polyhedra.
    for (std::size_t f = 0; f < a.face_count(); ++f) {
      const Plane& p = a.face_planes()[f];
      EXPECT_LE(dot(p.normal, rotate_inverse(pa.orientation, r.point_a - pa.position)) - p.offset,
                1e-12);
    }
  }
  std::printf(
      "[ gjk      ] 5000 random pairs: %d separated (worst relative error %.2e), "
      "%d intersecting, %.2f iterations on average\n",
      stats.separated, stats.worst_relative, stats.intersecting,
      static_cast<double>(stats.iterations) / 5000.0);
  EXPECT_GT(stats.separated, 1000);
  EXPECT_GT(stats.intersecting, 500);
}

TEST(Gjk, CurvedShapesAgainstEachOther) {
  // Ellipsoid pairs along a principal axis: distance = gap between the tips.
  const Ellipsoid e{{0.5, 1.0, 2.0}};
  EXPECT_NEAR(distance(e, at({}), e, at({0, 0, 5.0})), 1.0, 1e-12);
  // B turned 90 degrees about z: its 1.0 semi-axis now along x.
  EXPECT_NEAR(distance(e, at({}), e, at({2.0, 0, 0}, about({0, 0, 1}, kPi / 2))), 0.5, 1e-12);
  // Two cylinders side by side, axes parallel: distance between the surfaces.
  const Cylinder c{0.5, 1.0};
  EXPECT_NEAR(distance(c, at({}), c, at({1.7, 0, 0.3})), 0.7, 1e-12);
  // Crossed cylinders: axes along x and y at heights 0 and 2: 2 - 2 r.
  EXPECT_NEAR(
      distance(c, at({}, about({0, 1, 0}, kPi / 2)), c, at({0, 0, 2}, about({1, 0, 0}, kPi / 2))),
      1.0, 1e-12);
}

TEST(Gjk, WarmStartFromAStaleSimplexGivesTheSameResult) {
  std::mt19937_64 rng(8);
  for (int pair = 0; pair < 500; ++pair) {
    const ConvexShape a = testing::random_polyhedron(rng, 20);
    const ConvexShape b = pair % 2 ? ConvexShape{Ellipsoid{{0.5, 0.8, 0.3}}}
                                   : ConvexShape{testing::random_polyhedron(rng, 20)};
    const Pose pa = at({}, random_rotation(rng));
    Pose pb = at(uniform(rng, 0.5, 3.0) * random_unit(rng), random_rotation(rng));
    GjkWarmStart warm;
    gjk_distance(a, pa, b, pb, &warm);
    pb.position += 0.05 * random_unit(rng);  // the next step
    pb.orientation = normalized(about(random_unit(rng), 0.05) * pb.orientation);
    const DistanceResult cold = gjk_distance(a, pa, b, pb);
    const DistanceResult hot = gjk_distance(a, pa, b, pb, &warm);
    EXPECT_EQ(cold.intersecting, hot.intersecting);
    EXPECT_NEAR(hot.distance, cold.distance, 1e-9 * cold.distance + 1e-12);
  }
}

TEST(Gjk, StopBeyondReturnsAProvenLowerBound) {
  GjkSettings settings;
  settings.stop_beyond = 0.5;
  const Box unit{{1, 1, 1}};
  const DistanceResult far =
      gjk_distance(unit, at({}), unit, at({5, 1, 0.5}, about({1, 1, 0}, 0.4)), nullptr, settings);
  const DistanceResult exact =
      gjk_distance(unit, at({}), unit, at({5, 1, 0.5}, about({1, 1, 0}, 0.4)));
  EXPECT_GT(far.distance, 0.5);
  EXPECT_LE(far.distance, exact.distance * (1 + 1e-12));
  EXPECT_LE(far.iterations, exact.iterations);
  const DistanceResult near =
      gjk_distance(unit, at({}), unit, at({2.3, 0, 0}), nullptr, settings);  // below the limit
  EXPECT_NEAR(near.distance, 0.3, 1e-13);
}

TEST(Gjk, DegenerateConfigurationsNeverGiveNaN) {
  const Box unit{{1, 1, 1}};
  // Same shape, same pose.
  EXPECT_TRUE(gjk_distance(unit, at({}), unit, at({})).intersecting);
  // Exactly touching faces: distance 0 (or rounding).
  const DistanceResult touch = gjk_distance(unit, at({}), unit, at({2.0, 0.5, 0.0}));
  EXPECT_LE(touch.distance, 1e-14);
  // A point (sphere of radius 0) against a box, and a flat triangle.
  EXPECT_NEAR(gjk_distance(Sphere{0.0}, at({3, 0, 0}), unit, at({})).distance, 2.0, 1e-14);
  const Triangle tri{{-5, -5, 0}, {5, -5, 0}, {0, 5, 0}};
  EXPECT_NEAR(gjk_distance(tri, at({}), unit, at({0.5, 0.2, 1.7}, about({0, 0, 1}, 0.3))).distance,
              0.7, 1e-13);
  // Coplanar triangles side by side, and overlapping.
  const Triangle small{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  EXPECT_NEAR(gjk_distance(small, at({}), small, at({2, 0, 0})).distance, 1.0, 1e-14);
  EXPECT_TRUE(gjk_distance(small, at({}), small, at({0.2, 0.2, 0})).intersecting);
  // Far apart and tiny: relative accuracy holds at any scale.
  const DistanceResult tiny =
      gjk_distance(Box{{1e-6, 1e-6, 1e-6}}, at({}), Sphere{1e-6}, at({1e-5, 0, 0}));
  EXPECT_NEAR(tiny.distance, 8e-6, 1e-18);
  std::mt19937_64 rng(5);
  for (int i = 0; i < 2000; ++i) {  // random boxes just off touching: finite results
    const Quaternion q = random_rotation(rng);
    const Vec3 dir = random_unit(rng);
    const Vec3 back = rotate_inverse(q, -dir);
    const double reach = dot(support(unit, back), back) + dot(support(unit, dir), dir);
    const DistanceResult r = gjk_distance(unit, at({}), unit, at((reach + 1e-12) * dir, q));
    ASSERT_TRUE(std::isfinite(r.distance) && std::isfinite(r.point_a.x) &&
                std::isfinite(r.point_b.z));
    EXPECT_GE(r.distance, 0.0);
  }
}

// ---------------------------------------------------------------- EPA

TEST(Epa, BoxesOverlappingAlongOneAxis) {
  const Box unit{{1, 1, 1}};
  const PenetrationResult r = epa_penetration(unit, at({}), unit, at({1.5, 0.2, 0.1}));
  EXPECT_TRUE(r.converged);
  EXPECT_NEAR(r.depth, 0.5, 1e-12);
  EXPECT_NEAR(r.normal.x, 1.0, 1e-12);
  EXPECT_NEAR(r.point_a.x, 1.0, 1e-12);
  EXPECT_NEAR(r.point_b.x, 0.5, 1e-12);
  EXPECT_NEAR(norm(r.point_a - r.point_b - r.depth * r.normal), 0.0, 1e-12);
  // Rotated pair: same overlap seen in a turned frame.
  const Quaternion q = about({1, 2, 3}, 0.7);
  const PenetrationResult turned =
      epa_penetration(unit, at({}, q), unit, at(rotate(q, Vec3{0.2, -1.6, 0.1}), q));
  EXPECT_NEAR(turned.depth, 0.4, 1e-12);
  EXPECT_NEAR(dot(turned.normal, rotate(q, Vec3{0, -1, 0})), 1.0, 1e-12);
}

TEST(Epa, SphereSphere) {
  const PenetrationResult r =
      epa_penetration(Sphere{1.0}, at({}), Sphere{0.5}, at({0.72, -0.96, 0}));
  EXPECT_NEAR(r.depth, 0.3, 1e-9);  // 1.5 - 1.2
  EXPECT_NEAR(norm(r.normal - Vec3{0.6, -0.8, 0.0}), 0.0, 1e-4);
  std::printf("[ epa      ] sphere-sphere: depth error %.1e after %d expansions\n",
              std::abs(r.depth - 0.3), r.iterations);
}

TEST(Epa, SeparatedShapesGiveMinusTheDistance) {
  const PenetrationResult r = epa_penetration(Sphere{1.0}, at({}), Sphere{1.0}, at({0, 3, 0}));
  EXPECT_NEAR(r.depth, -1.0, 1e-13);
  EXPECT_NEAR(r.normal.y, 1.0, 1e-13);
}

TEST(Epa, RandomPolyhedraMatchTheExactPenetrationDepth) {
  std::mt19937_64 rng(99);
  int checked = 0;
  double worst = 0.0;
  for (int pair = 0; pair < 1000; ++pair) {
    const ConvexPolyhedron a = testing::random_polyhedron(rng, 12);
    const ConvexPolyhedron b = testing::random_polyhedron(rng, 12);
    const Pose pa = at({}, random_rotation(rng));
    const Pose pb = at(uniform(rng, 0.0, 1.0) * random_unit(rng), random_rotation(rng));
    const PenetrationResult r = epa_penetration(a, pa, b, pb);
    if (r.depth <= 0.0) continue;
    ++checked;
    const double exact = -testing::max_separation(testing::place(a, pa.position, pa.orientation),
                                                  testing::place(b, pb.position, pb.orientation));
    worst = std::max(worst, std::abs(r.depth - exact));
    EXPECT_NEAR(r.depth, exact, 1e-8) << "pair " << pair;
    // Moving B by depth * normal (a hair more) separates the shapes.
    const Pose moved{pb.position + (r.depth + 1e-7) * r.normal, pb.orientation};
    EXPECT_FALSE(gjk_distance(a, pa, b, moved).intersecting) << "pair " << pair;
  }
  std::printf("[ epa      ] %d intersecting random pairs: worst depth error %.1e\n", checked,
              worst);
  EXPECT_GT(checked, 500);
}

// ---------------------------------------------------------------- timing

ConvexPolyhedron thirty_vertex_polyhedron(std::mt19937_64& rng) {
  std::vector<Vec3> points;
  for (int i = 0; i < 30; ++i) {
    const Vec3 u = random_unit(rng);
    points.push_back({0.6 * u.x, 0.4 * u.y, 0.5 * u.z});
  }
  return make_convex_polyhedron(points);
}

TEST(Gjk, TimingOfOneCall) {
  std::mt19937_64 rng(31);
  const ConvexShape a = thirty_vertex_polyhedron(rng), b = thirty_vertex_polyhedron(rng);
  // Contact-range poses (centres 1.2 to 1.5 apart, bounding radii 0.6 each:
  // separated by up to a third of a size), both orientations random.
  std::vector<std::pair<Pose, Pose>> poses;
  for (int i = 0; i < 1000; ++i)
    poses.push_back({at({}, random_rotation(rng)),
                     at(uniform(rng, 1.2, 1.5) * random_unit(rng), random_rotation(rng))});
  using Clock = std::chrono::steady_clock;
  const int calls = 200000;
  double sink = 0.0;
  long iterations = 0, intersecting = 0;
  auto start = Clock::now();
  for (int i = 0; i < calls; ++i) {
    const auto& [pa, pb] = poses[i % poses.size()];
    const DistanceResult r = gjk_distance(a, pa, b, pb);
    sink += r.distance;
    iterations += r.iterations;
    intersecting += r.intersecting;
  }
  const double cold_ns =
      std::chrono::duration<double, std::nano>(Clock::now() - start).count() / calls;
  const double cold_iterations = static_cast<double>(iterations) / calls;

  // A DEM-like sequence: B drifts and spins slowly (0.01 rad per step) at
  // 1.2 to 1.4 from A; the warm start is kept.
  Pose pa = at({}), pb = at({1.3, 0.1, 0.0}, random_rotation(rng));
  const Quaternion spin = about({0.3, 1, 0.2}, 0.01);
  GjkWarmStart warm;
  iterations = 0;
  start = Clock::now();
  for (int i = 0; i < calls; ++i) {
    pb.position = {1.3 + 0.1 * std::sin(1e-3 * i), 0.1 * std::cos(1e-3 * i), 0.0};
    pb.orientation = spin * pb.orientation;
    if (i % 64 == 0) pb.orientation = normalized(pb.orientation);
    const DistanceResult r = gjk_distance(a, pa, b, pb, &warm);
    sink += r.distance;
    iterations += r.iterations;
    intersecting += r.intersecting;
  }
  const double warm_ns =
      std::chrono::duration<double, std::nano>(Clock::now() - start).count() / calls;
  std::printf(
      "[ gjk      ] two 30-vertex polyhedra, separated: cold %.0f ns/call (%.2f "
      "iterations), warm-started %.0f ns/call (%.2f iterations); %ld of %d calls "
      "intersecting\n",
      cold_ns, cold_iterations, warm_ns, static_cast<double>(iterations) / calls, intersecting,
      2 * calls);
  EXPECT_TRUE(std::isfinite(sink));
}

}  // namespace
}  // namespace sanguis::geometry
