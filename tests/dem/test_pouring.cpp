// Pouring particles from a region at a given rate during the run (issue #3): the count
// and the timing, no overlap at insertion, bodies as well as spheres, and a restart in
// the middle of the pour that continues bit for bit.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include "core/config.hpp"
#include "core/io/vtk_reader.hpp"
#include "dem/dem_case.hpp"
#include "dem/dem_run.hpp"

namespace sanguis::dem {
namespace {

const char* kPour = R"(
[simulation]
end_time_s = 0.2
seed = 21
[domain]
min_m = [0.0, 0.0, 0.0]
max_m = [0.03, 0.03, 0.06]
[[shape]]
name = "brick"
type = "box"
size_m = [0.004, 0.002, 0.002]
[[material]]
name = "glass"
density_kg_m3 = 2500.0
[[material]]
name = "wall"
[[interaction]]
materials = ["glass", "glass"]
normal_restitution = 0.4
tangential_restitution = 0.3
max_overlap_ratio = 0.01
max_impact_velocity_m_s = 1.0
[[interaction]]
materials = ["glass", "wall"]
normal_restitution = 0.4
tangential_restitution = 0.3
max_overlap_ratio = 0.01
max_impact_velocity_m_s = 1.0
[[obstacle]]
type = "plane"
material = "wall"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[particles]]
material = "glass"
radius_m = 1e-3
arrangement = "pour"
count = 60
rate_per_s = 1000.0
region_min_m = [0.0, 0.0, 0.04]
region_max_m = [0.03, 0.03, 0.06]
velocity_m_s = [0.0, 0.0, -0.5]
[[particles]]
material = "glass"
shape = "brick"
arrangement = "pour"
count = 20
rate_per_s = 400.0
start_s = 0.01
region_min_m = [0.0, 0.0, 0.04]
region_max_m = [0.03, 0.03, 0.06]
)";

DemCase pour_case() {
  return load_dem_case(ConfigTable::parse_string(kPour, "pour.toml"), "pour.toml");
}

TEST(Pouring, InsertsAtTheRateWithoutOverlap) {
  DemCase c = pour_case();
  EXPECT_EQ(c.setup.particles.size(), 0u);
  DemSimulation sim(c.setup);
  sim.run_until(0.0305);  // spheres due: floor(30.5) + 1 = 31; bricks: floor(8.2) + 1 = 9
  EXPECT_EQ(sim.particles().size(), 31u + 9u);
  sim.run_until(0.2);
  ASSERT_EQ(sim.particles().size(), 80u);
  int bodies = 0;
  for (std::size_t i = 0; i < sim.particles().size(); ++i) bodies += !sim.particles().spherical[i];
  EXPECT_EQ(bodies, 20);
  EXPECT_LT(sim.diagnostics().max_overlap_ratio, 0.05);  // no particle was placed overlapping
  EXPECT_GT(sim.diagnostics().wall_contacts, 0);         // they reached the floor
}

TEST(Pouring, APourThatStartsEmptyTakesItsThreadsAndMatchesOneThread) {
  DemCase c = pour_case();
  c.setup.particles_per_thread = 20;  // two threads from 40 particles on
  DemSimulation serial(c.setup);
  c.setup.threads = 2;
  DemSimulation threaded(c.setup);
  EXPECT_EQ(threaded.threads(), 1);  // empty
  serial.run_until(0.06);            // about 70 particles by then
  threaded.run_until(0.06);
  EXPECT_EQ(threaded.threads(), 2);
  const auto& a = serial.particles().position;
  const auto& b = threaded.particles().position;
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)), 0);
}

TEST(Pouring, RestartInTheMiddleOfThePourIsBitForBit) {
  const auto file = std::filesystem::temp_directory_path() / "sanguis_test_pour.ckpt";
  DemCase c = pour_case();
  DemSimulation whole(c.setup);
  whole.run_until(0.02);
  whole.save_checkpoint(file);
  whole.run_until(0.06);
  DemSimulation resumed(c.setup);
  resumed.load_checkpoint(file);
  resumed.run_until(0.06);
  ASSERT_EQ(resumed.particles().size(), whole.particles().size());
  const auto& a = whole.particles().position;
  const auto& b = resumed.particles().position;
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)), 0);
  std::filesystem::remove(file);
}

// Runs the pour case to 0.05 s through run_dem_case (quiet) into a fresh folder `name` of
// the temporary directory, frames every frame_interval, checkpoints every
// checkpoint_interval (0: only at the end); returns the folder.
std::filesystem::path run_pour_case(const std::string& name, double frame_interval,
                                    double checkpoint_interval) {
  const auto dir = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(dir);
  DemCase c = pour_case();
  c.stop.end_time = 0.05;
  c.output.interval = frame_interval;
  c.output.checkpoint_interval = checkpoint_interval;
  RunOptions options;
  options.output_dir = dir;
  options.quiet = true;
  std::ostringstream console;
  run_dem_case(c, options, console);
  return dir;
}

// Checkpoints written along the way leave a run's results unchanged (the dam-break
// validations checkpoint every 0.05 s so that a killed run loses little): the last frame
// of a run with a checkpoint every 5 ms is the same file as that of a run with none.
TEST(Pouring, CheckpointsAlongTheWayLeaveTheRunUnchanged) {
  std::string frames[2];
  const double intervals[2] = {0.005, 0.0};
  for (int k = 0; k < 2; ++k) {
    const auto dir =
        run_pour_case("sanguis_test_pour_checkpoints_" + std::to_string(k), 0.025, intervals[k]);
    const auto particles = io::read_pvd(dir / "particles.pvd");
    ASSERT_FALSE(particles.empty());
    std::ifstream in(particles.back().dataset, std::ios::binary);
    frames[k].assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    // run.log notes each checkpoint written along the way: several, then none.
    std::ifstream log(dir / "run.log");
    int checkpoints = 0;
    for (std::string line; std::getline(log, line);)
      checkpoints += line.rfind("checkpoint:", 0) == 0;
    if (k == 0) {
      EXPECT_GE(checkpoints, 5);
    } else {
      EXPECT_EQ(checkpoints, 0);
    }
    std::filesystem::remove_all(dir);
  }
  EXPECT_FALSE(frames[0].empty());
  EXPECT_EQ(frames[0], frames[1]);
}

// The bodies poured during a run have their surfaces in every frame, from the first
// (empty) one on, so that the frames of bodies.pvd match those of particles.pvd.
TEST(Pouring, RunWritesBodySurfacesFromTheFirstFrame) {
  const auto dir = run_pour_case("sanguis_test_pour_bodies", 0.01, 0.0);
  const auto particles = io::read_pvd(dir / "particles.pvd");
  const auto bodies = io::read_pvd(dir / "bodies.pvd");
  ASSERT_EQ(bodies.size(), particles.size());
  for (std::size_t k = 0; k < bodies.size(); ++k) EXPECT_EQ(bodies[k].time, particles[k].time);
  EXPECT_TRUE(io::read_polymesh_vtp(bodies.front().dataset).polygons.empty());
  EXPECT_FALSE(io::read_polymesh_vtp(bodies.back().dataset).polygons.empty());
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sanguis::dem
