#pragma once
// Memory of this process from /proc/self/status (Linux), for the bytes per
// particle the benchmarks report: resident set now (VmRSS) and its peak (VmHWM).
#include <cstdint>
#include <fstream>
#include <string>

namespace sanguis::bench {

// Value of a "Name:   1234 kB" line of /proc/self/status in bytes; 0 if absent.
inline std::int64_t proc_status_bytes(const std::string& name) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(name + ":", 0) == 0) return 1024 * std::stoll(line.substr(name.size() + 1));
  }
  return 0;
}

inline std::int64_t resident_bytes() {
  return proc_status_bytes("VmRSS");
}
inline std::int64_t peak_resident_bytes() {
  return proc_status_bytes("VmHWM");
}

}  // namespace sanguis::bench
