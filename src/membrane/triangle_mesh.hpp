#pragma once
// Closed triangulated membranes (thesis §4.2.2 and footnote 3 of §4.3.4): an
// icosahedron subdivided k times (20 * 4^k triangles: 320, 1280, 5120, 20480
// for k = 2..5), each new node projected back to the unit sphere, then mapped
// onto the capsule's shape (sphere, ellipsoid, or the biconcave red blood cell
// of eq. 4.21, Evans & Fung 1972). Reading and writing: Wavefront OBJ, and VTK
// PolyData (.vtp) with optional per-node / per-triangle data.
//
// Storage is a structure of arrays: node positions are one contiguous
// std::vector<Vec3>; triangles list their three node indices counter-clockwise
// seen from outside, so that (x1 - x0) x (x2 - x0) points outward.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/quaternion.hpp"
#include "core/vec3.hpp"

namespace sanguis::membrane {

using NodeIndex = std::int32_t;
using Triangle = std::array<NodeIndex, 3>;

struct TriangleMesh {
  std::vector<Vec3> positions;      // node positions
  std::vector<Triangle> triangles;  // node indices, counter-clockwise seen from outside

  std::size_t node_count() const { return positions.size(); }
  std::size_t triangle_count() const { return triangles.size(); }
};

// The unit icosphere: an icosahedron subdivided `subdivisions` times (each
// triangle into four, edge midpoints shared), every node on the unit sphere.
// 20 * 4^k triangles, 10 * 4^k + 2 nodes. The icosahedron is oriented with two
// vertices on the z axis (the symmetry axis of the biconcave cell), so the
// poles are nodes. Throws std::invalid_argument for k < 0 or k > 8.
TriangleMesh icosphere(int subdivisions);

// Number of subdivisions giving `triangles` triangles (20 * 4^k); throws
// std::invalid_argument naming the value when it is not of that form.
int subdivisions_for_triangles(std::int64_t triangles);

// Shapes onto which the unit icosphere is mapped, node by node.
struct SphereShape {
  double radius = 1.0;
};
struct EllipsoidShape {
  Vec3 semi_axes{1.0, 1.0, 1.0};  // along x, y, z
};
// Biconcave red blood cell of eq. 4.21 (Evans & Fung 1972) with its symmetry
// axis along z: x = R cos(phi) cos(psi), y = R cos(phi) sin(psi),
// z = (R/2) sin(phi) (a1 + a2 cos^2 phi + a3 cos^4 phi). R is the largest
// radius (a c in the thesis; 3.91 um for a human RBC). The thesis writes the
// axis along y; a placement rotation gives that orientation.
struct BiconcaveShape {
  double radius = 1.0;
  double alpha1 = 0.207, alpha2 = 2.003, alpha3 = -1.123;
};

// Maps every node of a unit-sphere mesh onto the shape. A node (px, py, pz) on
// the unit sphere is the point of latitude phi = asin(pz) and longitude
// psi = atan2(py, px); the ellipsoid and biconcave maps keep (phi, psi).
void map_to_sphere(TriangleMesh& mesh, const SphereShape& shape);
void map_to_ellipsoid(TriangleMesh& mesh, const EllipsoidShape& shape);
void map_to_biconcave(TriangleMesh& mesh, const BiconcaveShape& shape);

// Pre-inflation: scales the node positions about the mesh's node centroid by
// `stretch` (> 0), e.g. 1.05 for a capsule whose stress-free shape is 5 %
// smaller than its initial shape. Throws std::invalid_argument if stretch <= 0.
void inflate(TriangleMesh& mesh, double stretch);

// Rigid placement: x -> rotate(orientation, x) + position.
void place(std::vector<Vec3>& positions, const Quaternion& orientation, const Vec3& position);

// Wavefront OBJ ("v" and "f" records, 1-based). Reading goes through
// io::read_obj and checks that every index is a valid node.
void write_obj(const std::filesystem::path& path, const TriangleMesh& mesh);
TriangleMesh read_obj(const std::filesystem::path& path);

// Optional data written with a mesh to .vtp: one value (or 3-vector) per
// triangle (principal tensions...) or per node (forces, curvatures...).
struct MeshField {
  std::string name;
  int components = 1;          // 1 or 3
  std::vector<double> values;  // components * triangle (or node) count
};

void write_vtp(const std::filesystem::path& path, const TriangleMesh& mesh,
               const std::vector<MeshField>& triangle_fields = {},
               const std::vector<MeshField>& node_fields = {});

}  // namespace sanguis::membrane
