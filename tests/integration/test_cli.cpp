// End-to-end tests of the `sanguis` executable (app/main.cpp): exit codes
// (0 ok, 1 blow-up, 2 bad input), error messages naming file and key, bad input
// leaving an existing output directory untouched, the files a run writes, and
// `params --json`.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "cli_harness.hpp"
#include "core/config.hpp"
#include "dem/dem_case.hpp"

namespace sanguis {
namespace {

namespace fs = std::filesystem;

std::string read_file(const fs::path& path) {
  return testing_cli::read_text_file(path);
}

void write_file(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

std::string quoted(const std::string& s) {
  return testing_cli::shell_quoted(s);
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

std::size_t count_of(const std::string& text, const std::string& part) {
  std::size_t n = 0;
  for (std::size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
  return n;
}

// Every regular file under `dir` (relative path -> bytes).
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    const std::string rel = fs::relative(entry.path(), dir).string();
    files[rel] = entry.is_regular_file() ? read_file(entry.path()) : std::string("<dir>");
  }
  return files;
}

// --- A minimal JSON reader: validates the text and collects numbers by dotted path.

class JsonReader {
 public:
  explicit JsonReader(std::string text) : s_(std::move(text)) {}

  // True if the whole text is one valid JSON value.
  bool parse() {
    try {
      value("");
      skip();
      return i_ == s_.size();
    } catch (const std::runtime_error&) {
      return false;
    }
  }
  const std::map<std::string, double>& numbers() const { return numbers_; }

 private:
  void skip() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
  }
  char peek() {
    skip();
    if (i_ >= s_.size()) throw std::runtime_error("unexpected end");
    return s_[i_];
  }
  void expect(char c) {
    if (peek() != c) throw std::runtime_error(std::string("expected ") + c);
    ++i_;
  }
  std::string string() {
    expect('"');
    std::string out;
    while (i_ < s_.size() && s_[i_] != '"') {
      if (s_[i_] == '\\') ++i_;
      if (i_ < s_.size()) out += s_[i_++];
    }
    if (i_ >= s_.size()) throw std::runtime_error("unterminated string");
    ++i_;
    return out;
  }
  void value(const std::string& path) {
    const char c = peek();
    if (c == '{') {
      ++i_;
      if (peek() == '}') {
        ++i_;
        return;
      }
      for (;;) {
        const std::string key = string();
        expect(':');
        value(path.empty() ? key : path + "." + key);
        if (peek() == ',') {
          ++i_;
          continue;
        }
        expect('}');
        return;
      }
    }
    if (c == '[') {
      ++i_;
      if (peek() == ']') {
        ++i_;
        return;
      }
      for (int k = 0;; ++k) {
        value(path + "[" + std::to_string(k) + "]");
        if (peek() == ',') {
          ++i_;
          continue;
        }
        expect(']');
        return;
      }
    }
    if (c == '"') {
      string();
      return;
    }
    for (const char* word : {"true", "false", "null"}) {
      const std::string w(word);
      if (s_.compare(i_, w.size(), w) == 0) {
        i_ += w.size();
        return;
      }
    }
    // Number: strict JSON grammar (no leading '+', no bare '.', no inf/nan).
    const std::size_t start = i_;
    if (s_[i_] == '-') ++i_;
    const auto digits = [&] {
      const std::size_t from = i_;
      while (i_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[i_]))) ++i_;
      if (i_ == from) throw std::runtime_error("expected digits");
    };
    digits();
    if (i_ < s_.size() && s_[i_] == '.') {
      ++i_;
      digits();
    }
    if (i_ < s_.size() && (s_[i_] == 'e' || s_[i_] == 'E')) {
      ++i_;
      if (i_ < s_.size() && (s_[i_] == '+' || s_[i_] == '-')) ++i_;
      digits();
    }
    numbers_[path] = std::stod(s_.substr(start, i_ - start));
  }

  std::string s_;
  std::size_t i_ = 0;
  std::map<std::string, double> numbers_;
};

// --- Fixture ----------------------------------------------------------------------

using Result = testing_cli::CommandResult;
class CliTest : public testing_cli::SanguisCommandTest {};

// 30 glass spheres (R = 1 mm) dropped with a little random velocity onto a steel
// floor; 10000 steps of 2 us (Tc/21.7), output every 2500 steps.
const std::string kFallingCase = R"(
[simulation]
name = "falling"
end_time_s = 0.02
time_step_s = 2e-6
seed = 5

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
friction = 0.5
rolling_friction = 0.05

