// TriangleMesh: icosphere counts and orientation, shape maps (sphere,
// ellipsoid, biconcave eq. 4.21), pre-inflation, placement, OBJ round trip and
// VTK output. Tolerances: round-off (1e-12 relative).
#include "membrane/triangle_mesh.hpp"

#include <gtest/gtest.h>

#include "core/io/vtk_reader.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "membrane/measures.hpp"

using namespace sanguis;
using namespace sanguis::membrane;

namespace {
std::filesystem::path temp_path(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("sanguis_membrane_" + name);
}
}  // namespace

TEST(TriangleMesh, IcosphereCountsAndUnitRadius) {
  for (int k = 0; k <= 5; ++k) {
    const TriangleMesh m = icosphere(k);
    const std::size_t p = std::size_t{1} << (2 * k);  // 4^k
    EXPECT_EQ(m.triangle_count(), 20 * p);
    EXPECT_EQ(m.node_count(), 10 * p + 2);
    for (const auto& x : m.positions) ASSERT_NEAR(norm(x), 1.0, 1e-14);
    EXPECT_EQ(subdivisions_for_triangles(static_cast<std::int64_t>(m.triangle_count())), k);
  }
  EXPECT_THROW(subdivisions_for_triangles(1000), std::invalid_argument);
  EXPECT_THROW(icosphere(-1), std::invalid_argument);
}

TEST(TriangleMesh, TrianglesPointOutwardAndPolesAreNodes) {
  const TriangleMesh m = icosphere(3);
  for (const auto& t : m.triangles) {
    const Vec3 &a = m.positions[t[0]], &b = m.positions[t[1]], &c = m.positions[t[2]];
    ASSERT_GT(dot(cross(b - a, c - a), a + b + c), 0.0);
  }
  EXPECT_EQ(m.positions[0], (Vec3{0, 0, 1}));
  EXPECT_EQ(m.positions[11], (Vec3{0, 0, -1}));
  // The volume of the inscribed polyhedron approaches 4/3 pi from below.
  const double v = enclosed_volume(m.triangles, m.positions);
  EXPECT_LT(v, 4.0 / 3.0 * std::numbers::pi);
  EXPECT_GT(v, 0.97 * 4.0 / 3.0 * std::numbers::pi);
}

TEST(TriangleMesh, ShapeMapsPutNodesOnTheSurface) {
  TriangleMesh sphere = icosphere(2);
  map_to_sphere(sphere, {2.5});
  for (const auto& x : sphere.positions) EXPECT_NEAR(norm(x), 2.5, 1e-14);

  TriangleMesh ellipsoid = icosphere(2);
  map_to_ellipsoid(ellipsoid, {{3.0, 2.0, 1.0}});
  for (const auto& x : ellipsoid.positions)
    EXPECT_NEAR(x.x * x.x / 9 + x.y * x.y / 4 + x.z * x.z, 1.0, 1e-13);

  // eq. 4.21: z = (R/2) sin(phi) (a1 + a2 cos^2 + a3 cos^4), r = R cos(phi).
  const BiconcaveShape rbc{3.91, 0.207, 2.003, -1.123};
  const TriangleMesh unit_sphere = icosphere(3);
  TriangleMesh cell = unit_sphere;
  map_to_biconcave(cell, rbc);
  double thickest = 0.0;
  for (std::size_t i = 0; i < cell.node_count(); ++i) {
    // The node of latitude phi: cos(phi) cos(psi) = px, cos(phi) sin(psi) = py, sin(phi) = pz.
    const Vec3 p = unit_sphere.positions[i], x = cell.positions[i];
    const double c2 = p.x * p.x + p.y * p.y;
    EXPECT_NEAR(x.x, rbc.radius * p.x, 1e-13);
    EXPECT_NEAR(x.y, rbc.radius * p.y, 1e-13);
    EXPECT_NEAR(x.z, 0.5 * rbc.radius * p.z * (0.207 + 2.003 * c2 - 1.123 * c2 * c2), 1e-13);
    thickest = std::max(thickest, 2.0 * std::fabs(x.z));
  }
  // Evans & Fung: dimple 2 * 0.207 * R/2 = 0.81 um at the poles, about 2.57 um at the thickest.
  EXPECT_NEAR(2.0 * cell.positions[0].z, 0.207 * 3.91, 1e-12);
  EXPECT_NEAR(thickest, 2.57, 0.02);
}

TEST(TriangleMesh, InflationScalesAboutTheCentroidAndPlacementMoves) {
  TriangleMesh m = icosphere(2);
  map_to_sphere(m, {1.0});
  for (auto& x : m.positions) x += Vec3{1, 2, 3};
  inflate(m, 1.1);
  for (const auto& x : m.positions) EXPECT_NEAR(norm(x - Vec3{1, 2, 3}), 1.1, 1e-13);
  EXPECT_THROW(inflate(m, 0.0), std::invalid_argument);

  std::vector<Vec3> x{{1, 0, 0}};
  place(x, Quaternion::from_axis_angle({0, 0, 1}, 0.5 * std::numbers::pi), {0, 0, 5});
  EXPECT_NEAR(x[0].x, 0.0, 1e-15);
  EXPECT_NEAR(x[0].y, 1.0, 1e-15);
  EXPECT_NEAR(x[0].z, 5.0, 1e-15);
}

TEST(TriangleMesh, ObjRoundTripIsExact) {
  TriangleMesh m = icosphere(2);
  map_to_biconcave(m, {});
  const auto path = temp_path("roundtrip.obj");
  write_obj(path, m);
  const TriangleMesh back = read_obj(path);
  ASSERT_EQ(back.node_count(), m.node_count());
  ASSERT_EQ(back.triangles, m.triangles);
  for (std::size_t i = 0; i < m.node_count(); ++i) EXPECT_EQ(back.positions[i], m.positions[i]);
  std::filesystem::remove(path);
}

TEST(TriangleMesh, ObjWithBadIndexIsRejected) {
  const auto path = temp_path("bad.obj");
  {
    std::ofstream out(path);
    out << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n";
  }
  EXPECT_THROW(read_obj(path), std::runtime_error);
  std::filesystem::remove(path);
}

TEST(TriangleMesh, WritesVtpWithTriangleData) {
  const TriangleMesh m = icosphere(1);
  const auto path = temp_path("mesh.vtp");
  write_vtp(path, m, {{"tension", 1, std::vector<double>(m.triangle_count(), 2.0)}});
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("NumberOfPolys=\"80\""), std::string::npos);
  EXPECT_NE(text.find("Name=\"tension\""), std::string::npos);
  std::filesystem::remove(path);
  EXPECT_THROW(write_vtp(path, m, {{"bad", 1, {1.0}}}), std::invalid_argument);
}

TEST(TriangleMesh, WritesVtpWithNodeData) {
  const TriangleMesh m = icosphere(1);
  const auto path = temp_path("nodes.vtp");
  std::vector<double> force(3 * m.node_count());
  for (std::size_t k = 0; k < force.size(); ++k) force[k] = static_cast<double>(k);
  write_vtp(path, m, {}, {{"force", 3, force}});
  const io::PolyMesh back = io::read_polymesh_vtp(path);
  EXPECT_EQ(io::find_array(back.point_data, "force").values, force);
  EXPECT_EQ(back.polygons.size(), m.triangle_count());
  std::filesystem::remove(path);
  EXPECT_THROW(write_vtp(path, m, {}, {{"force", 3, {1.0}}}), std::invalid_argument);
}
