// End-to-end tests of `sanguis slice` (scripts/flow_slice.py) on a small
// lid-driven cavity run: the cells a plane cuts, as CSV rows and a PNG, and
// clear refusals that leave an earlier slice intact.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "cli_harness.hpp"

namespace sanguis {
namespace {

using testing_cli::CommandResult;
using testing_cli::read_text_file;
using testing_cli::shell_quoted;
namespace fs = std::filesystem;

/// The rows of a slice CSV (after its header) as numbers.
std::vector<std::vector<double>> slice_rows(const fs::path& csv, std::string& header) {
  std::istringstream in(read_text_file(csv));
  std::getline(in, header);
  std::vector<std::vector<double>> rows;
  for (std::string line; std::getline(in, line);) {
    std::istringstream fields(line);
    std::vector<double> row;
    for (std::string value; std::getline(fields, value, ',');) row.push_back(std::stod(value));
    rows.push_back(row);
  }
  return rows;
}

class FlowSliceTest : public testing_cli::SanguisCommandTest {
 protected:
  /// The cavity of cases/flow at 16^3 cells to t = 0.1 s, frames every 0.05 s.
  fs::path run_cavity() {
    const fs::path out = dir_ / "cavity";
    const std::string case_file = std::string(SANGUIS_SOURCE_DIR) + "/cases/flow/cavity-re100.toml";
    const CommandResult r =
        sanguis("run " + shell_quoted(case_file) + " -q -t 1 -o " + shell_quoted(out.string()) +
                " --set simulation.end_time_s=0.1"
                " --set 'flow.grid.cells=[16,16,16]'"
                " --set output.interval_s=0.05");
    EXPECT_EQ(r.code, 0) << r.err;
    return out;
  }
};

TEST_F(FlowSliceTest, WritesOneRowPerCellTheMidPlaneCutsAndAPng) {
  const fs::path run = run_cavity();
  const fs::path png = dir_ / "slice.png";
  const CommandResult r =
      sanguis("slice " + shell_quoted(run.string()) + " --field velocity:x --normal z -o " +
              shell_quoted(png.string()));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("t = 0.1 s"), std::string::npos) << r.out;  // the last frame
  EXPECT_EQ(read_text_file(png).substr(0, 4), "\x89PNG");
  std::string header;
  const auto rows = slice_rows(dir_ / "slice.csv", header);
  EXPECT_EQ(header, "x_low_m,y_low_m,x_high_m,y_high_m,velocity_x");
  // One layer of the 16 x 16 cells, tiling the unit square; the lid (y = 1)
  // drags the top row along +x, the bottom row moves far less.
  ASSERT_EQ(rows.size(), 256u);
  double area = 0.0, top = 0.0, bottom = 0.0;
  for (const auto& row : rows) {
    ASSERT_EQ(row.size(), 5u);
    EXPECT_NEAR(row[2] - row[0], 1.0 / 16.0, 1e-12);
    EXPECT_NEAR(row[3] - row[1], 1.0 / 16.0, 1e-12);
    area += (row[2] - row[0]) * (row[3] - row[1]);
    if (row[3] > 1.0 - 1e-12) top += row[4] / 16.0;
    if (row[1] < 1e-12) bottom += std::abs(row[4]) / 16.0;
    EXPECT_LE(std::abs(row[4]), 1.0);
  }
  EXPECT_NEAR(area, 1.0, 1e-12);
  EXPECT_GT(top, 0.2);
  EXPECT_LT(bottom, 0.1 * top);

  // An earlier frame and another plane and field.
  const CommandResult first = sanguis("slice " + shell_quoted(run.string()) +
                                      " --frame 0 --normal x --at 0.25 --field pressure -o " +
                                      shell_quoted((dir_ / "p.png").string()));
  ASSERT_EQ(first.code, 0) << first.err;
  EXPECT_NE(first.out.find("t = 0 s"), std::string::npos) << first.out;
  EXPECT_EQ(slice_rows(dir_ / "p.csv", header).size(), 256u);
  EXPECT_EQ(header, "y_low_m,z_low_m,y_high_m,z_high_m,pressure");
}

TEST_F(FlowSliceTest, RefusesBadInputAndKeepsTheSliceAlreadyWritten) {
  const fs::path run = run_cavity();
  const fs::path png = dir_ / "slice.png";
  const std::string slice =
      "slice " + shell_quoted(run.string()) + " -o " + shell_quoted(png.string());
  ASSERT_EQ(sanguis(slice).code, 0);
  const std::string before = read_text_file(png);
  const std::string table = read_text_file(dir_ / "slice.csv");

  CommandResult r = sanguis(slice + " --field vorticity");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--field vorticity: no such cell array"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("vorticity_magnitude"), std::string::npos) << r.err;  // what there is
  r = sanguis(slice + " --field velocity");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("give velocity:x"), std::string::npos) << r.err;
  r = sanguis(slice + " --at 1.5");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("outside the domain along z"), std::string::npos) << r.err;
  r = sanguis(slice + " --frame 7");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("the run has 3 frames"), std::string::npos) << r.err;
  r = sanguis("slice " + shell_quoted(dir_.string()));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("flow.pvd: missing"), std::string::npos) << r.err;

  EXPECT_EQ(read_text_file(png), before);
  EXPECT_EQ(read_text_file(dir_ / "slice.csv"), table);
}

}  // namespace
}  // namespace sanguis
