// Tests for the VTK XML writers (core/io/vtk.hpp) and the atomic file helper
// they rely on (core/io/atomic_file.hpp). Files are re-read as text, parsed
// by a small strict XML parser and their base64 payloads decoded, so the
// checks cover what ParaView would actually read.
#include <gtest/gtest.h>

#include <bit>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/io/atomic_file.hpp"
#include "core/io/vtk.hpp"

namespace sanguis::io {
namespace {

namespace fs = std::filesystem;

// --- Test fixtures and helpers ------------------------------------------------

/// `call` throws an `Error` whose message contains `needle` (an array's name, a path).
template <typename Error, typename Call>
void expect_throw_naming(Call&& call, const std::string& needle) {
  try {
    call();
    FAIL() << "expected an exception naming " << needle;
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find(needle), std::string::npos) << error.what();
  }
}

// A fresh directory per test under the system temp dir, removed afterwards.
class VtkWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string test_name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::random_device entropy;
    directory_ = fs::temp_directory_path() /
                 ("sanguis_test_vtk_" + test_name + "_" + std::to_string(entropy()));
    fs::create_directories(directory_);
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(directory_, ignored);
  }
  fs::path directory_;
};

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in) << "cannot read " << path;
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Minimal strict XML parser: prolog, elements, attributes, text. Throws on
// anything malformed (unbalanced tags, unquoted or duplicate attributes,
// stray '<' or '&', content after the root).
struct XmlElement {
  std::string name;
  std::map<std::string, std::string> attributes;
  std::vector<std::unique_ptr<XmlElement>> children;
  std::string text;

  const XmlElement& child(const std::string& child_name) const {
    for (const auto& element : children) {
      if (element->name == child_name) return *element;
    }
    throw std::runtime_error("<" + name + "> has no child <" + child_name + ">");
  }
  // The DataArray child with Name="array_name".
  const XmlElement& data_array(const std::string& array_name) const {
    for (const auto& element : children) {
      if (element->name == "DataArray" && element->attributes.count("Name") &&
          element->attributes.at("Name") == array_name) {
        return *element;
      }
    }
    throw std::runtime_error("<" + name + "> has no DataArray '" + array_name + "'");
  }
  std::vector<std::string> child_array_names() const {
    std::vector<std::string> names;
    for (const auto& element : children) names.push_back(element->attributes.at("Name"));
    return names;
  }
};

class XmlParser {
 public:
  explicit XmlParser(std::string text) : text_(std::move(text)) {}

  std::unique_ptr<XmlElement> parse_document() {
    skip_spaces();
    if (text_.compare(position_, 5, "<?xml") == 0) {
      const std::size_t end = text_.find("?>", position_);
      if (end == std::string::npos) fail("unterminated prolog");
      position_ = end + 2;
    }
    skip_spaces();
    auto root = parse_element();
    skip_spaces();
    if (position_ != text_.size()) fail("content after the root element");
    return root;
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw std::runtime_error("malformed XML at offset " + std::to_string(position_) + ": " + why);
  }
  bool at_end() const { return position_ >= text_.size(); }
  char peek() const { return at_end() ? '\0' : text_[position_]; }
  void skip_spaces() {
    while (!at_end() && std::isspace(static_cast<unsigned char>(peek()))) ++position_;
  }
  void expect(char c) {
    if (peek() != c) fail(std::string("expected '") + c + "'");
    ++position_;
  }
  std::string parse_name() {
    const std::size_t begin = position_;
    while (!at_end() && (std::isalnum(static_cast<unsigned char>(peek())) || peek() == '_' ||
                         peek() == '-' || peek() == ':' || peek() == '.')) {
      ++position_;
    }
    if (position_ == begin) fail("expected a name");
    return text_.substr(begin, position_ - begin);
  }
  void check_character_data(const std::string& data) const {
    for (std::size_t i = 0; i < data.size(); ++i) {
      if (data[i] == '<') fail("'<' in character data");
      if (data[i] == '&') {
        const std::size_t semicolon = data.find(';', i);
        const std::string entity = data.substr(i, semicolon - i + 1);
        if (entity != "&amp;" && entity != "&lt;" && entity != "&gt;" && entity != "&quot;" &&
            entity != "&apos;") {
          fail("bad entity " + entity);
        }
      }
    }
  }

