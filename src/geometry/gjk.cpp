#include "geometry/gjk.hpp"

#include <stdexcept>
#include <vector>

#include "geometry/hull_builder.hpp"

namespace sanguis::geometry {

DistanceResult gjk_distance(const ConvexShape& a, const Pose& pose_a, const ConvexShape& b,
                            const Pose& pose_b, GjkWarmStart* warm, const GjkSettings& settings) {
  return std::visit(
      [&](const auto& shape_a, const auto& shape_b) {
        return gjk_distance(shape_a, pose_a, shape_b, pose_b, warm, settings);
      },
      a, b);
}

namespace {

PenetrationResult separated(const DistanceResult& d, const Pose& pose_a, const Pose& pose_b) {
  PenetrationResult r;
  r.depth = -d.distance;
  const Vec3 gap = d.point_b - d.point_a;
  r.normal = detail::unit_direction(norm2(gap) > 0.0 ? gap : pose_b.position - pose_a.position);
  r.point_a = d.point_a;
  r.point_b = d.point_b;
  r.converged = true;
  return r;
}

// Barycentric weights of p (in the triangle's plane) on triangle (a, b, c)
// with unit normal n, clamped to the triangle.
std::array<double, 3> barycentric(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                                  const Vec3& n) {
  const double whole = dot(n, cross(b - a, c - a));
  std::array<double, 3> l = {dot(n, cross(b - p, c - p)), dot(n, cross(c - p, a - p)),
                             dot(n, cross(a - p, b - p))};
  if (!(whole > 0.0)) return {1.0, 0.0, 0.0};
  double sum = 0.0;
  for (double& x : l) {
    x = std::max(0.0, x / whole);
    sum += x;
  }
  if (!(sum > 0.0)) return {1.0, 0.0, 0.0};
  for (double& x : l) x /= sum;
  return l;
}

// The alive face whose plane is nearest to the origin (the origin is inside).
std::uint32_t nearest_face(const detail::HullBuilder& hull) {
  std::uint32_t best = UINT32_MAX;
  double best_offset = std::numeric_limits<double>::infinity();
  for (std::uint32_t f = 0; f < hull.faces().size(); ++f) {
    const auto& face = hull.faces()[f];
    if (!face.alive || norm2(face.normal) == 0.0) continue;
    if (face.offset < best_offset) {
      best_offset = face.offset;
      best = f;
    }
  }
  return best;
}

template <class ShapeA, class ShapeB>
PenetrationResult expand_polytope(const ShapeA& a, const Pose& pose_a, const ShapeB& b,
                                  const Pose& pose_b, const EpaSettings& settings) {
  GjkWarmStart last_simplex;
  const DistanceResult gjk = gjk_distance(a, pose_a, b, pose_b, &last_simplex, settings.gjk);
  if (!gjk.intersecting) return separated(gjk, pose_a, pose_b);

  const detail::RelativePose rel(pose_a, pose_b);
  std::vector<detail::SimplexPoint> points;
  const auto support_point = [&](const Vec3& d) {
    detail::SimplexPoint p;
    p.a = support(a, d);
    p.b = support(b, rel.to_b(-d));
    p.w = p.a - rel.from_b(p.b);
    return p;
  };
  for (int i = 0; i < last_simplex.size; ++i)
    points.push_back({last_simplex.on_a[i] - rel.from_b(last_simplex.on_b[i]), last_simplex.on_a[i],
                      last_simplex.on_b[i]});
  for (int x = -1; x <= 1; ++x)  // the 6 axis and 8 diagonal directions
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z) {
        const int nonzero = (x != 0) + (y != 0) + (z != 0);
        if (nonzero == 1 || nonzero == 3)
          points.push_back(support_point({double(x), double(y), double(z)}));
      }
  double scale = 0.0;
  for (const auto& p : points) scale = std::max(scale, norm(p.w));

  PenetrationResult result;
  result.point_a = gjk.point_a;
  result.point_b = gjk.point_b;
  result.normal = detail::unit_direction(pose_b.position - pose_a.position);
  detail::HullBuilder hull(1e-13 * scale);
  for (const auto& p : points) hull.add_vertex(p.w);
  try {
    detail::quickhull(hull);
  } catch (const std::invalid_argument&) {
    result.converged = true;  // A - B is flat: the shapes only touch
    return result;
  }

  std::uint32_t face = nearest_face(hull);
  for (; result.iterations < settings.max_iterations; ++result.iterations) {
    const auto& f = hull.faces()[face];
    const detail::SimplexPoint w = support_point(f.normal);
    const double gap = dot(f.normal, w.w) - f.offset;
    if (gap <= settings.relative_tolerance * std::max(f.offset, 1e-15 * scale)) {
      result.converged = true;
      break;
    }
    const std::uint32_t index = hull.add_vertex(w.w);
    points.push_back(w);
    if (!hull.add_point(index, face)) break;  // rounding: keep the current face
    face = nearest_face(hull);
  }

  const auto& f = hull.faces()[face];
  const std::array<double, 3> l =
      barycentric(f.offset * f.normal, hull.point(f.vertex[0]), hull.point(f.vertex[1]),
                  hull.point(f.vertex[2]), f.normal);
  Vec3 on_a, on_b;
  for (int i = 0; i < 3; ++i) {
    on_a += l[i] * points[f.vertex[i]].a;
    on_b += l[i] * points[f.vertex[i]].b;
  }
  result.depth = std::max(0.0, f.offset);
  result.normal = rotate(pose_a.orientation, f.normal);
  result.point_a = pose_a.position + rotate(pose_a.orientation, on_a);
  result.point_b = pose_b.position + rotate(pose_b.orientation, on_b);
  return result;
}

}  // namespace

PenetrationResult epa_penetration(const ConvexShape& a, const Pose& pose_a, const ConvexShape& b,
                                  const Pose& pose_b, const EpaSettings& settings) {
  return std::visit(
      [&](const auto& shape_a, const auto& shape_b) {
        return expand_polytope(shape_a, pose_a, shape_b, pose_b, settings);
      },
      a, b);
}

}  // namespace sanguis::geometry
