#include "core/io/mesh_files.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>

namespace sanguis::io {
namespace {

std::string read_whole_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot open mesh file");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw std::runtime_error(path.string() + ": read error");
  return bytes;
}

[[noreturn]] void fail_at(const std::filesystem::path& path, std::size_t line,
                          const std::string& reason) {
  throw std::runtime_error(path.string() + ":" + std::to_string(line) + ": " + reason);
}

bool parse_double(std::string_view token, double& value) {
  const char* first = token.data();
  const char* last = first + token.size();
  if (first != last && *first == '+') ++first;  // from_chars rejects a leading '+'
  const auto [ptr, ec] = std::from_chars(first, last, value);
  return ec == std::errc() && ptr == last && std::isfinite(value);
}

// ---------------------------------------------------------------- merging

// Merges positions within `tolerance` (absolute) with a uniform hash grid of
// cell size `tolerance`: a match can only lie in the 27 cells around.
class VertexWelder {
 public:
  explicit VertexWelder(double tolerance) : tolerance_(tolerance) {}

  std::uint32_t insert(const Vec3& p, std::vector<Vec3>& vertices) {
    const Key key = cell_of(p);
    if (tolerance_ > 0.0) {
      for (std::int64_t dx = -1; dx <= 1; ++dx)
        for (std::int64_t dy = -1; dy <= 1; ++dy)
          for (std::int64_t dz = -1; dz <= 1; ++dz) {
            const auto it = cells_.find({key.i + dx, key.j + dy, key.k + dz});
            if (it == cells_.end()) continue;
            for (const std::uint32_t v : it->second)
              if (norm2(vertices[v] - p) <= tolerance_ * tolerance_) return v;
          }
    } else {
      const auto it = cells_.find(key);
      if (it != cells_.end())
        for (const std::uint32_t v : it->second)
          if (vertices[v] == p) return v;
    }
    const auto index = static_cast<std::uint32_t>(vertices.size());
    vertices.push_back(p);
    cells_[key].push_back(index);
    return index;
  }

 private:
  struct Key {
    std::int64_t i, j, k;
    bool operator==(const Key&) const = default;
  };
  struct KeyHash {
    std::size_t operator()(const Key& key) const {
      std::uint64_t h = static_cast<std::uint64_t>(key.i) * 0x9E3779B97F4A7C15ULL;
      h ^= static_cast<std::uint64_t>(key.j) + 0x7F4A7C159E3779B9ULL + (h << 6) + (h >> 2);
      h ^= static_cast<std::uint64_t>(key.k) + 0x94D049BB133111EBULL + (h << 6) + (h >> 2);
      return static_cast<std::size_t>(h);
    }
  };

  Key cell_of(const Vec3& p) const {
    if (tolerance_ <= 0.0) {  // exact merging: hash the bit patterns
      return {std::bit_cast<std::int64_t>(p.x), std::bit_cast<std::int64_t>(p.y),
              std::bit_cast<std::int64_t>(p.z)};
    }
    return {static_cast<std::int64_t>(std::floor(p.x / tolerance_)),
            static_cast<std::int64_t>(std::floor(p.y / tolerance_)),
            static_cast<std::int64_t>(std::floor(p.z / tolerance_))};
  }