  std::unique_ptr<XmlElement> parse_element() {
    expect('<');
    auto element = std::make_unique<XmlElement>();
    element->name = parse_name();
    while (true) {
      skip_spaces();
      if (peek() == '/') {
        ++position_;
        expect('>');
        return element;
      }
      if (peek() == '>') {
        ++position_;
        break;
      }
      const std::string attribute = parse_name();
      skip_spaces();
      expect('=');
      skip_spaces();
      const char quote = peek();
      if (quote != '"' && quote != '\'') fail("unquoted attribute " + attribute);
      ++position_;
      const std::size_t end = text_.find(quote, position_);
      if (end == std::string::npos) fail("unterminated attribute " + attribute);
      const std::string value = text_.substr(position_, end - position_);
      check_character_data(value);
      if (!element->attributes.emplace(attribute, value).second) {
        fail("duplicate attribute " + attribute);
      }
      position_ = end + 1;
    }
    while (true) {
      const std::size_t text_end = text_.find('<', position_);
      if (text_end == std::string::npos) fail("unclosed element <" + element->name + ">");
      const std::string data = text_.substr(position_, text_end - position_);
      check_character_data(data);
      element->text += data;
      position_ = text_end;
      if (text_.compare(position_, 2, "</") == 0) {
        position_ += 2;
        const std::string closing = parse_name();
        if (closing != element->name) {
          fail("</" + closing + "> closes <" + element->name + ">");
        }
        skip_spaces();
        expect('>');
        return element;
      }
      element->children.push_back(parse_element());
    }
  }

  std::string text_;
  std::size_t position_ = 0;
};

std::unique_ptr<XmlElement> parse_xml_file(const fs::path& path) {
  return XmlParser(read_text(path)).parse_document();
}

// Strict base64 decoder (whitespace around the payload ignored).
std::vector<std::uint8_t> base64_decode(const std::string& encoded_with_spaces) {
  std::string encoded;
  for (const char c : encoded_with_spaces) {
    if (!std::isspace(static_cast<unsigned char>(c))) encoded += c;
  }
  if (encoded.size() % 4 != 0) throw std::runtime_error("base64 length not a multiple of 4");
  const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<std::uint8_t> bytes;
  for (std::size_t group = 0; group < encoded.size(); group += 4) {
    std::uint32_t bits = 0;
    int padding = 0;
    for (int k = 0; k < 4; ++k) {
      const char c = encoded[group + k];
      std::uint32_t sextet = 0;
      if (c == '=') {
        if (group + 4 != encoded.size() || k < 2) throw std::runtime_error("misplaced padding");
        ++padding;
      } else {
        if (padding > 0) throw std::runtime_error("data after padding");
        const std::size_t index = alphabet.find(c);
        if (index == std::string::npos) throw std::runtime_error("invalid base64 character");
        sextet = static_cast<std::uint32_t>(index);
      }
      bits = (bits << 6) | sextet;
    }
    bytes.push_back(static_cast<std::uint8_t>(bits >> 16));
    if (padding < 2) bytes.push_back(static_cast<std::uint8_t>(bits >> 8));
    if (padding < 1) bytes.push_back(static_cast<std::uint8_t>(bits));
  }
  return bytes;
}

std::uint64_t read_uint64_little_endian(const std::vector<std::uint8_t>& bytes,
                                        std::size_t offset) {
  std::uint64_t value = 0;
  for (int k = 7; k >= 0; --k) value = (value << 8) | bytes.at(offset + k);
  return value;
}

