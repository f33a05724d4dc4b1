#include "geometry/polytope.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

namespace sanguis::geometry {
namespace {

Vec3 loop_mean(const Polytope& p, const std::vector<std::uint32_t>& loop) {
  Vec3 mean;
  for (const std::uint32_t v : loop) mean += p.vertices[v];
  return mean / static_cast<double>(loop.size());
}

// Twice the area vector of a planar loop (about its mean, to keep the digits).
Vec3 loop_area_vector(const Polytope& p, const std::vector<std::uint32_t>& loop) {
  const Vec3 c = loop_mean(p, loop);
  Vec3 n;
  for (std::size_t i = 0; i < loop.size(); ++i)
    n += cross(p.vertices[loop[i]] - c, p.vertices[loop[(i + 1) % loop.size()]] - c);
  return n;
}

// Points on the cutting plane sorted counter-clockwise about `normal`: the cap
// of a convex body is convex, so the angle about the points' mean orders it.
std::vector<std::uint32_t> cap_loop(const std::vector<Vec3>& vertices,
                                    std::vector<std::uint32_t> on_plane, const Vec3& normal) {
  std::sort(on_plane.begin(), on_plane.end());
  on_plane.erase(std::unique(on_plane.begin(), on_plane.end()), on_plane.end());
  if (on_plane.size() < 3) return {};
  Vec3 mean;
  for (const std::uint32_t v : on_plane) mean += vertices[v];
  mean = mean / static_cast<double>(on_plane.size());
  const Vec3 helper = std::abs(normal.x) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  const Vec3 u = cross(normal, helper) / norm(cross(normal, helper));
  const Vec3 w = cross(normal, u);
  std::vector<std::pair<double, std::uint32_t>> by_angle;
  for (const std::uint32_t v : on_plane) {
    const Vec3 r = vertices[v] - mean;
    by_angle.emplace_back(std::atan2(dot(r, w), dot(r, u)), v);
  }
  std::sort(by_angle.begin(), by_angle.end());
  std::vector<std::uint32_t> loop;
  for (const auto& [angle, v] : by_angle) loop.push_back(v);
  return loop;
}

// Drops unused vertices and renumbers.
Polytope compacted(const std::vector<Vec3>& vertices,
                   std::vector<std::vector<std::uint32_t>> faces) {
  std::vector<std::uint32_t> renumber(vertices.size(), UINT32_MAX);
  Polytope out;
  for (auto& loop : faces)
    for (std::uint32_t& v : loop) {
      if (renumber[v] == UINT32_MAX) {
        renumber[v] = static_cast<std::uint32_t>(out.vertices.size());
        out.vertices.push_back(vertices[v]);
      }
      v = renumber[v];
    }
  out.faces = std::move(faces);
  return out;
}

}  // namespace

Polytope to_polytope(const ConvexPolyhedron& p, const Vec3& position, const Quaternion& q) {
  Polytope out;
  out.vertices.reserve(p.vertices().size());
  for (const Vec3& v : p.vertices()) out.vertices.push_back(position + rotate(q, v));
  for (std::size_t f = 0; f < p.face_count(); ++f) {
    const auto loop = p.face(f);
    out.faces.emplace_back(loop.begin(), loop.end());
  }
  return out;
}

std::vector<Plane> face_planes(const Polytope& p) {
  std::vector<Plane> planes;
  planes.reserve(p.faces.size());
  for (const auto& loop : p.faces) {
    const Vec3 n = loop_area_vector(p, loop);
    const double length = norm(n);
    if (!(length > 0.0)) continue;  // a degenerate loop bounds nothing
    const Vec3 unit = n / length;
    planes.push_back({unit, dot(unit, loop_mean(p, loop))});
  }
  return planes;
}

Polytope clip(const Polytope& p, const Plane& plane, double tolerance) {
  const std::size_t n = p.vertices.size();
  std::vector<double> height(n);
  std::vector<int> side(n);  // -1 inside, 0 on the plane, +1 outside
  bool any_inside = false, any_outside = false;
  for (std::size_t i = 0; i < n; ++i) {
    height[i] = dot(plane.normal, p.vertices[i]) - plane.offset;
    side[i] = height[i] > tolerance ? 1 : (height[i] < -tolerance ? -1 : 0);
    any_inside |= side[i] < 0;
    any_outside |= side[i] > 0;
  }
  if (!any_outside) return p;
  if (!any_inside) return {};

  std::vector<Vec3> vertices = p.vertices;
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> crossing;  // edge -> new vertex
  // The point where edge (i, j) crosses the plane, computed once per edge
  // from the same ordered end points so that both faces share it exactly.
  const auto crossing_point = [&](std::uint32_t i, std::uint32_t j) {
    const auto key = std::minmax(i, j);
    const auto it = crossing.find(key);
    if (it != crossing.end()) return it->second;
    const double t = height[key.first] / (height[key.first] - height[key.second]);
    vertices.push_back(p.vertices[key.first] +
                       t * (p.vertices[key.second] - p.vertices[key.first]));
    const auto index = static_cast<std::uint32_t>(vertices.size() - 1);
    crossing.emplace(key, index);
    return index;
  };

  std::vector<std::vector<std::uint32_t>> faces;
  std::vector<std::uint32_t> on_plane;
  for (const auto& loop : p.faces) {
    std::vector<std::uint32_t> kept;
    bool all_on_plane = true;
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const std::uint32_t i = loop[k], j = loop[(k + 1) % loop.size()];
      all_on_plane &= side[i] == 0;
      if (side[i] <= 0) kept.push_back(i);
      if (side[i] == 0) on_plane.push_back(i);
      if (side[i] * side[j] < 0) {
        kept.push_back(crossing_point(i, j));
        on_plane.push_back(kept.back());
      }
    }
    if (!all_on_plane && kept.size() >= 3) faces.push_back(std::move(kept));
  }
  std::vector<std::uint32_t> cap = cap_loop(vertices, on_plane, plane.normal);
  if (cap.size() >= 3) faces.push_back(std::move(cap));
  if (faces.size() < 4) return {};
  return compacted(vertices, std::move(faces));
}