[[interaction]]
materials = ["glass", "steel"]
normal_restitution = 0.5
tangential_restitution = 0.4
max_overlap_ratio = 0.01
max_impact_velocity_m_s = 1.0

[[obstacle]]
name = "floor"
type = "plane"
material = "steel"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[[particles]]
material = "glass"
radius_m = 1e-3
arrangement = "random"
count = 30
region_min_m = [0.0, 0.0, 0.0]
region_max_m = [0.012, 0.012, 0.008]
velocity_noise_m_s = 0.2

[output]
interval_s = 0.005
)";

const char* kDiagnosticsHeader =
    "time_s,kinetic_energy_translational_J,kinetic_energy_rotational_J,mean_velocity_m_s,"
    "max_velocity_m_s,mean_angular_velocity_rad_s,particle_contacts,wall_contacts,"
    "max_overlap_over_radius";

std::string replaced(const std::string& text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  if (at == std::string::npos) {
    ADD_FAILURE() << "case text lacks '" << from << "'";
    return text;
  }
  std::string out = text;
  out.replace(at, from.size(), to);
  return out;
}

// --- Version and help ---------------------------------------------------------------

TEST_F(CliTest, VersionAndHelp) {
  const Result version = sanguis("--version");
  EXPECT_EQ(version.code, 0) << version.err;
  EXPECT_NE(version.out.find("sanguis 0."), std::string::npos) << version.out;

  const Result help = sanguis("--help");
  EXPECT_EQ(help.code, 0) << help.err;
  EXPECT_NE(help.out.find("run"), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("params"), std::string::npos) << help.out;

  const Result run_help = sanguis("run --help");
  EXPECT_EQ(run_help.code, 0);
  EXPECT_NE(run_help.out.find("--restart"), std::string::npos) << run_help.out;
}

TEST_F(CliTest, BadCommandLineIsExitCode2) {
  EXPECT_EQ(sanguis("").code, 2);     // a subcommand is required
  EXPECT_EQ(sanguis("run").code, 2);  // the case file is required
  EXPECT_EQ(sanguis("frobnicate").code, 2);
  EXPECT_EQ(sanguis("params --en abc").code, 2);
}

// --- Bad input: exit 2, message with file and key, output directory untouched -----

class BadCaseTest : public CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    output_ = dir_ / "previous-run";
    fs::create_directories(output_ / "particles");
    write_file(output_ / "diagnostics.csv", "time_s,mean_velocity_m_s\n0,1.5\n0.1,1.25\n");
    write_file(output_ / "KEEP-ME.marker", "results of an earlier run\n");
    write_file(output_ / "particles" / "particles_00000000.vtu", "<VTKFile/>\n");
    before_ = snapshot(output_);
  }

  // Runs the case and checks exit code 2, the message and the untouched directory.
  void expect_rejected(const fs::path& case_file, const std::vector<std::string>& message_parts,
                       const std::string& extra_args = "") {
    const Result r = sanguis("run " + quoted(case_file.string()) + " --output " +
                             quoted(output_.string()) + " --quiet " + extra_args);
    EXPECT_EQ(r.code, 2) << r.out << r.err;
    EXPECT_NE(r.err.find("sanguis: error:"), std::string::npos) << r.err;
    for (const std::string& part : message_parts) {
      EXPECT_NE(r.err.find(part), std::string::npos) << "stderr lacks '" << part << "': " << r.err;
    }
    EXPECT_EQ(snapshot(output_), before_) << "the output directory was modified";
  }

  fs::path output_;
  std::map<std::string, std::string> before_;
};

TEST_F(BadCaseTest, UnknownKey) {
  const fs::path file = dir_ / "typo.toml";
  write_file(file, replaced(kFallingCase, "radius_m = 1e-3", "raduis_m = 1e-3\nradius_m = 1e-3"));
  expect_rejected(file, {file.string(), "particles[0].raduis_m", "unknown key"});
}

TEST_F(BadCaseTest, MissingFile) {
  const fs::path file = dir_ / "no-such-case.toml";
  expect_rejected(file, {file.string(), "does not exist"});
}