// Decodes a binary DataArray: checks the UInt64 byte-count header against the
// payload and returns the raw 8-byte words that follow it.
std::vector<std::uint64_t> decode_words(const XmlElement& data_array) {
  EXPECT_EQ(data_array.attributes.at("format"), "binary");
  const std::vector<std::uint8_t> bytes = base64_decode(data_array.text);
  EXPECT_GE(bytes.size(), 8u);
  const std::uint64_t byte_count = read_uint64_little_endian(bytes, 0);
  EXPECT_EQ(byte_count, bytes.size() - 8) << "header byte count vs payload";
  EXPECT_EQ(byte_count % 8, 0u);
  std::vector<std::uint64_t> words;
  for (std::size_t offset = 8; offset + 8 <= bytes.size(); offset += 8) {
    words.push_back(read_uint64_little_endian(bytes, offset));
  }
  return words;
}

std::vector<std::uint64_t> bits_of(const std::vector<double>& values) {
  std::vector<std::uint64_t> bits;
  for (const double value : values) bits.push_back(std::bit_cast<std::uint64_t>(value));
  return bits;
}

std::vector<std::int64_t> as_int64(const std::vector<std::uint64_t>& words) {
  std::vector<std::int64_t> values;
  for (const std::uint64_t word : words) values.push_back(static_cast<std::int64_t>(word));
  return values;
}

std::vector<double> as_double(const std::vector<std::uint64_t>& words) {
  std::vector<double> values;
  for (const std::uint64_t word : words) values.push_back(std::bit_cast<double>(word));
  return values;
}

PointCloud make_three_particles() {
  PointCloud cloud;
  cloud.points = {{0.0, 0.0, 0.0}, {1.5, -2.25, 3.0}, {0.1, 1e-300, -7.0}};
  // Values chosen to catch lossy encodings: non-representable decimal,
  // subnormal, negative zero, extreme exponent.
  cloud.point_data.push_back(
      {"radius", 1, {0.1, std::numeric_limits<double>::denorm_min(), 1.0 / 3.0}});
  cloud.point_data.push_back({"velocity", 3, {1, 2, 3, -0.0, 5e-324, 6, 1e308, -8, 9.5}});
  cloud.int_point_data.push_back({"id", 1, {7, -5, std::int64_t{1} << 40}});
  return cloud;
}

// --- write_file_atomically ------------------------------------------------------

TEST_F(VtkWriterTest, AtomicWriteReplacesFileAndLeavesNoTemporary) {
  const fs::path path = directory_ / "data.txt";
  write_file_atomically(path, [](std::ostream& out) { out << "first"; });
  write_file_atomically(path, [](std::ostream& out) { out << "second version"; });
  EXPECT_EQ(read_text(path), "second version");
  EXPECT_FALSE(fs::exists(directory_ / "data.txt.tmp"));
}

TEST_F(VtkWriterTest, AtomicWriteKeepsOldFileWhenWriterThrows) {
  const fs::path path = directory_ / "data.txt";
  write_file_atomically(path, [](std::ostream& out) { out << "complete"; });
  EXPECT_THROW(write_file_atomically(path,
                                     [](std::ostream& out) {
                                       out << "half";
                                       throw std::logic_error("interrupted");
                                     }),
               std::logic_error);
  EXPECT_EQ(read_text(path), "complete");
  EXPECT_FALSE(fs::exists(directory_ / "data.txt.tmp"));
}

TEST_F(VtkWriterTest, AtomicWriteIntoMissingDirectoryThrowsNamingThePath) {
  const fs::path path = directory_ / "no_such_dir" / "frame.vtu";
  expect_throw_naming<std::runtime_error>(
      [&] { write_file_atomically(path, [](std::ostream& out) { out << "x"; }); }, path.string());
}

// --- write_point_cloud_vtu ---------------------------------------------------------

