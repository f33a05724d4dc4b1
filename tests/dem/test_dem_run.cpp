// The run driver: the settle stop condition, output cadence and files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/config.hpp"
#include "dem/dem_run.hpp"

namespace sanguis::dem {
namespace {

const char* kSettle = R"(
[simulation]
end_time_s = 2.0
[domain]
min_m = [0.0, 0.0, 0.0]
max_m = [0.01, 0.01, 0.02]
periodic = [true, true, false]
[[material]]
name = "glass"
density_kg_m3 = 2500.0
[[material]]
name = "wall"
[[interaction]]
materials = ["glass", "glass"]
normal_restitution = 0.3
tangential_restitution = 0.3
max_overlap_ratio = 0.01
max_impact_velocity_m_s = 0.5
rolling_friction = 0.1
[[interaction]]
materials = ["glass", "wall"]
normal_restitution = 0.3
tangential_restitution = 0.3
max_overlap_ratio = 0.01
max_impact_velocity_m_s = 0.5
rolling_friction = 0.1
[[obstacle]]
type = "plane"
material = "wall"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[particles]]
material = "glass"
radius_m = 1e-3
arrangement = "lattice"
spacing_m = 2.5e-3
region_min_m = [0.0, 0.0, 0.002]
region_max_m = [0.01, 0.01, 0.01]
velocity_noise_m_s = 0.05
[output]
interval_s = 0.01
vtk = false
[stop]
mean_velocity_below_m_s = 1e-5
check_after_s = 0.05
)";

TEST(DemRun, StopsWhenSettledAndWritesOneRowPerOutput) {
  const auto dir = std::filesystem::temp_directory_path() / "sanguis_test_dem_run";
  std::filesystem::remove_all(dir);
  const DemCase c = load_dem_case(ConfigTable::parse_string(kSettle, "settle.toml"), "settle.toml");
  RunOptions options;
  options.output_dir = dir;
  options.quiet = true;
  std::ostringstream console;
  const RunSummary summary = run_dem_case(c, options, console);
  EXPECT_TRUE(summary.settled);
  EXPECT_LT(summary.simulated_time, c.stop.end_time);
  EXPECT_GE(summary.simulated_time, 0.05);
  EXPECT_LT(summary.last.mean_velocity, 1e-5);

  std::ifstream csv(dir / "diagnostics.csv");
  std::string line;
  int rows = -1;  // header
  while (std::getline(csv, line)) ++rows;
  // One row at t = 0 and one per 0.01 s until the stop.
  EXPECT_EQ(rows, 1 + static_cast<int>(std::lround(summary.simulated_time / 0.01)));
  EXPECT_TRUE(std::filesystem::exists(dir / "checkpoint.bin"));
  EXPECT_FALSE(std::filesystem::exists(dir / "particles.pvd"));  // vtk = false
  std::filesystem::remove_all(dir);
}

TEST(DemRun, AnEndTimeOffTheOutputGridGetsItsOwnSnapshot) {
  const auto dir = std::filesystem::temp_directory_path() / "sanguis_test_dem_run_frames";
  std::filesystem::remove_all(dir);
  std::string text = kSettle;
  text.replace(text.find("end_time_s = 2.0"), 16, "end_time_s = 0.02");
  text.replace(text.find("interval_s = 0.01"), 17, "interval_s = 0.006");
  text.replace(text.find("vtk = false"), 11, "vtk = true");
  text.replace(text.find("mean_velocity_below_m_s = 1e-5"), 30, "mean_velocity_below_m_s = 1e-12");
  const DemCase c = load_dem_case(ConfigTable::parse_string(text, "frames.toml"), "frames.toml");
  RunOptions options;
  options.output_dir = dir;
  options.quiet = true;
  std::ostringstream console;
  run_dem_case(c, options, console);
  // Outputs at 0, 0.006, 0.012, 0.018 and the end 0.02: five distinct frames.
  int frames = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir / "particles")) {
    frames += e.path().extension() == ".vtu";
  }
  EXPECT_EQ(frames, 5);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sanguis::dem
