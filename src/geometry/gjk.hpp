#pragma once
// Distance between two posed convex shapes by the Gilbert-Johnson-Keerthi
// algorithm (Gilbert, Johnson & Keerthi, IEEE J. Robot. Autom. 4 (1988) 193),
// in van den Bergen's formulation (J. Graphics Tools 4 (1999) 7; "Collision
// Detection in Interactive 3D Environments", 2003, §4.3), with the
// signed-volume sub-algorithm of Montanari, Petrinic & Barbieri (ACM Trans.
// Graph. 36 (2017) 30) for the point of a simplex closest to the origin;
// penetration depth of intersecting shapes by the Expanding Polytope
// Algorithm (van den Bergen 2001, "Proximity queries and penetration depth
// computation on 3D game objects", GDC). Thesis app. A.2.2.
//
// GJK works on the Minkowski difference D = A - B: the distance between A and
// B is the distance from the origin to D, and D is known only through its
// support function s_D(d) = s_A(d) - s_B(-d). Each iteration takes
// w = s_D(-v), where v is the current point of D closest to the origin, adds w
// to a simplex (at most 4 points of D) and replaces v by the point of the
// simplex closest to the origin, dropping the simplex points not needed.
// v . w / |v| is a lower bound and |v| an upper bound of the distance.
//
// Everything is computed in A's body frame (one rotation per support of B,
// none for A) and converted to space frame at the end.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/mat3.hpp"
#include "core/quaternion.hpp"
#include "core/vec3.hpp"
#include "geometry/shapes.hpp"