TEST_F(VtkWriterTest, PointCloudIsWellFormedUnstructuredGrid) {
  const fs::path path = directory_ / "particles.vtu";
  write_point_cloud_vtu(path, make_three_particles());
  EXPECT_FALSE(fs::exists(directory_ / "particles.vtu.tmp"));

  const auto root = parse_xml_file(path);
  EXPECT_EQ(root->name, "VTKFile");
  EXPECT_EQ(root->attributes.at("type"), "UnstructuredGrid");
  EXPECT_EQ(root->attributes.at("byte_order"), "LittleEndian");
  EXPECT_EQ(root->attributes.at("header_type"), "UInt64");
  EXPECT_EQ(root->attributes.count("compressor"), 0u);

  const XmlElement& piece = root->child("UnstructuredGrid").child("Piece");
  EXPECT_EQ(piece.attributes.at("NumberOfPoints"), "3");
  EXPECT_EQ(piece.attributes.at("NumberOfCells"), "3");

  const XmlElement& point_data = piece.child("PointData");
  EXPECT_EQ(point_data.child_array_names(), (std::vector<std::string>{"radius", "velocity", "id"}));
  EXPECT_EQ(point_data.data_array("radius").attributes.at("type"), "Float64");
  EXPECT_EQ(point_data.data_array("velocity").attributes.at("NumberOfComponents"), "3");
  EXPECT_EQ(point_data.data_array("id").attributes.at("type"), "Int64");

  const XmlElement& points = piece.child("Points").child("DataArray");
  EXPECT_EQ(points.attributes.at("type"), "Float64");
  EXPECT_EQ(points.attributes.at("NumberOfComponents"), "3");
}

TEST_F(VtkWriterTest, PointCloudArraysDecodeBitForBit) {
  const fs::path path = directory_ / "particles.vtu";
  const PointCloud cloud = make_three_particles();
  write_point_cloud_vtu(path, cloud);
  const auto root = parse_xml_file(path);
  const XmlElement& piece = root->child("UnstructuredGrid").child("Piece");

  EXPECT_EQ(decode_words(piece.child("PointData").data_array("radius")),
            bits_of(cloud.point_data[0].values));
  EXPECT_EQ(decode_words(piece.child("PointData").data_array("velocity")),
            bits_of(cloud.point_data[1].values));
  EXPECT_EQ(as_int64(decode_words(piece.child("PointData").data_array("id"))),
            cloud.int_point_data[0].values);

  std::vector<double> coordinates;
  for (const Vec3& point : cloud.points)
    coordinates.insert(coordinates.end(), {point.x, point.y, point.z});
  EXPECT_EQ(decode_words(piece.child("Points").child("DataArray")), bits_of(coordinates));
}

TEST_F(VtkWriterTest, PointCloudHasOneVertexCellPerPoint) {
  const fs::path path = directory_ / "particles.vtu";
  write_point_cloud_vtu(path, make_three_particles());
  const auto root = parse_xml_file(path);
  const XmlElement& cells = root->child("UnstructuredGrid").child("Piece").child("Cells");

  EXPECT_EQ(as_int64(decode_words(cells.data_array("connectivity"))),
            (std::vector<std::int64_t>{0, 1, 2}));
  EXPECT_EQ(as_int64(decode_words(cells.data_array("offsets"))),
            (std::vector<std::int64_t>{1, 2, 3}));

  const XmlElement& types = cells.data_array("types");
  EXPECT_EQ(types.attributes.at("type"), "UInt8");
  const std::vector<std::uint8_t> type_bytes = base64_decode(types.text);
  ASSERT_EQ(type_bytes.size(), 8u + 3u);
  EXPECT_EQ(read_uint64_little_endian(type_bytes, 0), 3u);
  for (std::size_t i = 8; i < type_bytes.size(); ++i) EXPECT_EQ(type_bytes[i], 1) << "VTK_VERTEX";
}

