// Bit-for-bit restart: a run interrupted by a checkpoint and resumed in a fresh
// simulation continues exactly like the uninterrupted run, for every integrator
// (the Adams-Bashforth history included) with friction and rolling-friction
// contact memories, walls and a periodic axis; then the same through the
// executable (`sanguis run --restart`), comparing the output files byte for byte.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/config.hpp"
#include "dem/dem_case.hpp"
#include "dem/dem_run.hpp"
#include "dem/simulation.hpp"

namespace sanguis::dem {
namespace {

namespace fs = std::filesystem;

// 200 glass spheres placed at random with random velocities in a box that is
// periodic along x, closed by a floor and two side walls along y; a strong gravity
// makes them settle into a bed with lasting contacts within a few thousand steps.
const std::string kBoxCase = R"(
[simulation]
name = "restart"
end_time_s = 0.01
integrator = "INTEGRATOR"
seed = 11
gravity_m_s2 = [0.0, 0.0, -100.0]

[domain]
min_m = [0.0, 0.0, 0.0]
max_m = [0.015, 0.015, 0.03]
periodic = [true, false, false]

[[material]]
name = "glass"
density_kg_m3 = 2500.0

[[material]]
name = "steel"

[[interaction]]
materials = ["glass", "glass"]
normal_restitution = 0.5
tangential_restitution = 0.4
max_overlap_ratio = 0.01
max_impact_velocity_m_s = 1.0
friction = 0.5
rolling_friction = 0.1

[[interaction]]
materials = ["glass", "steel"]
normal_restitution = 0.6
tangential_restitution = 0.4
max_overlap_ratio = 0.01
max_impact_velocity_m_s = 1.0
friction = 0.4
rolling_friction = 0.1

[[obstacle]]
name = "floor"
type = "plane"
material = "steel"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[[obstacle]]
name = "front"
type = "plane"
material = "steel"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]

[[obstacle]]
name = "back"
type = "plane"
material = "steel"
point_m = [0.0, 0.015, 0.0]
normal = [0.0, -1.0, 0.0]

[[particles]]
material = "glass"
radius_min_m = 0.9e-3
radius_max_m = 1.1e-3
arrangement = "random"
count = 200
region_min_m = [0.0, 0.0, 0.0]
region_max_m = [0.015, 0.015, 0.012]
velocity_noise_m_s = 0.5
)";

DemCase box_case(const std::string& integrator) {
  std::string text = kBoxCase;
  text.replace(text.find("INTEGRATOR"), 10, integrator);
  DemCase c = load_dem_case(ConfigTable::parse_string(text, "restart.toml"), "restart.toml");
  c.setup.storage_sort_interval = 70;  // several storage sorts before and after a restart
  return c;
}

template <typename T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

// A per-particle array in id order: the test compares runs whose storage may have been
// sorted at different steps (DemSetup::storage_sort_interval).
template <typename T>
std::vector<T> by_id(const std::vector<T>& values, const ParticleStore& p) {
  return in_id_order(values, p.id);
}

void expect_identical(const DemSimulation& a, const DemSimulation& b) {
  EXPECT_EQ(a.step_index(), b.step_index());
  const ParticleStore& p = a.particles();
  const ParticleStore& q = b.particles();
  EXPECT_TRUE(same_bytes(by_id(p.position, p), by_id(q.position, q))) << "positions differ";
  EXPECT_TRUE(same_bytes(by_id(p.velocity, p), by_id(q.velocity, q))) << "velocities differ";
  EXPECT_TRUE(same_bytes(by_id(p.angular_velocity, p), by_id(q.angular_velocity, q)))
      << "angular velocities differ";
  EXPECT_TRUE(same_bytes(by_id(p.force, p), by_id(q.force, q))) << "forces differ";
  EXPECT_TRUE(same_bytes(by_id(p.torque, p), by_id(q.torque, q))) << "torques differ";
  EXPECT_TRUE(same_bytes(a.particle_contacts().history, b.particle_contacts().history))
      << "particle contact histories differ";
  EXPECT_TRUE(same_bytes(a.wall_contacts().history, b.wall_contacts().history))
      << "wall contact histories differ";
  // Spot check with plain == as well, so a failure names a value.
  const std::vector<std::uint32_t> pi = id_order(p.id), qi = id_order(q.id);
  for (std::size_t k = 0; k < p.size(); k += 37) {
    EXPECT_EQ(p.position[pi[k]], q.position[qi[k]]) << "particle " << p.id[pi[k]];
    EXPECT_EQ(p.angular_velocity[pi[k]], q.angular_velocity[qi[k]]) << "particle " << p.id[pi[k]];
  }
}