namespace sanguis::geometry {

struct Pose {
  Vec3 position;           // of the body origin, space frame
  Quaternion orientation;  // rotate(orientation, .) maps body -> space (unit)
};

struct DistanceResult {
  double distance = 0.0;  // 0 when intersecting
  Vec3 point_a, point_b;  // closest points of A and B, space frame
  bool intersecting = false;
  int iterations = 0;  // support evaluations of A - B
};

struct GjkSettings {
  // Stop when |v|^2 - v.w <= relative_tolerance |v|^2: the returned distance
  // then exceeds the true one by at most relative_tolerance times it.
  double relative_tolerance = 1e-12;
  // Intersecting (distance 0) when |v|^2 <= touching_tolerance max |w_i|^2:
  // the origin is on the simplex up to rounding.
  double touching_tolerance = 1e-26;
  int max_iterations = 128;
  // Stop as soon as the distance is proven larger than this (the DEM only
  // needs distances below the sum of the crusts): `distance` then holds the
  // proven lower bound (> stop_beyond) and the points the current estimates.
  double stop_beyond = std::numeric_limits<double>::infinity();
};

// Warm start: the support points of the last simplex, in each body's frame
// (they remain points of the same shapes whatever the new poses). A DEM
// contact keeps one between steps; poses change little, so the old simplex
// is nearly the final one and GJK ends in one or two iterations. Valid only
// for the same two shapes in the same order.
struct GjkWarmStart {
  std::int32_t size = 0;  // 0: cold start
  // The four bytes the alignment of on_a leaves, named so that every copy carries
  // them and they are zero: checkpoints write warm starts as raw bytes, and an
  // unnamed gap held whatever the stack had (a Clang build's checkpoints then
  // differed with the thread count while the states were the same bits).
  std::int32_t unused = 0;
  std::array<Vec3, 4> on_a{}, on_b{};
};
static_assert(sizeof(GjkWarmStart) == 2 * sizeof(std::int32_t) + 8 * sizeof(Vec3),
              "GjkWarmStart has no unnamed padding");

namespace detail {

// The small helpers of the sub-algorithm below are forced inline: GCC kept
// area2, closest_on_segment and closest_on_triangle as calls (19 % of
// `bench dem-crosses` in closest_on_triangle alone), and inlined the crosses'
// contact step runs 5-8 % faster on one thread, with the same bits
// (docs/performance.md, "GJK: inlined helpers and the stopping tolerance").

// B's frame seen from A's: x_A = r x_B + t.
struct RelativePose {
  Mat3 r;
  Vec3 t;
  RelativePose(const Pose& a, const Pose& b) {
    const Quaternion a_inverse = conjugate(a.orientation);
    r = rotation_matrix(a_inverse * b.orientation);
    t = rotate(a_inverse, b.position - a.position);
  }
  Vec3 to_b(const Vec3& d) const {  // r^T d (a direction)
    return {r(0, 0) * d.x + r(1, 0) * d.y + r(2, 0) * d.z,
            r(0, 1) * d.x + r(1, 1) * d.y + r(2, 1) * d.z,
            r(0, 2) * d.x + r(1, 2) * d.y + r(2, 2) * d.z};
  }
  Vec3 from_b(const Vec3& p) const { return r * p + t; }
};

struct SimplexPoint {
  Vec3 w;  // a - b, in A's frame
  Vec3 a;  // on A, A's body frame
  Vec3 b;  // on B, B's body frame
};

struct Simplex {
  std::array<SimplexPoint, 4> point{};
  std::array<double, 4> lambda{};  // barycentric weights of the closest point
  int size = 0;
};

[[gnu::always_inline]] inline bool same_sign(double a, double b) {
  return (a > 0.0 && b > 0.0) || (a < 0.0 && b < 0.0);
}

[[gnu::always_inline]] inline int largest_component(const Vec3& v) {
  const double x = std::abs(v.x), y = std::abs(v.y), z = std::abs(v.z);
  return x >= y ? (x >= z ? 0 : 2) : (y >= z ? 1 : 2);
}

// Closest point to the origin on segment s1 s2 (Montanari et al. 2017, S1D):
// barycentric weights from the projection along the segment's longest axis;
// if the projection falls outside, the nearer end point.
[[gnu::always_inline]] inline void closest_on_segment(const Vec3& s1, const Vec3& s2,
                                                      double lambda[2]) {
  const Vec3 t = s2 - s1;
  const double tt = norm2(t);
  if (tt > 0.0) {
    const Vec3 p0 = s1 - (dot(s1, t) / tt) * t;
    const int i = largest_component(t);
    const double mu = s1[i] - s2[i];
    const double c1 = p0[i] - s2[i], c2 = s1[i] - p0[i];
    if (same_sign(mu, c1) && same_sign(mu, c2)) {
      lambda[0] = c1 / mu;
      lambda[1] = c2 / mu;
      return;
    }
  }
  const bool first = norm2(s1) <= norm2(s2);
  lambda[0] = first ? 1.0 : 0.0;
  lambda[1] = first ? 0.0 : 1.0;
}

// Signed doubled area of (p, q, r) in the coordinate plane (x, y).
[[gnu::always_inline]] inline double area2(const Vec3& p, const Vec3& q, const Vec3& r, int x,
                                           int y) {
  return (q[x] - p[x]) * (r[y] - p[y]) - (q[y] - p[y]) * (r[x] - p[x]);
}

// Closest point on triangle s1 s2 s3 (S2D): project the origin onto the
// plane, then compare signed areas in the coordinate plane where the triangle
// casts its largest shadow (cyclic axes, so that the shadow's area is n_k).
// Outside: the best edge among those the projection lies beyond.
[[gnu::always_inline]] inline void closest_on_triangle(const Vec3& s1, const Vec3& s2,
                                                       const Vec3& s3, double lambda[3]) {
  const Vec3 n = cross(s2 - s1, s3 - s1);
  const double nn = norm2(n);
  const double longest = std::max({norm2(s2 - s1), norm2(s3 - s1), norm2(s3 - s2)});
  bool check[3] = {true, true, true};
  if (nn > 1e-24 * longest * longest) {  // not a sliver: the plane is well defined
    const Vec3 p0 = (dot(n, s1) / nn) * n;
    const int k = largest_component(n);
    const int x = (k + 1) % 3, y = (k + 2) % 3;
    const double mu = n[k];
    const double c[3] = {area2(p0, s2, s3, x, y), area2(s1, p0, s3, x, y), area2(s1, s2, p0, x, y)};
    if (same_sign(mu, c[0]) && same_sign(mu, c[1]) && same_sign(mu, c[2])) {
      for (int i = 0; i < 3; ++i) lambda[i] = c[i] / mu;
      return;
    }
    for (int i = 0; i < 3; ++i) check[i] = !same_sign(mu, c[i]);
  }
  const Vec3* s[3] = {&s1, &s2, &s3};
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {  // edge opposite corner i
    if (!check[i]) continue;
    const int j = (i + 1) % 3, l = (i + 2) % 3;
    double mu[2];
    closest_on_segment(*s[j], *s[l], mu);
    const double d = norm2(mu[0] * *s[j] + mu[1] * *s[l]);
    if (d < best) {
      best = d;
      lambda[i] = 0.0;
      lambda[j] = mu[0];
      lambda[l] = mu[1];
    }
  }
}

[[gnu::always_inline]] inline double det3(const Vec3& a, const Vec3& b, const Vec3& c) {
  return dot(a, cross(b, c));
}

// Closest point on tetrahedron s1..s4 (S3D): C_i is the signed volume with
// s_i replaced by the origin, sum C_i the tetrahedron's; the origin is inside
// when all share its sign. Otherwise the best face among those it lies beyond.
inline void closest_on_tetrahedron(const Vec3 s[4], double lambda[4]) {
  const double c[4] = {det3(s[1], s[2], s[3]), -det3(s[0], s[2], s[3]), det3(s[0], s[1], s[3]),
                       -det3(s[0], s[1], s[2])};
  const double volume = c[0] + c[1] + c[2] + c[3];
  if (same_sign(volume, c[0]) && same_sign(volume, c[1]) && same_sign(volume, c[2]) &&
      same_sign(volume, c[3])) {
    for (int i = 0; i < 4; ++i) lambda[i] = c[i] / volume;
    return;
  }
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 4; ++i) {  // face opposite corner i
    if (same_sign(volume, c[i])) continue;
    int f[3], m = 0;
    for (int j = 0; j < 4; ++j)
      if (j != i) f[m++] = j;
    double mu[3];
    closest_on_triangle(s[f[0]], s[f[1]], s[f[2]], mu);
    const double d = norm2(mu[0] * s[f[0]] + mu[1] * s[f[1]] + mu[2] * s[f[2]]);
    if (d < best) {
      best = d;
      lambda[i] = 0.0;
      for (int j = 0; j < 3; ++j) lambda[f[j]] = mu[j];
    }
  }
}

// The point of the simplex closest to the origin, and its barycentric
// weights (zero for the simplex points it does not need).
inline Vec3 closest_point(const Simplex& simplex, double lambda[4]) {
  lambda[0] = 1.0;
  lambda[1] = lambda[2] = lambda[3] = 0.0;
  const auto& p = simplex.point;
  if (simplex.size == 2) {
    closest_on_segment(p[0].w, p[1].w, lambda);
  } else if (simplex.size == 3) {
    closest_on_triangle(p[0].w, p[1].w, p[2].w, lambda);
  } else if (simplex.size == 4) {
    const Vec3 s[4] = {p[0].w, p[1].w, p[2].w, p[3].w};
    closest_on_tetrahedron(s, lambda);
  }
  Vec3 v;
  for (int i = 0; i < simplex.size; ++i) v += lambda[i] * p[i].w;
  return v;
}

// Keeps the simplex points with positive weight, in place.
inline void keep_support(Simplex& simplex, const double lambda[4]) {
  int kept = 0;
  for (int i = 0; i < simplex.size; ++i) {
    if (!(lambda[i] > 0.0)) continue;
    if (kept != i) simplex.point[kept] = simplex.point[i];
    simplex.lambda[kept++] = lambda[i];
  }
  if (kept == 0) {  // cannot happen with finite input; keep one point
    simplex.lambda[0] = 1.0;
    kept = 1;
  }
  simplex.size = kept;
}

// Replaces the simplex by the smallest sub-simplex containing its point
// closest to the origin, and returns that point.
inline Vec3 reduce_to_closest(Simplex& simplex) {
  double lambda[4];
  const Vec3 v = closest_point(simplex, lambda);
  keep_support(simplex, lambda);
  return v;
}

inline bool contains(const Simplex& simplex, const Vec3& w) {
  for (int i = 0; i < simplex.size; ++i)
    if (simplex.point[i].w == w) return true;
  return false;
}

inline double largest_norm2(const Simplex& simplex) {
  double m = 0.0;
  for (int i = 0; i < simplex.size; ++i) m = std::max(m, norm2(simplex.point[i].w));
  return m;
}

// The previous simplex re-posed: its body-frame points are still points of
// the same shapes, so their differences are points of the new A - B.
inline Vec3 load_warm_start(const GjkWarmStart& warm, const RelativePose& rel, Simplex& simplex) {
  simplex.size = std::min(warm.size, 4);
  for (int i = 0; i < simplex.size; ++i)
    simplex.point[i] = {warm.on_a[i] - rel.from_b(warm.on_b[i]), warm.on_a[i], warm.on_b[i]};
  return reduce_to_closest(simplex);
}

inline void store_warm_start(const Simplex& simplex, GjkWarmStart& warm) {
  warm.size = simplex.size;
  for (int i = 0; i < simplex.size; ++i) {
    warm.on_a[i] = simplex.point[i].a;
    warm.on_b[i] = simplex.point[i].b;
  }
}

}  // namespace detail