TEST_F(VtkWriterTest, EmptyPointCloudIsValid) {
  const fs::path path = directory_ / "empty.vtu";
  PointCloud cloud;
  cloud.point_data.push_back({"radius", 1, {}});
  write_point_cloud_vtu(path, cloud);

  const auto root = parse_xml_file(path);
  const XmlElement& piece = root->child("UnstructuredGrid").child("Piece");
  EXPECT_EQ(piece.attributes.at("NumberOfPoints"), "0");
  EXPECT_EQ(piece.attributes.at("NumberOfCells"), "0");
  EXPECT_TRUE(decode_words(piece.child("Points").child("DataArray")).empty());
  EXPECT_TRUE(decode_words(piece.child("PointData").data_array("radius")).empty());
  EXPECT_TRUE(decode_words(piece.child("Cells").data_array("offsets")).empty());
}

TEST_F(VtkWriterTest, ArrayNamesAreXmlEscaped) {
  const fs::path path = directory_ / "names.vtu";
  PointCloud cloud;
  cloud.points = {{1, 2, 3}};
  cloud.point_data.push_back({"a<b & \"c\"", 1, {4.0}});
  write_point_cloud_vtu(path, cloud);
  const auto root = parse_xml_file(path);  // would throw on a raw '<' or '"'
  const XmlElement& point_data = root->child("UnstructuredGrid").child("Piece").child("PointData");
  EXPECT_EQ(point_data.child_array_names(),
            (std::vector<std::string>{"a&lt;b &amp; &quot;c&quot;"}));
}

TEST_F(VtkWriterTest, PointDataSizeMismatchThrowsNamingTheArray) {
  const fs::path path = directory_ / "bad.vtu";
  PointCloud cloud = make_three_particles();
  cloud.point_data[1].values.pop_back();  // velocity: 8 values for 3 x 3
  expect_throw_naming<std::invalid_argument>([&] { write_point_cloud_vtu(path, cloud); },
                                             "'velocity'");
  EXPECT_FALSE(fs::exists(path)) << "nothing is written for invalid input";

  cloud = make_three_particles();
  cloud.int_point_data[0].values.push_back(1);
  expect_throw_naming<std::invalid_argument>([&] { write_point_cloud_vtu(path, cloud); }, "'id'");
}

TEST_F(VtkWriterTest, DuplicateOrEmptyArrayNamesThrow) {
  PointCloud cloud = make_three_particles();
  cloud.int_point_data.push_back({"radius", 1, {1, 2, 3}});
  EXPECT_THROW(write_point_cloud_vtu(directory_ / "dup.vtu", cloud), std::invalid_argument);
  cloud = make_three_particles();
  cloud.point_data[0].name.clear();
  EXPECT_THROW(write_point_cloud_vtu(directory_ / "unnamed.vtu", cloud), std::invalid_argument);
}

// --- write_polymesh_vtp ---------------------------------------------------------------

// A unit square split into a triangle and a quad... plus one polyline.
PolyMesh make_mesh() {
  PolyMesh mesh;
  mesh.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 2, 0}};
  mesh.polygons = {{0, 1, 2, 3}, {3, 2, 4}};
  mesh.lines = {{0, 2, 4}};
  // One tuple per cell, lines first: [line, quad, triangle].
  mesh.cell_data.push_back({"normal", 3, {0, 0, 0, 0, 0, 1, 0, 0, -1}});
  mesh.int_cell_data.push_back({"kind", 1, {10, 20, 30}});
  return mesh;
}

