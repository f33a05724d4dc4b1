// The sanguis executable: parse the command line, run, report. Errors map to
// exit codes: 0 success, 1 simulation failure (blow-up), 2 bad input.
#include <mpi.h>
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <numbers>
#include <sstream>

#include "analysis_commands.hpp"
#include "benchmarks.hpp"
#include "core/config.hpp"
#include "core/error.hpp"
#include "core/version.hpp"
#include "dem/dem_case.hpp"
#include "dem/dem_run.hpp"
#include "dem/parameter_procedure.hpp"
#include "flow/flow_case.hpp"
#include "flow/flow_run.hpp"
#include "flow/mpi_session.hpp"

namespace {

using namespace sanguis;

struct ParamsOptions {
  double radius = 1e-3;
  double density = 2500.0;
  double en = 0.45;
  double et = 0.3;
  double overlap_ratio = 0.005;
  double velocity = 2.62;
  double friction = 0.5;
  double rolling_pp = 0.0;
  double rolling_pw = -1.0;  // < 0: same as particle-particle
  std::string damping_model = "thesis";
  bool json = false;
};

void print_params(const ParamsOptions& o) {
  const double mass = 4.0 / 3.0 * std::numbers::pi * std::pow(o.radius, 3) * o.density;
  const dem::NormalDampingModel model = dem::parse_normal_damping_model(o.damping_model);
  struct Row {
    const char* name;
    dem::ProcedureResult r;
  };
  const auto derive = [&](double reduced_mass, double reduced_radius, double rolling) {
    dem::ProcedureInput in;
    in.reduced_mass = reduced_mass;
    in.reduced_radius = reduced_radius;
    in.inertia_factor = 2.5;
    in.normal_restitution = o.en;
    in.tangential_restitution = o.et;
    in.max_overlap = o.overlap_ratio * o.radius;
    in.max_impact_velocity = o.velocity;
    in.friction = o.friction;
    in.rolling_friction = rolling;
    in.damping_model = model;
    return dem::derive_contact_parameters(in);
  };
  const Row rows[2] = {
      {"particle-particle", derive(0.5 * mass, 0.5 * o.radius, o.rolling_pp)},
      {"particle-wall", derive(mass, o.radius, o.rolling_pw < 0 ? o.rolling_pp : o.rolling_pw)}};

  if (o.json) {
    std::ostringstream j;
    j.precision(10);
    j << "{\"inputs\":{\"radius_m\":" << o.radius << ",\"density_kg_m3\":" << o.density
      << ",\"normal_restitution\":" << o.en << ",\"tangential_restitution\":" << o.et
      << ",\"max_overlap_ratio\":" << o.overlap_ratio
      << ",\"max_impact_velocity_m_s\":" << o.velocity << ",\"normal_damping_model\":\""
      << o.damping_model << "\"}";
    for (const Row& row : rows) {
      const auto& p = row.r.parameters;
      j << ",\"" << row.name << "\":{\"kn_N_m\":" << p.normal_stiffness
        << ",\"eta_n_N_s_m\":" << p.normal_damping << ",\"kt_N_m\":" << p.tangential_stiffness
        << ",\"eta_t_N_s_m\":" << p.tangential_damping
        << ",\"gamma_t_1_s\":" << row.r.tangential_damping_rate << ",\"mu_c\":" << p.friction
        << ",\"kr_N_m_rad\":" << p.rolling_stiffness << ",\"eta_r_N_m_s_rad\":" << p.rolling_damping
        << ",\"mu_r\":" << p.rolling_friction << ",\"contact_time_s\":" << row.r.contact_time
        << ",\"recommended_time_step_s\":" << row.r.recommended_time_step
        << ",\"damping_ratio\":" << row.r.damping_ratio
        << ",\"effective_restitution\":" << row.r.effective_restitution << "}";
    }
    j << "}";
    std::cout << j.str() << "\n";
    return;
  }
  std::printf("Contact parameters by the procedure of thesis §2.4 (eq. 2.16-2.28)\n");
  std::printf("  inputs: R = %g m, rho = %g kg/m3 (m = %.6g kg), en = %g, et = %g,\n", o.radius,
              o.density, mass, o.en, o.et);
  std::printf("          delta_max = %g R, v_max = %g m/s, mu_c = %g, damping model '%s'\n\n",
              o.overlap_ratio, o.velocity, o.friction, o.damping_model.c_str());
  std::printf("%-32s %16s %16s\n", "", rows[0].name, rows[1].name);
  const auto line = [&](const char* label, auto get) {
    std::printf("%-32s %16.6g %16.6g\n", label, get(rows[0].r), get(rows[1].r));
  };
  line("kn [N/m]          eq. 2.21", [](const auto& r) { return r.parameters.normal_stiffness; });
  line("eta_n [N s/m]     eq. 2.22", [](const auto& r) { return r.parameters.normal_damping; });
  line("kt [N/m]          eq. 2.23",
       [](const auto& r) { return r.parameters.tangential_stiffness; });
  line("eta_t [N s/m]     eq. 2.24", [](const auto& r) { return r.parameters.tangential_damping; });
  line("gamma_t [1/s]     eta_t/2m_ij", [](const auto& r) { return r.tangential_damping_rate; });
  line("kr [N m/rad]      eq. 2.28", [](const auto& r) { return r.parameters.rolling_stiffness; });
  line("eta_r [N m s/rad] eq. 2.28", [](const auto& r) { return r.parameters.rolling_damping; });
  line("Tc [s]            eq. 2.17", [](const auto& r) { return r.contact_time; });
  line("dt = Tc/20 [s]", [](const auto& r) { return r.recommended_time_step; });
  line("damping ratio gamma_n/omega_0", [](const auto& r) { return r.damping_ratio; });
  line("rebound ratio with max(.,0)", [](const auto& r) { return r.effective_restitution; });
  std::printf(
      "\nThe last line is the restitution the clamped law of eq. 2.5 really gives; use\n"
      "--damping-model exact_restitution to make it equal en.\n");
}

struct RunArgs {
  std::string case_file, output;
  bool restart = false, quiet = false;
  int threads = 0;
  std::int64_t seed = -1;
  std::vector<std::string> overrides;
};

// True when mpirun started this program on several processes (Open MPI or a PMI launcher):
// a DEM run is then decomposed over them. Alone, a DEM run never starts MPI.
bool several_mpi_processes() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}) {
    const char* value = std::getenv(name);
    if (value != nullptr && std::atoi(value) > 1) return true;
  }
  return false;
}

