#pragma once
// Runs a flow case to its end with outputs: the block grid with the flow
// fields as ParaView files with a .pvd time index, diagnostics.csv, run.log,
// checkpoints and a progress line with ETA. Restart continues bit for bit
// from the checkpoint (one file per MPI rank).

#include <cstdint>
#include <filesystem>
#include <iosfwd>

#include "flow/flow_case.hpp"

namespace sanguis::flow {

struct FlowRunOptions {
  std::filesystem::path output_dir;
  bool restart = false;   ///< continue from the checkpoint in output_dir
  bool quiet = false;     ///< no progress line
  double stop_at = -1.0;  ///< stop (with a checkpoint) at this time instead of the end; < 0: off
  std::int64_t max_steps = -1;  ///< stop (with a checkpoint) after this many steps; < 0: off
};

struct FlowRunSummary {
  std::int64_t steps = 0;            ///< steps done by this call
  double simulated_time = 0.0;       ///< time reached (s)
  double wall_seconds = 0.0;         ///< of the time loop
  double regrid_seconds = 0.0;       ///< of the time loop spent regridding ([flow.adapt])
  double cells = 0.0;                ///< leaf cells at the end (all ranks)
  std::int64_t pressure_cycles = 0;  ///< V-cycles of each step's final projection, summed
  int ranks = 1;                     ///< MPI ranks sharing the forest
};

FlowRunSummary run_flow_case(const FlowCase& c, const FlowRunOptions& options,
                             std::ostream& console);

}  // namespace sanguis::flow
