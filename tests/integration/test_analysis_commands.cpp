// End-to-end tests of `sanguis analyze`, `ensemble` and `calibrate` on a small
// dam break (tests/integration/data/dam-break-tiny.toml), and of `run --set`.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_harness.hpp"
#include "core/io/vtk_reader.hpp"

namespace sanguis {
namespace {

using testing_cli::CommandResult;
using testing_cli::read_text_file;
using testing_cli::shell_quoted;
namespace fs = std::filesystem;

const std::string kTinyCase =
    shell_quoted(std::string(SANGUIS_SOURCE_DIR) + "/tests/integration/data/dam-break-tiny.toml");

// The first data row of a CSV file as name -> value (text).
std::map<std::string, std::string> first_row(const fs::path& file) {
  std::istringstream in(read_text_file(file));
  std::string header, row;
  std::getline(in, header);
  std::getline(in, row);
  std::map<std::string, std::string> values;
  std::istringstream h(header), r(row);
  std::string name, value;
  while (std::getline(h, name, ',') && std::getline(r, value, ',')) values[name] = value;
  return values;
}

double number(const std::map<std::string, std::string>& row, const std::string& key) {
  const auto it = row.find(key);
  if (it == row.end()) throw std::runtime_error("no column " + key);
  return std::stod(it->second);
}

class AnalysisCommandTest : public testing_cli::SanguisCommandTest {};

TEST_F(AnalysisCommandTest, AnalyzeMeasuresTheCollapseOfASmallColumn) {
  const fs::path run = dir_ / "run";
  const CommandResult r =
      sanguis("run " + kTinyCase + " --quiet --threads 1 -o " + shell_quoted(run.string()));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(read_text_file(run / "obstacles.csv").find("4,box,0.25,gate"), std::string::npos);

  const CommandResult a = sanguis("analyze " + shell_quoted(run.string()));
  ASSERT_EQ(a.code, 0) << a.err;
  const fs::path out = run / "analysis";
  const auto s = first_row(out / "summary.csv");
  // The initial frame is the gate removal (obstacles.csv), at 0.25 s.
  EXPECT_NEAR(number(s, "initial_time_s"), 0.25, 0.025);
  EXPECT_EQ(number(s, "release_time_s"), 0.25);  // the clock of velocity.csv starts there
  // The column stands 16 mm long behind the gate; one pixel is half a mean radius.
  EXPECT_NEAR(number(s, "L0_m"), 0.016, 0.002);
  // 200 beads of 2 mm in 16 x 16 mm at a packing fraction near 0.6: H0 about 4.4 cm.
  EXPECT_GT(number(s, "H0_m"), 0.03);
  EXPECT_LT(number(s, "H0_m"), 0.07);
  EXPECT_GT(number(s, "Linf_m"), 2 * number(s, "L0_m"));
  EXPECT_LE(number(s, "Linf_20pc_m"), number(s, "Linf_m"));
  EXPECT_GE(number(s, "Linf_1pc_m"), number(s, "Linf_m"));
  EXPECT_LT(number(s, "Hinf_m"), number(s, "H0_m"));
  EXPECT_EQ(number(s, "regime"), 2.0);  // collapsed
  EXPECT_GT(number(s, "com_displacement_x_m"), 0.0);
  // A random loose packing of frictional spheres: 3 to 6 neighbours.
  EXPECT_GT(number(s, "pair_coordination"), 3.0);
  EXPECT_LT(number(s, "pair_coordination"), 6.0);
  // Four beads across: most touch a wall, where they lack neighbours; those
  // that touch none have more. The default bulk (four mean radii, 8 mm, in
  // from every side) is empty in a column 16 mm wide.
  EXPECT_GT(number(s, "particles_touching_obstacles_fraction"), 0.5);
  EXPECT_LT(number(s, "particles_touching_obstacles_fraction"), 1.0);
  EXPECT_GT(number(s, "pair_coordination_away_from_obstacles"), number(s, "pair_coordination"));
  EXPECT_NEAR(number(s, "bulk_margin_m"), 0.008, 0.0005);
  EXPECT_EQ(number(s, "bulk_particles"), 0.0);
  // The walls carry the column: floor most of it, nothing pulls down.
  const std::string walls = read_text_file(out / "walls.csv");
  EXPECT_NE(walls.find("\"side wall, front\""), std::string::npos);
  EXPECT_NE(walls.find("\"gate\""), std::string::npos);
  for (const char* file : {"runout.csv", "height.csv", "velocity.csv", "force_pdf.csv",
                           "fabric.csv", "coordination.csv", "strong_network.vtp"}) {
    EXPECT_TRUE(fs::exists(out / file)) << file;
  }
  const io::PolyMesh strong = io::read_polymesh_vtp(out / "strong_network.vtp");
  const io::PolyMesh all = io::read_polymesh_vtp(run / "contacts" / "branches_00000010.vtp");
  EXPECT_LT(strong.lines.size(), all.lines.size());

  // A bulk one radius in from every side: the core of the column, better
  // surrounded than the column as a whole.
  const fs::path core = dir_ / "core";
  const CommandResult b = sanguis("analyze " + shell_quoted(run.string()) +
                                  " --bulk-margin 0.002 --out " + shell_quoted(core.string()));
  ASSERT_EQ(b.code, 0) << b.err;
  EXPECT_NE(b.out.find("bulk (0.002 m in from every side)"), std::string::npos) << b.out;
  const auto c = first_row(core / "summary.csv");
  EXPECT_GT(number(c, "bulk_particles"), 10.0);
  EXPECT_LT(number(c, "bulk_particles"), number(c, "particles"));
  EXPECT_GT(number(c, "bulk_pair_coordination"), number(c, "pair_coordination"));
  EXPECT_LT(number(c, "bulk_pair_coordination"), 7.0);
  EXPECT_NE(read_text_file(core / "coordination.csv").find("\"bulk\""), std::string::npos);
  EXPECT_EQ(sanguis("analyze " + shell_quoted(run.string()) + " --bulk-margin -1").code, 2);
}

TEST_F(AnalysisCommandTest, AnalyzeRefusesAFolderThatIsNotARun) {
  const CommandResult a = sanguis("analyze " + shell_quoted(dir_.string()));
  EXPECT_EQ(a.code, 2);
  EXPECT_NE(a.err.find("not a sanguis DEM output folder"), std::string::npos) << a.err;
}

TEST_F(AnalysisCommandTest, EnsembleRunsSeedsInParallelAndAggregates) {
  const fs::path root = dir_ / "ens";
  const CommandResult e = sanguis("ensemble " + kTinyCase + " --seeds 2 --jobs 2 -o " +
                                  shell_quoted(root.string()) + " --set simulation.end_time_s=0.3");
  ASSERT_EQ(e.code, 0) << e.err << e.out;
  const std::string table = read_text_file(root / "ensemble.csv");
  EXPECT_NE(table.find("Linf_m,"), std::string::npos);
  EXPECT_NE(table.find("fraction_collapsed,"), std::string::npos);
  // Columns four beads wide have no bulk: its coordination has no runs, not a mean of zeros.
  EXPECT_NE(table.find("\nbulk_pair_coordination,,,,,0\n"), std::string::npos) << table;
  EXPECT_NE(table.find("\nbulk_particles,0,0,0,0,2\n"), std::string::npos) << table;
  // Different seeds, different packings.
  EXPECT_NE(read_text_file(root / "seed_1" / "particles" / "particles_00000000.vtu"),
            read_text_file(root / "seed_2" / "particles" / "particles_00000000.vtu"));
  EXPECT_NE(read_text_file(root / "seed_2" / "run.log").find("seed            2"),
            std::string::npos);
}

// An ensemble as one point of a flow map (Fig. 3.6): its column and how its runs ended;
// a folder without ensembles is refused and the map left as it was.
TEST_F(AnalysisCommandTest, FlowMapMapsEnsemblesAndRefusesFoldersWithout) {
  const fs::path root = dir_ / "ens";
  const CommandResult e = sanguis("ensemble " + kTinyCase + " --seeds 2 --jobs 2 -o " +
                                  shell_quoted(root.string()) + " --set simulation.end_time_s=0.3");
  ASSERT_EQ(e.code, 0) << e.err << e.out;
  const fs::path map = dir_ / "map";
  const CommandResult m =
      sanguis("flow-map " + shell_quoted(dir_.string()) + " -o " + shell_quoted(map.string()));
  ASSERT_EQ(m.code, 0) << m.err << m.out;
  const auto point = first_row(map / "flow_map.csv");
  EXPECT_EQ(point.at("ensemble"), root.string());
  EXPECT_EQ(point.at("runs"), "2");
  const int collapsed = std::stoi(point.at("collapsed")),
            fractured = std::stoi(point.at("fractured"));
  EXPECT_EQ(collapsed + fractured + std::stoi(point.at("stable")), 2);
  EXPECT_EQ(point.at("outcome"), collapsed == 2               ? "collapsed"
                                 : fractured == 2             ? "fractured"
                                 : collapsed + fractured == 0 ? "stable"
                                                              : "intermittent");
  EXPECT_GT(number(point, "H0_m"), 0.0);
  EXPECT_EQ(read_text_file(map / "flow_map.png").substr(0, 4), "\x89PNG");
  // A folder without ensembles is refused, naming it, and the map stays as it was.
  const std::string before = read_text_file(map / "flow_map.csv");
  const CommandResult bad = sanguis("flow-map " + shell_quoted((root / "seed_1").string()) +
                                    " -o " + shell_quoted(map.string()));
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("seed_1: no ensemble.csv in it or in its subfolders"), std::string::npos)
      << bad.err;
  EXPECT_EQ(read_text_file(map / "flow_map.csv"), before);
}

// Friction against run-out: two values bracket a target, the estimate lies
// between them; a measure that does not exist is refused with the list.
TEST_F(AnalysisCommandTest, CalibrateFitsAParameterToATarget) {
  const fs::path root = dir_ / "cal";
  const std::string common = "calibrate " + kTinyCase +
                             " --parameter interaction[0].friction --values 0.1,0.8 --seeds 1 "
                             "--jobs 2 --set simulation.end_time_s=0.45 -o " +
                             shell_quoted(root.string());
  const CommandResult bad = sanguis(common + " --measure nonsense --target 1");
  EXPECT_EQ(bad.code, 2) << bad.err;
  EXPECT_NE(bad.err.find("runout_ratio"), std::string::npos) << bad.err;

  CommandResult c = sanguis(common + " --measure Linf_m --target 0.05");
  ASSERT_EQ(c.code, 0) << c.err << c.out;
  std::istringstream table(read_text_file(root / "calibration.csv"));
  std::string line;
  std::vector<double> runout;
  std::getline(table, line);
  while (std::getline(table, line)) {
    runout.push_back(std::stod(line.substr(line.find(',') + 1)));
  }
  ASSERT_EQ(runout.size(), 2u);
  EXPECT_GT(runout[0], runout[1]);  // more friction, shorter run-out
  const double target = 0.5 * (runout[0] + runout[1]);
  std::ostringstream exact;
  exact.precision(17);
  exact << target;
  c = sanguis(common + " --measure Linf_m --target " + exact.str());
  ASSERT_EQ(c.code, 0) << c.err;
  const auto result = first_row(root / "calibration_result.csv");
  EXPECT_EQ(number(result, "bracketed"), 1.0);
  // A straight line through the two points: the midpoint of the values.
  EXPECT_NEAR(number(result, "estimate"), 0.45, 1e-6);
}

// A calibration continued from one prepared state (the column at rest before
// the gate opens), varying two keys together; a second call with --reuse keeps
// the finished runs, and a changed command line runs them again.
TEST_F(AnalysisCommandTest, CalibrateContinuesFromAPreparedStateAndReusesRuns) {
  const fs::path prepared = dir_ / "prepared";
  const CommandResult p =
      sanguis("run " + kTinyCase + " --quiet --threads 1 -o " + shell_quoted(prepared.string()) +
              " --set simulation.end_time_s=0.2");
  ASSERT_EQ(p.code, 0) << p.err;
  const fs::path root = dir_ / "cal";
  const auto calibrate = [&](const std::string& values, const fs::path& from) {
    return "calibrate " + kTinyCase +
           " --parameter interaction[0].friction,interaction[1].friction --values " + values +
           " --measure Linf_m --target 0.05 --jobs 2 --set simulation.end_time_s=0.45 -o " +
           shell_quoted(root.string()) + " --from " + shell_quoted(from.string());
  };
  const std::string common = calibrate("0.1,0.8", prepared);
  const CommandResult c = sanguis(common);
  ASSERT_EQ(c.code, 0) << c.err << c.out;
  EXPECT_NE(c.out.find("(0 reused, 0 resumed)"), std::string::npos) << c.out;
  const fs::path run = root / "value_0.8" / "seed_1";
  // The run holds the prepared frames unchanged and continues them with both keys set.
  EXPECT_EQ(read_text_file(run / "particles" / "particles_00000000.vtu"),
            read_text_file(prepared / "particles" / "particles_00000000.vtu"));
  const std::string log = read_text_file(run / "run.log");
  const std::string prepared_log = read_text_file(prepared / "run.log");
  ASSERT_EQ(log.substr(0, prepared_log.size()), prepared_log);  // continued, not restarted
  const std::string continuation = log.substr(prepared_log.size());
  EXPECT_NE(continuation.find("mu_c = 0.8"), std::string::npos) << continuation;
  EXPECT_EQ(continuation.find("mu_c = 0.5\n"), std::string::npos);
  EXPECT_EQ(continuation.find("mu_c = 0.45"), std::string::npos);
  EXPECT_NE(read_text_file(run / "calibration_run.txt").find("--restart"), std::string::npos);
  EXPECT_EQ(read_text_file(run / "calibration_run.txt").find("--output"), std::string::npos);
  const std::string table = read_text_file(root / "calibration.csv");

  const CommandResult again = sanguis(common + " --reuse");
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_NE(again.out.find("(2 reused, 0 resumed)"), std::string::npos) << again.out;
  EXPECT_EQ(read_text_file(run / "run.log"), log);  // not run again
  EXPECT_EQ(read_text_file(root / "calibration.csv"), table);
  // A value added: the others are kept.
  const CommandResult changed = sanguis(calibrate("0.1,0.5,0.8", prepared) + " --reuse");
  ASSERT_EQ(changed.code, 0) << changed.err;
  EXPECT_NE(changed.out.find("(2 reused, 0 resumed)"), std::string::npos) << changed.out;
  EXPECT_EQ(read_text_file(run / "run.log"), log);
  EXPECT_NE(read_text_file(root / "value_0.5" / "seed_1" / "run.log").find("mu_c = 0.5"),
            std::string::npos);
  // Changed settings: run again.
  const CommandResult other = sanguis(calibrate("0.1,0.8", prepared) +
                                      " --reuse --set interaction[0].rolling_friction=0.1");
  ASSERT_EQ(other.code, 0) << other.err;
  EXPECT_NE(other.out.find("(0 reused, 0 resumed)"), std::string::npos) << other.out;

  const CommandResult seeds = sanguis(common + " --seeds 2");
  EXPECT_EQ(seeds.code, 2);
  EXPECT_NE(seeds.err.find("--seeds"), std::string::npos) << seeds.err;
  const CommandResult empty = sanguis(calibrate("0.1,0.8", dir_));
  EXPECT_EQ(empty.code, 2);
  EXPECT_NE(empty.err.find("no checkpoint.bin"), std::string::npos) << empty.err;
}

// A calibration stopped part-way (a killed call, an ended session) goes on with
// --reuse from the checkpoint its unfinished run left, to the bits of a run that
// was never stopped; a run whose command changed starts afresh.
TEST_F(AnalysisCommandTest, CalibrateResumesAnInterruptedRunToTheSameBits) {
  const fs::path prepared = dir_ / "prepared";
  ASSERT_EQ(sanguis("run " + kTinyCase + " --quiet --threads 1 -o " +
                    shell_quoted(prepared.string()) + " --set simulation.end_time_s=0.2")
                .code,
            0);
  const std::string friction =
      " --set interaction[0].friction=0.8 --set "
      "interaction[1].friction=0.8";
  const auto calibrate = [&](const fs::path& root) {
    return "calibrate " + kTinyCase +
           " --parameter interaction[0].friction,interaction[1].friction --values 0.1,0.8"
           " --measure Linf_m --target 0.05 --jobs 2 --set simulation.end_time_s=0.45 -o " +
           shell_quoted(root.string()) + " --from " + shell_quoted(prepared.string());
  };
  const fs::path whole = dir_ / "whole";
  ASSERT_EQ(sanguis(calibrate(whole)).code, 0);
  const fs::path whole_run = whole / "value_0.8" / "seed_1";
  const std::string command = read_text_file(whole_run / "calibration_run.txt");
  EXPECT_EQ(read_text_file(whole_run / "calibration_started.txt"), command);

  // The state a call stopped at 0.3 s leaves: the run continued from the
  // prepared state with the same settings, its start recorded, no finish.
  const fs::path stopped = dir_ / "stopped";
  const fs::path run = stopped / "value_0.8" / "seed_1";
  fs::create_directories(run.parent_path());
  fs::copy(prepared, run, fs::copy_options::recursive);
  ASSERT_EQ(sanguis("run " + kTinyCase + " --restart --quiet --threads 1 -o " +
                    shell_quoted(run.string()) + friction + " --set simulation.end_time_s=0.3")
                .code,
            0);
  {
    std::ofstream record(run / "calibration_started.txt");
    record << command;
  }
  const CommandResult resumed = sanguis(calibrate(stopped) + " --reuse");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  EXPECT_NE(resumed.out.find("(0 reused, 1 resumed)"), std::string::npos) << resumed.out;
  const std::string log = read_text_file(run / "run.log");
  EXPECT_NE(log.find("restart from checkpoint at t = 0.300"), std::string::npos) << log;
  EXPECT_EQ(read_text_file(run / "checkpoint.bin"), read_text_file(whole_run / "checkpoint.bin"));
  EXPECT_EQ(read_text_file(run / "calibration_run.txt"), command);
  EXPECT_EQ(read_text_file(stopped / "calibration.csv"), read_text_file(whole / "calibration.csv"));

  // A started record of another command: not resumed, run afresh from --from.
  {
    std::ofstream record(run / "calibration_started.txt");
    record << "run something else\n";
  }
  fs::remove(run / "calibration_run.txt");
  const CommandResult fresh = sanguis(calibrate(stopped) + " --reuse");
  ASSERT_EQ(fresh.code, 0) << fresh.err;
  EXPECT_NE(fresh.out.find("(1 reused, 0 resumed)"), std::string::npos) << fresh.out;
  EXPECT_EQ(read_text_file(run / "run.log").find("at t = 0.300"), std::string::npos);
  EXPECT_EQ(read_text_file(run / "checkpoint.bin"), read_text_file(whole_run / "checkpoint.bin"));
}

// Processes whose command line mentions `text` (a scan of /proc).
int processes_mentioning(const std::string& text) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream in(entry.path() / "cmdline", std::ios::binary);
    const std::string cmdline((std::istreambuf_iterator<char>(in)),
                              std::istreambuf_iterator<char>());
    if (cmdline.find(text) != std::string::npos) ++count;
  }
  return count;
}