TEST_F(BadCaseTest, TomlSyntaxError) {
  const fs::path file = dir_ / "syntax.toml";
  // Line 3 of the file (the text starts with a newline) loses its closing quote.
  write_file(file, replaced(kFallingCase, "name = \"falling\"", "name = \"falling"));
  expect_rejected(file, {file.string(), "TOML syntax error at line 3"});
}

TEST_F(BadCaseTest, OutOfRangeValueAndTimeStep) {
  const fs::path file = dir_ / "range.toml";
  write_file(file, replaced(kFallingCase, "time_step_s = 2e-6", "time_step_s = 1e-5"));
  expect_rejected(file, {file.string(), "simulation.time_step_s", "Tc/10"});
}

TEST_F(BadCaseTest, RestartWithoutCheckpoint) {
  const fs::path file = dir_ / "good.toml";
  write_file(file, kFallingCase);
  expect_rejected(file, {(output_ / "checkpoint.bin").string(), "no checkpoint"}, "--restart");
}

// --- A valid run --------------------------------------------------------------------

TEST_F(CliTest, SmallCaseRunsAndWritesItsOutputs) {
  const fs::path file = dir_ / "falling.toml";
  write_file(file, kFallingCase);
  const fs::path out = dir_ / "out";
  const Result r =
      sanguis("run " + quoted(file.string()) + " --output " + quoted(out.string()) + " --quiet");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("30 particles"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("10000 steps"), std::string::npos) << r.out;

  // diagnostics.csv: the documented header, one row per output (t = 0, 5, 10, 15, 20 ms).
  const std::vector<std::string> csv = lines_of(read_file(out / "diagnostics.csv"));
  ASSERT_EQ(csv.size(), 6u);
  EXPECT_EQ(csv[0], kDiagnosticsHeader);
  for (std::size_t k = 1; k < csv.size(); ++k) {
    const double t = std::stod(csv[k].substr(0, csv[k].find(',')));
    EXPECT_NEAR(t, 0.005 * static_cast<double>(k - 1), 1e-12) << csv[k];
    EXPECT_EQ(count_of(csv[k], ","), 8u) << csv[k];
  }
  EXPECT_EQ(csv[1].substr(0, 2), "0,");

  // ParaView indexes and the frames they name.
  const std::string particles_pvd = read_file(out / "particles.pvd");
  const std::string obstacles_pvd = read_file(out / "obstacles.pvd");
  EXPECT_EQ(count_of(particles_pvd, "<DataSet"), 5u) << particles_pvd;
  EXPECT_EQ(count_of(obstacles_pvd, "<DataSet"), 5u) << obstacles_pvd;
  for (int k = 0; k < 5; ++k) {
    char name[64];
    std::snprintf(name, sizeof name, "particles/particles_%08d.vtu", k);
    EXPECT_NE(particles_pvd.find(name), std::string::npos) << name;
    const std::string vtu = read_file(out / name);
    EXPECT_NE(vtu.find("UnstructuredGrid"), std::string::npos) << name;
    EXPECT_NE(vtu.find("NumberOfPoints=\"30\""), std::string::npos) << name;
    std::snprintf(name, sizeof name, "obstacles/obstacles_%08d.vtp", k);
    EXPECT_TRUE(fs::is_regular_file(out / name)) << name;
  }

  // run.log: resolved parameters; checkpoint.bin: a DEM checkpoint.
  const std::string log = read_file(out / "run.log");
  EXPECT_NE(log.find("kn = "), std::string::npos) << log;
  EXPECT_NE(log.find("glass - steel (wall)"), std::string::npos) << log;
  EXPECT_NE(log.find("time step       2e-06 s"), std::string::npos) << log;
  EXPECT_NE(log.find("done: t = 0.02 s"), std::string::npos) << log;
  EXPECT_EQ(read_file(out / "checkpoint.bin").substr(0, 15), "SANGUIS-DEM-CK4");
}

TEST_F(CliTest, VtkCanBeSwitchedOff) {
  const fs::path file = dir_ / "novtk.toml";
  write_file(file, replaced(kFallingCase, "interval_s = 0.005", "interval_s = 0.005\nvtk = false"));
  const fs::path out = dir_ / "out";
  const Result r = sanguis("run " + quoted(file.string()) + " -o " + quoted(out.string()) + " -q");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(fs::exists(out / "particles.pvd"));
  EXPECT_FALSE(fs::exists(out / "particles"));
  EXPECT_EQ(lines_of(read_file(out / "diagnostics.csv")).size(), 6u);
  EXPECT_TRUE(fs::exists(out / "checkpoint.bin"));
}

