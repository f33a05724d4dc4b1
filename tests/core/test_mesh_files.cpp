// STL (ASCII and binary, auto-detected, vertices merged) and OBJ (polygons as
// fans, negative and slash-form indices) readers on small files written to a
// temporary folder; malformed files give errors naming the file and line.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

#include "core/io/mesh_files.hpp"

namespace sanguis::io {
namespace {

namespace fs = std::filesystem;

class MeshFilesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string test_name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::random_device entropy;
    directory_ = fs::temp_directory_path() /
                 ("sanguis_test_mesh_" + test_name + "_" + std::to_string(entropy()));
    fs::create_directories(directory_);
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(directory_, ignored);
  }
  fs::path write(const std::string& name, const std::string& bytes) const {
    const fs::path path = directory_ / name;
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }
  // The error message of reading `path` with `reader`.
  template <class Reader>
  static std::string error_of(Reader reader, const fs::path& path) {
    try {
      reader(path);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "no error";
  }
  fs::path directory_;
};

// Unit cube [0,1]^3 as 12 outward facets (corner i: bit 0 x, bit 1 y, bit 2 z).
std::vector<std::array<Vec3, 3>> cube_facets() {
  const auto corner = [](int i) {
    return Vec3{double(i & 1), double((i >> 1) & 1), double((i >> 2) & 1)};
  };
  const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  std::vector<std::array<Vec3, 3>> facets;
  for (const auto& q : quads) {
    facets.push_back({corner(q[0]), corner(q[1]), corner(q[2])});
    facets.push_back({corner(q[0]), corner(q[2]), corner(q[3])});
  }
  return facets;
}

std::string ascii_stl(const std::vector<std::array<Vec3, 3>>& facets) {
  std::string text = "solid cube exported by a test\n";
  for (const auto& f : facets) {
    text += "  facet normal 0 0 0\n    outer loop\n";
    for (const Vec3& v : f)
      text += "      vertex " + std::to_string(v.x) + " " + std::to_string(v.y) + " " +
              std::to_string(v.z) + "\n";
    text += "    endloop\n  endfacet\n";
  }
  return text + "endsolid cube\n";
}

std::string binary_stl(const std::vector<std::array<Vec3, 3>>& facets, const std::string& header) {
  std::string bytes(80, ' ');
  std::memcpy(bytes.data(), header.data(), std::min<std::size_t>(header.size(), 80));
  const auto count = static_cast<std::uint32_t>(facets.size());
  bytes.append(reinterpret_cast<const char*>(&count), 4);  // little-endian host
  for (const auto& f : facets) {
    const float normal[3] = {0, 0, 0};
    bytes.append(reinterpret_cast<const char*>(normal), 12);
    for (const Vec3& v : f) {
      const float xyz[3] = {float(v.x), float(v.y), float(v.z)};
      bytes.append(reinterpret_cast<const char*>(xyz), 12);
    }
    bytes.append(2, '\0');  // attribute byte count
  }
  return bytes;
}

double volume(const SurfaceMesh& m) {
  double six_v = 0.0;
  for (const auto& t : m.triangles)
    six_v += dot(m.vertices[t[0]], cross(m.vertices[t[1]], m.vertices[t[2]]));
  return six_v / 6.0;
}

TEST_F(MeshFilesTest, AsciiStlCubeIsMergedToEightVertices) {
  const SurfaceMesh m = read_stl(write("cube.stl", ascii_stl(cube_facets())));
  EXPECT_EQ(m.vertices.size(), 8u);
  EXPECT_EQ(m.triangles.size(), 12u);
  EXPECT_NEAR(volume(m), 1.0, 1e-15);  // orientation kept: outward
}

TEST_F(MeshFilesTest, BinaryStlIsDetectedEvenWithASolidHeader) {
  for (const std::string header : {"binary cube", "solid but actually binary"}) {
    const SurfaceMesh m = read_stl(write("cube.stl", binary_stl(cube_facets(), header)));
    EXPECT_EQ(m.vertices.size(), 8u);
    EXPECT_EQ(m.triangles.size(), 12u);
    EXPECT_NEAR(volume(m), 1.0, 1e-15);
  }
}

TEST_F(MeshFilesTest, StlMergeToleranceIsRelativeToTheMeshSize) {
  // One facet writes the corner (0, 0, 0) as (1e-12, 0, 0).
  std::string text = ascii_stl(cube_facets());
  const std::string first = "vertex 0.000000 0.000000 0.000000";
  text.replace(text.find(first), first.size(), "vertex 1e-12 0 0");
  const fs::path jittered = write("jittered.stl", text);
  EXPECT_EQ(read_stl(jittered).vertices.size(), 8u);         // merged: 1e-9 x diagonal
  EXPECT_EQ(read_stl(jittered, 0.0).vertices.size(), 9u);    // bitwise-equal only
  EXPECT_EQ(read_stl(jittered, 1e-13).vertices.size(), 9u);  // 1.7e-13 < 1e-12
}

TEST_F(MeshFilesTest, MalformedStlNamesFileAndLine) {
  std::string text = ascii_stl(cube_facets());
  const std::size_t third = text.find("vertex", text.find("vertex", text.find("vertex") + 1) + 1);
  text.replace(third, 6, "vortex");
  const fs::path bad = write("bad.stl", text);
  const std::string message = error_of([](const fs::path& p) { return read_stl(p); }, bad);
  EXPECT_NE(message.find("bad.stl:6:"), std::string::npos) << message;
  EXPECT_NE(message.find("expected 'vertex', found 'vortex'"), std::string::npos) << message;

  const fs::path number =
      write("number.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 1 2 zz\n");
  EXPECT_NE(error_of([](const fs::path& p) { return read_stl(p); }, number).find("number.stl:4:"),
            std::string::npos);
  const fs::path cut = write("cut.stl", binary_stl(cube_facets(), "binary").substr(0, 300));
  EXPECT_NE(error_of([](const fs::path& p) { return read_stl(p); }, cut).find("not an STL file"),
            std::string::npos);
  EXPECT_NE(error_of([](const fs::path& p) { return read_stl(p); }, directory_ / "missing.stl")
                .find("missing.stl"),
            std::string::npos);
}

TEST_F(MeshFilesTest, ObjPolygonsNegativeAndSlashIndices) {
  const std::string text =
      "# a unit cube with quads\n"
      "o cube\n"
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1 1.0\n"
      "vt 0 0\nvn 0 0 1\n"
      "f 1 5 7 3\n"
      "f 2/1 4/1 8/1 6/1\n"
      "f 1//1 2//1 6//1 5//1\n"
      "f 3/1/1 7/1/1 8/1/1 4/1/1\n"
      "s off\n"
      "f -8 -6 -5 -7\n"  // 1 3 4 2
      "f 5 6 8 7\n";
  const SurfaceMesh m = read_obj(write("cube.obj", text));
  EXPECT_EQ(m.vertices.size(), 8u);
  ASSERT_EQ(m.triangles.size(), 12u);
  EXPECT_EQ(m.triangles[8], (std::array<std::uint32_t, 3>{0, 2, 3}));
  EXPECT_EQ(m.triangles[9], (std::array<std::uint32_t, 3>{0, 3, 1}));
  EXPECT_NEAR(volume(m), 1.0, 1e-15);
  EXPECT_EQ(read_surface_mesh(write("CUBE.OBJ", text)).triangles.size(), 12u);
}

TEST_F(MeshFilesTest, MalformedObjNamesFileAndLine) {
  const auto obj_error = [this](const std::string& name, const std::string& text) {
    return error_of([](const fs::path& p) { return read_obj(p); }, write(name, text));
  };
  std::string e = obj_error("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n");
  EXPECT_NE(e.find("range.obj:5:"), std::string::npos) << e;
  EXPECT_NE(e.find("exceeds the vertex count 3"), std::string::npos) << e;
  e = obj_error("coord.obj", "v 0 0 0\nv 1 nan? 0\n");
  EXPECT_NE(e.find("coord.obj:2: bad vertex coordinate 'nan?'"), std::string::npos) << e;
  e = obj_error("short.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n");
  EXPECT_NE(e.find("short.obj:3:"), std::string::npos) << e;
  e = obj_error("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
  EXPECT_NE(e.find("zero.obj:4: bad face index '0'"), std::string::npos) << e;
  e = obj_error("back.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n");
  EXPECT_NE(e.find("back.obj:4:"), std::string::npos) << e;
  e = error_of([](const fs::path& p) { return read_surface_mesh(p); }, write("mesh.ply", "ply\n"));
  EXPECT_NE(e.find("unknown mesh format '.ply'"), std::string::npos) << e;
}

}  // namespace
}  // namespace sanguis::io