// Stopping an ensemble stops its runs: they must not go on writing into
// folders that the next call clears.
TEST_F(AnalysisCommandTest, StoppingAnEnsembleStopsItsRuns) {
  const fs::path root = dir_ / "ens";
  const std::string command =
      shell_quoted(SANGUIS_BINARY) + " ensemble " + kTinyCase + " --seeds 2 --jobs 2 -o " +
      shell_quoted(root.string()) + " --set simulation.end_time_s=1000 >/dev/null 2>&1 & " +
      "P=$!; for i in $(seq 100); do [ -s " + shell_quoted((root / "seed_2" / "run.log").string()) +
      " ] && break; sleep 0.1; done; kill -TERM $P; wait $P; echo $? > " +
      shell_quoted((dir_ / "status").string());
  ASSERT_EQ(std::system(command.c_str()), 0);
  EXPECT_EQ(read_text_file(dir_ / "status"), "143\n");  // ended by SIGTERM
  int left = processes_mentioning(root.string());
  for (int wait = 0; wait < 50 && left > 0; ++wait) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    left = processes_mentioning(root.string());
  }
  EXPECT_EQ(left, 0);
  // The runs had started.
  EXPECT_TRUE(fs::exists(root / "seed_1" / "console.txt"));
}

TEST_F(AnalysisCommandTest, RunSetOverridesAreStrict) {
  const fs::path out = dir_ / "o";
  CommandResult r = sanguis("run " + kTinyCase + " -q -o " + shell_quoted(out.string()) +
                            " --set interaction[0].frictionn=0.3");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("frictionn"), std::string::npos) << r.err;
  r = sanguis("run " + kTinyCase + " -q -o " + shell_quoted(out.string()) +
              " --set interaction[7].friction=0.3");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no element 7"), std::string::npos) << r.err;
  r = sanguis("run " + kTinyCase + " -q -o " + shell_quoted(out.string()) +
              " --set simulation.end_time_s=-1");
  EXPECT_EQ(r.code, 2);
  EXPECT_FALSE(fs::exists(out));
  // A table the case leaves out can be given; a misspelt one is refused.
  r = sanguis("run " + kTinyCase + " -q -o " + shell_quoted(out.string()) +
              " --set stopp.mean_velocity_below_m_s=1e-3");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("stopp"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  r = sanguis("run " + kTinyCase + " -q -o " + shell_quoted(out.string()) +
              " --set stop.mean_velocity_below_m_s=100 --set stop.check_after_s=0.3");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(read_text_file(out / "run.log").find("settled"), std::string::npos)
      << read_text_file(out / "run.log");
}

}  // namespace
}  // namespace sanguis
