#include "core/io/vtk.hpp"

#include <array>
#include <bit>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <set>
#include <stdexcept>
#include <string_view>
#include <utility>

#include "core/io/atomic_file.hpp"

namespace sanguis::io {

namespace {

// --- Base64 ------------------------------------------------------------------

// Streams bytes to `out` as standard base64 (RFC 4648 alphabet, '=' padding).
// Encoding on the fly avoids holding a second, 4/3-sized copy of large arrays.
class Base64Encoder {
 public:
  explicit Base64Encoder(std::ostream& out) : out_(out) { buffer_.reserve(kFlushSize + 4); }
  Base64Encoder(const Base64Encoder&) = delete;
  Base64Encoder& operator=(const Base64Encoder&) = delete;

  void put_byte(std::uint8_t byte) {
    pending_[pending_count_++] = byte;
    if (pending_count_ == 3) {
      emit_pending();
    }
  }

  // VTK reads the byte order declared in the file header; we always declare
  // little endian and produce it explicitly, independent of the host.
  void put_uint64_little_endian(std::uint64_t value) {
    for (int byte_index = 0; byte_index < 8; ++byte_index) {
      put_byte(static_cast<std::uint8_t>(value >> (8 * byte_index)));
    }
  }

  // Emits the last partial group with padding and flushes to the stream.
  void finish() {
    if (pending_count_ > 0) {
      emit_pending();
    }
    out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
    buffer_.clear();
  }

 private:
  static constexpr std::size_t kFlushSize = 1 << 16;
  static constexpr std::string_view kAlphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

  void emit_pending() {
    const std::uint32_t group = (std::uint32_t{pending_[0]} << 16) |
                                (pending_count_ > 1 ? std::uint32_t{pending_[1]} << 8 : 0u) |
                                (pending_count_ > 2 ? std::uint32_t{pending_[2]} : 0u);
    buffer_.push_back(kAlphabet[(group >> 18) & 0x3F]);
    buffer_.push_back(kAlphabet[(group >> 12) & 0x3F]);
    buffer_.push_back(pending_count_ > 1 ? kAlphabet[(group >> 6) & 0x3F] : '=');
    buffer_.push_back(pending_count_ > 2 ? kAlphabet[group & 0x3F] : '=');
    pending_count_ = 0;
    if (buffer_.size() >= kFlushSize) {
      out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
      buffer_.clear();
    }
  }

  std::ostream& out_;
  std::array<std::uint8_t, 3> pending_{};
  int pending_count_ = 0;
  std::string buffer_;
};

// --- XML helpers ---------------------------------------------------------------

std::string xml_escape(std::string_view text) {
  std::string escaped;
  escaped.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        escaped += "&amp;";
        break;
      case '<':
        escaped += "&lt;";
        break;
      case '>':
        escaped += "&gt;";
        break;
      case '"':
        escaped += "&quot;";
        break;
      case '\'':
        escaped += "&apos;";
        break;
      default:
        escaped += c;
    }
  }
  return escaped;
}

std::string xml_unescape(std::string_view text) {
  static constexpr std::array<std::pair<std::string_view, char>, 5> kEntities = {{
      {"&amp;", '&'},
      {"&lt;", '<'},
      {"&gt;", '>'},
      {"&quot;", '"'},
      {"&apos;", '\''},
  }};
  std::string plain;
  plain.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    bool replaced = false;
    if (text[i] == '&') {
      for (const auto& [entity, character] : kEntities) {
        if (text.substr(i, entity.size()) == entity) {
          plain += character;
          i += entity.size();
          replaced = true;
          break;
        }
      }
    }
    if (!replaced) {
      plain += text[i];
      ++i;
    }
  }
  return plain;
}

// %.17g: enough digits for every double to read back to the same bits.
std::string format_exact(double value) {
  std::array<char, 32> text{};
  std::snprintf(text.data(), text.size(), "%.17g", value);
  return text.data();
}

