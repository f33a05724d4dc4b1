#include "analysis_commands.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <charconv>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/io/atomic_file.hpp"
#include "core/progress.hpp"
#include "dem/analysis/analyze.hpp"
#include "dem/analysis/calibration_fit.hpp"

extern char** environ;

namespace sanguis::app {
namespace fs = std::filesystem;
using dem::analysis::AnalysisOptions;
using dem::analysis::RunAnalysis;

namespace {

struct AnalyzeArgs {
  std::vector<std::string> runs;
  std::string out;
  double time = -1.0;
  double initial_time = -1.0;
  double wall = NAN, floor = NAN, pixel = NAN, strong = 5.0, gravity = 9.81, bulk_margin = NAN;
  std::vector<double> width;
  bool plot = false;
};

struct EnsembleArgs {
  std::string case_file, output;
  int seeds = 4, first_seed = 1, jobs = 0;
  std::vector<std::string> overrides;
  bool plot = false;
};

struct SliceArgs {
  std::string run, normal = "z", field = "speed", output;
  std::vector<int> frame;  // at most one: given or not
  std::vector<double> time, at;
  bool blocks = false;
};

struct FlowMapArgs {
  std::vector<std::string> ensembles;
  std::string output = "flow-map";
  bool no_plot = false;
};

struct CalibrateArgs {
  std::string case_file, output, measure, from;
  std::vector<std::string> parameters;  // each gets the same value
  std::vector<double> values;
  double target = NAN, target_std = 0.0;
  int seeds = 0, first_seed = 1, jobs = 0;  // seeds 0: 2, or 1 with --from
  std::vector<std::string> overrides;
  bool reuse = false;
};

AnalysisOptions analysis_options(const AnalyzeArgs& a) {
  AnalysisOptions o;
  o.final_time = a.time;
  if (a.initial_time >= 0) o.initial_time = a.initial_time;
  if (!std::isnan(a.wall)) o.wall_x = a.wall;
  if (!std::isnan(a.floor)) o.floor_z = a.floor;
  if (!std::isnan(a.pixel)) o.pixel = a.pixel;
  if (a.width.size() == 2) {
    o.y_min = a.width[0];
    o.y_max = a.width[1];
  }
  o.strong_force_ratio = a.strong;
  o.gravity = a.gravity;
  if (!std::isnan(a.bulk_margin)) o.bulk_margin = a.bulk_margin;
  return o;
}

std::string source_dir() {
  return SANGUIS_SOURCE_DIR;
}

// A shell word holding s exactly (single quotes; a quote inside as '\\'').
std::string shell_quoted(const std::string& s) {
  std::string out = "'";
  for (const char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// Draws the figures of an analysis folder (scripts/plot_analysis.py, matplotlib).
void plot(const fs::path& dir) {
  const std::string command = "/usr/bin/python3 " +
                              shell_quoted(source_dir() + "/scripts/plot_analysis.py") + " " +
                              shell_quoted(dir.string());
  if (std::system(command.c_str()) != 0) {
    std::cerr << "sanguis: warning: plotting failed (" << command
              << "); the CSV files are written\n";
  }
}

// A plane slice of a flow run as PNG and CSV (scripts/flow_slice.py, matplotlib):
// returns the script's exit status (2: bad input, its message printed).
int run_slice(const SliceArgs& a) {
  std::string command = "/usr/bin/python3 " +
                        shell_quoted(source_dir() + "/scripts/flow_slice.py") + " " +
                        shell_quoted(a.run) + " --normal " + shell_quoted(a.normal) + " --field " +
                        shell_quoted(a.field);
  const auto number = [](double v) {
    std::ostringstream text;
    text.precision(17);
    text << v;
    return text.str();
  };
  if (!a.frame.empty()) command += " --frame " + std::to_string(a.frame.front());
  if (!a.time.empty()) command += " --time " + number(a.time.front());
  if (!a.at.empty()) command += " --at " + number(a.at.front());
  if (a.blocks) command += " --blocks";
  if (!a.output.empty()) command += " --output " + shell_quoted(a.output);
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : 1;
}

// The map of flow regimes (thesis Fig. 3.6) from ensemble folders, CSV and PNG
// (scripts/flow_map.py, matplotlib): returns the script's exit status (2: bad
// input, its message printed).
int run_flow_map(const FlowMapArgs& a) {
  std::string command = "/usr/bin/python3 " + shell_quoted(source_dir() + "/scripts/flow_map.py");
  for (const std::string& dir : a.ensembles) command += " " + shell_quoted(dir);
  command += " --output " + shell_quoted(a.output);
  if (a.no_plot) command += " --no-plot";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : 1;
}

RunAnalysis analyze_one(const fs::path& run, const AnalysisOptions& options, const fs::path& out,
                        bool draw) {
  const dem::analysis::RunOutput output(run);
  RunAnalysis a = dem::analysis::analyze_run(output, options);
  dem::analysis::write_analysis(a, out);
  if (draw) plot(out);
  return a;
}

void print_summary(const RunAnalysis& a) {
  std::printf("%s: t0 = %.4g s, t = %.4g s, %zu particles, regime %s\n", a.run.c_str(),
              a.initial_time, a.final_time, a.particles,
              dem::analysis::to_string(a.regime).c_str());
  std::printf("  L0 = %.4g m  H0 = %.4g m (q1 %.4g, q3 %.4g)  a = H0/L0 = %.3g\n",
              a.initial_length.length, a.initial_height.mean, a.initial_height.first_quartile,
              a.initial_height.third_quartile,
              a.initial_length.length > 0 ? a.initial_height.mean / a.initial_length.length : 0.0);
  std::printf("  Linf = %.4g m [%.4g, %.4g]  Hinf = %.4g m (q1 %.4g, q3 %.4g)  repose %.3g deg\n",
              a.final_length.length, a.final_length.length_lower, a.final_length.length_upper,
              a.final_height.mean, a.final_height.first_quartile, a.final_height.third_quartile,
              a.repose.angle_deg);
  if (!a.coordination.empty()) {
    const auto& whole = a.coordination[0].second;
    std::printf("  coordination (t0): pairs %.3f, contact points %.3f; fabric anisotropy %.3f\n",
                whole.pair_coordination, whole.contact_point_coordination, a.fabric.anisotropy);
    std::printf("  %zu of %zu particles touch an obstacle; pairs of the others %.3f\n",
                whole.particles_touching_obstacles, whole.particles,
                whole.pair_coordination_away_from_obstacles);
  }
  if (const auto bulk = a.bulk(); bulk.particles > 0) {
    std::printf(
        "  bulk (%.3g m in from every side): %zu particles, pairs %.3f, contact points %.3f\n",
        a.bulk_margin, bulk.particles, bulk.pair_coordination, bulk.contact_point_coordination);
  }
}

int run_analyze(const AnalyzeArgs& args) {
  const AnalysisOptions options = analysis_options(args);
  std::vector<RunAnalysis> all;
  for (const std::string& run : args.runs) {
    const fs::path out = args.runs.size() == 1 && !args.out.empty() ? fs::path(args.out)
                                                                    : fs::path(run) / "analysis";
    all.push_back(analyze_one(run, options, out, args.plot));
    print_summary(all.back());
    std::printf("  written to %s\n", out.string().c_str());
  }
  if (all.size() > 1) {
    const fs::path out = args.out.empty() ? fs::path("ensemble-analysis") : fs::path(args.out);
    dem::analysis::write_ensemble(all, out);
    std::printf("ensemble of %zu runs: %s\n", all.size(), (out / "ensemble.csv").string().c_str());
  }
  return 0;
}

// --- Running many cases at once ----------------------------------------------

struct Job {
  std::vector<std::string> argv;
  fs::path log;
  fs::path start_from;   // not empty: the run folder starts as a copy of this one
  fs::path done_record;  // not empty: written with the command line once the run succeeded
  // Not empty: written with the command line when the run starts, so that a later
  // call can tell an interrupted run of the same command (see interrupted()).
  fs::path started_record;
  bool resume = false;  // continue the run folder from its own checkpoint, no fresh start
};

// The arguments that decide what a run computes: all but the program and the
// output folder (a run keeps its record when its folder is renamed).
std::string command_line(const std::vector<std::string>& argv) {
  std::string line;
  for (std::size_t k = 1; k < argv.size(); ++k) {
    if (argv[k] == "--output") {
      ++k;
      continue;
    }
    line += (line.empty() ? "" : " ") + argv[k];
  }
  return line;
}

// A record file (of a job's start or finish) naming exactly the job's command line.
bool record_names(const fs::path& record, const Job& job) {
  if (record.empty() || !fs::exists(record)) return false;
  std::ifstream in(record);
  std::string line;
  std::getline(in, line);
  return line == command_line(job.argv);
}

// A job whose record says it already ran with exactly this command line.
bool already_done(const Job& job) {
  return record_names(job.done_record, job);
}

// A job whose run started with exactly this command line and stopped before it
// finished (a killed call, a closed session) but left a checkpoint: continuing
// from it gives the bits of one uninterrupted run, as `sanguis run --restart` does.
bool interrupted(const Job& job) {
  return fs::exists(job.log.parent_path() / "checkpoint.bin") &&
         record_names(job.started_record, job);
}

// The command line of a resumed job: its own, continued from the run's checkpoint.
std::vector<std::string> resumed_argv(const Job& job) {
  std::vector<std::string> argv = job.argv;
  if (std::find(argv.begin(), argv.end(), "--restart") == argv.end()) {
    argv.insert(argv.begin() + 2, "--restart");  // after "sanguis run"
  }
  return argv;
}

// The running children, for the signal handler below (async-signal-safe: a
// fixed array of atomics, 0 = free slot).
constexpr std::size_t kMaxChildren = 256;
std::array<std::atomic<pid_t>, kMaxChildren> g_children{};

// Stopping `calibrate` or `ensemble` (Ctrl-C, kill, a closed terminal) stops its
// runs too: they would otherwise go on writing into folders that a new call
// clears and fills again.
extern "C" void stop_children_and_exit(int signal_number) {
  for (auto& child : g_children) {
    const pid_t pid = child.load();
    if (pid > 0) kill(pid, SIGTERM);
  }
  std::signal(signal_number, SIG_DFL);
  raise(signal_number);
}

struct ChildSignalGuard {
  ChildSignalGuard() {
    for (int s : {SIGINT, SIGTERM, SIGHUP}) std::signal(s, stop_children_and_exit);
  }
  ~ChildSignalGuard() {
    for (int s : {SIGINT, SIGTERM, SIGHUP}) std::signal(s, SIG_DFL);
  }
  ChildSignalGuard(const ChildSignalGuard&) = delete;
  ChildSignalGuard& operator=(const ChildSignalGuard&) = delete;
  static void add(pid_t pid) {
    for (auto& child : g_children) {
      pid_t free_slot = 0;
      if (child.compare_exchange_strong(free_slot, pid)) return;
    }
  }
  static void remove(pid_t pid) {
    for (auto& child : g_children) {
      pid_t expected = pid;
      if (child.compare_exchange_strong(expected, 0)) return;
    }
  }
};

// Runs the jobs as child processes of this executable, at most `parallel` at a
// time; each writes its console output to its log. Throws if any failed. A
// signal that stops this process stops the children first.
void run_jobs(const char* self, const std::vector<Job>& jobs, int parallel) {
  const ChildSignalGuard guard;
  ProgressReporter progress(std::cerr, isatty(STDERR_FILENO) != 0);
  std::map<pid_t, std::size_t> running;
  std::size_t next = 0, done = 0;
  std::vector<std::string> failures;
  const auto wait_one = [&]() {
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid < 0) return;
    const std::size_t k = running.at(pid);
    running.erase(pid);
    ChildSignalGuard::remove(pid);
    ++done;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      failures.push_back(jobs[k].log.string());
    } else if (!jobs[k].done_record.empty()) {
      io::write_file_atomically(jobs[k].done_record, [&](std::ostream& out) {
        out << command_line(jobs[k].argv) << "\n";
      });
    }
    char status_text[64];
    std::snprintf(status_text, sizeof status_text, "%zu / %zu runs", done, jobs.size());
    progress.update(static_cast<double>(done) / static_cast<double>(jobs.size()), status_text, 0.0);
  };
  while (next < jobs.size() || !running.empty()) {
    if (next < jobs.size() && static_cast<int>(running.size()) < parallel) {
      const Job& job = jobs[next];
      if (!job.done_record.empty()) fs::remove(job.done_record);
      if (!job.start_from.empty() && !job.resume) {
        const fs::path run = job.log.parent_path();
        fs::remove_all(run);
        fs::create_directories(run.parent_path());
        fs::copy(job.start_from, run, fs::copy_options::recursive);
        // the source's own records
        for (const fs::path& record : {job.done_record, job.started_record}) {
          if (!record.empty()) fs::remove(record);
        }
      }
      fs::create_directories(job.log.parent_path());
      if (!job.started_record.empty() && !job.resume) {
        io::write_file_atomically(
            job.started_record, [&](std::ostream& out) { out << command_line(job.argv) << "\n"; });
      }
      posix_spawn_file_actions_t actions;
      posix_spawn_file_actions_init(&actions);
      // A resumed run appends to its console log: the earlier part stays readable.
      posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, job.log.c_str(),
                                       O_WRONLY | O_CREAT | (job.resume ? O_APPEND : O_TRUNC),
                                       0644);
      posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
      const std::vector<std::string> args = job.resume ? resumed_argv(job) : job.argv;
      std::vector<char*> argv;
      for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      pid_t pid = 0;
      const int rc = posix_spawn(&pid, self, &actions, nullptr, argv.data(), environ);
      posix_spawn_file_actions_destroy(&actions);
      if (rc != 0) throw std::runtime_error(std::string("cannot start ") + self);
      ChildSignalGuard::add(pid);
      running[pid] = next++;
    } else {
      wait_one();
    }
  }
  progress.finish(std::to_string(jobs.size()) + " runs done");
  if (!failures.empty()) {
    std::string list;
    for (const auto& f : failures) list += "\n  " + f;
    throw SimulationError(std::to_string(failures.size()) + " run(s) failed, see" + list);
  }
}

int default_jobs(int jobs) {
  if (jobs > 0) return jobs;
  const long cores = sysconf(_SC_NPROCESSORS_ONLN);
  return cores > 0 ? static_cast<int>(cores) : 1;
}

// argv[0] names the program for ps (run_jobs starts this executable by its path).
// A run continued from `start_from` (a run folder with a checkpoint) takes no
// seed: it restarts from the copied checkpoint.
Job run_job(const std::string& case_file, const fs::path& out, int seed,
            const std::vector<std::string>& overrides, const fs::path& start_from = {}) {
  Job job;
  job.argv = {"sanguis", "run", case_file, "--output", out.string()};
  if (!start_from.empty()) job.argv.push_back("--restart");
  for (const char* a : {"--quiet", "--threads", "1"}) job.argv.push_back(a);
  if (start_from.empty()) {
    job.argv.push_back("--seed");
    job.argv.push_back(std::to_string(seed));
  }
  for (const std::string& o : overrides) {
    job.argv.push_back("--set");
    job.argv.push_back(o);
  }
  job.log = out / "console.txt";
  job.start_from = start_from;
  return job;
}

std::string case_name(const std::string& case_file) {
  return fs::path(case_file).stem().string();
}

int run_ensemble(const char* self, const EnsembleArgs& args) {
  const fs::path root = args.output.empty()
                            ? fs::path("output") / (case_name(args.case_file) + "-ensemble")
                            : fs::path(args.output);
  std::vector<Job> jobs;
  std::vector<fs::path> runs;
  for (int k = 0; k < args.seeds; ++k) {
    const int seed = args.first_seed + k;
    runs.push_back(root / ("seed_" + std::to_string(seed)));
    jobs.push_back(run_job(args.case_file, runs.back(), seed, args.overrides));
  }
  std::printf("sanguis ensemble: %d runs of %s, %d at a time, into %s\n", args.seeds,
              args.case_file.c_str(), default_jobs(args.jobs), root.string().c_str());
  std::fflush(stdout);  // the header before the children's progress
  run_jobs(self, jobs, default_jobs(args.jobs));
  std::vector<RunAnalysis> all;
  for (const fs::path& run : runs) {
    all.push_back(analyze_one(run, {}, run / "analysis", false));
    print_summary(all.back());
  }
  dem::analysis::write_ensemble(all, root);
  if (args.plot) plot(root);
  std::printf("ensemble summary: %s\n", (root / "ensemble.csv").string().c_str());
  return 0;
}

// --- Calibration ---------------------------------------------------------------

double summary_value(const RunAnalysis& a, const std::string& name) {
  for (const auto& [key, value] : dem::analysis::summary_values(a)) {
    if (key == name) return value;
  }
  std::string known;
  for (const auto& [key, value] : dem::analysis::summary_values(a)) known += " " + key;
  throw InputError("", "--measure", "unknown measure '" + name + "'; one of:" + known);
}

// The checks of `calibrate`'s options that need no run.
void check_calibrate_args(const CalibrateArgs& args) {
  (void)summary_value(RunAnalysis{}, args.measure);  // an unknown measure fails before any run
  if (args.values.size() < 2) throw InputError("", "--values", "give at least two values");
  for (std::size_t k = 1; k < args.values.size(); ++k) {
    if (!(args.values[k] > args.values[k - 1])) {
      throw InputError("", "--values", "values must increase");
    }
  }
  if (!args.from.empty()) {
    if (!fs::exists(fs::path(args.from) / "checkpoint.bin")) {
      throw InputError(args.from, "--from",
                       "no checkpoint.bin in this folder: give the output folder of a "
                       "`sanguis run` of the same case");
    }
    if (args.seeds > 1) {
      throw InputError("", "--seeds",
                       "runs continued from one --from state are identical whatever the seed; "
                       "give --seeds 1 (or leave it out)");
    }
  }
}

int run_calibrate(const char* self, const CalibrateArgs& args) {
  check_calibrate_args(args);
  const int seeds = args.seeds > 0 ? args.seeds : (args.from.empty() ? 2 : 1);
  const fs::path root = args.output.empty()
                            ? fs::path("output") / (case_name(args.case_file) + "-calibrate")
                            : fs::path(args.output);
  std::vector<Job> jobs;
  std::vector<std::vector<fs::path>> runs(args.values.size());
  std::size_t reused = 0, resumed = 0;
  for (std::size_t i = 0; i < args.values.size(); ++i) {
    // The shortest text that reads back as the same double: exact in --set,
    // and a readable folder name (0.8, not 0.80000000000000004).
    char text[32];
    const auto written = std::to_chars(text, text + sizeof text, args.values[i]);
    const std::string value(text, written.ptr);
    std::vector<std::string> overrides = args.overrides;
    for (const std::string& key : args.parameters) overrides.push_back(key + "=" + value);
    for (int k = 0; k < seeds; ++k) {
      const int seed = args.first_seed + k;
      // Folders named by the value: a list with a value added reuses the others.
      runs[i].push_back(root / ("value_" + value) / ("seed_" + std::to_string(seed)));
      Job job = run_job(args.case_file, runs[i].back(), seed, overrides, args.from);
      job.done_record = runs[i].back() / "calibration_run.txt";
      job.started_record = runs[i].back() / "calibration_started.txt";
      if (args.reuse && already_done(job)) {
        ++reused;
      } else {
        job.resume = args.reuse && interrupted(job);
        resumed += job.resume ? 1 : 0;
        jobs.push_back(std::move(job));
      }
    }
  }
  std::string keys;  // "a, b" on the console, "a+b" in the CSV
  for (const std::string& key : args.parameters) keys += (keys.empty() ? "" : ", ") + key;
  std::string csv_keys;
  for (const std::string& key : args.parameters) csv_keys += (csv_keys.empty() ? "" : "+") + key;
  std::printf(
      "sanguis calibrate: %s over %zu values x %d seeds = %zu runs (%zu reused, %zu resumed), "
      "%d at a time%s\n",
      keys.c_str(), args.values.size(), seeds, jobs.size() + reused, reused, resumed,
      default_jobs(args.jobs),
      args.from.empty() ? "" : (", each continued from " + args.from).c_str());
  std::fflush(stdout);  // the header before the children's progress
  if (!jobs.empty()) run_jobs(self, jobs, default_jobs(args.jobs));

  std::vector<double> mean(args.values.size()), sem(args.values.size()), sd(args.values.size());
  std::vector<std::vector<double>> samples(args.values.size());
  for (std::size_t i = 0; i < args.values.size(); ++i) {
    double sum = 0, sum2 = 0;
    for (const fs::path& run : runs[i]) {
      const RunAnalysis a = analyze_one(run, {}, run / "analysis", false);
      const double m = summary_value(a, args.measure);
      samples[i].push_back(m);
      sum += m;
      sum2 += m * m;
    }
    const double n = static_cast<double>(runs[i].size());
    mean[i] = sum / n;
    sd[i] = n > 1 ? std::sqrt(std::max(0.0, (sum2 - n * mean[i] * mean[i]) / (n - 1))) : 0.0;
    sem[i] = sd[i] / std::sqrt(n);
  }
  // With a few seeds per value a per-value spread is itself very uncertain (two
  // runs may agree by chance): weight by the spread pooled over all values.
  double pooled_variance = 0.0, dof = 0.0;
  for (std::size_t i = 0; i < args.values.size(); ++i) {
    const double n = static_cast<double>(samples[i].size());
    pooled_variance += (n - 1) * sd[i] * sd[i];
    dof += n - 1;
  }
  if (dof > 0) {
    pooled_variance /= dof;
    for (std::size_t i = 0; i < args.values.size(); ++i) {
      sem[i] = std::sqrt(pooled_variance / static_cast<double>(samples[i].size()));
    }
  }
  const dem::analysis::CalibrationFit fit =
      dem::analysis::fit_crossing(args.values, mean, sem, dof > 0, args.target, args.target_std);

  io::write_file_atomically(root / "calibration.csv", [&](std::ostream& out) {
    out.precision(10);
    out << "value," << args.measure << "_mean," << args.measure << "_std,runs\n";
    for (std::size_t i = 0; i < args.values.size(); ++i) {
      out << args.values[i] << "," << mean[i] << "," << sd[i] << "," << samples[i].size() << "\n";
    }
  });
  io::write_file_atomically(root / "calibration_result.csv", [&](std::ostream& out) {
    out.precision(10);
    out << "parameter,measure,target,target_std,estimate,estimate_std,bracketed,slope,turns\n"
        << csv_keys << "," << args.measure << "," << args.target << "," << args.target_std << ","
        << fit.value << "," << fit.std << "," << (fit.bracketed ? 1 : 0) << "," << fit.slope << ","
        << (fit.turns ? 1 : 0) << "\n";
  });
  for (std::size_t i = 0; i < args.values.size(); ++i) {
    std::printf("  %s = %-10.4g %s = %.4g +- %.2g\n", keys.c_str(), args.values[i],
                args.measure.c_str(), mean[i], sd[i]);
  }
  if (fit.turns) {
    std::printf(
        "WARNING: %s does not reach %.4g over these values: it comes nearest (%.4g) at %s = %.4g "
        "and moves away on both sides. No crossing to fit; the nearest value is given.\n",
        args.measure.c_str(), args.target, mean[fit.closest], keys.c_str(), fit.value);
  } else {
    std::printf(
        "%s = %.4g +- %.2g for %s = %.4g%s\n", keys.c_str(), fit.value, fit.std,
        args.measure.c_str(), args.target,
        fit.bracketed ? "" : "  (WARNING: target outside the measured range, extrapolated)");
  }
  std::printf("written: %s\n", (root / "calibration_result.csv").string().c_str());
  return 0;
}

}  // namespace

