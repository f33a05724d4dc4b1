#pragma once
// Convex shapes for non-spherical particles and obstacles (thesis app. A.2;
// Grains3D: Wachs et al., Powder Technol. 224 (2012) 374, and Rakotonirina &
// Wachs, Powder Technol. 324 (2018) 18).
//
// Every shape lives in its own body frame. A shape made by its constructor or
// factory has its centroid (centre of volume) at the body origin, so that the
// particle position is its centre of mass; the only exceptions are the flat
// Triangle (obstacle facets, in the obstacle's frame) and the cores returned
// by shrunk(), which stay in the frame of the shape they were shrunk from.
//
// A convex shape is known to the distance algorithms only through its support
// function s(d) = argmax_{x in shape} d.x (van den Bergen, "Collision
// Detection in Interactive 3D Environments", 2003, §4.3). Each alternative has
// an inline, allocation-free support(); the variant overload visits once.
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <variant>
#include <vector>

#include "core/io/mesh_files.hpp"
#include "core/quaternion.hpp"
#include "core/vec3.hpp"

namespace sanguis::geometry {

// Triangles with counter-clockwise corners seen from outside, same layout as
// the STL/OBJ readers produce.
using TriangleMesh = io::SurfaceMesh;

struct Aabb {
  Vec3 min, max;  // corners, min <= max componentwise
};

// Oriented plane: dot(normal, x) = offset, unit normal pointing out of the
// solid (the inside is dot(normal, x) <= offset).
struct Plane {
  Vec3 normal;
  double offset = 0.0;
};

struct Sphere {
  double radius = 0.0;
};

struct Box {
  Vec3 half_extents;  // along the body axes x, y, z
};

// Circular cylinder along the body z axis, z in [-half_height, half_height].
struct Cylinder {
  double radius = 0.0;
  double half_height = 0.0;
};

// Right circular cone along z, apex up. Its centroid lies a quarter of the
// height above the base, so with axial_offset = 0 the base is at z = -h/4 and
// the apex at z = 3h/4. A non-zero axial_offset shifts the whole cone along z;
// only shrunk() makes such cones (the core of a cone is not centred on the
// cone's centroid).
struct Cone {
  double radius = 0.0;        // of the base
  double height = 0.0;        // base to apex
  double axial_offset = 0.0;  // z of the centroid in the body frame
};

struct Ellipsoid {
  Vec3 semi_axes;  // along x, y, z
};

// A flat triangle (obstacle facet from an STL/OBJ surface), in the obstacle's
// frame; not centred. Zero volume: no mass properties, no core.
struct Triangle {
  Vec3 a, b, c;
};

class ConvexPolyhedron;
namespace detail {
// Assembles a ConvexPolyhedron from vertices and face loops that are already a
// convex polyhedron (counter-clockwise seen from outside): computes the face
// planes and the vertex adjacency. Used by convex_hull() and shrunk(); it does
// not check convexity, so it is not for user input.
struct PolyhedronFactory {
  static ConvexPolyhedron assemble(std::vector<Vec3> vertices,
                                   const std::vector<std::vector<std::uint32_t>>& faces);
};
}  // namespace detail

// Convex polyhedron: vertices, faces as index loops (counter-clockwise seen
// from outside, coplanar triangles merged into one polygon) and the face
// planes. Made only by convex_hull() / make_convex_polyhedron() (which compute
// the hull, so it is convex by construction) and by shrunk().
class ConvexPolyhedron {
 public:
  // Above this many vertices support() walks the vertex graph uphill instead
  // of scanning all vertices.
  static constexpr std::size_t kHillClimbThreshold = 48;

  const std::vector<Vec3>& vertices() const { return vertices_; }
  std::size_t face_count() const { return planes_.size(); }
  std::span<const std::uint32_t> face(std::size_t f) const {
    return {face_vertices_.data() + face_start_[f], face_start_[f + 1] - face_start_[f]};
  }
  const std::vector<Plane>& face_planes() const { return planes_; }
  // Vertices joined to vertex v by an edge.
  std::span<const std::uint32_t> neighbours(std::uint32_t v) const {
    return {neighbour_list_.data() + neighbour_start_[v],
            neighbour_start_[v + 1] - neighbour_start_[v]};
  }