// Opening tag of a binary DataArray, the base64 payload (byte count header +
// values, one block, as VTK expects for uncompressed data) and the closing tag.
// `emit_values` receives the encoder and puts exactly `value_bytes` bytes.
template <typename EmitValues>
void write_binary_data_array(std::ostream& out, std::string_view indent, std::string_view vtk_type,
                             std::string_view name, int components, std::uint64_t value_bytes,
                             EmitValues&& emit_values) {
  out << indent << "<DataArray type=\"" << vtk_type << "\" Name=\"" << xml_escape(name)
      << "\" NumberOfComponents=\"" << components << "\" format=\"binary\">\n"
      << indent << "  ";
  Base64Encoder encoder(out);
  encoder.put_uint64_little_endian(value_bytes);
  emit_values(encoder);
  encoder.finish();
  out << "\n" << indent << "</DataArray>\n";
}

void write_float64_array(std::ostream& out, std::string_view indent, std::string_view name,
                         int components, const std::vector<double>& values) {
  write_binary_data_array(out, indent, "Float64", name, components, values.size() * 8,
                          [&](Base64Encoder& encoder) {
                            for (const double value : values) {
                              encoder.put_uint64_little_endian(std::bit_cast<std::uint64_t>(value));
                            }
                          });
}

void write_int64_array(std::ostream& out, std::string_view indent, std::string_view name,
                       int components, const std::vector<std::int64_t>& values) {
  write_binary_data_array(out, indent, "Int64", name, components, values.size() * 8,
                          [&](Base64Encoder& encoder) {
                            for (const std::int64_t value : values) {
                              // Two's complement conversion, well defined.
                              encoder.put_uint64_little_endian(static_cast<std::uint64_t>(value));
                            }
                          });
}

void write_uint8_array(std::ostream& out, std::string_view indent, std::string_view name,
                       const std::vector<std::uint8_t>& values) {
  write_binary_data_array(out, indent, "UInt8", name, 1, values.size(),
                          [&](Base64Encoder& encoder) {
                            for (const std::uint8_t value : values) encoder.put_byte(value);
                          });
}

void write_points(std::ostream& out, std::string_view indent, const std::vector<Vec3>& points) {
  out << indent << "<Points>\n";
  const std::string array_indent = std::string(indent) + "  ";
  write_binary_data_array(
      out, array_indent, "Float64", "Points", 3, points.size() * 3 * 8,
      [&](Base64Encoder& encoder) {
        for (const Vec3& point : points) {
          encoder.put_uint64_little_endian(std::bit_cast<std::uint64_t>(point.x));
          encoder.put_uint64_little_endian(std::bit_cast<std::uint64_t>(point.y));
          encoder.put_uint64_little_endian(std::bit_cast<std::uint64_t>(point.z));
        }
      });
  out << indent << "</Points>\n";
}

// <PointData>/<CellData> section with the Float64 arrays, then the Int64 ones.
void write_attribute_section(std::ostream& out, std::string_view indent, std::string_view tag,
                             const std::vector<DataArray>& float_arrays,
                             const std::vector<IntDataArray>& int_arrays) {
  out << indent << "<" << tag << ">\n";
  const std::string array_indent = std::string(indent) + "  ";
  for (const DataArray& array : float_arrays) {
    write_float64_array(out, array_indent, array.name, array.components, array.values);
  }
  for (const IntDataArray& array : int_arrays) {
    write_int64_array(out, array_indent, array.name, array.components, array.values);
  }
  out << indent << "</" << tag << ">\n";
}

void write_file_header(std::ostream& out, std::string_view dataset_type) {
  // version 1.0 is the first version that allows header_type="UInt64".
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"" << dataset_type
      << "\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      << "  <" << dataset_type << ">\n";
}

void write_file_footer(std::ostream& out, std::string_view dataset_type) {
  out << "  </" << dataset_type << ">\n"
      << "</VTKFile>\n";
}

// --- Validation ----------------------------------------------------------------

