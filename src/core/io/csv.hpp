#pragma once
// Time-series output as CSV (one row per sample, first column the time by
// convention): trivially readable by numpy/pandas/gnuplot and robust to
// crashes, since each row is flushed as soon as it is written.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace sanguis::io {

class CsvWriter {
 public:
  // Opens `path` and writes the header line "col0,col1,...".
  //
  // With append = true and an existing, non-empty file, the file is reopened
  // for appending instead: its header must equal the one `columns` would
  // produce (otherwise std::runtime_error naming the file; appending rows of a
  // different layout would corrupt it), and it must end with a complete line
  // (otherwise std::runtime_error: call truncate_after() first on restart,
  // which drops a row cut off by a crash). A missing or empty file is created
  // with a header as if append were false.
  //
  // Throws std::invalid_argument if `columns` is empty or a column name
  // contains ',', '"', '\r' or '\n' (names are written unquoted), and
  // std::runtime_error naming the file if it cannot be opened.
  CsvWriter(std::filesystem::path path, std::vector<std::string> columns, bool append = false);

  // Writes one row, numbers printed with %.17g so that they read back to the
  // same double, then flushes so that a crashed run keeps every row written.
  // Throws std::invalid_argument if values.size() != number of columns, and
  // std::runtime_error naming the file if the write fails.
  void row(const std::vector<double>& values);

  const std::filesystem::path& path() const { return path_; }
  const std::vector<std::string>& columns() const { return columns_; }

  // For a restart from a checkpoint at time `last_time_kept`: atomically
  // rewrites `path` keeping the header and the data rows whose first column
  // is <= last_time_kept. Rows that cannot be complete (unparsable first
  // field, a last line without its newline, i.e. cut off by a crash) are
  // dropped too. A missing file is left missing (nothing was written before
  // the checkpoint). Throws std::runtime_error naming the file if it cannot be
  // read or rewritten. Do not call it while a CsvWriter has the file open.
  static void truncate_after(const std::filesystem::path& path, double last_time_kept);

 private:
  std::filesystem::path path_;
  std::vector<std::string> columns_;
  std::ofstream out_;
};

}  // namespace sanguis::io
