#include "membrane/triangle_mesh.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "core/io/atomic_file.hpp"
#include "core/io/mesh_files.hpp"
#include "core/io/vtk.hpp"

namespace sanguis::membrane {

namespace {

Vec3 unit(const Vec3& v) {
  return v / norm(v);
}

// Icosahedron with one vertex at each pole: two rings of five vertices at
// z = +-1/sqrt(5), the lower ring turned by 36 degrees.
TriangleMesh icosahedron() {
  TriangleMesh m;
  const double z = 1.0 / std::sqrt(5.0), r = 2.0 / std::sqrt(5.0);
  constexpr double kStep = 2.0 * std::numbers::pi / 5.0;
  m.positions.push_back({0.0, 0.0, 1.0});  // 0: north pole
  for (int k = 0; k < 5; ++k)              // 1..5: upper ring
    m.positions.push_back({r * std::cos(k * kStep), r * std::sin(k * kStep), z});
  for (int k = 0; k < 5; ++k)  // 6..10: lower ring
    m.positions.push_back({r * std::cos((k + 0.5) * kStep), r * std::sin((k + 0.5) * kStep), -z});
  m.positions.push_back({0.0, 0.0, -1.0});  // 11: south pole
  for (int k = 0; k < 5; ++k) {
    const NodeIndex u0 = 1 + k, u1 = 1 + (k + 1) % 5, l0 = 6 + k, l1 = 6 + (k + 1) % 5;
    m.triangles.push_back({0, u0, u1});
    m.triangles.push_back({u0, l0, u1});
    m.triangles.push_back({u1, l0, l1});
    m.triangles.push_back({11, l1, l0});
  }
  // Orient every face outward (the solid is convex and centred at the origin).
  for (auto& t : m.triangles) {
    const Vec3 &a = m.positions[t[0]], &b = m.positions[t[1]], &c = m.positions[t[2]];
    if (dot(cross(b - a, c - a), a + b + c) < 0.0) std::swap(t[1], t[2]);
  }
  return m;
}

// Splits each triangle into four; edge midpoints are shared between the two
// triangles of an edge and pushed back onto the unit sphere.
TriangleMesh subdivide(const TriangleMesh& in) {
  TriangleMesh out;
  out.positions = in.positions;
  out.triangles.reserve(4 * in.triangles.size());
  std::unordered_map<std::uint64_t, NodeIndex> midpoint_of_edge;
  const auto midpoint = [&](NodeIndex a, NodeIndex b) {
    const auto lo = static_cast<std::uint64_t>(std::min(a, b));
    const auto hi = static_cast<std::uint64_t>(std::max(a, b));
    const auto [it, inserted] =
        midpoint_of_edge.try_emplace((lo << 32) | hi, static_cast<NodeIndex>(out.positions.size()));
    if (inserted) out.positions.push_back(unit(in.positions[a] + in.positions[b]));
    return it->second;
  };
  for (const auto& t : in.triangles) {
    const NodeIndex ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
    out.triangles.push_back({t[0], ab, ca});
    out.triangles.push_back({ab, t[1], bc});
    out.triangles.push_back({ca, bc, t[2]});
    out.triangles.push_back({ab, bc, ca});
  }
  return out;
}

}  // namespace

TriangleMesh icosphere(int subdivisions) {
  if (subdivisions < 0 || subdivisions > 8)
    throw std::invalid_argument("icosphere: subdivisions must be in [0, 8], got " +
                                std::to_string(subdivisions));
  TriangleMesh m = icosahedron();
  for (int k = 0; k < subdivisions; ++k) m = subdivide(m);
  return m;
}

int subdivisions_for_triangles(std::int64_t triangles) {
  std::int64_t n = 20;
  for (int k = 0; k <= 8; ++k, n *= 4)
    if (n == triangles) return k;
  throw std::invalid_argument(
      "triangle count must be 20 * 4^k (20, 80, 320, 1280, 5120, ...), got " +
      std::to_string(triangles));
}

void map_to_sphere(TriangleMesh& mesh, const SphereShape& shape) {
  for (auto& x : mesh.positions) x = shape.radius * unit(x);
}

void map_to_ellipsoid(TriangleMesh& mesh, const EllipsoidShape& shape) {
  for (auto& x : mesh.positions) {
    const Vec3 p = unit(x);
    x = {shape.semi_axes.x * p.x, shape.semi_axes.y * p.y, shape.semi_axes.z * p.z};
  }
}

void map_to_biconcave(TriangleMesh& mesh, const BiconcaveShape& shape) {
  // eq. 4.21 with cos(phi) cos(psi) = px, cos(phi) sin(psi) = py, sin(phi) = pz.
  for (auto& x : mesh.positions) {
    const Vec3 p = unit(x);
    const double c2 = p.x * p.x + p.y * p.y;  // cos^2(phi)
    const double thickness = shape.alpha1 + shape.alpha2 * c2 + shape.alpha3 * c2 * c2;
    x = {shape.radius * p.x, shape.radius * p.y, 0.5 * shape.radius * p.z * thickness};
  }
}

void inflate(TriangleMesh& mesh, double stretch) {
  if (!(stretch > 0.0))
    throw std::invalid_argument("inflate: stretch must be > 0, got " + std::to_string(stretch));
  Vec3 centre;
  for (const auto& x : mesh.positions) centre += x;
  centre = centre / static_cast<double>(mesh.positions.size());
  for (auto& x : mesh.positions) x = centre + stretch * (x - centre);
}

void place(std::vector<Vec3>& positions, const Quaternion& orientation, const Vec3& position) {
  for (auto& x : positions) x = rotate(orientation, x) + position;
}

void write_obj(const std::filesystem::path& path, const TriangleMesh& mesh) {
  io::write_file_atomically(path, [&](std::ostream& out) {
    out.precision(17);
    out << "# sanguis membrane: " << mesh.node_count() << " nodes, " << mesh.triangle_count()
        << " triangles\n";
    for (const auto& x : mesh.positions) out << "v " << x.x << ' ' << x.y << ' ' << x.z << '\n';
    for (const auto& t : mesh.triangles)
      out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
  });
}

TriangleMesh read_obj(const std::filesystem::path& path) {
  const io::SurfaceMesh s = io::read_obj(path);
  TriangleMesh m;
  m.positions = s.vertices;
  m.triangles.reserve(s.triangles.size());
  for (const auto& t : s.triangles) {
    for (const auto i : t)
      if (i >= s.vertices.size())
        throw std::runtime_error(path.string() + ": face index " + std::to_string(i + 1) +
                                 " beyond the " + std::to_string(s.vertices.size()) + " vertices");
    m.triangles.push_back(
        {static_cast<NodeIndex>(t[0]), static_cast<NodeIndex>(t[1]), static_cast<NodeIndex>(t[2])});
  }
  return m;
}

void write_vtp(const std::filesystem::path& path, const TriangleMesh& mesh,
               const std::vector<MeshField>& triangle_fields,
               const std::vector<MeshField>& node_fields) {
  io::PolyMesh poly;
  poly.points = mesh.positions;
  poly.polygons.reserve(mesh.triangle_count());
  for (const auto& t : mesh.triangles) poly.polygons.push_back({t[0], t[1], t[2]});
  for (const auto& f : triangle_fields) poly.cell_data.push_back({f.name, f.components, f.values});
  for (const auto& f : node_fields) poly.point_data.push_back({f.name, f.components, f.values});
  io::write_polymesh_vtp(path, poly);
}

}  // namespace sanguis::membrane