// Contacts that carry memory (a tangential spring and a rolling spring) right now.
int contacts_with_memory(const ContactList& list) {
  int n = 0;
  for (const ContactHistory& h : list.history) {
    const bool tangential = norm2(h.tangential_displacement) > 0.0;
    const bool rolling = norm2(h.rolling_spring_torque) > 0.0;
    n += tangential && rolling ? 1 : 0;
  }
  return n;
}

// Steps on to a state whose contacts hold memories (tangential and rolling springs)
// of particle pairs and of particles on walls, or a restart test proves little: at
// least 6000 steps, then to the first such state (deterministic: the same step every
// time). False if none is reached within 20000 steps.
bool step_to_live_contacts(DemSimulation& sim) {
  while (sim.step_index() < 6000) sim.step();
  while (contacts_with_memory(sim.particle_contacts()) < 20 ||
         contacts_with_memory(sim.wall_contacts()) < 5) {
    if (sim.step_index() >= 20000) return false;
    sim.step();
  }
  return true;
}

class RestartTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string test_name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    for (char& ch : test_name) ch = ch == '/' ? '_' : ch;  // parameterised: "Name/euler"
    std::random_device entropy;
    dir_ = fs::temp_directory_path() /
           ("sanguis_test_restart_" + test_name + "_" + std::to_string(entropy()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  fs::path dir_;
};

class IntegratorRestartTest : public RestartTest,
                              public ::testing::WithParamInterface<std::string> {};

TEST_P(IntegratorRestartTest, ResumedRunIsBitForBitIdentical) {
  constexpr int kAfter = 1000;
  const DemCase c = box_case(GetParam());
  ASSERT_EQ(to_string(c.setup.integrator), GetParam());
  ASSERT_EQ(c.setup.particles.size(), 200u);
  const fs::path checkpoint = dir_ / "checkpoint.bin";

  DemSimulation original(c.setup);
  ASSERT_TRUE(step_to_live_contacts(original));
  const std::int64_t before = original.step_index();
  RecordProperty("checkpoint_step", static_cast<int>(before));
  if (c.setup.integrator == IntegratorKind::kAdamsBashforth2 ||
      c.setup.integrator == IntegratorKind::kAdamsBashforth3) {
    ASSERT_EQ(original.integrator().history().depth, 2);
  }
  original.save_checkpoint(checkpoint);
  for (int k = 0; k < kAfter; ++k) original.step();

  DemSimulation resumed(c.setup);
  resumed.load_checkpoint(checkpoint);
  EXPECT_EQ(resumed.step_index(), before);
  for (int k = 0; k < kAfter; ++k) resumed.step();
  expect_identical(original, resumed);

  // The diagnostics of both agree exactly too.
  const DemDiagnostics d1 = original.diagnostics();
  const DemDiagnostics d2 = resumed.diagnostics();
  EXPECT_EQ(d1.kinetic_energy_translational, d2.kinetic_energy_translational);
  EXPECT_EQ(d1.kinetic_energy_rotational, d2.kinetic_energy_rotational);
  EXPECT_EQ(d1.particle_contacts, d2.particle_contacts);
  EXPECT_EQ(d1.max_overlap_ratio, d2.max_overlap_ratio);
}

TEST_P(IntegratorRestartTest, ContinuingWithoutTheCheckpointDiverges) {
  // Control: a fresh simulation that only copies the particle state, without the
  // checkpoint's contact memories, neighbour lists and multistep history, does not
  // reproduce the run: the comparison above is sensitive to what the checkpoint carries.
  constexpr int kAfter = 300;
  const DemCase c = box_case(GetParam());
  DemSimulation original(c.setup);
  ASSERT_TRUE(step_to_live_contacts(original));
  DemSetup copy = c.setup;
  copy.particles = original.particles();
  DemSimulation naive(copy);
  for (int k = 0; k < kAfter; ++k) {
    original.step();
    naive.step();
  }
  EXPECT_FALSE(same_bytes(by_id(original.particles().position, original.particles()),
                          by_id(naive.particles().position, naive.particles())));
}

TEST_F(RestartTest, MultistepHistoryIsPartOfTheCheckpoint) {
  // Dropping the Adams-Bashforth history after loading changes the continuation.
  for (const char* integrator : {"adams_bashforth_2", "adams_bashforth_3"}) {
    SCOPED_TRACE(integrator);
    const DemCase c = box_case(integrator);
    const fs::path checkpoint = dir_ / (std::string(integrator) + ".bin");
    DemSimulation original(c.setup);
    for (int k = 0; k < 200; ++k) original.step();
    original.save_checkpoint(checkpoint);
    for (int k = 0; k < 50; ++k) original.step();

    DemSimulation with_history(c.setup), without_history(c.setup);
    with_history.load_checkpoint(checkpoint);
    without_history.load_checkpoint(checkpoint);
    EXPECT_EQ(with_history.integrator().history().depth, 2);
    without_history.integrator().history().depth = 0;
    for (int k = 0; k < 50; ++k) {
      with_history.step();
      without_history.step();
    }
    EXPECT_TRUE(same_bytes(by_id(original.particles().position, original.particles()),
                           by_id(with_history.particles().position, with_history.particles())));
    EXPECT_FALSE(
        same_bytes(by_id(original.particles().position, original.particles()),
                   by_id(without_history.particles().position, without_history.particles())));
  }
}

TEST_F(RestartTest, CheckpointOfAnotherCaseIsRejected) {
  const DemCase leapfrog = box_case("leapfrog");
  const DemCase euler = box_case("euler");
  const fs::path checkpoint = dir_ / "checkpoint.bin";
  DemSimulation a(leapfrog.setup);
  a.step();
  a.save_checkpoint(checkpoint);
  DemSimulation b(euler.setup);
  EXPECT_THROW(b.load_checkpoint(checkpoint), InputError);
  std::ofstream(dir_ / "garbage.bin") << "not a checkpoint";
  DemSimulation d(leapfrog.setup);
  EXPECT_THROW(d.load_checkpoint(dir_ / "garbage.bin"), InputError);
  EXPECT_THROW(d.load_checkpoint(dir_ / "missing.bin"), InputError);
}

INSTANTIATE_TEST_SUITE_P(AllIntegrators, IntegratorRestartTest,
                         ::testing::Values("euler", "leapfrog", "adams_bashforth_2",
                                           "adams_bashforth_3"),
                         [](const auto& info) { return info.param; });

// --- Through the executable ----------------------------------------------------------

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in) << "cannot read " << path;
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Output files of a run that must not depend on how it was split (run.log does).
std::map<std::string, std::string> run_outputs(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    const std::string rel = fs::relative(entry.path(), dir).string();
    if (entry.is_regular_file() && rel != "run.log") files[rel] = read_file(entry.path());
  }
  return files;
}