  double tolerance_;
  std::unordered_map<Key, std::vector<std::uint32_t>, KeyHash> cells_;
};

// Facet corners (three per facet) -> indexed mesh with merged vertices.
SurfaceMesh weld(const std::vector<Vec3>& corners, double relative_tolerance) {
  Vec3 lo = corners.empty() ? Vec3{} : corners.front(), hi = lo;
  for (const Vec3& p : corners)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  VertexWelder welder(relative_tolerance * norm(hi - lo));
  SurfaceMesh mesh;
  for (std::size_t t = 0; t + 2 < corners.size(); t += 3) {
    std::array<std::uint32_t, 3> tri{};
    for (int c = 0; c < 3; ++c) tri[c] = welder.insert(corners[t + c], mesh.vertices);
    if (tri[0] != tri[1] && tri[1] != tri[2] && tri[2] != tri[0]) mesh.triangles.push_back(tri);
  }
  return mesh;
}

// ---------------------------------------------------------------- STL

float read_float_le(const char* bytes) {
  std::uint32_t bits;
  std::memcpy(&bits, bytes, 4);
  if constexpr (std::endian::native == std::endian::big) bits = __builtin_bswap32(bits);
  return std::bit_cast<float>(bits);
}

std::uint32_t read_u32_le(const char* bytes) {
  std::uint32_t value;
  std::memcpy(&value, bytes, 4);
  if constexpr (std::endian::native == std::endian::big) value = __builtin_bswap32(value);
  return value;
}

bool is_binary_stl(const std::string& bytes) {
  if (bytes.size() < 84) return false;
  const std::uint64_t count = read_u32_le(bytes.data() + 80);
  return bytes.size() == 84 + 50 * count;
}

std::vector<Vec3> binary_stl_corners(const std::filesystem::path& path, const std::string& bytes) {
  const std::uint32_t count = read_u32_le(bytes.data() + 80);
  std::vector<Vec3> corners;
  corners.reserve(3 * static_cast<std::size_t>(count));
  for (std::uint32_t t = 0; t < count; ++t) {
    const char* facet = bytes.data() + 84 + 50 * static_cast<std::size_t>(t);
    for (int c = 0; c < 3; ++c) {  // skip the 12-byte normal
      const char* v = facet + 12 + 12 * c;
      const Vec3 p{read_float_le(v), read_float_le(v + 4), read_float_le(v + 8)};
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw std::runtime_error(path.string() + ": binary STL facet " + std::to_string(t) +
                                 " has a non-finite coordinate");
      corners.push_back(p);
    }
  }
  return corners;
}

// Whitespace tokenizer that remembers the line of each token.
class Tokenizer {
 public:
  explicit Tokenizer(const std::string& text) : text_(text) {}

  bool next(std::string_view& token) {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (pos_ == text_.size()) return false;
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    token = std::string_view(text_).substr(start, pos_ - start);
    return true;
  }
  void skip_line() {
    while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
  }
  std::size_t line() const { return line_; }

 private:
  const std::string& text_;
  std::size_t pos_ = 0;
  std::size_t line_ = 1;
};

class AsciiStlParser {
 public:
  AsciiStlParser(const std::filesystem::path& path, const std::string& text)
      : path_(path), tokens_(text) {}

  std::vector<Vec3> corners() {
    std::string_view token;
    if (!tokens_.next(token) || token != "solid") fail("expected 'solid' at the start");
    tokens_.skip_line();  // the solid's name, possibly with spaces
    std::vector<Vec3> corners;
    while (true) {
      if (!tokens_.next(token)) fail("unexpected end of file: missing 'endsolid'");
      if (token == "endsolid") {
        tokens_.skip_line();
        if (!tokens_.next(token)) break;  // end of file
        if (token != "solid") fail("expected 'solid' after 'endsolid', found '" + str(token) + "'");
        tokens_.skip_line();
        continue;
      }
      if (token != "facet") fail("expected 'facet' or 'endsolid', found '" + str(token) + "'");
      facet(corners);
    }
    return corners;
  }

 private:
  void facet(std::vector<Vec3>& corners) {
    expect("normal");
    number();
    number();
    number();
    expect("outer");
    expect("loop");
    for (int c = 0; c < 3; ++c) {
      expect("vertex");
      const double x = number(), y = number(), z = number();
      corners.push_back({x, y, z});
    }
    expect("endloop");
    expect("endfacet");
  }

  void expect(std::string_view word) {
    std::string_view token;
    if (!tokens_.next(token)) fail("unexpected end of file: expected '" + str(word) + "'");
    if (token != word) fail("expected '" + str(word) + "', found '" + str(token) + "'");
  }

  double number() {
    std::string_view token;
    if (!tokens_.next(token)) fail("unexpected end of file: expected a number");
    double value = 0.0;
    if (!parse_double(token, value)) fail("expected a finite number, found '" + str(token) + "'");
    return value;
  }

  [[noreturn]] void fail(const std::string& reason) const {
    fail_at(path_, tokens_.line(), reason);
  }
  static std::string str(std::string_view s) { return std::string(s); }

