#include "geometry/shapes.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "geometry/convex_hull.hpp"
#include "geometry/polytope.hpp"

namespace sanguis::geometry {

// ---------------------------------------------------------------- support helpers

Vec3 detail::unit_direction_slow(const Vec3& d) {
  const double scale = std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)});
  if (!(scale > 0.0) || !std::isfinite(scale)) return {1.0, 0.0, 0.0};
  const Vec3 r = d / scale;  // largest component +-1: no under/overflow below
  return r / norm(r);
}

std::uint32_t ConvexPolyhedron::hill_climb(const Vec3& d) const {
  std::uint32_t best = axis_extremes_[0];
  double best_dot = dot(vertices_[best], d);
  for (int k = 1; k < 6; ++k) {
    const double h = dot(vertices_[axis_extremes_[k]], d);
    if (h > best_dot) {
      best_dot = h;
      best = axis_extremes_[k];
    }
  }
  for (bool moved = true; moved;) {
    moved = false;
    for (const std::uint32_t n : neighbours(best)) {
      const double h = dot(vertices_[n], d);
      if (h > best_dot) {
        best_dot = h;
        best = n;
        moved = true;
      }
    }
  }
  return best;
}

ConvexPolyhedron detail::PolyhedronFactory::assemble(
    std::vector<Vec3> vertices, const std::vector<std::vector<std::uint32_t>>& faces) {
  ConvexPolyhedron p;
  p.vertices_ = std::move(vertices);
  p.face_start_.push_back(0);
  for (const auto& loop : faces) {
    p.face_vertices_.insert(p.face_vertices_.end(), loop.begin(), loop.end());
    p.face_start_.push_back(static_cast<std::uint32_t>(p.face_vertices_.size()));
  }
  Polytope view;
  view.vertices = p.vertices_;
  view.faces = faces;
  p.planes_ = face_planes(view);
  // Vertex graph from the face loops (each edge seen from both faces).
  std::vector<std::vector<std::uint32_t>> adjacent(p.vertices_.size());
  for (const auto& loop : faces)
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const std::uint32_t a = loop[k], b = loop[(k + 1) % loop.size()];
      adjacent[a].push_back(b);
      adjacent[b].push_back(a);
    }
  p.neighbour_start_.push_back(0);
  for (auto& list : adjacent) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    p.neighbour_list_.insert(p.neighbour_list_.end(), list.begin(), list.end());
    p.neighbour_start_.push_back(static_cast<std::uint32_t>(p.neighbour_list_.size()));
  }
  for (int k = 0; k < 3; ++k) {
    for (std::uint32_t i = 0; i < p.vertices_.size(); ++i) {
      if (p.vertices_[i][k] > p.vertices_[p.axis_extremes_[2 * k]][k]) p.axis_extremes_[2 * k] = i;
      if (p.vertices_[i][k] < p.vertices_[p.axis_extremes_[2 * k + 1]][k])
        p.axis_extremes_[2 * k + 1] = i;
    }
  }
  return p;
}

// ---------------------------------------------------------------- bounds

namespace {

double max_vertex_norm(std::span<const Vec3> vertices) {
  double r2 = 0.0;
  for (const Vec3& v : vertices) r2 = std::max(r2, norm2(v));
  return std::sqrt(r2);
}

struct BoundingRadius {
  double operator()(const Sphere& s) const { return s.radius; }
  double operator()(const Box& b) const { return norm(b.half_extents); }
  double operator()(const Cylinder& c) const { return std::hypot(c.radius, c.half_height); }
  double operator()(const Cone& c) const {
    const double apex = std::abs(c.axial_offset + 0.75 * c.height);
    return std::max(apex, std::hypot(c.radius, c.axial_offset - 0.25 * c.height));
  }
  double operator()(const Ellipsoid& e) const {
    return std::max({e.semi_axes.x, e.semi_axes.y, e.semi_axes.z});
  }
  double operator()(const ConvexPolyhedron& p) const { return max_vertex_norm(p.vertices()); }
  double operator()(const Triangle& t) const {
    const Vec3 v[3] = {t.a, t.b, t.c};
    return max_vertex_norm(v);
  }
};

}  // namespace

double bounding_radius(const ConvexShape& shape) {
  return std::visit(BoundingRadius{}, shape);
}

Aabb local_bounds(const ConvexShape& shape) {
  return bounds(shape, {}, {});
}

Aabb bounds(const ConvexShape& shape, const Vec3& position, const Quaternion& q) {
  return std::visit(
      [&](const auto& s) {
        // Space axis k seen from the body is row k of R (R v = rotate(q, v)).
        const Mat3 r = rotation_matrix(q);
        Aabb box;
        for (int k = 0; k < 3; ++k) {
          const Vec3 axis = r.row(k);
          box.max[k] = position[k] + dot(axis, support(s, axis));
          box.min[k] = position[k] + dot(axis, support(s, -axis));
        }
        return box;
      },
      shape);
}

