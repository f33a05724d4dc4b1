// The flow-adaptive benchmark: the adaptive obstacle wake of
// cases/flow/obstacle-wake.toml (a cube in a channel at Re = 100, 8 cells per
// D at the finest, blocks near the cube kept finest, the wavelet criterion on
// the velocity every 10 steps) run for --steps steps from its start through
// `sanguis run`'s own loop, so that the regrid share is the one a user sees
// (its seconds include the final diagnostics row and checkpoint, well under
// one step).
#include <unistd.h>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "benchmarks.hpp"
#include "core/config.hpp"
#include "flow/flow_case.hpp"
#include "flow/flow_run.hpp"

namespace sanguis::bench {

std::string run_flow_adaptive(const BenchOptions& o, const std::filesystem::path& case_file) {
  namespace fs = std::filesystem;
  if (o.steps < 1) throw std::invalid_argument("flow-adaptive: --steps must be >= 1");
  flow::FlowCase c = flow::load_flow_case(ConfigTable::parse_file(case_file), case_file);
  c.forest.threads = o.threads;
  c.vtk = false;
  c.checkpoint_interval = 0.0;
  if (o.beside_finer_relaxation > 0.0) {
    c.options.pressure.beside_finer_relaxation = o.beside_finer_relaxation;
    c.options.viscous.beside_finer_relaxation = o.beside_finer_relaxation;
  }
  const fs::path dir =
      fs::temp_directory_path() / ("sanguis_bench_flow_adaptive_" + std::to_string(getpid()));
  flow::FlowRunOptions run;
  run.output_dir = dir;
  run.quiet = true;
  run.max_steps = o.steps;
  std::ostringstream console;
  const flow::FlowRunSummary s = flow::run_flow_case(c, run, console);
  fs::remove_all(dir);

  // The uniform grid at the finest level the run may reach.
  const int levels_up = c.adapt.enabled ? c.adapt.max_level - c.forest.level : 0;
  double uniform = static_cast<double>(c.cells[0]) * c.cells[1] * c.cells[2];
  for (int l = 0; l < levels_up; ++l) uniform *= 8.0;
  std::ostringstream json;
  json.precision(6);
  json << "{\"benchmark\":\"flow-adaptive\",\"code\":\"sanguis\",\"case\":\""
       << case_file.filename().string() << "\",\"steps\":" << s.steps
       << ",\"threads\":" << o.threads << ",\"ranks\":" << s.ranks
       << ",\"simulated_time_s\":" << s.simulated_time
       << ",\"cells\":" << static_cast<std::int64_t>(s.cells)
       << ",\"cells_uniform\":" << static_cast<std::int64_t>(uniform)
       << ",\"seconds\":" << s.wall_seconds
       << ",\"seconds_per_step\":" << s.wall_seconds / static_cast<double>(s.steps)
       << ",\"pressure_vcycles_per_step\":"
       << static_cast<double>(s.pressure_cycles) / static_cast<double>(s.steps)
       << ",\"regrid_fraction\":" << s.regrid_seconds / s.wall_seconds << "}";
  return json.str();
}

}  // namespace sanguis::bench
