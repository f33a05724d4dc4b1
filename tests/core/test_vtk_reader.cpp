// io/vtk_reader: what io/vtk writes reads back bit for bit; foreign or broken
// files are refused with the file named.
#include "core/io/vtk_reader.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

namespace sanguis::io {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("sanguis_vtk_reader_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(VtkReader, PointCloudRoundTripsBitForBit) {
  const fs::path dir = temp_dir("cloud");
  PointCloud cloud;
  cloud.points = {{0.1, -2.5e-300, 3.0}, {std::nextafter(1.0, 2.0), 0.0, -0.0}};
  cloud.point_data = {{"radius", 1, {1e-3, std::numeric_limits<double>::denorm_min()}},
                      {"velocity", 3, {1, 2, 3, 4, 5, 6}}};
  cloud.int_point_data = {{"id", 1, {7, -9}}};
  write_point_cloud_vtu(dir / "a.vtu", cloud);
  const PointCloud back = read_point_cloud_vtu(dir / "a.vtu");
  ASSERT_EQ(back.points.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(std::bit_cast<std::uint64_t>(back.points[k].x),
              std::bit_cast<std::uint64_t>(cloud.points[k].x));
    EXPECT_EQ(std::bit_cast<std::uint64_t>(back.points[k].z),
              std::bit_cast<std::uint64_t>(cloud.points[k].z));
  }
  EXPECT_EQ(find_array(back.point_data, "radius").values, cloud.point_data[0].values);
  EXPECT_EQ(find_array(back.point_data, "velocity").components, 3);
  EXPECT_EQ(find_array(back.point_data, "velocity").values, cloud.point_data[1].values);
  EXPECT_EQ(find_array(back.int_point_data, "id").values, cloud.int_point_data[0].values);
  EXPECT_THROW(find_array(back.point_data, "mass"), std::runtime_error);
}

TEST(VtkReader, PolyMeshRoundTripsLinesPolygonsAndCellData) {
  const fs::path dir = temp_dir("mesh");
  PolyMesh mesh;
  mesh.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  mesh.lines = {{0, 3}};
  mesh.polygons = {{0, 1, 2}, {1, 2, 3, 0}};
  mesh.cell_data = {{"force_magnitude", 1, {1.5, 2.5, 3.5}}};
  mesh.int_cell_data = {{"first_id", 1, {4, 5, 6}}};
  mesh.point_data = {{"force_magnitude", 3, {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12}}};
  write_polymesh_vtp(dir / "m.vtp", mesh);
  const PolyMesh back = read_polymesh_vtp(dir / "m.vtp");
  EXPECT_EQ(back.lines, mesh.lines);
  EXPECT_EQ(back.polygons, mesh.polygons);
  EXPECT_EQ(find_array(back.cell_data, "force_magnitude").values, mesh.cell_data[0].values);
  EXPECT_EQ(find_array(back.int_cell_data, "first_id").values, mesh.int_cell_data[0].values);
  // Point arrays may share a name with a cell array.
  EXPECT_EQ(find_array(back.point_data, "force_magnitude").values, mesh.point_data[0].values);
  mesh.point_data[0].values.pop_back();
  EXPECT_THROW(write_polymesh_vtp(dir / "bad.vtp", mesh), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.vtp"));
}

TEST(VtkReader, PvdListsFramesRelativeToItsFolder) {
  const fs::path dir = temp_dir("pvd");
  PvdIndex index(dir / "particles.pvd");
  index.add(0.0, "particles/p0.vtu");
  index.add(0.25, "particles/p1.vtu");
  index.write();
  const auto frames = read_pvd(dir / "particles.pvd");
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[1].time, 0.25);
  EXPECT_EQ(fs::path(frames[1].dataset), dir / "particles/p1.vtu");
  EXPECT_THROW(read_pvd(dir / "missing.pvd"), std::runtime_error);
}

TEST(VtkReader, RefusesOtherFilesNamingThem) {
  const fs::path dir = temp_dir("bad");
  { std::ofstream(dir / "not.vtu") << "hello"; }
  try {
    read_point_cloud_vtu(dir / "not.vtu");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not.vtu"), std::string::npos);
  }
  EXPECT_THROW(read_point_cloud_vtu(dir / "absent.vtu"), std::runtime_error);
  // A truncated payload.
  PointCloud cloud;
  cloud.points = {{1, 2, 3}};
  write_point_cloud_vtu(dir / "t.vtu", cloud);
  std::ifstream in(dir / "t.vtu");
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const std::size_t at = text.find("format=\"binary\">") + 16;
  const std::size_t end = text.find("</DataArray>", at);
  text.erase(at + (end - at) / 2, (end - at) / 2);
  std::ofstream(dir / "t.vtu", std::ios::trunc) << text;
  EXPECT_THROW(read_point_cloud_vtu(dir / "t.vtu"), std::runtime_error);
}

}  // namespace
}  // namespace sanguis::io