template <typename Array>
void check_attribute_arrays(const std::filesystem::path& path, std::string_view section,
                            std::size_t tuple_count, const std::vector<Array>& arrays,
                            std::set<std::string>& names_seen) {
  for (const Array& array : arrays) {
    const std::string where =
        path.string() + ": " + std::string(section) + " array '" + array.name + "'";
    if (array.name.empty()) {
      throw std::invalid_argument(path.string() + ": " + std::string(section) +
                                  " array with an empty name");
    }
    // ParaView would show only one of two equally named arrays.
    if (!names_seen.insert(array.name).second) {
      throw std::invalid_argument(where + " appears twice");
    }
    if (array.components < 1) {
      throw std::invalid_argument(where + " has " + std::to_string(array.components) +
                                  " components (must be >= 1)");
    }
    const std::size_t expected = static_cast<std::size_t>(array.components) * tuple_count;
    if (array.values.size() != expected) {
      throw std::invalid_argument(where + " has " + std::to_string(array.values.size()) +
                                  " values, expected " + std::to_string(array.components) +
                                  " components x " + std::to_string(tuple_count) +
                                  " tuples = " + std::to_string(expected));
    }
  }
}

void check_cells(const std::filesystem::path& path, std::string_view kind,
                 const std::vector<std::vector<std::int64_t>>& cells, std::size_t min_size,
                 std::size_t point_count) {
  for (std::size_t cell = 0; cell < cells.size(); ++cell) {
    const std::string where = path.string() + ": " + std::string(kind) + " " + std::to_string(cell);
    if (cells[cell].size() < min_size) {
      throw std::invalid_argument(where + " has " + std::to_string(cells[cell].size()) +
                                  " points, needs at least " + std::to_string(min_size));
    }
    for (const std::int64_t index : cells[cell]) {
      if (index < 0 || static_cast<std::uint64_t>(index) >= point_count) {
        throw std::invalid_argument(where + " refers to point " + std::to_string(index) +
                                    " but the mesh has " + std::to_string(point_count) + " points");
      }
    }
  }
}

// <Lines>/<Polys> element: concatenated point indices and, per cell, the
// offset one past its last index (VTK XML convention: no leading 0).
void write_cell_array(std::ostream& out, std::string_view indent, std::string_view tag,
                      const std::vector<std::vector<std::int64_t>>& cells) {
  std::vector<std::int64_t> connectivity;
  std::vector<std::int64_t> offsets;
  offsets.reserve(cells.size());
  for (const auto& cell : cells) {
    connectivity.insert(connectivity.end(), cell.begin(), cell.end());
    offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
  }
  const std::string array_indent = std::string(indent) + "  ";
  out << indent << "<" << tag << ">\n";
  write_int64_array(out, array_indent, "connectivity", 1, connectivity);
  write_int64_array(out, array_indent, "offsets", 1, offsets);
  out << indent << "</" << tag << ">\n";
}

// --- .pvd parsing ----------------------------------------------------------------

// Attributes of one start tag, `tag` being the text between '<name' and '>'.
// Only what PvdIndex::write() produces needs to be understood.
std::vector<std::pair<std::string, std::string>> parse_attributes(
    std::string_view tag, const std::filesystem::path& file) {
  std::vector<std::pair<std::string, std::string>> attributes;
  std::size_t i = 0;
  const auto skip_spaces = [&] {
    while (i < tag.size() && (tag[i] == ' ' || tag[i] == '\t' || tag[i] == '\n' || tag[i] == '\r'))
      ++i;
  };
  while (true) {
    skip_spaces();
    if (i >= tag.size() || tag[i] == '/') break;
    const std::size_t name_begin = i;
    while (i < tag.size() && tag[i] != '=' && tag[i] != ' ') ++i;
    std::string name(tag.substr(name_begin, i - name_begin));
    skip_spaces();
    if (i >= tag.size() || tag[i] != '=') {
      throw std::runtime_error(file.string() + ": malformed attribute '" + name + "'");
    }
    ++i;
    skip_spaces();
    if (i >= tag.size() || (tag[i] != '"' && tag[i] != '\'')) {
      throw std::runtime_error(file.string() + ": attribute '" + name + "' is not quoted");
    }
    const char quote = tag[i++];
    const std::size_t value_end = tag.find(quote, i);
    if (value_end == std::string_view::npos) {
      throw std::runtime_error(file.string() + ": unterminated value of attribute '" + name + "'");
    }
    attributes.emplace_back(std::move(name), xml_unescape(tag.substr(i, value_end - i)));
    i = value_end + 1;
  }
  return attributes;
}