TEST_F(CliTest, RunLogGivesTheEndTimeToMoreThanFourDigits) {
  // Scripts tell a finished run from a stopped one by the time of run.log's done line
  // (validation/dem/_outputs.py); four digits would print 0.01235 for 0.012346 s.
  const fs::path file = dir_ / "falling.toml";
  write_file(file, kFallingCase);
  const fs::path out = dir_ / "out";
  const Result r = sanguis("run " + quoted(file.string()) + " -o " + quoted(out.string()) +
                           " -q --set simulation.end_time_s=0.012346");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string log = read_file(out / "run.log");
  EXPECT_NE(log.find("done: t = 0.012346 s, 6173 steps"), std::string::npos) << log;
}

TEST_F(CliTest, RunLogRecordsEachCheckpointWrittenOnTheWay) {
  // A killed run continues from its last checkpoint: scripts read these lines to know
  // how far it got and what that part cost (validation/dem/_outputs.py).
  const fs::path file = dir_ / "falling.toml";
  write_file(file, replaced(kFallingCase, "interval_s = 0.005",
                            "interval_s = 0.005\ncheckpoint_interval_s = 0.008"));
  const fs::path out = dir_ / "out";
  const Result r = sanguis("run " + quoted(file.string()) + " -o " + quoted(out.string()) + " -q");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string log = read_file(out / "run.log");
  EXPECT_NE(log.find("checkpoint: t = 0.008 s, 4000 steps in "), std::string::npos) << log;
  EXPECT_NE(log.find("checkpoint: t = 0.016 s, 8000 steps in "), std::string::npos) << log;
  EXPECT_EQ(count_of(log, "checkpoint: "), 2u) << log;
  EXPECT_LT(log.find("checkpoint: t = 0.016"), log.find("done: t = 0.02 s"));
  // Durations alone do not say when a part of a run ran, or whether it was paused
  // between: the start, checkpoint and done lines carry the date in UTC.
  const std::string stamp = R"(\d{4}-\d{2}-\d{2} \d{2}:\d{2}:\d{2} UTC)";
  EXPECT_TRUE(std::regex_search(log, std::regex("^sanguis \\S+, started " + stamp + "\n"))) << log;
  EXPECT_TRUE(std::regex_search(
      log, std::regex("checkpoint: t = 0.008 s, 4000 steps in \\S+, " + stamp + "\n")))
      << log;
  EXPECT_TRUE(std::regex_search(
      log, std::regex("done: t = 0.02 s, 10000 steps in \\S+ \\([^)]*\\), ended " + stamp + "\n")))
      << log;
}

// --- A blow-up -----------------------------------------------------------------------