TEST_F(VtkWriterTest, PolyMeshIsWellFormedPolyData) {
  const fs::path path = directory_ / "walls.vtp";
  write_polymesh_vtp(path, make_mesh());
  const auto root = parse_xml_file(path);
  EXPECT_EQ(root->attributes.at("type"), "PolyData");
  EXPECT_EQ(root->attributes.at("header_type"), "UInt64");

  const XmlElement& piece = root->child("PolyData").child("Piece");
  EXPECT_EQ(piece.attributes.at("NumberOfPoints"), "5");
  EXPECT_EQ(piece.attributes.at("NumberOfPolys"), "2");
  EXPECT_EQ(piece.attributes.at("NumberOfLines"), "1");
  EXPECT_EQ(piece.attributes.at("NumberOfVerts"), "0");
  EXPECT_EQ(piece.attributes.at("NumberOfStrips"), "0");

  const XmlElement& polys = piece.child("Polys");
  EXPECT_EQ(as_int64(decode_words(polys.data_array("connectivity"))),
            (std::vector<std::int64_t>{0, 1, 2, 3, 3, 2, 4}));
  EXPECT_EQ(as_int64(decode_words(polys.data_array("offsets"))), (std::vector<std::int64_t>{4, 7}));
  const XmlElement& lines = piece.child("Lines");
  EXPECT_EQ(as_int64(decode_words(lines.data_array("connectivity"))),
            (std::vector<std::int64_t>{0, 2, 4}));
  EXPECT_EQ(as_int64(decode_words(lines.data_array("offsets"))), (std::vector<std::int64_t>{3}));
}

TEST_F(VtkWriterTest, PolyMeshCellDataIsWrittenInLinesThenPolygonsOrder) {
  const fs::path path = directory_ / "walls.vtp";
  const PolyMesh mesh = make_mesh();
  write_polymesh_vtp(path, mesh);
  const auto root = parse_xml_file(path);
  const XmlElement& cell_data = root->child("PolyData").child("Piece").child("CellData");
  EXPECT_EQ(as_double(decode_words(cell_data.data_array("normal"))), mesh.cell_data[0].values);
  EXPECT_EQ(as_int64(decode_words(cell_data.data_array("kind"))),
            (std::vector<std::int64_t>{10, 20, 30}));
  const auto point_coordinates = as_double(
      decode_words(root->child("PolyData").child("Piece").child("Points").child("DataArray")));
  EXPECT_EQ(point_coordinates.size(), 15u);
  EXPECT_EQ(point_coordinates[13], 2.0);  // y of point 4
}

TEST_F(VtkWriterTest, PolyMeshWithOnlyPolygonsHasEmptyLines) {
  const fs::path path = directory_ / "plane.vtp";
  PolyMesh mesh;
  mesh.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  mesh.polygons = {{0, 1, 2, 3}};
  write_polymesh_vtp(path, mesh);
  const auto root = parse_xml_file(path);
  const XmlElement& piece = root->child("PolyData").child("Piece");
  EXPECT_EQ(piece.attributes.at("NumberOfLines"), "0");
  EXPECT_TRUE(decode_words(piece.child("Lines").data_array("offsets")).empty());
  EXPECT_EQ(as_int64(decode_words(piece.child("Polys").data_array("offsets"))),
            (std::vector<std::int64_t>{4}));
}

TEST_F(VtkWriterTest, PolyMeshValidationThrows) {
  const fs::path path = directory_ / "bad.vtp";
  PolyMesh mesh = make_mesh();
  mesh.cell_data[0].values.resize(6);  // sized for the polygons only, forgetting the line
  expect_throw_naming<std::invalid_argument>([&] { write_polymesh_vtp(path, mesh); }, "'normal'");

  mesh = make_mesh();
  mesh.polygons[1][2] = 5;  // only 5 points
  EXPECT_THROW(write_polymesh_vtp(path, mesh), std::invalid_argument);
  mesh = make_mesh();
  mesh.polygons[1] = {0, 1};  // not a polygon
  EXPECT_THROW(write_polymesh_vtp(path, mesh), std::invalid_argument);
  mesh = make_mesh();
  mesh.lines[0] = {-1, 2};
  EXPECT_THROW(write_polymesh_vtp(path, mesh), std::invalid_argument);
  EXPECT_FALSE(fs::exists(path));
}

// --- write_image_block_vti, write_multiblock_vtm ------------------------------------------