  const std::filesystem::path& path_;
  Tokenizer tokens_;
};

// ---------------------------------------------------------------- OBJ

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const std::size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

// A face corner as written ("i", "i/t", "i//n", "i/t/n"), resolved to a
// 0-based index; positive indices are range-checked once all vertices are read.
std::int64_t obj_corner_index(const std::filesystem::path& path, std::size_t line,
                              std::string_view corner, std::size_t vertices_so_far) {
  const std::string_view index_text = corner.substr(0, corner.find('/'));
  std::int64_t index = 0;
  const auto [ptr, ec] =
      std::from_chars(index_text.data(), index_text.data() + index_text.size(), index);
  if (ec != std::errc() || ptr != index_text.data() + index_text.size() || index == 0)
    fail_at(path, line, "bad face index '" + std::string(corner) + "'");
  if (index > 0) return index - 1;
  const std::int64_t resolved = static_cast<std::int64_t>(vertices_so_far) + index;
  if (resolved < 0)
    fail_at(path, line,
            "face index " + std::to_string(index) + " points before the first vertex (" +
                std::to_string(vertices_so_far) + " read so far)");
  return resolved;
}

struct ObjFace {
  std::vector<std::int64_t> corners;
  std::size_t line;
};

}  // namespace

SurfaceMesh read_stl(const std::filesystem::path& path, double merge_tolerance) {
  if (!(merge_tolerance >= 0.0))
    throw std::invalid_argument("read_stl: merge_tolerance must be >= 0");
  const std::string bytes = read_whole_file(path);
  std::vector<Vec3> corners;
  if (is_binary_stl(bytes)) {
    corners = binary_stl_corners(path, bytes);
  } else {
    const std::size_t first = bytes.find_first_not_of(" \t\r\n");
    if (first == std::string::npos || bytes.compare(first, 5, "solid") != 0) {
      const std::string count =
          bytes.size() >= 84 ? std::to_string(read_u32_le(bytes.data() + 80)) : "?";
      throw std::runtime_error(path.string() +
                               ": not an STL file: no 'solid' header (ASCII) and size " +
                               std::to_string(bytes.size()) +
                               " bytes is not 84 + 50 x (triangle count " + count + ") (binary)");
    }
    corners = AsciiStlParser(path, bytes).corners();
  }
  if (corners.empty()) throw std::runtime_error(path.string() + ": STL file has no facets");
  return weld(corners, merge_tolerance);
}

SurfaceMesh read_obj(const std::filesystem::path& path) {
  const std::string text = read_whole_file(path);
  SurfaceMesh mesh;
  std::vector<ObjFace> faces;
  std::istringstream lines(text);
  std::string line;
  std::size_t line_number = 0;
  while (std::getline(lines, line)) {
    ++line_number;
    const std::vector<std::string_view> words = split_words(line);
    if (words.empty() || words[0] == "#") continue;
    if (words[0] == "v") {
      if (words.size() < 4 || words.size() > 5)
        fail_at(path, line_number, "a vertex needs 3 coordinates (and an optional weight)");
      Vec3 p;
      for (int k = 0; k < 3; ++k)
        if (!parse_double(words[1 + k], p[k]))
          fail_at(path, line_number, "bad vertex coordinate '" + std::string(words[1 + k]) + "'");
      mesh.vertices.push_back(p);
    } else if (words[0] == "f") {
      if (words.size() < 4) fail_at(path, line_number, "a face needs at least 3 corners");
      ObjFace face{{}, line_number};
      for (std::size_t c = 1; c < words.size(); ++c)
        face.corners.push_back(obj_corner_index(path, line_number, words[c], mesh.vertices.size()));
      faces.push_back(std::move(face));
    }
    // Other records (vt, vn, g, o, s, usemtl, mtllib, l, ...) carry no geometry we use.
  }
  for (const ObjFace& face : faces) {
    for (const std::int64_t index : face.corners)
      if (index >= static_cast<std::int64_t>(mesh.vertices.size()))
        fail_at(path, face.line,
                "face index " + std::to_string(index + 1) + " exceeds the vertex count " +
                    std::to_string(mesh.vertices.size()));
    for (std::size_t c = 1; c + 1 < face.corners.size(); ++c)
      mesh.triangles.push_back({static_cast<std::uint32_t>(face.corners[0]),
                                static_cast<std::uint32_t>(face.corners[c]),
                                static_cast<std::uint32_t>(face.corners[c + 1])});
  }
  if (mesh.triangles.empty()) throw std::runtime_error(path.string() + ": OBJ file has no faces");
  return mesh;
}

SurfaceMesh read_surface_mesh(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == ".stl") return read_stl(path);
  if (extension == ".obj") return read_obj(path);
  throw std::runtime_error(path.string() + ": unknown mesh format '" + extension +
                           "' (expected .stl or .obj)");
}

}  // namespace sanguis::io