int sanguis(const std::string& args, const fs::path& log) {
  const std::string command =
      std::string("'") + SANGUIS_BINARY + "' " + args + " >'" + log.string() + "' 2>&1 </dev/null";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// 60 spheres with friction and rolling friction falling into a corner, 10000 steps of
// 2 us, output every 2000 steps; the split run stops at step 4000 (an output time).
const std::string kCliCase = R"(
[simulation]
name = "cli-restart"
end_time_s = END_TIME
time_step_s = 2e-6
integrator = "adams_bashforth_3"
seed = 2

[domain]
min_m = [0.0, 0.0, 0.0]
max_m = [0.012, 0.012, 0.02]

[[material]]
name = "glass"
density_kg_m3 = 2500.0

[[material]]
name = "steel"

[[interaction]]
materials = ["glass", "glass"]
normal_restitution = 0.5
tangential_restitution = 0.4
max_overlap_ratio = 0.01
max_impact_velocity_m_s = 1.0
rolling_friction = 0.1

[[interaction]]
materials = ["glass", "steel"]
normal_restitution = 0.5
tangential_restitution = 0.4
max_overlap_ratio = 0.01
max_impact_velocity_m_s = 1.0
rolling_friction = 0.1

[[obstacle]]
type = "plane"
material = "steel"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[[obstacle]]
type = "box"
material = "steel"
min_m = [0.0, 0.0, 0.0]
max_m = [0.002, 0.012, 0.02]

[[particles]]
material = "glass"
radius_m = 1e-3
arrangement = "random"
count = 60
region_min_m = [0.002, 0.0, 0.0]
region_max_m = [0.012, 0.012, 0.012]
velocity_noise_m_s = 0.5

[output]
interval_s = 0.004
)";

std::string cli_case(const std::string& end_time) {
  std::string text = kCliCase;
  text.replace(text.find("END_TIME"), 8, end_time);
  return text;
}

