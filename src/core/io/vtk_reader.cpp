#include "core/io/vtk_reader.hpp"

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>

namespace sanguis::io {
namespace {

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open '" + path.string() + "' for reading");
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) throw std::runtime_error("read failure on '" + path.string() + "'");
  return text;
}

// Value of attribute `name` inside one opening tag, or empty when absent.
std::string attribute(std::string_view tag, std::string_view name) {
  std::string key(" ");  // built by appends: GCC 12 warns (-Wrestrict) on " " + string
  key.append(name).append("=\"");
  const std::size_t at = tag.find(key);
  if (at == std::string_view::npos) return {};
  const std::size_t begin = at + key.size();
  const std::size_t end = tag.find('"', begin);
  if (end == std::string_view::npos) return {};
  return std::string(tag.substr(begin, end - begin));
}

int base64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

std::vector<std::uint8_t> decode_base64(std::string_view text, const std::string& where) {
  std::vector<std::uint8_t> bytes;
  bytes.reserve(text.size() * 3 / 4);
  std::uint32_t buffer = 0;
  int bits = 0;
  for (const char c : text) {
    if (c == '=' || c == ' ' || c == '\n' || c == '\r' || c == '\t') continue;
    const int value = base64_value(c);
    if (value < 0) throw std::runtime_error(where + ": invalid base64 character");
    buffer = (buffer << 6) | static_cast<std::uint32_t>(value);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      bytes.push_back(static_cast<std::uint8_t>((buffer >> bits) & 0xFFu));
    }
  }
  return bytes;
}

std::uint64_t little_endian_u64(const std::uint8_t* p) {
  std::uint64_t value = 0;
  for (int k = 7; k >= 0; --k) value = (value << 8) | p[k];
  return value;
}

// One <DataArray> of the file: its attributes and decoded 8-byte values.
struct RawArray {
  std::string type;
  std::string name;
  int components = 1;
  std::vector<std::uint64_t> words;
};

// Every <DataArray> between text[begin, end).
std::vector<RawArray> arrays_in(const std::string& text, std::size_t begin, std::size_t end,
                                const std::filesystem::path& path) {
  std::vector<RawArray> arrays;
  constexpr std::string_view kOpen = "<DataArray";
  for (std::size_t at = text.find(kOpen, begin); at != std::string::npos && at < end;
       at = text.find(kOpen, at + 1)) {
    const std::size_t tag_end = text.find('>', at);
    const std::size_t close = text.find("</DataArray>", tag_end);
    if (tag_end == std::string::npos || close == std::string::npos) {
      throw std::runtime_error(path.string() + ": unterminated <DataArray>");
    }
    const std::string_view tag(text.data() + at, tag_end - at);
    RawArray array;
    array.type = attribute(tag, "type");
    array.name = attribute(tag, "Name");
    const std::string where = path.string() + ": array '" + array.name + "'";
    if (attribute(tag, "format") != "binary") {
      throw std::runtime_error(where + ": only format=\"binary\" is read");
    }
    if (array.type != "Float64" && array.type != "Int64") continue;  // cell types (UInt8)
    const std::string components = attribute(tag, "NumberOfComponents");
    array.components = components.empty() ? 1 : std::stoi(components);
    const std::vector<std::uint8_t> bytes =
        decode_base64(std::string_view(text.data() + tag_end + 1, close - tag_end - 1), where);
    if (bytes.size() < 8) throw std::runtime_error(where + ": missing byte count header");
    const std::uint64_t count = little_endian_u64(bytes.data());
    if (count % 8 != 0 || count > bytes.size() - 8) {
      throw std::runtime_error(where + ": truncated payload");
    }
    array.words.resize(count / 8);
    for (std::size_t k = 0; k < array.words.size(); ++k) {
      array.words[k] = little_endian_u64(bytes.data() + 8 + 8 * k);
    }
    arrays.push_back(std::move(array));
  }
  return arrays;
}

// [begin, end) of the element <tag>...</tag>; npos pair when absent.
std::pair<std::size_t, std::size_t> section(const std::string& text, const std::string& tag) {
  const std::size_t begin = text.find("<" + tag + ">");
  if (begin == std::string::npos) return {std::string::npos, std::string::npos};
  const std::size_t end = text.find("</" + tag + ">", begin);
  return {begin, end == std::string::npos ? text.size() : end};
}

std::vector<RawArray> section_arrays(const std::string& text, const std::string& tag,
                                     const std::filesystem::path& path) {
  const auto [begin, end] = section(text, tag);
  if (begin == std::string::npos) return {};
  return arrays_in(text, begin, end, path);
}

std::vector<double> as_doubles(const RawArray& a) {
  std::vector<double> values(a.words.size());
  for (std::size_t k = 0; k < values.size(); ++k) values[k] = std::bit_cast<double>(a.words[k]);
  return values;
}

std::vector<std::int64_t> as_ints(const RawArray& a) {
  std::vector<std::int64_t> values(a.words.size());
  for (std::size_t k = 0; k < values.size(); ++k) {
    values[k] = static_cast<std::int64_t>(a.words[k]);
  }
  return values;
}

void split_attributes(const std::vector<RawArray>& raw, std::vector<DataArray>& floats,
                      std::vector<IntDataArray>& ints) {
  for (const RawArray& a : raw) {
    if (a.type == "Float64")
      floats.push_back({a.name, a.components, as_doubles(a)});
    else
      ints.push_back({a.name, a.components, as_ints(a)});
  }
}

