#pragma once
// Incremental convex hull with triangular faces: the machinery shared by
// Quickhull (convex_hull.cpp) and the Expanding Polytope Algorithm (gjk.cpp).
// Not a public interface of the geometry layer.
//
// Each face knows its neighbour across each edge. A point p is added by
// finding the faces that see it (p strictly above their plane), removing them
// and joining their boundary (the horizon) to p (Barber, Dobkin & Huhdanpaa,
// ACM TOMS 22 (1996) 469, §3). Visibility uses the exact orientation predicate
// (predicates.hpp): with floating-point planes, sliver faces of nearly
// coplanar points get normals wrong by far more than any tolerance, the
// visible faces stop forming a disc and the surface is corrupted. The
// tolerance only decides which points are worth adding (those more than it
// outside in floating point).
#include <array>
#include <cstdint>
#include <vector>

#include "core/vec3.hpp"

namespace sanguis::geometry::detail {

class HullBuilder {
 public:
  struct Face {
    std::array<std::uint32_t, 3> vertex{};     // counter-clockwise seen from outside
    std::array<std::uint32_t, 3> neighbour{};  // face across edge (vertex[i], vertex[i + 1])
    Vec3 normal;                               // outward unit normal
    double offset = 0.0;                       // plane dot(normal, x) = offset
    bool alive = true;
  };

  explicit HullBuilder(double tolerance) : tolerance_(tolerance) {}

  std::uint32_t add_vertex(const Vec3& p);
  const Vec3& point(std::uint32_t i) const { return points_[i]; }
  std::size_t point_count() const { return points_.size(); }
  double tolerance() const { return tolerance_; }

  // Starts with the tetrahedron of four stored points (not coplanar), oriented
  // outward whatever their order.
  void start(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d);

  // Signed distance from the face's plane (floating point: for choosing the
  // farthest point and for the tolerance, not for visibility).
  double distance(std::uint32_t face, const Vec3& p) const {
    return dot(faces_[face].normal, p) - faces_[face].offset;
  }

  // Whether p lies strictly above the face's plane (exact predicate).
  bool sees(std::uint32_t face, const Vec3& p) const;

  // Adds stored point p, which must see face `seed`. The faces it sees are
  // found with the exact predicate, so they always form a disc bounded by one
  // simple loop on a convex hull; the loop is checked all the same. Returns
  // false (hull unchanged) if the seed is not seen or the check fails.
  bool add_point(std::uint32_t p, std::uint32_t seed);

  // Faces removed and created by the last successful add_point.
  const std::vector<std::uint32_t>& removed_faces() const { return visible_; }
  const std::vector<std::uint32_t>& created_faces() const { return created_; }

  const std::vector<Face>& faces() const { return faces_; }

 private:
  struct HorizonEdge {
    std::uint32_t face;  // the visible face
    int edge;            // its edge on the horizon
  };

  void set_plane(Face& f) const;
  bool collect_visible(std::uint32_t p, std::uint32_t seed);
  bool horizon_is_simple_loop();
  void cone_horizon(std::uint32_t p);

  double tolerance_;
  std::vector<Vec3> points_;
  std::vector<Face> faces_;
  // Scratch, reused between calls: per-face visibility stamps for the current
  // add_point, and per-vertex links along the horizon.
  std::uint32_t stamp_ = 0;
  std::vector<std::uint32_t> visible_stamp_, hidden_stamp_;
  std::vector<std::uint32_t> visible_, created_, stack_;
  std::vector<HorizonEdge> horizon_;
  std::vector<std::uint32_t> vertex_stamp_, starts_at_, ends_at_;
};

// Quickhull on all stored points of `hull` (at least 4, not coplanar within
// the hull's tolerance): picks an initial tetrahedron of extreme points, then
// repeatedly adds the farthest outside point of a face. Points within the
// tolerance of the hull are treated as inside. Throws std::invalid_argument
// saying so for fewer than 4 points, or points that are (nearly) coincident,
// collinear or coplanar.
void quickhull(HullBuilder& hull);

// Indices of the alive faces.
std::vector<std::uint32_t> alive_faces(const HullBuilder& hull);

}  // namespace sanguis::geometry::detail