ImageBlock make_block() {
  ImageBlock block;
  block.origin = {0.5, -1.0, 0.1 + 0.2};
  block.spacing = 1.0 / 3.0;
  block.cells = {2, 1, 3};
  block.cell_data.push_back({"pressure", 1, {1, 2, 3, 4, 5, 1e-300}});
  block.int_cell_data.push_back({"level", 1, {4, 4, 4, 4, 4, 4}});
  return block;
}

TEST_F(VtkWriterTest, ImageBlockIsImageDataWithExactGeometryAndCellData) {
  const fs::path path = directory_ / "block.vti";
  const ImageBlock block = make_block();
  write_image_block_vti(path, block);
  const auto root = parse_xml_file(path);
  EXPECT_EQ(root->attributes.at("type"), "ImageData");
  EXPECT_EQ(root->attributes.at("header_type"), "UInt64");
  const XmlElement& image = root->child("ImageData");
  // Extents count points (cells + 1 per direction); origin and spacing round-trip.
  EXPECT_EQ(image.attributes.at("WholeExtent"), "0 2 0 1 0 3");
  EXPECT_EQ(image.attributes.at("Origin"), "0.5 -1 0.30000000000000004");
  EXPECT_EQ(image.attributes.at("Spacing"),
            "0.33333333333333331 0.33333333333333331 0.33333333333333331");
  const XmlElement& piece = image.child("Piece");
  EXPECT_EQ(piece.attributes.at("Extent"), "0 2 0 1 0 3");
  const XmlElement& cells = piece.child("CellData");
  EXPECT_EQ(cells.child_array_names(), (std::vector<std::string>{"pressure", "level"}));
  EXPECT_EQ(decode_words(cells.data_array("pressure")), bits_of(block.cell_data[0].values));
  EXPECT_EQ(as_int64(decode_words(cells.data_array("level"))), block.int_cell_data[0].values);
}

TEST_F(VtkWriterTest, ImageBlockValidationThrowsAndWritesNothing) {
  const fs::path path = directory_ / "bad.vti";
  ImageBlock block = make_block();
  block.cell_data[0].values.pop_back();  // 5 values for 6 cells
  expect_throw_naming<std::invalid_argument>([&] { write_image_block_vti(path, block); },
                                             "'pressure'");
  block = make_block();
  block.cells[1] = 0;
  EXPECT_THROW(write_image_block_vti(path, block), std::invalid_argument);
  block = make_block();
  block.spacing = 0.0;
  EXPECT_THROW(write_image_block_vti(path, block), std::invalid_argument);
  EXPECT_FALSE(fs::exists(path));
}

TEST_F(VtkWriterTest, MultiblockIndexListsGroupsAndTheirFiles) {
  const fs::path path = directory_ / "frame.vtm";
  write_multiblock_vtm(path, {{"level 2", {{"b0", "frame/b0.vti"}, {"b1", "frame/b1.vti"}}},
                              {"level 3 <fine>", {{"b2", "frame/b2.vti"}}},
                              {"level 4", {}}});
  const auto root = parse_xml_file(path);
  EXPECT_EQ(root->attributes.at("type"), "vtkMultiBlockDataSet");
  const XmlElement& set = root->child("vtkMultiBlockDataSet");
  ASSERT_EQ(set.children.size(), 3u);
  EXPECT_EQ(set.children[0]->attributes.at("index"), "0");
  EXPECT_EQ(set.children[1]->attributes.at("name"), "level 3 &lt;fine&gt;");
  ASSERT_EQ(set.children[0]->children.size(), 2u);
  EXPECT_EQ(set.children[0]->children[1]->name, "DataSet");
  EXPECT_EQ(set.children[0]->children[1]->attributes.at("index"), "1");
  EXPECT_EQ(set.children[0]->children[1]->attributes.at("file"), "frame/b1.vti");
  EXPECT_EQ(set.children[1]->children[0]->attributes.at("name"), "b2");
  EXPECT_TRUE(set.children[2]->children.empty());
  EXPECT_THROW(write_multiblock_vtm(directory_ / "bad.vtm", {{"level 0", {{"b0", ""}}}}),
               std::invalid_argument);
  EXPECT_FALSE(fs::exists(directory_ / "bad.vtm"));
}