std::function<bool()> add_analysis_commands(CLI::App& app) {
  auto analyze = std::make_shared<AnalyzeArgs>();
  auto ensemble = std::make_shared<EnsembleArgs>();
  auto calibrate = std::make_shared<CalibrateArgs>();
  auto slice = std::make_shared<SliceArgs>();
  auto flow_map = std::make_shared<FlowMapArgs>();

  auto* an = app.add_subcommand(
      "analyze", "measure DEM run folders (run-out, heights, velocity, contact network...)");
  an->add_option("runs", analyze->runs, "run output folders (several: also an ensemble summary)")
      ->required()
      ->check(CLI::ExistingDirectory);
  an->add_option("--out", analyze->out,
                 "output folder (default RUN/analysis; several runs: the ensemble folder)");
  an->add_option("--time", analyze->time, "final frame time [s] (default: the last frame)");
  an->add_option("--initial-time", analyze->initial_time,
                 "initial frame time [s] (default: when the gate is removed, else 0)");
  an->add_option("--wall", analyze->wall, "x of the back wall [m] (default: from the particles)");
  an->add_option("--floor", analyze->floor, "z of the floor [m] (default: from the particles)");
  an->add_option("--pixel", analyze->pixel, "top-view pixel size [m] (default: mean radius / 2)");
  an->add_option("--width", analyze->width, "channel width as Y_MIN Y_MAX [m]")->expected(2);
  an->add_option("--strong", analyze->strong, "strong network: Fc / <Fc> above this")
      ->capture_default_str();
  an->add_option("--gravity", analyze->gravity, "|g| [m/s^2]")->capture_default_str();
  an->add_option("--bulk-margin", analyze->bulk_margin,
                 "coordination of the bulk: the column less this margin on every side [m] "
                 "(default: two mean bounding diameters)")
      ->check(CLI::NonNegativeNumber);
  an->add_flag("--plot", analyze->plot, "draw PNG figures (matplotlib)");

  auto* en = app.add_subcommand("ensemble", "run a case over several seeds in parallel, analyze");
  en->add_option("case", ensemble->case_file, "case file (TOML)")
      ->required()
      ->check(CLI::ExistingFile);
  en->add_option("--seeds", ensemble->seeds, "number of runs")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  en->add_option("--first-seed", ensemble->first_seed, "seed of the first run")
      ->capture_default_str();
  en->add_option("--jobs,-j", ensemble->jobs, "runs at a time (default: the cores)");
  en->add_option("--output,-o", ensemble->output, "folder (default output/<case>-ensemble)");
  en->add_option("--set", ensemble->overrides, "override KEY=VALUE in every run");
  en->add_flag("--plot", ensemble->plot, "draw PNG figures");

  auto* ca = app.add_subcommand(
      "calibrate", "fit one case parameter to a target measure over an ensemble of runs");
  ca->add_option("case", calibrate->case_file, "case file (TOML)")
      ->required()
      ->check(CLI::ExistingFile);
  ca->add_option("--parameter", calibrate->parameters,
                 "case key to vary, e.g. interaction[0].friction; several (a,b or repeated): "
                 "all take the same value")
      ->required()
      ->delimiter(',');
  ca->add_option("--values", calibrate->values, "increasing values to try (a,b,c or a b c)")
      ->required()
      ->delimiter(',');
  ca->add_option("--measure", calibrate->measure,
                 "summary column of `analyze`, e.g. repose_angle_deg, runout_ratio")
      ->required();
  ca->add_option("--target", calibrate->target, "target value of the measure")->required();
  ca->add_option("--target-std", calibrate->target_std, "uncertainty of the target")
      ->capture_default_str();
  ca->add_option("--seeds", calibrate->seeds, "runs per value (default 2; 1 with --from)")
      ->check(CLI::PositiveNumber);
  ca->add_option("--first-seed", calibrate->first_seed, "seed of the first run")
      ->capture_default_str();
  ca->add_option("--jobs,-j", calibrate->jobs, "runs at a time (default: the cores)");
  ca->add_option("--output,-o", calibrate->output, "folder (default output/<case>-calibrate)");
  ca->add_option("--set", calibrate->overrides, "override KEY=VALUE in every run");
  ca->add_option("--from", calibrate->from,
                 "continue every run from this run folder's checkpoint (a common prepared "
                 "packing) instead of starting the case afresh")
      ->check(CLI::ExistingDirectory);
  ca->add_flag("--reuse", calibrate->reuse,
               "keep the runs that already finished with the same command line "
               "(VALUE_i/SEED_k/calibration_run.txt) instead of running them again, and "
               "continue those it started but did not finish from their last checkpoint");

  auto* sl = app.add_subcommand(
      "slice", "a plane slice of a flow run as PNG and CSV (speed, pressure, vorticity...)");
  sl->add_option("run", slice->run, "flow run folder (its flow.pvd) or one .vtu frame")->required();
  auto* frame = sl->add_option("--frame", slice->frame,
                               "frame index (default: the last; negative counts back)")
                    ->expected(1);
  sl->add_option("--time", slice->time, "the frame nearest to this time [s]")
      ->expected(1)
      ->excludes(frame);
  sl->add_option("--normal", slice->normal, "normal of the plane")
      ->check(CLI::IsMember({"x", "y", "z"}))
      ->capture_default_str();
  sl->add_option("--at", slice->at, "plane position along the normal [m] (default: mid-domain)")
      ->expected(1);
  sl->add_option("--field", slice->field,
                 "cell array (velocity:x, pressure, vorticity_magnitude, viscosity, level, rank, "
                 "block) or speed")
      ->capture_default_str();
  sl->add_flag("--blocks", slice->blocks, "outline the blocks");
  sl->add_option("--output,-o", slice->output,
                 "PNG file, the CSV beside it (default RUN/slice_FIELD_NORMALAT.png)");

  auto* fm = app.add_subcommand(
      "flow-map",
      "map of flow regimes (thesis Fig. 3.6) from ensembles: each one (L0, H0) point, "
      "repeatable or intermittent, as CSV and PNG");
  fm->add_option("ensembles", flow_map->ensembles,
                 "ensemble folders (their ensemble.csv), or folders whose subfolders are")
      ->required();
  fm->add_option("--output,-o", flow_map->output, "folder for flow_map.csv and flow_map.png")
      ->capture_default_str();
  fm->add_flag("--no-plot", flow_map->no_plot, "the CSV only");

  // Not the resolved path: /proc/self/exe still starts this executable when its
  // file was replaced (a rebuild) while a long study runs.
  const std::string self_path = "/proc/self/exe";
  return [=]() {
    if (*an) return run_analyze(*analyze) == 0;
    if (*en) return run_ensemble(self_path.c_str(), *ensemble) == 0;
    if (*ca) return run_calibrate(self_path.c_str(), *calibrate) == 0;
    if (*sl) {
      const int status = run_slice(*slice);
      if (status == 2) {
        throw InputError(slice->run, "slice", "the slice script refused its input (message above)");
      }
      if (status != 0) {
        throw std::runtime_error("slice: scripts/flow_slice.py failed (exit status " +
                                 std::to_string(status) + ")");
      }
      return true;
    }
    if (*fm) {
      const int status = run_flow_map(*flow_map);
      if (status == 2) {
        throw InputError("", "flow-map", "the flow-map script refused its input (message above)");
      }
      if (status != 0) {
        throw std::runtime_error("flow-map: scripts/flow_map.py failed (exit status " +
                                 std::to_string(status) + ")");
      }
      return true;
    }
    return false;
  };
}

}  // namespace sanguis::app
