// Tests for CsvWriter (core/io/csv.hpp): header handling, exact round-trip of
// doubles, per-row flushing, append mode and truncation on restart.
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/io/csv.hpp"

namespace sanguis::io {
namespace {

namespace fs = std::filesystem;

class CsvWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string test_name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::random_device entropy;
    directory_ = fs::temp_directory_path() /
                 ("sanguis_test_csv_" + test_name + "_" + std::to_string(entropy()));
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

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

// Parses the data rows (everything after the header) back into doubles.
std::vector<std::vector<double>> read_rows(const fs::path& path) {
  std::istringstream text(read_text(path));
  std::string line;
  std::getline(text, line);  // header
  std::vector<std::vector<double>> rows;
  while (std::getline(text, line)) {
    std::vector<double> row;
    std::istringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) {
      char* end = nullptr;
      row.push_back(std::strtod(field.c_str(), &end));
      EXPECT_EQ(*end, '\0') << "unparsable field '" << field << "'";
    }
    rows.push_back(row);
  }
  return rows;
}

TEST_F(CsvWriterTest, WritesHeaderOnCreation) {
  const fs::path path = directory_ / "energy.csv";
  CsvWriter writer(path, {"time", "kinetic", "potential"});
  EXPECT_EQ(read_text(path), "time,kinetic,potential\n");
  EXPECT_EQ(writer.columns().size(), 3u);
}

TEST_F(CsvWriterTest, ValuesRoundTripExactly) {
  const fs::path path = directory_ / "values.csv";
  const std::vector<double> values = {0.1,
                                      1e-300,
                                      1.0 / 3.0,
                                      -0.0,
                                      std::numeric_limits<double>::denorm_min(),
                                      std::numeric_limits<double>::max(),
                                      -123456789.0123456789,
                                      0.1 + 0.2};
  std::vector<std::string> columns;
  for (std::size_t i = 0; i < values.size(); ++i) columns.push_back("c" + std::to_string(i));
  {
    CsvWriter writer(path, columns);
    writer.row(values);
  }
  const auto rows = read_rows(path);
  ASSERT_EQ(rows.size(), 1u);
  ASSERT_EQ(rows[0].size(), values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    EXPECT_EQ(std::bit_cast<std::uint64_t>(rows[0][i]), std::bit_cast<std::uint64_t>(values[i]))
        << "column " << i << " value " << values[i];
  }
  EXPECT_NE(read_text(path).find("0.10000000000000001,1e-300,0.33333333333333331,"),
            std::string::npos);
}

TEST_F(CsvWriterTest, RowsAreOnDiskBeforeTheWriterCloses) {
  const fs::path path = directory_ / "live.csv";
  CsvWriter writer(path, {"t", "x"});
  writer.row({1.0, 2.0});
  // Read through an independent stream while the writer is still open, as a
  // crashed process would leave it.
  EXPECT_EQ(read_text(path), "t,x\n1,2\n");
  writer.row({3.0, 4.5});
  EXPECT_EQ(read_text(path), "t,x\n1,2\n3,4.5\n");
}

TEST_F(CsvWriterTest, WrongRowSizeThrowsAndWritesNothing) {
  const fs::path path = directory_ / "sizes.csv";
  CsvWriter writer(path, {"t", "x", "y"});
  EXPECT_THROW(writer.row({1.0, 2.0}), std::invalid_argument);
  EXPECT_THROW(writer.row({1.0, 2.0, 3.0, 4.0}), std::invalid_argument);
  EXPECT_EQ(read_text(path), "t,x,y\n");
  writer.row({1.0, 2.0, 3.0});  // still usable afterwards
  EXPECT_EQ(read_rows(path).size(), 1u);
}

TEST_F(CsvWriterTest, InvalidColumnsThrow) {
  EXPECT_THROW(CsvWriter(directory_ / "a.csv", {}), std::invalid_argument);
  EXPECT_THROW(CsvWriter(directory_ / "b.csv", {"t", "x,y"}), std::invalid_argument);
  EXPECT_THROW(CsvWriter(directory_ / "c.csv", {"t", "x\n"}), std::invalid_argument);
}

TEST_F(CsvWriterTest, UnwritablePathThrowsNamingIt) {
  const fs::path path = directory_ / "missing_dir" / "x.csv";
  try {
    CsvWriter writer(path, {"t"});
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find(path.string()), std::string::npos) << error.what();
  }
}