const std::string* find_attribute(
    const std::vector<std::pair<std::string, std::string>>& attributes, std::string_view name) {
  for (const auto& [key, value] : attributes) {
    if (key == name) return &value;
  }
  return nullptr;
}

}  // namespace

// --- Public writers ------------------------------------------------------------

void write_point_cloud_vtu(const std::filesystem::path& path, const PointCloud& cloud) {
  const std::size_t point_count = cloud.points.size();
  std::set<std::string> names_seen;
  check_attribute_arrays(path, "point data", point_count, cloud.point_data, names_seen);
  check_attribute_arrays(path, "point data", point_count, cloud.int_point_data, names_seen);

  // One VTK_VERTEX per point: connectivity i, offset i + 1.
  std::vector<std::int64_t> connectivity(point_count);
  std::vector<std::int64_t> offsets(point_count);
  for (std::size_t i = 0; i < point_count; ++i) {
    connectivity[i] = static_cast<std::int64_t>(i);
    offsets[i] = static_cast<std::int64_t>(i + 1);
  }
  constexpr std::uint8_t kVtkVertex = 1;
  const std::vector<std::uint8_t> types(point_count, kVtkVertex);

  write_file_atomically(path, [&](std::ostream& out) {
    write_file_header(out, "UnstructuredGrid");
    out << "    <Piece NumberOfPoints=\"" << point_count << "\" NumberOfCells=\"" << point_count
        << "\">\n";
    write_attribute_section(out, "      ", "PointData", cloud.point_data, cloud.int_point_data);
    write_points(out, "      ", cloud.points);
    out << "      <Cells>\n";
    write_int64_array(out, "        ", "connectivity", 1, connectivity);
    write_int64_array(out, "        ", "offsets", 1, offsets);
    write_uint8_array(out, "        ", "types", types);
    out << "      </Cells>\n"
        << "    </Piece>\n";
    write_file_footer(out, "UnstructuredGrid");
  });
}

void write_hex_mesh_vtu(const std::filesystem::path& path, const HexMesh& mesh) {
  const std::size_t cell_count = mesh.cells.size();
  std::set<std::string> names_seen;
  check_attribute_arrays(path, "cell data", cell_count, mesh.cell_data, names_seen);
  check_attribute_arrays(path, "cell data", cell_count, mesh.int_cell_data, names_seen);
  const auto point_count = static_cast<std::int64_t>(mesh.points.size());
  std::vector<std::int64_t> connectivity;
  connectivity.reserve(8 * cell_count);
  std::vector<std::int64_t> offsets(cell_count);
  for (std::size_t c = 0; c < cell_count; ++c) {
    for (const std::int64_t p : mesh.cells[c]) {
      if (p < 0 || p >= point_count) {
        throw std::invalid_argument(path.string() + ": hexahedron " + std::to_string(c) +
                                    " has point index " + std::to_string(p) + " out of range");
      }
      connectivity.push_back(p);
    }
    offsets[c] = static_cast<std::int64_t>(8 * (c + 1));
  }
  constexpr std::uint8_t kVtkHexahedron = 12;
  const std::vector<std::uint8_t> types(cell_count, kVtkHexahedron);
  write_file_atomically(path, [&](std::ostream& out) {
    write_file_header(out, "UnstructuredGrid");
    out << "    <Piece NumberOfPoints=\"" << mesh.points.size() << "\" NumberOfCells=\""
        << cell_count << "\">\n";
    write_attribute_section(out, "      ", "CellData", mesh.cell_data, mesh.int_cell_data);
    write_points(out, "      ", mesh.points);
    out << "      <Cells>\n";
    write_int64_array(out, "        ", "connectivity", 1, connectivity);
    write_int64_array(out, "        ", "offsets", 1, offsets);
    write_uint8_array(out, "        ", "types", types);
    out << "      </Cells>\n"
        << "    </Piece>\n";
    write_file_footer(out, "UnstructuredGrid");
  });
}

