#include "geometry/convex_hull.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "geometry/hull_builder.hpp"
#include "geometry/polytope.hpp"

namespace sanguis::geometry {
namespace {

using Loop = std::vector<std::uint32_t>;
using Builder = detail::HullBuilder;
constexpr std::uint32_t kNone = UINT32_MAX;

// Coplanar-face merging: grows regions of adjacent triangles from the largest
// unassigned one, accepting a neighbour whose three vertices lie within the
// tolerance of the seed's plane (checking against the seed, not the previous
// triangle, so that a gently curved surface is not merged by drift).
std::vector<std::uint32_t> coplanar_regions(const Builder& hull,
                                            const std::vector<std::uint32_t>& triangles,
                                            std::uint32_t& region_count) {
  const auto& faces = hull.faces();
  std::vector<double> area(faces.size(), 0.0);
  for (const std::uint32_t t : triangles) {
    const auto& v = faces[t].vertex;
    area[t] = norm(cross(hull.point(v[1]) - hull.point(v[0]), hull.point(v[2]) - hull.point(v[0])));
  }
  std::vector<std::uint32_t> order = triangles;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return area[a] > area[b]; });
  std::vector<std::uint32_t> region(faces.size(), kNone);
  region_count = 0;
  std::vector<std::uint32_t> stack;
  for (const std::uint32_t seed : order) {
    if (region[seed] != kNone) continue;
    const std::uint32_t r = region_count++;
    region[seed] = r;
    stack.assign(1, seed);
    while (!stack.empty()) {
      const std::uint32_t t = stack.back();
      stack.pop_back();
      for (const std::uint32_t u : faces[t].neighbour) {
        if (region[u] != kNone || dot(faces[u].normal, faces[seed].normal) <= 0.0) continue;
        bool coplanar = true;
        for (const std::uint32_t v : faces[u].vertex)
          coplanar &= std::abs(hull.distance(seed, hull.point(v))) <= hull.tolerance();
        if (!coplanar) continue;
        region[u] = r;
        stack.push_back(u);
      }
    }
  }
  return region;
}

// Boundary of a region as one loop (empty if it is not a single simple loop).
Loop region_boundary(const Builder& hull, const std::vector<std::uint32_t>& members,
                     const std::vector<std::uint32_t>& region, std::uint32_t r) {
  std::unordered_map<std::uint32_t, std::uint32_t> next;
  std::size_t edges = 0;
  for (const std::uint32_t t : members) {
    const auto& f = hull.faces()[t];
    for (int e = 0; e < 3; ++e) {
      if (region[f.neighbour[e]] == r) continue;
      if (!next.emplace(f.vertex[e], f.vertex[(e + 1) % 3]).second) return {};
      ++edges;
    }
  }
  if (next.empty()) return {};
  Loop loop;
  std::uint32_t v = next.begin()->first;
  do {
    loop.push_back(v);
    const auto it = next.find(v);
    if (it == next.end() || loop.size() > edges) return {};
    v = it->second;
  } while (v != loop.front());
  return loop.size() == edges ? loop : Loop{};
}

std::vector<Loop> merged_faces(const Builder& hull) {
  const std::vector<std::uint32_t> triangles = detail::alive_faces(hull);
  std::uint32_t region_count = 0;
  const std::vector<std::uint32_t> region = coplanar_regions(hull, triangles, region_count);
  std::vector<std::vector<std::uint32_t>> members(region_count);
  for (const std::uint32_t t : triangles) members[region[t]].push_back(t);
  std::vector<Loop> loops;
  for (std::uint32_t r = 0; r < region_count; ++r) {
    Loop loop = members[r].size() == 1 ? Loop{} : region_boundary(hull, members[r], region, r);
    if (!loop.empty()) {
      loops.push_back(std::move(loop));
      continue;
    }
    for (const std::uint32_t t : members[r]) {  // single triangle, or a region we cannot trace
      const auto& v = hull.faces()[t].vertex;
      loops.push_back({v[0], v[1], v[2]});
    }
  }
  return loops;
}

// A vertex in only two faces lies on their common edge: drop it from both
// (when both keep at least three corners).
void drop_edge_vertices(std::vector<Loop>& loops, std::size_t vertex_count) {
  std::vector<std::vector<std::uint32_t>> faces_of(vertex_count);
  for (std::uint32_t f = 0; f < loops.size(); ++f)
    for (const std::uint32_t v : loops[f]) faces_of[v].push_back(f);
  for (std::uint32_t v = 0; v < vertex_count; ++v) {
    const auto& fs = faces_of[v];
    if (fs.size() != 2 || loops[fs[0]].size() <= 3 || loops[fs[1]].size() <= 3) continue;
    for (const std::uint32_t f : fs) std::erase(loops[f], v);
  }
}

void check_points(std::span<const Vec3> points) {
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!std::isfinite(points[i].x) || !std::isfinite(points[i].y) || !std::isfinite(points[i].z))
      throw std::invalid_argument("convex hull: point " + std::to_string(i) +
                                  " has a non-finite coordinate");
}

Aabb box_of(std::span<const Vec3> points) {
  Aabb box{points.front(), points.front()};
  for (const Vec3& p : points)
    for (int k = 0; k < 3; ++k) {
      box.min[k] = std::min(box.min[k], p[k]);
      box.max[k] = std::max(box.max[k], p[k]);
    }
  return box;
}

}  // namespace