// GJK distance for two concrete shape types (any types with a
// support(shape, direction) overload); the ConvexShape overload below
// dispatches here once.
template <class ShapeA, class ShapeB>
DistanceResult gjk_distance(const ShapeA& a, const Pose& pose_a, const ShapeB& b,
                            const Pose& pose_b, GjkWarmStart* warm = nullptr,
                            const GjkSettings& settings = {}) {
  const detail::RelativePose rel(pose_a, pose_b);
  const auto support_point = [&](const Vec3& d) {  // of A - B along d, A's frame
    detail::SimplexPoint p;
    p.a = support(a, d);
    p.b = support(b, rel.to_b(-d));
    p.w = p.a - rel.from_b(p.b);
    return p;
  };
  detail::Simplex simplex;
  Vec3 v;
  if (warm && warm->size > 0) {
    v = detail::load_warm_start(*warm, rel, simplex);
  } else {
    simplex.size = 1;
    simplex.point[0] = support_point(rel.t);  // A's point towards B minus B's towards A
    simplex.lambda[0] = 1.0;
    v = simplex.point[0].w;
  }

  const auto touching = [&] {
    return simplex.size == 4 ||
           norm2(v) <= settings.touching_tolerance * detail::largest_norm2(simplex);
  };
  DistanceResult result;
  bool intersecting = touching();
  double lower_bound = -1.0;
  int iteration = 0;
  while (!intersecting && iteration < settings.max_iterations) {
    ++iteration;
    const double vv = norm2(v);
    const detail::SimplexPoint w = support_point(-v);
    const double vw = dot(v, w.w);
    if (vw > 0.0 && vw * vw > settings.stop_beyond * settings.stop_beyond * vv) {
      lower_bound = vw / std::sqrt(vv);
      break;
    }
    if (vv - vw <= settings.relative_tolerance * vv || detail::contains(simplex, w.w)) break;
    simplex.point[simplex.size++] = w;
    double lambda[4];
    const Vec3 next = detail::closest_point(simplex, lambda);
    if (!(norm2(next) < vv)) {  // no progress: rounding has the last word
      --simplex.size;           // back to the previous simplex and weights
      break;
    }
    detail::keep_support(simplex, lambda);
    v = next;
    intersecting = touching();
  }

  Vec3 on_a, on_b;  // witness points: the closest point's weights on each body
  for (int i = 0; i < simplex.size; ++i) {
    on_a += simplex.lambda[i] * simplex.point[i].a;
    on_b += simplex.lambda[i] * simplex.point[i].b;
  }
  result.point_a = pose_a.position + rotate(pose_a.orientation, on_a);
  result.point_b = pose_b.position + rotate(pose_b.orientation, on_b);
  result.intersecting = intersecting;
  result.distance = intersecting ? 0.0 : (lower_bound >= 0.0 ? lower_bound : norm(v));
  result.iterations = iteration;
  if (warm) detail::store_warm_start(simplex, *warm);
  return result;
}