// Planes that do not reach the original p cannot cut any part of it: they
// are skipped up front (most planes of a neighbouring element face away).
Polytope clip(Polytope p, const std::vector<Plane>& halfspaces, double tolerance) {
  std::vector<std::size_t> cuts;
  for (std::size_t i = 0; i < halfspaces.size(); ++i) {
    double reach = -std::numeric_limits<double>::infinity();
    for (const Vec3& v : p.vertices) reach = std::max(reach, dot(halfspaces[i].normal, v));
    if (reach - halfspaces[i].offset > tolerance) cuts.push_back(i);
  }
  for (const std::size_t i : cuts) {
    p = clip(p, halfspaces[i], tolerance);
    if (p.empty()) return {};
  }
  return p;
}

// Fan of each face joined to the vertices' mean r: for the tetrahedron
// (0, a, b, c) with D = a.(b x c), V = D/6, integral of x = D/24 (a + b + c)
// and integral of x x^T = D/120 (a a^T + b b^T + c c^T + s s^T), s = a + b + c.
VolumeMoments volume_moments(const Polytope& p) {
  VolumeMoments m;
  if (p.vertices.empty()) return m;
  Vec3 r;
  for (const Vec3& v : p.vertices) r += v;
  r = r / static_cast<double>(p.vertices.size());
  double volume = 0.0;
  Vec3 first;
  Mat3 second;
  for (const auto& loop : p.faces)
    for (std::size_t k = 1; k + 1 < loop.size(); ++k) {
      const Vec3 a = p.vertices[loop[0]] - r;
      const Vec3 b = p.vertices[loop[k]] - r;
      const Vec3 c = p.vertices[loop[k + 1]] - r;
      const double det = dot(a, cross(b, c));
      const Vec3 s = a + b + c;
      volume += det / 6.0;
      first += (det / 24.0) * s;
      second = second + (det / 120.0) * (outer(a, a) + outer(b, b) + outer(c, c) + outer(s, s));
    }
  // Back to the frame's origin: x = y + r.
  m.volume = volume;
  m.first = first + volume * r;
  m.second = second + outer(first, r) + outer(r, first) + volume * outer(r, r);
  return m;
}

}  // namespace sanguis::geometry
