#pragma once
// Readers for triangulated surfaces: STL (ASCII and binary, auto-detected) and
// Wavefront OBJ. They feed obstacle surfaces (one Triangle shape per facet) and
// particle shapes (the convex hull of the vertices, after checking that the
// mesh is convex, see geometry/convex_hull.hpp).
//
// Formats: STL as in the 3D Systems "StereoLithography Interface
// Specification" (1989); OBJ as in the Wavefront "Advanced Visualizer" manual,
// appendix B1 ("v" and "f" records only).
#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "core/vec3.hpp"

namespace sanguis::io {

// An indexed triangle soup. Triangles keep the orientation stored in the file
// (counter-clockwise seen from outside for a well-formed closed surface).
struct SurfaceMesh {
  std::vector<Vec3> vertices;                           // positions, in the file's unit
  std::vector<std::array<std::uint32_t, 3>> triangles;  // indices into vertices
};

// Reads an STL file, ASCII or binary (binary when the size is exactly
// 84 + 50 N bytes, N being the triangle count stored at byte 80; otherwise the
// file must start with "solid"). STL stores every facet with its own three
// vertices: positions closer than merge_tolerance times the diagonal of the
// mesh's bounding box are merged into one vertex (0: only bitwise-equal
// positions), and facets that become degenerate (two corners merged) are
// dropped. Facet normals in the file are ignored (the vertex order defines the
// orientation). Throws std::runtime_error naming the file (and the line for
// ASCII) if it cannot be read or is malformed.
SurfaceMesh read_stl(const std::filesystem::path& path, double merge_tolerance = 1e-9);

// Reads the "v x y z [w]" and "f i j k ..." records of a Wavefront OBJ file
// (other records are ignored). Face indices are 1-based; negative indices
// count back from the last vertex read so far; "i/t/n" forms use the vertex
// index i. A polygon with n > 3 corners becomes a fan of n - 2 triangles
// (exact for the convex polygons that exporters write). Throws
// std::runtime_error naming the file and the line for malformed input.
SurfaceMesh read_obj(const std::filesystem::path& path);

// read_stl or read_obj according to the extension (.stl / .obj, any case);
// std::runtime_error naming the file for any other extension.
SurfaceMesh read_surface_mesh(const std::filesystem::path& path);

}  // namespace sanguis::io