TEST_F(CliTest, UnstableTimeStepExitsWithCode1AndKeepsASnapshot) {
  // dt = 5 Tc, allowed explicitly: contacts are not resolved and overlaps explode.
  const double tc =
      dem::load_dem_case(ConfigTable::parse_string(kFallingCase, "falling.toml"), "falling.toml")
          .smallest_contact_time;
  std::ostringstream dt;
  dt.precision(17);
  dt << "time_step_s = " << 5.0 * tc << "\nallow_large_time_step = true";
  const fs::path file = dir_ / "unstable.toml";
  write_file(file, replaced(kFallingCase, "time_step_s = 2e-6", dt.str()));
  const fs::path out = dir_ / "out";
  const Result r = sanguis("run " + quoted(file.string()) + " -o " + quoted(out.string()) + " -q");
  EXPECT_EQ(r.code, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("sanguis: simulation stopped:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("exceeds the bound 0.5"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("time step is too large"), std::string::npos) << r.err;

  // The log has the parameters and the reason; the CSV and the .pvd end with the
  // state at the failure (t > 0), whose frame exists; no checkpoint of a broken state.
  const std::string log = read_file(out / "run.log");
  EXPECT_NE(log.find("kn = "), std::string::npos) << log;
  EXPECT_NE(log.find("ERROR: step "), std::string::npos) << log;
  EXPECT_NE(log.find("exceeds the bound"), std::string::npos) << log;
  // The date says when a run broke off, which durations alone cannot.
  EXPECT_TRUE(std::regex_search(
      log, std::regex(R"(\nended by this error, \d{4}-\d{2}-\d{2} \d{2}:\d{2}:\d{2} UTC\n)")))
      << log;
  const std::vector<std::string> csv = lines_of(read_file(out / "diagnostics.csv"));
  ASSERT_GE(csv.size(), 3u);
  EXPECT_EQ(csv[0], kDiagnosticsHeader);
  EXPECT_GT(std::stod(csv.back().substr(0, csv.back().find(','))), 0.0);
  const std::string pvd = read_file(out / "particles.pvd");
  ASSERT_GE(count_of(pvd, "<DataSet"), 2u) << pvd;
  const std::size_t last = pvd.rfind("<DataSet");
  const std::size_t time_at = pvd.find("timestep=\"", last) + 10;
  EXPECT_GT(std::stod(pvd.substr(time_at, pvd.find('"', time_at) - time_at)), 0.0) << pvd;
  const std::size_t file_at = pvd.find("file=\"", last) + 6;
  const std::string frame = pvd.substr(file_at, pvd.find('"', file_at) - file_at);
  EXPECT_NE(read_file(out / frame).find("NumberOfPoints=\"30\""), std::string::npos) << frame;
  EXPECT_FALSE(fs::exists(out / "checkpoint.bin"));
}

// --- params ----------------------------------------------------------------------------

TEST_F(CliTest, ParamsJsonIsParseable) {
  const Result r = sanguis("params --json --radius 0.002 --en 0.6");
  ASSERT_EQ(r.code, 0) << r.err;
  JsonReader json(r.out);
  ASSERT_TRUE(json.parse()) << r.out;
  const auto& n = json.numbers();
  ASSERT_TRUE(n.count("particle-particle.kn_N_m")) << r.out;
  ASSERT_TRUE(n.count("particle-wall.kn_N_m")) << r.out;
  EXPECT_GT(n.at("particle-particle.kn_N_m"), 0.0);
  // A wall has twice the reduced mass and radius of a pair of equal spheres.
  EXPECT_NEAR(n.at("particle-wall.kn_N_m") / n.at("particle-particle.kn_N_m"), 2.0, 1e-6);
  EXPECT_EQ(n.at("inputs.radius_m"), 0.002);
  EXPECT_EQ(n.at("inputs.normal_restitution"), 0.6);
  EXPECT_NEAR(n.at("particle-particle.recommended_time_step_s"),
              n.at("particle-particle.contact_time_s") / 20.0,
              1e-9 * n.at("particle-particle.contact_time_s"));

  const Result text = sanguis("params");
  EXPECT_EQ(text.code, 0);
  EXPECT_NE(text.out.find("kn [N/m]"), std::string::npos) << text.out;
}

// `--steps 0` times the multigrid and the smoother alone, with no flow solver built: the
// line stays valid JSON (no step figures divided by zero) and carries the triad it is
// measured against.
TEST_F(CliTest, BenchFlowCavityWithoutStepsPrintsTheSmootherAgainstTheTriad) {
  const Result r = sanguis("bench flow-cavity --cells-per-side 16 --steps 0");
  ASSERT_EQ(r.code, 0) << r.err;
  JsonReader json(r.out.substr(r.out.rfind('{')));
  ASSERT_TRUE(json.parse()) << r.out;
  const auto& n = json.numbers();
  EXPECT_EQ(n.at("steps"), 0.0);
  EXPECT_EQ(n.at("cell_updates_per_s"), 0.0);
  EXPECT_GT(n.at("stream_triad_GB_s"), 0.0);
  EXPECT_GE(n.at("stream_triad_array_MiB"), 32.0);
  EXPECT_GT(n.at("smoother_bandwidth_fraction"), 0.0);
  EXPECT_GT(n.at("multigrid_reduction_per_cycle"), 1.0);
}

TEST(JsonReaderSelfTest, RejectsInvalidJson) {
  EXPECT_TRUE(JsonReader(R"({"a":{"b":[1,2.5e3,-0.1]},"c":"x","d":true})").parse());
  EXPECT_FALSE(JsonReader(R"({"a":1,})").parse());
  EXPECT_FALSE(JsonReader(R"({"a":nan})").parse());
  EXPECT_FALSE(JsonReader(R"({"a":1} trailing)").parse());
  EXPECT_FALSE(JsonReader(R"({"a":.5})").parse());
}

}  // namespace
}  // namespace sanguis
