#pragma once
// Runs a DEM case to its end with outputs: ParaView files (particles and
// obstacles with .pvd time indexes), diagnostics.csv, run.log, checkpoints and a
// progress line with ETA. Restart continues bit for bit from checkpoint.bin.
#include <filesystem>
#include <iosfwd>

#include "dem/dem_case.hpp"

namespace sanguis::dem {

struct RunOptions {
  std::filesystem::path output_dir;
  bool restart = false;   // continue from output_dir/checkpoint.bin
  bool quiet = false;     // no progress line
  double stop_at = -1.0;  // stop (with a checkpoint) at this time instead of end_time; < 0: off
};

struct RunSummary {
  std::int64_t steps = 0;
  double simulated_time = 0.0;
  double wall_seconds = 0.0;
  bool settled = false;
  DemDiagnostics last;
};

// Throws InputError (bad restart files) or SimulationError (blow-up, after writing a
// final snapshot and checkpoint-free log entry).
RunSummary run_dem_case(const DemCase& c, const RunOptions& options, std::ostream& console);

}  // namespace sanguis::dem