std::vector<Vec3> read_points(const std::string& text, const std::filesystem::path& path) {
  const std::vector<RawArray> raw = section_arrays(text, "Points", path);
  if (raw.size() != 1 || raw[0].type != "Float64" || raw[0].components != 3) {
    throw std::runtime_error(path.string() +
                             ": <Points> must hold one Float64 array of 3 components");
  }
  const std::vector<double> xyz = as_doubles(raw[0]);
  std::vector<Vec3> points(xyz.size() / 3);
  for (std::size_t k = 0; k < points.size(); ++k) {
    points[k] = {xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]};
  }
  return points;
}

std::vector<std::vector<std::int64_t>> read_cells(const std::string& text, const std::string& tag,
                                                  const std::filesystem::path& path) {
  std::vector<std::int64_t> connectivity, offsets;
  for (const RawArray& a : section_arrays(text, tag, path)) {
    if (a.name == "connectivity") connectivity = as_ints(a);
    if (a.name == "offsets") offsets = as_ints(a);
  }
  std::vector<std::vector<std::int64_t>> cells;
  cells.reserve(offsets.size());
  std::int64_t begin = 0;
  for (const std::int64_t end : offsets) {
    if (end < begin || end > static_cast<std::int64_t>(connectivity.size())) {
      throw std::runtime_error(path.string() + ": <" + tag + "> offsets out of range");
    }
    cells.emplace_back(connectivity.begin() + begin, connectivity.begin() + end);
    begin = end;
  }
  return cells;
}

void check_tuples(const std::filesystem::path& path, std::size_t tuples,
                  const std::vector<DataArray>& floats, const std::vector<IntDataArray>& ints) {
  for (const DataArray& a : floats) {
    if (a.values.size() != tuples * static_cast<std::size_t>(a.components)) {
      throw std::runtime_error(path.string() + ": array '" + a.name + "' has the wrong size");
    }
  }
  for (const IntDataArray& a : ints) {
    if (a.values.size() != tuples * static_cast<std::size_t>(a.components)) {
      throw std::runtime_error(path.string() + ": array '" + a.name + "' has the wrong size");
    }
  }
}

}  // namespace

PointCloud read_point_cloud_vtu(const std::filesystem::path& path) {
  const std::string text = read_text(path);
  if (text.find("type=\"UnstructuredGrid\"") == std::string::npos) {
    throw std::runtime_error(path.string() + ": not a VTK UnstructuredGrid (.vtu) file");
  }
  PointCloud cloud;
  cloud.points = read_points(text, path);
  split_attributes(section_arrays(text, "PointData", path), cloud.point_data, cloud.int_point_data);
  check_tuples(path, cloud.points.size(), cloud.point_data, cloud.int_point_data);
  return cloud;
}

PolyMesh read_polymesh_vtp(const std::filesystem::path& path) {
  const std::string text = read_text(path);
  if (text.find("type=\"PolyData\"") == std::string::npos) {
    throw std::runtime_error(path.string() + ": not a VTK PolyData (.vtp) file");
  }
  PolyMesh mesh;
  mesh.points = read_points(text, path);
  mesh.lines = read_cells(text, "Lines", path);
  mesh.polygons = read_cells(text, "Polys", path);
  split_attributes(section_arrays(text, "CellData", path), mesh.cell_data, mesh.int_cell_data);
  check_tuples(path, mesh.lines.size() + mesh.polygons.size(), mesh.cell_data, mesh.int_cell_data);
  std::vector<IntDataArray> int_point_data;  // our writer writes none
  split_attributes(section_arrays(text, "PointData", path), mesh.point_data, int_point_data);
  check_tuples(path, mesh.points.size(), mesh.point_data, int_point_data);
  return mesh;
}

std::vector<PvdIndex::Entry> read_pvd(const std::filesystem::path& path) {
  // load_existing() takes a missing index for an empty one (restart before any frame).
  if (!std::filesystem::exists(path)) {
    throw std::runtime_error("cannot open '" + path.string() + "' for reading");
  }
  PvdIndex index(path);
  index.load_existing(std::numeric_limits<double>::infinity());
  std::vector<PvdIndex::Entry> entries = index.entries();
  for (PvdIndex::Entry& e : entries) e.dataset = (path.parent_path() / e.dataset).string();
  return entries;
}

const DataArray& find_array(const std::vector<DataArray>& arrays, const std::string& name) {
  for (const DataArray& a : arrays) {
    if (a.name == name) return a;
  }
  throw std::runtime_error("no array '" + name + "'");
}

const IntDataArray& find_array(const std::vector<IntDataArray>& arrays, const std::string& name) {
  for (const IntDataArray& a : arrays) {
    if (a.name == name) return a;
  }
  throw std::runtime_error("no array '" + name + "'");
}

namespace {
template <typename Array>
bool named_array_exists(const std::vector<Array>& arrays, const std::string& name) {
  for (const Array& a : arrays) {
    if (a.name == name) return true;
  }
  return false;
}
}  // namespace

bool has_array(const std::vector<DataArray>& arrays, const std::string& name) {
  return named_array_exists(arrays, name);
}

bool has_array(const std::vector<IntDataArray>& arrays, const std::string& name) {
  return named_array_exists(arrays, name);
}

}  // namespace sanguis::io