ConvexPolyhedron convex_hull(std::span<const Vec3> points, double relative_tolerance) {
  if (points.size() < 4)
    throw std::invalid_argument("convex hull: needs at least 4 points, got " +
                                std::to_string(points.size()));
  if (!(relative_tolerance > 0.0))
    throw std::invalid_argument("convex hull: relative_tolerance must be > 0");
  check_points(points);
  const Aabb box = box_of(points);
  const Vec3 centre = 0.5 * (box.min + box.max);
  Builder hull(relative_tolerance * norm(box.max - box.min));
  for (const Vec3& p : points) hull.add_vertex(p - centre);
  detail::quickhull(hull);

  std::vector<Loop> loops = merged_faces(hull);
  drop_edge_vertices(loops, points.size());
  // Renumber the used vertices, taking the exact input coordinates.
  std::vector<std::uint32_t> renumber(points.size(), kNone);
  std::vector<Vec3> vertices;
  for (Loop& loop : loops)
    for (std::uint32_t& v : loop) {
      if (renumber[v] == kNone) {
        renumber[v] = static_cast<std::uint32_t>(vertices.size());
        vertices.push_back(points[v]);
      }
      v = renumber[v];
    }
  return detail::PolyhedronFactory::assemble(std::move(vertices), loops);
}

ConvexPolyhedron make_convex_polyhedron(std::vector<Vec3> points, Vec3* centroid,
                                        double relative_tolerance) {
  const ConvexPolyhedron hull = convex_hull(points, relative_tolerance);
  const VolumeMoments m = volume_moments(to_polytope(hull));
  const Vec3 c = m.first / m.volume;
  std::vector<Vec3> shifted;
  shifted.reserve(hull.vertices().size());
  for (const Vec3& v : hull.vertices()) shifted.push_back(v - c);
  std::vector<Loop> loops;
  for (std::size_t f = 0; f < hull.face_count(); ++f)
    loops.emplace_back(hull.face(f).begin(), hull.face(f).end());
  if (centroid) *centroid = c;
  return detail::PolyhedronFactory::assemble(std::move(shifted), loops);
}

// ---------------------------------------------------------------- convexity check

namespace {

struct MeshEdges {
  // Directed edge (a, b) -> the triangle that has it.
  std::unordered_map<std::uint64_t, std::uint32_t> owner;
  static std::uint64_t key(std::uint32_t a, std::uint32_t b) {
    return (static_cast<std::uint64_t>(a) << 32) | b;
  }
};

// Closed and consistently oriented: each directed edge once, its reverse once.
bool closed_and_oriented(const TriangleMesh& mesh, MeshEdges& edges) {
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t)
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = mesh.triangles[t][e], b = mesh.triangles[t][(e + 1) % 3];
      if (a == b || !edges.owner.emplace(MeshEdges::key(a, b), t).second) return false;
    }
  for (const auto& [k, t] : edges.owner)
    if (!edges.owner.contains(MeshEdges::key(static_cast<std::uint32_t>(k & 0xFFFFFFFFu),
                                             static_cast<std::uint32_t>(k >> 32))))
      return false;
  return true;
}

double signed_volume(const TriangleMesh& mesh) {
  double six_v = 0.0;
  for (const auto& t : mesh.triangles)
    six_v += dot(mesh.vertices[t[0]], cross(mesh.vertices[t[1]], mesh.vertices[t[2]]));
  return six_v / 6.0;
}

// Every vertex of the neighbouring triangle across each edge lies behind the
// triangle's plane (orientation `sign`) by at least -tolerance.
bool edges_convex(const TriangleMesh& mesh, const MeshEdges& edges, double sign, double tolerance) {
  for (const auto& tri : mesh.triangles) {
    const Vec3& a = mesh.vertices[tri[0]];
    const Vec3 n = sign * cross(mesh.vertices[tri[1]] - a, mesh.vertices[tri[2]] - a);
    const double length = norm(n);
    if (!(length > 0.0)) continue;  // a degenerate sliver has no plane to test
    for (int e = 0; e < 3; ++e) {
      const auto& other = mesh.triangles[edges.owner.at(MeshEdges::key(tri[(e + 1) % 3], tri[e]))];
      for (const std::uint32_t v : other)
        if (dot(n, mesh.vertices[v] - a) / length > tolerance) return false;
    }
  }
  return true;
}

}  // namespace

bool is_convex_mesh(const TriangleMesh& mesh, double relative_tolerance) {
  if (mesh.vertices.size() < 4 || mesh.triangles.size() < 4) return false;
  for (const auto& t : mesh.triangles)
    for (const std::uint32_t v : t)
      if (v >= mesh.vertices.size()) return false;
  MeshEdges edges;
  if (!closed_and_oriented(mesh, edges)) return false;
  const Aabb box = box_of(mesh.vertices);
  const double tolerance = relative_tolerance * norm(box.max - box.min);
  const double volume = signed_volume(mesh);
  if (volume == 0.0) return false;
  if (!edges_convex(mesh, edges, volume > 0.0 ? 1.0 : -1.0, tolerance)) return false;
  std::optional<ConvexPolyhedron> hull;
  try {
    hull.emplace(convex_hull(mesh.vertices, std::max(relative_tolerance, kHullTolerance)));
  } catch (const std::invalid_argument&) {
    return false;  // flat: no solid
  }
  const Polytope hull_polytope = to_polytope(*hull);
  double hull_area = 0.0;
  for (const auto& loop : hull_polytope.faces) {
    Vec3 twice_area;
    for (std::size_t i = 1; i + 1 < loop.size(); ++i)
      twice_area += cross(hull_polytope.vertices[loop[i]] - hull_polytope.vertices[loop[0]],
                          hull_polytope.vertices[loop[i + 1]] - hull_polytope.vertices[loop[0]]);
    hull_area += 0.5 * norm(twice_area);
  }
  return std::abs(volume_moments(hull_polytope).volume - std::abs(volume)) <= tolerance * hull_area;
}

}  // namespace sanguis::geometry