// --- PvdIndex --------------------------------------------------------------------------

TEST_F(VtkWriterTest, PvdIndexWritesCollectionWithExactTimes) {
  const fs::path path = directory_ / "particles.pvd";
  PvdIndex index(path);
  index.add(0.0, "frames/particles_0.vtu");
  index.add(0.1, "frames/particles_1.vtu");
  index.add(0.1 + 0.2, "frames/walls_1.vtp", 1);
  index.write();

  const auto root = parse_xml_file(path);
  EXPECT_EQ(root->attributes.at("type"), "Collection");
  const XmlElement& collection = root->child("Collection");
  ASSERT_EQ(collection.children.size(), 3u);
  EXPECT_EQ(collection.children[1]->attributes.at("timestep"), "0.10000000000000001");
  EXPECT_EQ(collection.children[1]->attributes.at("file"), "frames/particles_1.vtu");
  EXPECT_EQ(collection.children[2]->attributes.at("timestep"), "0.30000000000000004");
  EXPECT_EQ(collection.children[2]->attributes.at("part"), "1");
  EXPECT_EQ(collection.children[0]->attributes.at("part"), "0");
}

TEST_F(VtkWriterTest, PvdIndexLoadExistingKeepsEntriesUpToTime) {
  const fs::path path = directory_ / "run.pvd";
  PvdIndex original(path);
  const std::vector<double> times = {0.0, 0.1, 0.1 + 0.2, 0.5, 1e-300};
  for (std::size_t i = 0; i < times.size(); ++i) {
    original.add(times[i], "f & g/frame_" + std::to_string(i) + ".vtu", static_cast<int>(i % 2));
  }
  original.write();

  PvdIndex restarted(path);
  restarted.add(42.0, "stale.vtu");    // replaced by load_existing
  restarted.load_existing(0.1 + 0.2);  // exact time of the third entry: kept
  ASSERT_EQ(restarted.entries().size(), 4u);
  const std::vector<std::size_t> expected_kept = {0, 1, 2, 4};  // insertion order
  for (std::size_t k = 0; k < expected_kept.size(); ++k) {
    const PvdIndex::Entry& entry = restarted.entries()[k];
    const std::size_t i = expected_kept[k];
    EXPECT_EQ(std::bit_cast<std::uint64_t>(entry.time), std::bit_cast<std::uint64_t>(times[i]));
    EXPECT_EQ(entry.dataset, "f & g/frame_" + std::to_string(i) + ".vtu");
    EXPECT_EQ(entry.part, static_cast<int>(i % 2));
  }

  // Continue the series and rewrite: old kept entries then new ones.
  restarted.add(0.4, "frame_new.vtu");
  restarted.write();
  PvdIndex reread(path);
  reread.load_existing(std::numeric_limits<double>::infinity());
  ASSERT_EQ(reread.entries().size(), 5u);
  EXPECT_EQ(reread.entries().back().dataset, "frame_new.vtu");
  EXPECT_EQ(reread.entries().back().time, 0.4);
}

TEST_F(VtkWriterTest, PvdIndexLoadExistingOfMissingFileGivesEmptyIndex) {
  PvdIndex index(directory_ / "never_written.pvd");
  index.add(1.0, "x.vtu");
  index.load_existing(10.0);
  EXPECT_TRUE(index.entries().empty());
}

TEST_F(VtkWriterTest, PvdIndexLoadExistingRejectsOtherFiles) {
  const fs::path path = directory_ / "not_a.pvd";
  write_file_atomically(path, [](std::ostream& out) { out << "time,x\n0,1\n"; });
  PvdIndex index(path);
  EXPECT_THROW(index.load_existing(1.0), std::runtime_error);
}

}  // namespace
}  // namespace sanguis::io