TEST_F(CsvWriterTest, WithoutAppendAnExistingFileIsReplaced) {
  const fs::path path = directory_ / "replace.csv";
  write_text(path, "old,header\n1,2\n");
  CsvWriter writer(path, {"t", "x"});
  EXPECT_EQ(read_text(path), "t,x\n");
}

TEST_F(CsvWriterTest, AppendContinuesExistingFileWithoutSecondHeader) {
  const fs::path path = directory_ / "append.csv";
  {
    CsvWriter writer(path, {"t", "x"});
    writer.row({0.0, 1.0});
    writer.row({0.5, 2.0});
  }
  {
    CsvWriter writer(path, {"t", "x"}, /*append=*/true);
    writer.row({1.0, 3.0});
  }
  EXPECT_EQ(read_text(path), "t,x\n0,1\n0.5,2\n1,3\n");
}

TEST_F(CsvWriterTest, AppendToMissingOrEmptyFileWritesHeader) {
  const fs::path missing = directory_ / "new.csv";
  {
    CsvWriter writer(missing, {"t", "x"}, /*append=*/true);
    writer.row({1.0, 2.0});
  }
  EXPECT_EQ(read_text(missing), "t,x\n1,2\n");

  const fs::path empty = directory_ / "empty.csv";
  write_text(empty, "");
  CsvWriter writer(empty, {"t"}, /*append=*/true);
  EXPECT_EQ(read_text(empty), "t\n");
}

TEST_F(CsvWriterTest, AppendWithDifferentHeaderThrowsAndKeepsFile) {
  const fs::path path = directory_ / "mismatch.csv";
  {
    CsvWriter writer(path, {"t", "x"});
    writer.row({1.0, 2.0});
  }
  EXPECT_THROW(CsvWriter(path, {"t", "x", "y"}, true), std::runtime_error);
  EXPECT_THROW(CsvWriter(path, {"t", "X"}, true), std::runtime_error);
  EXPECT_EQ(read_text(path), "t,x\n1,2\n");
}

TEST_F(CsvWriterTest, AppendAfterCutOffRowNeedsTruncation) {
  const fs::path path = directory_ / "crashed.csv";
  write_text(path, "t,x\n0,1\n1,2\n2,3.14");  // last row cut off mid-write
  EXPECT_THROW(CsvWriter(path, {"t", "x"}, true), std::runtime_error);

  CsvWriter::truncate_after(path, 10.0);
  EXPECT_EQ(read_text(path), "t,x\n0,1\n1,2\n");
  CsvWriter writer(path, {"t", "x"}, true);
  writer.row({2.0, 3.0});
  EXPECT_EQ(read_text(path), "t,x\n0,1\n1,2\n2,3\n");
}

TEST_F(CsvWriterTest, TruncateAfterKeepsHeaderAndRowsUpToTime) {
  const fs::path path = directory_ / "series.csv";
  {
    CsvWriter writer(path, {"time", "value"});
    for (const double time : {0.0, 0.1, 0.1 + 0.2, 0.5, 1.0}) writer.row({time, 2.0 * time});
  }
  CsvWriter::truncate_after(path, 0.1 + 0.2);  // exactly the third time: kept
  const auto rows = read_rows(path);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[2][0], 0.1 + 0.2);
  EXPECT_EQ(read_text(path).substr(0, 11), "time,value\n");
  EXPECT_FALSE(fs::exists(directory_ / "series.csv.tmp"));

  CsvWriter::truncate_after(path, -1.0);  // before every row: header only
  EXPECT_EQ(read_text(path), "time,value\n");
}

TEST_F(CsvWriterTest, TruncateAfterOnMissingFileDoesNothing) {
  const fs::path path = directory_ / "absent.csv";
  CsvWriter::truncate_after(path, 1.0);
  EXPECT_FALSE(fs::exists(path));
}

}  // namespace
}  // namespace sanguis::io