void write_image_block_vti(const std::filesystem::path& path, const ImageBlock& block) {
  for (const int n : block.cells) {
    if (n < 1) throw std::invalid_argument(path.string() + ": an image block needs cells >= 1");
  }
  if (!(block.spacing > 0.0)) {
    throw std::invalid_argument(path.string() + ": an image block needs a spacing > 0");
  }
  const std::size_t cell_count = static_cast<std::size_t>(block.cells[0]) *
                                 static_cast<std::size_t>(block.cells[1]) *
                                 static_cast<std::size_t>(block.cells[2]);
  std::set<std::string> names_seen;
  check_attribute_arrays(path, "cell data", cell_count, block.cell_data, names_seen);
  check_attribute_arrays(path, "cell data", cell_count, block.int_cell_data, names_seen);
  // Extents count points: cells n give 0..n.
  const std::string extent = "0 " + std::to_string(block.cells[0]) + " 0 " +
                             std::to_string(block.cells[1]) + " 0 " +
                             std::to_string(block.cells[2]);
  const std::string spacing = format_exact(block.spacing);
  write_file_atomically(path, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n"
        << "<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" "
           "header_type=\"UInt64\">\n"
        << "  <ImageData WholeExtent=\"" << extent << "\" Origin=\"" << format_exact(block.origin.x)
        << " " << format_exact(block.origin.y) << " " << format_exact(block.origin.z)
        << "\" Spacing=\"" << spacing << " " << spacing << " " << spacing << "\">\n"
        << "    <Piece Extent=\"" << extent << "\">\n";
    write_attribute_section(out, "      ", "CellData", block.cell_data, block.int_cell_data);
    out << "    </Piece>\n";
    write_file_footer(out, "ImageData");
  });
}

void write_multiblock_vtm(const std::filesystem::path& path,
                          const std::vector<MultiblockGroup>& groups) {
  for (const MultiblockGroup& group : groups) {
    for (const auto& member : group.members) {
      if (member.second.empty()) {
        throw std::invalid_argument(path.string() + ": member " + member.first + " of " +
                                    group.name + " has no file");
      }
    }
  }
  write_file_atomically(path, [&](std::ostream& out) {
    write_file_header(out, "vtkMultiBlockDataSet");
    for (std::size_t g = 0; g < groups.size(); ++g) {
      out << "    <Block index=\"" << g << "\" name=\"" << xml_escape(groups[g].name) << "\">\n";
      for (std::size_t m = 0; m < groups[g].members.size(); ++m) {
        const auto& [name, file] = groups[g].members[m];
        out << "      <DataSet index=\"" << m << "\" name=\"" << xml_escape(name) << "\" file=\""
            << xml_escape(file) << "\"/>\n";
      }
      out << "    </Block>\n";
    }
    write_file_footer(out, "vtkMultiBlockDataSet");
  });
}

void write_polymesh_vtp(const std::filesystem::path& path, const PolyMesh& mesh) {
  const std::size_t point_count = mesh.points.size();
  check_cells(path, "line", mesh.lines, 2, point_count);
  check_cells(path, "polygon", mesh.polygons, 3, point_count);
  const std::size_t cell_count = mesh.lines.size() + mesh.polygons.size();
  std::set<std::string> names_seen;
  check_attribute_arrays(path, "cell data", cell_count, mesh.cell_data, names_seen);
  check_attribute_arrays(path, "cell data", cell_count, mesh.int_cell_data, names_seen);
  std::set<std::string> point_names_seen;  // point and cell arrays may share a name
  check_attribute_arrays(path, "point data", point_count, mesh.point_data, point_names_seen);

  write_file_atomically(path, [&](std::ostream& out) {
    write_file_header(out, "PolyData");
    out << "    <Piece NumberOfPoints=\"" << point_count
        << "\" NumberOfVerts=\"0\" NumberOfLines=\"" << mesh.lines.size()
        << "\" NumberOfStrips=\"0\" NumberOfPolys=\"" << mesh.polygons.size() << "\">\n";
    if (!mesh.point_data.empty()) {
      write_attribute_section(out, "      ", "PointData", mesh.point_data, {});
    }
    write_attribute_section(out, "      ", "CellData", mesh.cell_data, mesh.int_cell_data);
    write_points(out, "      ", mesh.points);
    write_cell_array(out, "      ", "Lines", mesh.lines);
    write_cell_array(out, "      ", "Polys", mesh.polygons);
    out << "    </Piece>\n";
    write_file_footer(out, "PolyData");
  });
}