// GJK distance between two posed shapes (one std::visit, then the typed
// kernel above). Never returns NaN for finite input: when rounding stalls the
// iteration, the best estimate so far is returned.
DistanceResult gjk_distance(const ConvexShape& a, const Pose& pose_a, const ConvexShape& b,
                            const Pose& pose_b, GjkWarmStart* warm = nullptr,
                            const GjkSettings& settings = {});

struct PenetrationResult {
  // Penetration depth: the shortest translation of B that separates the
  // shapes is depth * normal. Negative (minus the distance) when they do not
  // intersect, then normal points from A's closest point to B's.
  double depth = 0.0;
  Vec3 normal;            // unit, from A towards B, space frame
  Vec3 point_a, point_b;  // witness points: point_a - point_b = depth * normal
  int iterations = 0;     // EPA expansions
  bool converged = false;
};

struct EpaSettings {
  // Stop when the support along the nearest face's normal is within
  // relative_tolerance * depth of the face (upper and lower bounds agree).
  double relative_tolerance = 1e-10;
  int max_iterations = 256;
  GjkSettings gjk;  // for the preceding GJK call
};

// Penetration depth, normal and witness points of two intersecting shapes
// (the fall-back when the overlap exceeds the crust): runs GJK, and if the
// shapes intersect expands a polytope inside A - B towards the boundary point
// nearest to the origin. The polytope starts as the hull of the final GJK
// simplex and the supports along 14 directions, so it contains the origin.
PenetrationResult epa_penetration(const ConvexShape& a, const Pose& pose_a, const ConvexShape& b,
                                  const Pose& pose_b, const EpaSettings& settings = {});

}  // namespace sanguis::geometry
