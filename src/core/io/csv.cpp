#include "core/io/csv.hpp"

#include <array>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <utility>

#include "core/io/atomic_file.hpp"

namespace sanguis::io {

namespace {

std::string join_header(const std::vector<std::string>& columns) {
  std::string header;
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (i > 0) header += ',';
    header += columns[i];
  }
  return header;
}

void check_columns(const std::filesystem::path& path, const std::vector<std::string>& columns) {
  if (columns.empty()) {
    throw std::invalid_argument(path.string() + ": a CSV file needs at least one column");
  }
  for (const std::string& column : columns) {
    if (column.find_first_of(",\"\r\n") != std::string::npos) {
      throw std::invalid_argument(path.string() + ": column name '" + column +
                                  "' contains a comma, quote or line break");
    }
  }
}

std::string read_whole_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw std::runtime_error("cannot open '" + path.string() + "' for reading");
  }
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) {
    throw std::runtime_error("read failure on '" + path.string() + "'");
  }
  return text;
}

// Splits on '\n'. The last element is what follows the last '\n': empty for
// a well-formed file, a partial line if the writer was interrupted.
std::vector<std::string_view> split_lines(std::string_view text) {
  std::vector<std::string_view> lines;
  std::size_t begin = 0;
  for (std::size_t end = text.find('\n'); end != std::string_view::npos;
       end = text.find('\n', begin)) {
    lines.push_back(text.substr(begin, end - begin));
    begin = end + 1;
  }
  lines.push_back(text.substr(begin));
  return lines;
}

std::string_view strip_carriage_return(std::string_view line) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  return line;
}

// Value of the first field of a data row; false if it is not a number.
bool parse_first_field(std::string_view line, double& value) {
  const std::string first_field(line.substr(0, line.find(',')));
  if (first_field.empty()) return false;
  char* end = nullptr;
  value = std::strtod(first_field.c_str(), &end);
  return *end == '\0';
}

}  // namespace

CsvWriter::CsvWriter(std::filesystem::path path, std::vector<std::string> columns, bool append)
    : path_(std::move(path)), columns_(std::move(columns)) {
  check_columns(path_, columns_);
  const std::string header = join_header(columns_);

  std::error_code size_error;
  const bool has_content = append && std::filesystem::exists(path_, size_error) &&
                           std::filesystem::file_size(path_, size_error) > 0 && !size_error;
  if (has_content) {
    const std::string text = read_whole_file(path_);
    const std::string_view existing_header =
        strip_carriage_return(std::string_view(text).substr(0, text.find('\n')));
    if (existing_header != header) {
      throw std::runtime_error(path_.string() + ": cannot append, existing header '" +
                               std::string(existing_header) + "' differs from '" + header + "'");
    }
    if (text.back() != '\n') {
      throw std::runtime_error(path_.string() +
                               ": cannot append, the last line is incomplete (interrupted run?); "
                               "truncate the file first");
    }
    out_.open(path_, std::ios::binary | std::ios::app);
  } else {
    out_.open(path_, std::ios::binary | std::ios::trunc);
  }
  if (!out_) {
    throw std::runtime_error("cannot open '" + path_.string() + "' for writing");
  }
  if (!has_content) {
    out_ << header << '\n';
    out_.flush();
    if (!out_) {
      throw std::runtime_error("write failure on '" + path_.string() + "'");
    }
  }
}

void CsvWriter::row(const std::vector<double>& values) {
  if (values.size() != columns_.size()) {
    throw std::invalid_argument(path_.string() + ": row has " + std::to_string(values.size()) +
                                " values but the file has " + std::to_string(columns_.size()) +
                                " columns");
  }
  // Build the whole line first so it goes out in one write: an interrupted
  // run then loses at most this row, not a random prefix of several.
  std::string line;
  std::array<char, 32> number{};
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i > 0) line += ',';
    std::snprintf(number.data(), number.size(), "%.17g", values[i]);
    line += number.data();
  }
  line += '\n';
  out_.write(line.data(), static_cast<std::streamsize>(line.size()));
  out_.flush();
  if (!out_) {
    throw std::runtime_error("write failure on '" + path_.string() + "'");
  }
}

void CsvWriter::truncate_after(const std::filesystem::path& path, double last_time_kept) {
  std::error_code exists_error;
  if (!std::filesystem::exists(path, exists_error)) return;

  const std::string text = read_whole_file(path);
  const std::vector<std::string_view> lines = split_lines(text);
  // lines.back() is the text after the last newline: empty, or a row cut off
  // by a crash; either way it is not kept. A file that is only a partial
  // header line keeps nothing but is still rewritten (empty).
  std::string kept;
  kept.reserve(text.size());
  if (lines.size() > 1) {
    kept.append(lines.front()).push_back('\n');
    for (std::size_t i = 1; i + 1 < lines.size(); ++i) {
      double time = 0.0;
      if (parse_first_field(strip_carriage_return(lines[i]), time) && time <= last_time_kept) {
        kept.append(lines[i]).push_back('\n');
      }
    }
  }
  write_file_atomically(path, [&](std::ostream& out) { out << kept; });
}

}  // namespace sanguis::io