// ---------------------------------------------------------------- crust

namespace {

[[noreturn]] void crust_too_large(const char* shape, double crust, const std::string& limit) {
  throw std::invalid_argument(std::string("shrunk: crust ") + std::to_string(crust) +
                              " too large for the " + shape + " (" + limit + ")");
}

double positive_or_throw(double value, const char* shape, double crust, const char* what,
                         double size) {
  if (!(value > 0.0)) crust_too_large(shape, crust, std::string(what) + " " + std::to_string(size));
  return value;
}

struct Shrink {
  double crust;

  ConvexShape operator()(const Sphere& s) const {
    return Sphere{positive_or_throw(s.radius - crust, "sphere", crust, "radius", s.radius)};
  }
  ConvexShape operator()(const Box& b) const {
    Vec3 h;
    for (int k = 0; k < 3; ++k)
      h[k] = positive_or_throw(b.half_extents[k] - crust, "box", crust, "half extent",
                               b.half_extents[k]);
    return Box{h};
  }
  ConvexShape operator()(const Cylinder& c) const {
    return Cylinder{
        positive_or_throw(c.radius - crust, "cylinder", crust, "radius", c.radius),
        positive_or_throw(c.half_height - crust, "cylinder", crust, "half height", c.half_height)};
  }
  // Inradius of the axial section (triangle of base 2r, height h):
  // rho = r h / (r + sqrt(r^2 + h^2)); the incentre is rho above the base.
  ConvexShape operator()(const Cone& c) const {
    const double rho = c.radius * c.height / (c.radius + std::hypot(c.radius, c.height));
    const double scale = positive_or_throw(1.0 - crust / rho, "cone", crust, "inradius", rho);
    const double base = c.axial_offset - 0.25 * c.height;
    const double incentre = base + rho;
    const double new_height = scale * c.height;
    const double new_base = incentre + scale * (base - incentre);  // = base + crust
    return Cone{scale * c.radius, new_height, new_base + 0.25 * new_height};
  }
  ConvexShape operator()(const Ellipsoid& e) const {
    Vec3 a;
    for (int k = 0; k < 3; ++k)
      a[k] = positive_or_throw(e.semi_axes[k] - crust, "ellipsoid", crust, "semi-axis",
                               e.semi_axes[k]);
    return Ellipsoid{a};
  }
  // Every face plane moved in by crust: the inner parallel body, computed by
  // clipping the polyhedron with the moved planes and taking the hull.
  ConvexShape operator()(const ConvexPolyhedron& p) const {
    Polytope core = to_polytope(p);
    const double size = BoundingRadius{}(p);
    std::vector<Plane> moved = p.face_planes();
    for (Plane& plane : moved) plane.offset -= crust;
    core = clip(std::move(core), moved, 1e-12 * size);
    if (core.empty()) crust_too_large("polyhedron", crust, "no core left");
    try {
      return convex_hull(core.vertices);
    } catch (const std::invalid_argument&) {
      crust_too_large("polyhedron", crust, "the core is flat");
    }
  }
  ConvexShape operator()(const Triangle&) const {
    crust_too_large("triangle", crust, "a flat facet has no interior; use crust 0");
  }
};

}  // namespace

ConvexShape shrunk(const ConvexShape& shape, double crust) {
  if (!(crust >= 0.0) || !std::isfinite(crust))
    throw std::invalid_argument("shrunk: crust must be finite and >= 0, got " +
                                std::to_string(crust));
  if (crust == 0.0) return shape;
  return std::visit(Shrink{crust}, shape);
}

// ---------------------------------------------------------------- tessellation

namespace {

using Tri = std::array<std::uint32_t, 3>;

std::uint32_t add(TriangleMesh& mesh, const Vec3& p) {
  mesh.vertices.push_back(p);
  return static_cast<std::uint32_t>(mesh.vertices.size() - 1);
}

// Unit sphere as latitude rings: poles plus (rings - 1) rings of `segments`.
TriangleMesh unit_sphere(int segments) {
  const int rings = std::max(2, segments / 2);
  TriangleMesh mesh;
  const std::uint32_t north = add(mesh, {0, 0, 1});
  for (int i = 1; i < rings; ++i) {
    const double theta = std::numbers::pi * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double phi = 2.0 * std::numbers::pi * j / segments;
      add(mesh,
          {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)});
    }
  }
  const std::uint32_t south = add(mesh, {0, 0, -1});
  const auto ring = [segments](int i, int j) {
    return static_cast<std::uint32_t>(1 + (i - 1) * segments + (j % segments));
  };
  for (int j = 0; j < segments; ++j) {
    mesh.triangles.push_back({north, ring(1, j), ring(1, j + 1)});
    for (int i = 1; i + 1 < rings; ++i) {
      mesh.triangles.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
      mesh.triangles.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
    }
    mesh.triangles.push_back({ring(rings - 1, j), south, ring(rings - 1, j + 1)});
  }
  return mesh;
}

