#include "core/progress.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>
#include <ostream>

#include "core/error.hpp"
#include "core/version.hpp"

namespace sanguis {

ProgressReporter::ProgressReporter(std::ostream& out, bool interactive, double log_interval_s)
    : out_(out),
      interactive_(interactive),
      log_interval_(interactive ? 0.5 : log_interval_s),
      start_(std::chrono::steady_clock::now()),
      last_print_(start_) {}

double ProgressReporter::elapsed_seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

std::string ProgressReporter::wall_clock_stamp() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S UTC", &utc);
  return buf;
}

std::ofstream open_run_log(const std::filesystem::path& dir, bool restart, double time_s) {
  std::ofstream log(dir / "run.log", restart ? std::ios::app : std::ios::trunc);
  if (!log) throw InputError((dir / "run.log").string(), "", "cannot write the run log");
  if (restart) {
    log << "\n--- restart from checkpoint at t = " << std::to_string(time_s) << " s, ";
  } else {
    log << "sanguis " << kVersion << ", started ";
  }
  log << ProgressReporter::wall_clock_stamp() << "\n";
  return log;
}

std::string ProgressReporter::format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  char buf[64];
  const auto s = static_cast<long long>(std::llround(seconds));
  if (s < 60) {
    std::snprintf(buf, sizeof buf, "%llds", s);
  } else if (s < 3600) {
    std::snprintf(buf, sizeof buf, "%lldm%02llds", s / 60, s % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%lldh%02lldm", s / 3600, (s % 3600) / 60);
  }
  return buf;
}

void ProgressReporter::update(double fraction, const std::string& status, double work_units) {
  const auto now = std::chrono::steady_clock::now();
  if (std::chrono::duration<double>(now - last_print_).count() < log_interval_) return;
  last_print_ = now;
  const double elapsed = elapsed_seconds();
  const double eta = fraction > 0 ? elapsed * (1.0 - fraction) / fraction : -1.0;
  char buf[256];
  const int used =
      std::snprintf(buf, sizeof buf, "[%5.1f%%] %s  elapsed %s  ETA %s", 100.0 * fraction,
                    status.c_str(), format_duration(elapsed).c_str(), format_duration(eta).c_str());
  if (work_units > 0 && elapsed > 0 && used > 0 && static_cast<std::size_t>(used) < sizeof buf) {
    std::snprintf(buf + used, sizeof buf - static_cast<std::size_t>(used), "  %.3g /s",
                  work_units / elapsed);
  }
  if (interactive_) {
    out_ << '\r' << buf << "\x1b[K" << std::flush;
  } else {
    out_ << buf << '\n' << std::flush;
  }
  printed_ = true;
}

void ProgressReporter::finish(const std::string& status) {
  if (interactive_ && printed_) out_ << '\r' << "\x1b[K";
  out_ << status << '\n' << std::flush;
}

}  // namespace sanguis
