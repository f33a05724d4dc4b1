#pragma once
// Helpers shared by the geometry tests: random poses and polyhedra, and a
// brute-force distance between convex polyhedra (closest features) that the
// GJK results are checked against.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "core/quaternion.hpp"
#include "core/vec3.hpp"
#include "geometry/convex_hull.hpp"
#include "geometry/shapes.hpp"

namespace sanguis::geometry::testing {

inline Vec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  while (true) {
    const Vec3 v{g(rng), g(rng), g(rng)};
    const double n = norm(v);
    if (n > 1e-6) return v / n;
  }
}

inline Quaternion random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return normalized(Quaternion{g(rng), g(rng), g(rng), g(rng)});
}

inline double uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

// Hull of n points on (and inside) a random ellipsoid, centred.
inline ConvexPolyhedron random_polyhedron(std::mt19937_64& rng, int n) {
  const Vec3 axes{uniform(rng, 0.3, 1.5), uniform(rng, 0.3, 1.5), uniform(rng, 0.3, 1.5)};
  std::vector<Vec3> points;
  for (int i = 0; i < n; ++i) {
    const Vec3 u = random_unit(rng);
    const double r = i % 3 == 2 ? std::cbrt(uniform(rng, 0.0, 1.0)) : 1.0;
    points.push_back({r * axes.x * u.x, r * axes.y * u.y, r * axes.z * u.z});
  }
  return make_convex_polyhedron(points);
}

// ---------------------------------------------------------------- brute force

// Closest point of triangle abc to p (Ericson, Real-Time Collision Detection,
// 2005, §5.1.5: Voronoi regions of the corners, edges, face).
inline Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + (vb * denom) * ab + (vc * denom) * ac;
}

// Squared distance between segments p1q1 and p2q2 (Ericson §5.1.9).
inline double segment_distance2(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2) {
  const Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r);
  double s = 0, t = 0;
  if (a <= 0 && e <= 0) return norm2(r);
  if (a <= 0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = dot(d1, r);
    if (e <= 0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = dot(d1, d2), denom = a * e - b * b;
      s = denom > 0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return norm2((p1 + s * d1) - (p2 + t * d2));
}

struct PlacedMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
};

inline PlacedMesh place(const ConvexPolyhedron& p, const Vec3& position, const Quaternion& q) {
  PlacedMesh m;
  for (const Vec3& v : p.vertices()) m.vertices.push_back(position + rotate(q, v));
  for (std::size_t f = 0; f < p.face_count(); ++f) {
    const auto loop = p.face(f);
    for (std::size_t k = 1; k + 1 < loop.size(); ++k)
      m.triangles.push_back({loop[0], loop[k], loop[k + 1]});
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const std::uint32_t a = loop[k], b = loop[(k + 1) % loop.size()];
      if (a < b) m.edges.emplace_back(a, b);
    }
  }
  return m;
}

// Distance between the boundaries of two convex polyhedra: minimum over
// vertex-face and edge-edge feature pairs (for disjoint convex polyhedra this
// is their distance).
inline double feature_distance(const PlacedMesh& a, const PlacedMesh& b) {
  double best = std::numeric_limits<double>::infinity();
  const auto vertex_face = [&best](const PlacedMesh& v, const PlacedMesh& f) {
    for (const Vec3& p : v.vertices)
      for (const auto& t : f.triangles)
        best = std::min(best, norm2(p - closest_on_triangle(p, f.vertices[t[0]], f.vertices[t[1]],
                                                            f.vertices[t[2]])));
  };
  vertex_face(a, b);
  vertex_face(b, a);
  for (const auto& [i, j] : a.edges)
    for (const auto& [k, l] : b.edges)
      best = std::min(
          best, segment_distance2(a.vertices[i], a.vertices[j], b.vertices[k], b.vertices[l]));
  return std::sqrt(best);
}

// Largest separation of the two polyhedra's projections over the candidate
// axes of the separating axis theorem (face normals, edge cross products):
// > 0 proves they are disjoint, <= 0 (over all candidates) that they overlap.
inline double max_separation(const PlacedMesh& a, const PlacedMesh& b) {
  std::vector<Vec3> axes;
  const auto add_normals = [&axes](const PlacedMesh& m) {
    for (const auto& t : m.triangles)
      axes.push_back(
          cross(m.vertices[t[1]] - m.vertices[t[0]], m.vertices[t[2]] - m.vertices[t[0]]));
  };
  add_normals(a);
  add_normals(b);
  for (const auto& [i, j] : a.edges)
    for (const auto& [k, l] : b.edges)
      axes.push_back(cross(a.vertices[j] - a.vertices[i], b.vertices[l] - b.vertices[k]));
  double best = -std::numeric_limits<double>::infinity();
  for (const Vec3& axis : axes) {
    const double n = norm(axis);
    if (!(n > 1e-12)) continue;
    const Vec3 u = axis / n;
    double amin = 1e300, amax = -1e300, bmin = 1e300, bmax = -1e300;
    for (const Vec3& v : a.vertices) {
      amin = std::min(amin, dot(u, v));
      amax = std::max(amax, dot(u, v));
    }
    for (const Vec3& v : b.vertices) {
      bmin = std::min(bmin, dot(u, v));
      bmax = std::max(bmax, dot(u, v));
    }
    best = std::max(best, std::max(bmin - amax, amin - bmax));
  }
  return best;
}

}  // namespace sanguis::geometry::testing