// --- PvdIndex --------------------------------------------------------------------

PvdIndex::PvdIndex(std::filesystem::path file) : file_(std::move(file)) {}

void PvdIndex::add(double time, const std::string& relative_dataset_path, int part) {
  entries_.push_back(Entry{time, relative_dataset_path, part});
}

void PvdIndex::write() const {
  write_file_atomically(file_, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n"
        << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        << "  <Collection>\n";
    for (const Entry& entry : entries_) {
      out << "    <DataSet timestep=\"" << format_exact(entry.time) << "\" group=\"\" part=\""
          << entry.part << "\" file=\"" << xml_escape(entry.dataset) << "\"/>\n";
    }
    out << "  </Collection>\n"
        << "</VTKFile>\n";
  });
}

void PvdIndex::load_existing(double up_to_time) {
  std::error_code status_error;
  if (!std::filesystem::exists(file_, status_error)) {
    entries_.clear();
    return;
  }
  std::ifstream in(file_, std::ios::binary);
  if (!in) {
    throw std::runtime_error("cannot open '" + file_.string() + "' for reading");
  }
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) {
    throw std::runtime_error("read failure on '" + file_.string() + "'");
  }
  if (text.find("<Collection") == std::string::npos) {
    throw std::runtime_error(file_.string() + ": not a .pvd file (no <Collection> element)");
  }

  std::vector<Entry> kept;
  constexpr std::string_view kDataSetTag = "<DataSet";
  for (std::size_t tag_begin = text.find(kDataSetTag); tag_begin != std::string::npos;
       tag_begin = text.find(kDataSetTag, tag_begin + 1)) {
    const std::size_t attributes_begin = tag_begin + kDataSetTag.size();
    const std::size_t tag_end = text.find('>', attributes_begin);
    if (tag_end == std::string::npos) {
      throw std::runtime_error(file_.string() + ": unterminated <DataSet> element");
    }
    const auto attributes = parse_attributes(
        std::string_view(text).substr(attributes_begin, tag_end - attributes_begin), file_);

    const std::string* time_text = find_attribute(attributes, "timestep");
    const std::string* dataset = find_attribute(attributes, "file");
    if (time_text == nullptr || dataset == nullptr) {
      throw std::runtime_error(file_.string() +
                               ": <DataSet> element without 'timestep' or 'file' attribute");
    }
    char* time_end = nullptr;
    const double time = std::strtod(time_text->c_str(), &time_end);
    if (time_text->empty() || *time_end != '\0') {
      throw std::runtime_error(file_.string() + ": invalid timestep '" + *time_text + "'");
    }
    int part = 0;
    if (const std::string* part_text = find_attribute(attributes, "part");
        part_text != nullptr && !part_text->empty()) {
      char* part_end = nullptr;
      const long parsed = std::strtol(part_text->c_str(), &part_end, 10);
      if (*part_end != '\0') {
        throw std::runtime_error(file_.string() + ": invalid part '" + *part_text + "'");
      }
      part = static_cast<int>(parsed);
    }
    if (time <= up_to_time) {
      kept.push_back(Entry{time, *dataset, part});
    }
  }
  entries_ = std::move(kept);
}

}  // namespace sanguis::io