  // Index of a vertex maximising dot(vertex, d) (the first one on ties).
  std::uint32_t support_index(const Vec3& d) const {
    if (vertices_.size() > kHillClimbThreshold) return hill_climb(d);
    // Branch-free running maximum: the maximum changes a few times in
    // unpredictable places, a mispredicted branch costs more than the
    // selects. Ties go to the lowest index; a NaN direction gives vertex 0.
    const Vec3* v = vertices_.data();
    const auto n = static_cast<std::uint32_t>(vertices_.size());
    std::uint32_t best = 0;
    double best_dot = -std::numeric_limits<double>::infinity();
    for (std::uint32_t i = 0; i < n; ++i) {
      const double h = dot(v[i], d);
      const bool better = h > best_dot;
      best_dot = better ? h : best_dot;
      best = better ? i : best;
    }
    return best;
  }

 private:
  friend struct detail::PolyhedronFactory;
  ConvexPolyhedron() = default;

  // Steepest ascent on the vertex graph: on a convex polytope a vertex with no
  // better neighbour maximises the linear function (the edges at a vertex span
  // the cone containing the polytope). Starts from the best of the six
  // axis-extreme vertices.
  std::uint32_t hill_climb(const Vec3& d) const;

  std::vector<Vec3> vertices_;
  std::vector<std::uint32_t> face_start_;  // face f: face_vertices_[face_start_[f] .. [f+1])
  std::vector<std::uint32_t> face_vertices_;
  std::vector<Plane> planes_;  // one per face
  std::vector<std::uint32_t> neighbour_start_;
  std::vector<std::uint32_t> neighbour_list_;
  std::array<std::uint32_t, 6> axis_extremes_{};  // argmax of +x, -x, +y, -y, +z, -z
};

using ConvexShape =
    std::variant<Sphere, Box, Cylinder, Cone, Ellipsoid, ConvexPolyhedron, Triangle>;

// ---------------------------------------------------------------- support

namespace detail {
// Unit vector along d; the +x axis for a zero (or non-finite) d, so that a
// support function always returns a point of the shape. Very small or very
// large d are rescaled before normalising instead of under/overflowing.
Vec3 unit_direction_slow(const Vec3& d);
inline Vec3 unit_direction(const Vec3& d) {
  const double n2 = norm2(d);
  if (n2 > 1e-280 && n2 < 1e280) return d / std::sqrt(n2);
  return unit_direction_slow(d);
}
// Same in the xy-plane: (cos, sin) of the azimuth of (x, y), (1, 0) for zero.
inline void unit_direction_2d(double x, double y, double& cx, double& cy) {
  const double n2 = x * x + y * y;
  if (n2 > 1e-280 && n2 < 1e280) {
    const double inv = 1.0 / std::sqrt(n2);
    cx = x * inv;
    cy = y * inv;
    return;
  }
  const Vec3 u = unit_direction_slow({x, y, 0.0});
  cx = u.x;
  cy = u.y;
}
}  // namespace detail

// Farthest point of the shape along d, in the body frame. For a zero
// direction every point qualifies; a fixed boundary point is returned.
inline Vec3 support(const Sphere& s, const Vec3& d) {
  return s.radius * detail::unit_direction(d);
}

inline Vec3 support(const Box& b, const Vec3& d) {
  return {std::copysign(b.half_extents.x, d.x), std::copysign(b.half_extents.y, d.y),
          std::copysign(b.half_extents.z, d.z)};
}

inline Vec3 support(const Cylinder& c, const Vec3& d) {
  double cx, cy;
  detail::unit_direction_2d(d.x, d.y, cx, cy);
  return {c.radius * cx, c.radius * cy, std::copysign(c.half_height, d.z)};
}

// The farthest point is the apex or a point of the base rim: the apex wins
// when d.apex >= d.rim, i.e. h d_z >= r |d_xy|.
inline Vec3 support(const Cone& c, const Vec3& d) {
  const double radial = std::sqrt(d.x * d.x + d.y * d.y);
  if (c.height * d.z >= c.radius * radial) return {0.0, 0.0, c.axial_offset + 0.75 * c.height};
  double cx, cy;
  detail::unit_direction_2d(d.x, d.y, cx, cy);
  return {c.radius * cx, c.radius * cy, c.axial_offset - 0.25 * c.height};
}

// For x^T A^-2 x <= 1 with A = diag(semi_axes): s(d) = A^2 d / |A d|.
inline Vec3 support(const Ellipsoid& e, const Vec3& d) {
  const Vec3& a = e.semi_axes;
  const Vec3 u = detail::unit_direction({a.x * d.x, a.y * d.y, a.z * d.z});
  return {a.x * u.x, a.y * u.y, a.z * u.z};
}

inline Vec3 support(const ConvexPolyhedron& p, const Vec3& d) {
  return p.vertices()[p.support_index(d)];
}

inline Vec3 support(const Triangle& t, const Vec3& d) {
  const double ha = dot(t.a, d), hb = dot(t.b, d), hc = dot(t.c, d);
  if (ha >= hb && ha >= hc) return t.a;
  return hb >= hc ? t.b : t.c;
}

inline Vec3 support(const ConvexShape& shape, const Vec3& d) {
  return std::visit([&d](const auto& s) { return support(s, d); }, shape);
}

// ---------------------------------------------------------------- bounds

// Radius of the smallest ball about the body origin containing the shape.
double bounding_radius(const ConvexShape& shape);

// Body-frame axis-aligned bounding box (exact: supports along +-x, +-y, +-z).
Aabb local_bounds(const ConvexShape& shape);

// Space-frame axis-aligned bounding box of the shape at `position` with
// orientation q (rotate(q, .) maps body to space); exact, from the supports
// along the six space axes expressed in the body frame.
Aabb bounds(const ConvexShape& shape, const Vec3& position, const Quaternion& q);

// ---------------------------------------------------------------- crust

// The core of the crust approach (thesis app. A.2.3; Wachs et al. 2012, §2.3):
// a shape whose Minkowski sum with a ball of radius `crust` approximates
// `shape`, in the same body frame. Contacts are then detected on the cores
// (distance < crust_a + crust_b) where GJK is fast and robust, instead of on
// the shapes themselves (distance 0, where GJK is slow).
//   Sphere, Box, Cylinder: radius / half extents / half height minus crust;
//     the rounded core is the shape with edges and corners rounded off.
//   Cone: the inner parallel body, i.e. the cone scaled about its inscribed
//     sphere's centre by 1 - crust/inradius (a cone is tangential to its
//     inscribed sphere, so every supporting plane moves in by exactly crust);
//     its centroid moves along z (axial_offset).
//   Ellipsoid: semi-axes minus crust; exact along the axes, and elsewhere the
//     rounded core bulges out of the ellipsoid by at most
//     crust (sqrt(k) - 1)^2 / (k + 1), k = (a_max - crust) / (a_min - crust)
//     (the triangle inequality |x| + |y| - |x + y| <= |y| (1 - cos angle)).
//   ConvexPolyhedron: the exact inner parallel body, i.e. every face plane
//     moved inward by crust (half-space clipping, then the hull). Where three
//     faces meet at a vertex this is the classical vertex offset; where more
//     meet (pyramid apex, octahedron) it stays exact, whereas moving vertices
//     would tilt faces, and faces that shrink to nothing drop out. The core's
//     centroid is then no longer exactly at the origin.
//   Triangle: only crust = 0 (a flat facet has no interior).
// crust = 0 returns the shape unchanged. Throws std::invalid_argument for a
// negative crust or one too large for the shape (no core left).
ConvexShape shrunk(const ConvexShape& shape, double crust);

// ---------------------------------------------------------------- output

// A closed surface mesh of the shape in its body frame (outward,
// counter-clockwise triangles) for output (ParaView) and tests. Curved
// surfaces get `resolution` segments around (>= 3); all vertices lie on the
// surface, so the mesh's solid is inscribed in the shape. Box and polyhedron
// are exact; a Triangle gives its single triangle (not closed).
TriangleMesh tessellate(const ConvexShape& shape, int resolution = 32);

}  // namespace sanguis::geometry
