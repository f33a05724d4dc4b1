#pragma once
// Progress line with ETA for long runs. On a terminal it rewrites one line; in a
// log (CI, nohup) it prints a new line at most every `log_interval` seconds.
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iosfwd>
#include <string>

namespace sanguis {

class ProgressReporter {
 public:
  ProgressReporter(std::ostream& out, bool interactive, double log_interval_s = 10.0);

  // `fraction` in [0, 1]; `work_units` is cumulative work (e.g. particle-steps) for a rate.
  void update(double fraction, const std::string& status, double work_units);
  void finish(const std::string& status);

  double elapsed_seconds() const;
  static std::string format_duration(double seconds);
  /// The date and time now, in UTC ("2026-12-05 19:15:02 UTC"): run logs stamp their
  /// start, restarts, checkpoints and end with it, so that a log read later says when
  /// each part ran (its durations alone do not say whether a run was paused between).
  static std::string wall_clock_stamp();

 private:
  std::ostream& out_;
  bool interactive_;
  double log_interval_;
  std::chrono::steady_clock::time_point start_, last_print_;
  bool printed_ = false;
};

/// A run's `run.log` in `dir`, opened (appended to on a restart) with the first line of
/// this segment written: "sanguis VERSION, started DATE" for a new run, or after a blank
/// line "--- restart from checkpoint at t = T s, DATE" (DEM and flow runs alike; scripts
/// read these lines). Throws InputError when the file cannot be written.
std::ofstream open_run_log(const std::filesystem::path& dir, bool restart, double time_s);

}  // namespace sanguis