TEST_F(RestartTest, CliRestartReproducesTheUninterruptedRun) {
  const fs::path case_file = dir_ / "case.toml";
  std::ofstream(case_file) << cli_case("0.02");
  const fs::path whole = dir_ / "whole";
  const fs::path split = dir_ / "split";

  // Reference: one go.
  ASSERT_EQ(sanguis("run '" + case_file.string() + "' -q -o '" + whole.string() + "'",
                    dir_ / "whole.txt"),
            0)
      << read_file(dir_ / "whole.txt");

  // Split: stop at t = 0.008 s with a checkpoint (RunOptions::stop_at), then resume with
  // `sanguis run --restart`.
  RunOptions first;
  first.output_dir = split;
  first.quiet = true;
  first.stop_at = 0.008;
  std::ostringstream console, progress;
  std::streambuf* const cerr_buffer = std::cerr.rdbuf(progress.rdbuf());  // the "done" line
  const RunSummary part = run_dem_case(load_dem_case(case_file), first, console);
  std::cerr.rdbuf(cerr_buffer);
  EXPECT_EQ(part.steps, 4000);
  EXPECT_EQ(part.simulated_time, 4000 * 2e-6);
  const std::string csv_at_stop = read_file(split / "diagnostics.csv");
  ASSERT_EQ(sanguis("run '" + case_file.string() + "' -q --restart -o '" + split.string() + "'",
                    dir_ / "split.txt"),
            0)
      << read_file(dir_ / "split.txt");

  const auto expected = run_outputs(whole);
  const auto actual = run_outputs(split);
  ASSERT_TRUE(expected.count("diagnostics.csv"));
  ASSERT_TRUE(expected.count("particles/particles_00000005.vtu"));  // t = 0.02 s
  ASSERT_TRUE(expected.count("checkpoint.bin"));
  // diagnostics.csv: 6 rows (t = 0, 4, ..., 20 ms), identical byte for byte; the rows
  // written before the stop are kept as they were.
  EXPECT_EQ(actual.at("diagnostics.csv"), expected.at("diagnostics.csv"));
  EXPECT_EQ(expected.at("diagnostics.csv").rfind(csv_at_stop, 0), 0u);
  // Every frame, the .pvd indexes and the final checkpoint are identical byte for byte.
  EXPECT_EQ(actual.at("particles/particles_00000005.vtu"),
            expected.at("particles/particles_00000005.vtu"));
  for (const auto& [name, bytes] : expected) {
    ASSERT_TRUE(actual.count(name)) << name << " is missing from the resumed run";
    EXPECT_TRUE(actual.at(name) == bytes) << name << " differs";
  }
  EXPECT_EQ(actual.size(), expected.size());
  // The resumed run appended to the log.
  EXPECT_NE(read_file(split / "run.log").find("--- restart from checkpoint at t = 0.008"),
            std::string::npos);
}

TEST_F(RestartTest, CliRestartExtendsAFinishedRun) {
  // The same case run to 8 ms, then resumed with the end time raised to 20 ms, both
  // through the executable only, gives the uninterrupted 20 ms run.
  const fs::path short_case = dir_ / "short.toml";
  const fs::path long_case = dir_ / "long.toml";
  std::ofstream(short_case) << cli_case("0.008");
  std::ofstream(long_case) << cli_case("0.02");
  const fs::path whole = dir_ / "whole";
  const fs::path split = dir_ / "split";
  ASSERT_EQ(
      sanguis("run '" + long_case.string() + "' -q -o '" + whole.string() + "'", dir_ / "a.txt"),
      0);
  ASSERT_EQ(
      sanguis("run '" + short_case.string() + "' -q -o '" + split.string() + "'", dir_ / "b.txt"),
      0);
  ASSERT_EQ(sanguis("run '" + long_case.string() + "' -q --restart -o '" + split.string() + "'",
                    dir_ / "c.txt"),
            0)
      << read_file(dir_ / "c.txt");
  const auto expected = run_outputs(whole);
  const auto actual = run_outputs(split);
  EXPECT_EQ(actual.at("diagnostics.csv"), expected.at("diagnostics.csv"));
  EXPECT_EQ(actual.at("particles.pvd"), expected.at("particles.pvd"));
  EXPECT_EQ(actual.at("particles/particles_00000005.vtu"),
            expected.at("particles/particles_00000005.vtu"));
  EXPECT_EQ(actual.at("checkpoint.bin"), expected.at("checkpoint.bin"));
}

}  // namespace
}  // namespace sanguis::dem