// After an error on one of several MPI processes: the others may wait in a collective
// for ever, so the whole job stops (mpirun reports the exit code).
void stop_other_processes(int code) {
  int initialised = 0, finalised = 0;
  MPI_Initialized(&initialised);
  MPI_Finalized(&finalised);
  if (!initialised || finalised) return;
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (size > 1) MPI_Abort(MPI_COMM_WORLD, code);
}

// The run's output folder: --output, or output/NAME; an existing file there is an error.
std::filesystem::path output_directory(const std::string& output, const std::string& name) {
  const std::filesystem::path dir =
      output.empty() ? std::filesystem::path("output") / name : std::filesystem::path(output);
  if (std::filesystem::exists(dir) && !std::filesystem::is_directory(dir)) {
    throw InputError(dir.string(), "--output", "exists and is not a directory");
  }
  return dir;
}

int run_command(const RunArgs& args) {
  ConfigTable cfg = ConfigTable::parse_file(args.case_file);
  for (const std::string& o : args.overrides) cfg.set_override(o);
  const std::string& output = args.output;
  const int threads = args.threads;
  const bool restart = args.restart, quiet = args.quiet;
  if (flow::is_flow_case(cfg)) {
    if (args.seed >= 0)
      throw InputError(args.case_file, "--seed", "a flow case has no random seed");
    flow::FlowCase fc = flow::load_flow_case(cfg, args.case_file);
    if (threads > 0) fc.forest.threads = threads;
    flow::FlowRunOptions options;
    options.output_dir = output_directory(output, fc.name);
    options.restart = restart;
    options.quiet = quiet;
    flow::run_flow_case(fc, options, std::cout);
    return 0;
  }
  if (args.seed >= 0) cfg.set_override("simulation.seed=" + std::to_string(args.seed));
  dem::DemCase c = dem::load_dem_case(cfg, args.case_file);
  if (threads > 0) c.setup.threads = threads;
  dem::RunOptions options;
  options.output_dir = output_directory(output, c.name);
  options.restart = restart;
  options.quiet = quiet;
  if (several_mpi_processes()) options.comm = flow::MpiSession::ensure().world();
  dem::run_dem_case(c, options, std::cout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"sanguis: cell-resolved biological fluids and granular flows (DEM)"};
  app.set_version_flag("--version", std::string("sanguis ") + sanguis::kVersion);
  app.require_subcommand(1);

  RunArgs ra;
  auto* run = app.add_subcommand("run", "run a case file");
  run->add_option("case", ra.case_file, "case file (TOML)")->required();
  run->add_option("--output,-o", ra.output, "output directory (default: output/<case name>)");
  run->add_flag("--restart", ra.restart, "continue from OUTPUT/checkpoint.bin");
  run->add_flag("--quiet,-q", ra.quiet,
                "no progress line (the one-line summary at the end is still printed)");
  run->add_option("--threads,-t", ra.threads,
                  "OpenMP threads (default: the case's simulation.threads, else all cores)")
      ->check(CLI::Range(1, 1024));
  run->add_option("--seed", ra.seed, "random seed (replaces simulation.seed)")
      ->check(CLI::NonNegativeNumber);
  run->add_option("--set", ra.overrides,
                  "replace a case value: KEY=VALUE (TOML), e.g. interaction[0].friction=0.3");

  ParamsOptions po;
  auto* params = app.add_subcommand("params", "contact parameters by the procedure of §2.4");
  params->add_option("--radius", po.radius, "particle radius [m]")->capture_default_str();
  params->add_option("--density", po.density, "density [kg/m3]")->capture_default_str();
  params->add_option("--en", po.en, "normal restitution coefficient")->capture_default_str();
  params->add_option("--et", po.et, "tangential restitution coefficient")->capture_default_str();
  params->add_option("--max-overlap-ratio", po.overlap_ratio, "delta_max / R")
      ->capture_default_str();
  params->add_option("--max-velocity", po.velocity, "maximum impact velocity v_max [m/s]")
      ->capture_default_str();
  params->add_option("--friction", po.friction, "Coulomb friction mu_c")->capture_default_str();
  params->add_option("--rolling-friction", po.rolling_pp, "rolling friction mu_r (pairs)")
      ->capture_default_str();
  params->add_option("--rolling-friction-wall", po.rolling_pw,
                     "rolling friction mu_r with walls (default: as pairs)");
  params->add_option("--damping-model", po.damping_model, "thesis | exact_restitution")
      ->capture_default_str();
  params->add_flag("--json", po.json, "machine-readable output");

  bench::BenchOptions bo;
  std::string bench_name;
  auto* bench_cmd = app.add_subcommand("bench", "throughput benchmarks (one JSON line)");
  bench_cmd
      ->add_option("name", bench_name,
                   "benchmark: dem-spheres | dem-crosses | membrane | flow-cavity | flow-adaptive")
      ->required();
  auto* particles_opt = bench_cmd->add_option(
      "--particles", bo.particles, "number of particles (dem-spheres 32000, dem-crosses 3000)");
  auto* steps_opt = bench_cmd->add_option(
      "--steps", bo.steps,
      "time steps (dem-spheres 2000, dem-crosses 500, membrane 20, flow-cavity 20, "
      "flow-adaptive 100)");
  bench_cmd->add_option("--threads", bo.threads, "threads")->capture_default_str();
  bench_cmd->add_option("--seed", bo.seed, "random seed")->capture_default_str();
  bench_cmd->add_option("--triangles", bo.triangles, "membrane: triangles per capsule (20*4^k)")
      ->capture_default_str();
  bench_cmd->add_option("--capsules", bo.capsules, "membrane: number of capsules")
      ->capture_default_str();
  bench_cmd->add_option("--cells-per-side", bo.cells_per_side, "flow-cavity: cells per edge")
      ->capture_default_str();
  bench_cmd->add_option(
      "--block-cells", bo.block_cells,
      "flow-cavity: cells per block edge (a power of two; default: as a case file "
      "without block_cells chooses: 32 where the cells per edge are a multiple of 32 "
      "and at least 128, else 16 where they are a multiple of 16 and at least 64, else 8)");
  bench_cmd->add_flag("--general-kernels", bo.general_kernels,
                      "flow-cavity: multigrid kernels that read constant coefficients too (A/B)");
  bench_cmd->add_flag("--unmerged-solver", bo.unmerged_solver,
                      "flow-cavity: multigrids on the flow's blocks, not on their families of 8 "
                      "merged into one block (A/B)");
  bench_cmd
      ->add_option("--prefetch", bo.prefetch,
                   "flow-cavity: when the multigrid prefetches the next block's cells "
                   "(\"out-of-cache\", the default, \"always\" or \"never\"; A/B)")
      ->check(CLI::IsMember({"out-of-cache", "always", "never"}));
  bench_cmd
      ->add_option("--relaxation", bo.relaxation,
                   "flow-cavity: over-relaxation of the multigrid smoother in the pressure "
                   "and viscous solves (default: the solver's, 1.25 and 1.15)")
      ->check(CLI::Range(0.0, 2.0));
  bench_cmd
      ->add_option("--pressure-relaxation", bo.pressure_relaxation,
                   "flow-cavity: the same for the projections' pressure solves only (A/B)")
      ->check(CLI::Range(0.0, 2.0));
  bench_cmd
      ->add_option("--beside-finer-relaxation", bo.beside_finer_relaxation,
                   "flow-adaptive: relaxation of the cells beside finer blocks in both solves "
                   "(default: the solver's, 1.0; 2 relaxes them as the rest; A/B)")
      ->check(CLI::Range(0.0, 2.0));
  bench_cmd
      ->add_option("--sweeps", bo.sweeps,
                   "flow-cavity: smoothing sweeps before and after the coarse correction "
                   "(default: the solver's, 2)")
      ->check(CLI::Range(0, 8));
  bench_cmd->add_flag("--scatter", bo.scatter,
                      "dem-spheres: fill the lattice in random order (ids scattered in space)");
  bench_cmd
      ->add_option("--storage-sort", bo.storage_sort_interval,
                   "dem: re-sort particles along space every N steps (0: never; default: "
                   "the solver's, 2000)")
      ->check(CLI::Range(std::int64_t{0}, std::int64_t{1} << 40));
  bench_cmd
      ->add_option("--flat-contacts", bo.flat_contacts,
                   "dem-crosses: \"patch\" (default) or \"point\", as flat_contacts in a case")
      ->check(CLI::IsMember({"patch", "point"}));
  bench_cmd
      ->add_option("--element-contacts", bo.element_contacts,
                   "dem-crosses: \"sum\" (default) or \"mean\", as element_contacts in a case")
      ->check(CLI::IsMember({"sum", "mean"}));
  std::string bench_case;
  bench_cmd->add_option("--case", bench_case,
                        "flow-adaptive: flow case file (default cases/flow/obstacle-wake.toml)");

  const auto run_analysis = app::add_analysis_commands(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }

  try {
    if (*run) return run_command(ra);
    if (run_analysis()) return 0;
    if (*params) {
      print_params(po);
      return 0;
    }
    if (*bench_cmd) {
      const bool particles_given = particles_opt->count() > 0;
      const bool steps_given = steps_opt->count() > 0;
      if (bench_name == "dem-spheres") {
        if (several_mpi_processes()) bo.comm = flow::MpiSession::ensure().world();
        const std::string line = bench::run_dem_spheres(bo);
        if (!line.empty()) std::cout << line << std::endl;
      } else if (bench_name == "dem-crosses") {
        if (!particles_given) bo.particles = 3000;
        if (!steps_given) bo.steps = 500;
        if (several_mpi_processes()) bo.comm = flow::MpiSession::ensure().world();
        const std::string line = bench::run_dem_crosses(bo);
        if (!line.empty()) std::cout << line << std::endl;
      } else if (bench_name == "membrane") {
        if (!steps_given) bo.steps = 20;
        std::cout << bench::run_membrane(bo) << std::endl;
      } else if (bench_name == "flow-adaptive") {
        if (!steps_given) bo.steps = 100;
        const std::string case_file =
            bench_case.empty() ? std::string(SANGUIS_SOURCE_DIR) + "/cases/flow/obstacle-wake.toml"
                               : bench_case;
        std::cout << bench::run_flow_adaptive(bo, case_file) << std::endl;
      } else if (bench_name == "flow-cavity") {
        if (!steps_given) bo.steps = 20;
        std::cout << bench::run_flow_cavity(bo) << std::endl;
      } else {
        throw InputError("", "bench",
                         "unknown benchmark '" + bench_name +
                             "' (dem-spheres, dem-crosses, membrane, flow-cavity, flow-adaptive)");
      }
      return 0;
    }
  } catch (const InputError& e) {
    std::cerr << "sanguis: error: " << e.what() << "\n";
    stop_other_processes(2);
    return 2;
  } catch (const SimulationError& e) {
    std::cerr << "sanguis: simulation stopped: " << e.what() << "\n";
    stop_other_processes(1);
    return 1;
  } catch (const std::invalid_argument& e) {
    std::cerr << "sanguis: error: " << e.what() << "\n";
    stop_other_processes(2);
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "sanguis: error: " << e.what() << "\n";
    stop_other_processes(1);
    return 1;
  }
  return 0;
}