// Circle of `segments` points at height z, counter-clockwise about +z.
void add_circle(TriangleMesh& mesh, double radius, double z, int segments) {
  for (int j = 0; j < segments; ++j) {
    const double phi = 2.0 * std::numbers::pi * j / segments;
    add(mesh, {radius * std::cos(phi), radius * std::sin(phi), z});
  }
}

struct Tessellate {
  int n;

  TriangleMesh operator()(const Sphere& s) const {
    TriangleMesh mesh = unit_sphere(n);
    for (Vec3& v : mesh.vertices) v *= s.radius;
    return mesh;
  }
  TriangleMesh operator()(const Ellipsoid& e) const {
    TriangleMesh mesh = unit_sphere(n);
    for (Vec3& v : mesh.vertices)
      v = {e.semi_axes.x * v.x, e.semi_axes.y * v.y, e.semi_axes.z * v.z};
    return mesh;
  }
  TriangleMesh operator()(const Box& b) const {
    TriangleMesh mesh;
    for (int i = 0; i < 8; ++i)  // corner i: bit 0 -> +x, bit 1 -> +y, bit 2 -> +z
      add(mesh, {i & 1 ? b.half_extents.x : -b.half_extents.x,
                 i & 2 ? b.half_extents.y : -b.half_extents.y,
                 i & 4 ? b.half_extents.z : -b.half_extents.z});
    const std::uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                       {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    for (const auto& q : quads) {
      mesh.triangles.push_back({q[0], q[1], q[2]});
      mesh.triangles.push_back({q[0], q[2], q[3]});
    }
    return mesh;
  }
  TriangleMesh operator()(const Cylinder& c) const {
    TriangleMesh mesh;
    const std::uint32_t top = add(mesh, {0, 0, c.half_height});
    const std::uint32_t bottom = add(mesh, {0, 0, -c.half_height});
    add_circle(mesh, c.radius, c.half_height, n);   // 2 .. n+1
    add_circle(mesh, c.radius, -c.half_height, n);  // n+2 .. 2n+1
    const auto t = [&](int j) { return static_cast<std::uint32_t>(2 + j % n); };
    const auto b = [&](int j) { return static_cast<std::uint32_t>(2 + n + j % n); };
    for (int j = 0; j < n; ++j) {
      mesh.triangles.push_back({top, t(j), t(j + 1)});
      mesh.triangles.push_back({bottom, b(j + 1), b(j)});
      mesh.triangles.push_back({b(j), b(j + 1), t(j + 1)});
      mesh.triangles.push_back({b(j), t(j + 1), t(j)});
    }
    return mesh;
  }
  TriangleMesh operator()(const Cone& c) const {
    TriangleMesh mesh;
    const std::uint32_t apex = add(mesh, {0, 0, c.axial_offset + 0.75 * c.height});
    const double base_z = c.axial_offset - 0.25 * c.height;
    const std::uint32_t centre = add(mesh, {0, 0, base_z});
    add_circle(mesh, c.radius, base_z, n);
    const auto r = [&](int j) { return static_cast<std::uint32_t>(2 + j % n); };
    for (int j = 0; j < n; ++j) {
      mesh.triangles.push_back({r(j), r(j + 1), apex});
      mesh.triangles.push_back({centre, r(j + 1), r(j)});
    }
    return mesh;
  }
  TriangleMesh operator()(const ConvexPolyhedron& p) const {
    TriangleMesh mesh;
    mesh.vertices = p.vertices();
    for (std::size_t f = 0; f < p.face_count(); ++f) {
      const auto loop = p.face(f);
      for (std::size_t k = 1; k + 1 < loop.size(); ++k)
        mesh.triangles.push_back({loop[0], loop[k], loop[k + 1]});
    }
    return mesh;
  }
  TriangleMesh operator()(const Triangle& t) const {
    TriangleMesh mesh;
    mesh.vertices = {t.a, t.b, t.c};
    mesh.triangles.push_back({0, 1, 2});
    return mesh;
  }
};

}  // namespace

TriangleMesh tessellate(const ConvexShape& shape, int resolution) {
  if (resolution < 3)
    throw std::invalid_argument("tessellate: resolution must be >= 3, got " +
                                std::to_string(resolution));
  return std::visit(Tessellate{resolution}, shape);
}

}  // namespace sanguis::geometry
