// The flow-cavity benchmark: lid-driven cubic cavity at Re = 100 (unit cube,
// lid velocity 1 along x at y = 1, nu = 0.01), fixed dt = 0.01, multigrid
// tolerance 1e-3 relative to the right-hand side (see bench/README.md).
#include <algorithm>
#include <chrono>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <unistd.h>

#include "benchmarks.hpp"
#include "flow/flow_case.hpp"
#include "flow/navier_stokes.hpp"

namespace sanguis::bench {

namespace {

flow::ForestSpec cavity_forest(std::int64_t cells_per_side, int block_cells, int threads) {
  if (block_cells < 2 || (block_cells & (block_cells - 1)) != 0) {
    throw std::invalid_argument("flow-cavity: --block-cells must be a power of two >= 2, got " +
                                std::to_string(block_cells));
  }
  if (cells_per_side < block_cells || cells_per_side % block_cells != 0) {
    throw std::invalid_argument("flow-cavity: --cells-per-side must be a multiple of " +
                                std::to_string(block_cells) + ", got " +
                                std::to_string(cells_per_side));
  }
  flow::ForestSpec spec;
  const int trees = static_cast<int>(cells_per_side / block_cells);
  spec.trees = {trees, trees, trees};
  spec.tree_length = 1.0 / trees;
  spec.block_cells = block_cells;
  spec.threads = threads;
  return spec;
}

/// Elements of each triad array: twice the last-level cache (sysconf), at least 2^22
/// doubles (32 MiB), so that the three arrays stream from memory, as STREAM asks (its
/// rule: arrays well beyond every cache). Until 2026-12-06 always 2^22, which a host
/// with a 480 MiB cache (a Xeon VM of that day) held in cache.
std::int64_t triad_elements() {
  long cache = 0;
#ifdef _SC_LEVEL3_CACHE_SIZE  // glibc's; elsewhere the floor below
  cache = sysconf(_SC_LEVEL3_CACHE_SIZE);
#endif
  const std::int64_t floor = std::int64_t{1} << 22;
  return std::max<std::int64_t>(floor, 2 * static_cast<std::int64_t>(std::max(cache, 0L)) / 8);
}

/// STREAM triad a = b + s c over three arrays of n doubles, best of 5,
/// counted as STREAM does: 24 bytes per element.
/// On `threads` threads, each streaming its own contiguous share (and touching it first,
/// so its pages lie where it runs), as STREAM does with OpenMP: the bandwidth the
/// machine gives that many cores, against which the smoother on as many threads is
/// measured.
double stream_triad_bytes_per_s(int threads, std::int64_t n) {
  std::vector<double> a(static_cast<std::size_t>(n)), b(a.size()), c(a.size());
#pragma omp parallel for schedule(static) num_threads(threads)
  for (std::int64_t i = 0; i < n; ++i) {
    a[static_cast<std::size_t>(i)] = 0.0;
    b[static_cast<std::size_t>(i)] = 1.0;
    c[static_cast<std::size_t>(i)] = 2.0;
  }
  double best = 0.0;
  for (int repeat = 0; repeat < 5; ++repeat) {
    const auto start = std::chrono::steady_clock::now();
#pragma omp parallel for schedule(static) num_threads(threads)
    for (std::int64_t i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      a[k] = b[k] + 3.0 * c[k];
    }
    const double s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    best = std::max(best, 24.0 * static_cast<double>(n) / s);
    b[static_cast<std::size_t>(repeat)] =
        a[static_cast<std::size_t>(n - 1 - repeat)];  // keep the loop observable
  }
  return best;
}

/// Bytes a V(s,s)-cycle moves per finest cell (s = sweeps; the numbers below for 2), counted at the
/// interior size of the arrays, for the kernels in use. General kernels: each red-black sweep reads
/// x, rhs, alpha and the three face coefficients twice (one colour per pass) and writes x: 2 x (6 x
/// 8 + 8) = 112 B; residual: 7 arrays read, 1 written = 64 B. Constant coefficients (the cavity's
/// pressure problem): a sweep reads x and rhs twice and writes x: 2 x (2 x 8 + 8) = 48 B; residual:
/// x, rhs read, r written = 24 B. Restriction and prolongation: 8 + 16 B; the
/// coarser levels add 1/7. A lower bound: the ghost layers make the rows
/// longer, and the passes around the cycle (the solve's own residual and norm,
/// the mean removed from this singular problem: about 70 B per cell) are not
/// counted, a larger share of the constant kernels' smaller total.
constexpr double sweep_bytes_per_cell(bool general) {
  return general ? 112.0 : 48.0;
}

constexpr double vcycle_bytes_per_cell(bool general, int sweeps) {
  const double sweep = sweep_bytes_per_cell(general), residual = general ? 64.0 : 24.0;
  return (2.0 * sweeps * sweep + residual + 24.0) * 8.0 / 7.0;
}

}  // namespace

std::array<flow::FlowBoundary, 6> cavity_boundaries(double lid_velocity) {
  std::array<flow::FlowBoundary, 6> bcs{};  // all walls at rest
  bcs[flow::face_index(1, 1)].wall_velocity = {lid_velocity, 0.0, 0.0};
  return bcs;
}

std::string run_flow_cavity(const BenchOptions& options_in) {
  BenchOptions o = options_in;
  if (o.block_cells == 0) {
    const int n = static_cast<int>(std::min<std::int64_t>(o.cells_per_side, 1 << 20));
    o.block_cells = flow::automatic_block_cells({n, n, n}, false);
  }
  const flow::Forest forest(cavity_forest(o.cells_per_side, o.block_cells, o.threads));
  flow::NavierStokesOptions options;
  options.dt_max = 0.01;
  options.pressure.tolerance = 1e-3;
  options.viscous.tolerance = 1e-3;
  options.pressure.constant_coefficient_kernels = !o.general_kernels;
  options.viscous.constant_coefficient_kernels = !o.general_kernels;
  const flow::NextBlockPrefetch prefetch = o.prefetch == "always" ? flow::NextBlockPrefetch::Always
                                           : o.prefetch == "never"
                                               ? flow::NextBlockPrefetch::Never
                                               : flow::NextBlockPrefetch::OutOfCache;
  for (flow::MultigridOptions* mg : {&options.pressure, &options.viscous}) {
    mg->prefetch = prefetch;
    if (o.relaxation > 0.0) mg->relaxation = o.relaxation;
    if (o.sweeps > 0) mg->pre_sweeps = mg->post_sweeps = o.sweeps;
  }
  if (o.pressure_relaxation > 0.0) options.pressure.relaxation = o.pressure_relaxation;
  options.merge_solver_blocks = !o.unmerged_solver;
  int cycles = 0, predictor = 0, pressure = 0, viscous = 0;
  double seconds = 0.0;
  if (o.steps > 0) {  // --steps 0 builds no flow solver, so larger grids fit in memory
    flow::NavierStokes ns(forest, cavity_boundaries(1.0), flow::Fluid{1.0, 0.01}, options);
    ns.set_velocity([](const Vec3&) { return Vec3{}; });
    const auto start = std::chrono::steady_clock::now();
    for (std::int64_t s = 0; s < o.steps; ++s) {
      const auto report = ns.step(0.01);
      cycles += report.pressure_cycles + report.predictor_cycles + report.viscous_cycles;
      predictor += report.predictor_cycles;
      pressure += report.pressure_cycles;
      viscous += report.viscous_cycles;
    }
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  // The multigrid alone: 10 V(2,2)-cycles of the cavity's pressure problem
  // (Neumann walls) on a random right-hand side.
  flow::Multigrid mg(forest, flow::uniform_kinds(forest, flow::BcKind::Neumann),
                     options.merge_solver_blocks);
  flow::ScalarBoundary bc;
  bc.kind = flow::uniform_kinds(forest, flow::BcKind::Neumann);
  const int b = forest.block_cells();
  flow::BlockField rhs(forest.local_blocks(), b), x(forest.local_blocks(), b);
  std::mt19937_64 random(o.seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int blk = 0; blk < forest.local_blocks(); ++blk)
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) rhs(blk, i, j, k) = uniform(random);
  // The solver's settings for its pressure solves (relaxation and sweeps included).
  flow::MultigridOptions mg_options = options.pressure;
  mg_options.tolerance = 0.0;
  mg_options.absolute_tolerance = 0.0;
  mg_options.max_cycles = 10;
  const auto mg_start = std::chrono::steady_clock::now();
  const auto mg_report = mg.solve(x, rhs, bc, mg_options);
  const double mg_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - mg_start).count();

  // The smoother alone (what issue #6's bandwidth target names): sweeps of
  // the finest level on the same problem, ghosts filled as in a V-cycle.
  // The best of a few rounds, as STREAM takes the best of its trials: on a
  // shared host single rounds spread by tens of per cent.
  constexpr int kSmootherSweeps = 20;
  constexpr int kSmootherRounds = 5;
  const auto best_of_rounds = [&](flow::Multigrid& multigrid, const flow::ScalarBoundary& bound) {
    double best = std::numeric_limits<double>::infinity();
    for (int round = 0; round < kSmootherRounds; ++round) {
      const auto start = std::chrono::steady_clock::now();
      multigrid.relax(x, rhs, bound, kSmootherSweeps, mg_options);
      best = std::min(
          best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    return best;
  };
  const double smooth_seconds = best_of_rounds(mg, bc);
  // The same sweeps with walls at rest on every face (the viscous solves'
  // case: each block beside a wall relaxes its closure rows, the quadratic
  // Dirichlet closure of the finest level).
  flow::ScalarBoundary walls;
  walls.kind = flow::uniform_kinds(forest, flow::BcKind::Dirichlet);
  flow::Multigrid walled(forest, walls.kind, options.merge_solver_blocks);
  const double walled_seconds = best_of_rounds(walled, walls);

  const double cells = static_cast<double>(o.cells_per_side * o.cells_per_side * o.cells_per_side);
  // The kernels that ran: constant ones where the option is on and detection
  // found alpha and beta constant on the finest level.
  const bool constant = !o.general_kernels && mg.constant_coefficients(0);
  // --steps 0 times the multigrid and the smoother alone: no per-step figures.
  const auto per_step = [&](int count) {
    return o.steps > 0 ? static_cast<double>(count) / static_cast<double>(o.steps) : 0.0;
  };
  std::ostringstream json;
  json.precision(6);
  json << "{\"benchmark\":\"flow-cavity\",\"code\":\"sanguis\",\"cells\":"
       << static_cast<std::int64_t>(cells) << ",\"steps\":" << o.steps
       << ",\"block_cells\":" << o.block_cells
       << ",\"solver_block_cells\":" << mg.solver_block_cells() << ",\"threads\":" << o.threads
       << ",\"ranks\":" << forest.ranks() << ",\"seconds\":" << seconds
       << ",\"cell_updates_per_s\":"
       << (o.steps > 0 ? cells * static_cast<double>(o.steps) / seconds : 0.0)
       << ",\"vcycles_per_step\":" << per_step(cycles)
       << ",\"vcycles_per_step_predictor_pressure_viscous\":[" << per_step(predictor) << ','
       << per_step(pressure) << ',' << per_step(viscous) << ']'
       << ",\"multigrid_s_per_vcycle_per_cell\":"
       << mg_seconds / (static_cast<double>(mg_report.cycles) * cells)
       << ",\"multigrid_reduction_per_cycle\":" << mg_report.mean_reduction()
       << ",\"multigrid_kernels\":\"" << (constant ? "constant" : "general") << "\""
       << ",\"relaxation\":" << mg_options.relaxation
       << ",\"viscous_relaxation\":" << options.viscous.relaxation
       << ",\"sweeps\":" << mg_options.pre_sweeps << ",\"prefetch\":\"" << o.prefetch << "\""
       << ",\"prefetch_finest\":\"" << mg.finest_prefetch() << "\"";
  const std::int64_t triad_n = triad_elements();
  const double triad = stream_triad_bytes_per_s(o.threads, triad_n);
  const double effective = vcycle_bytes_per_cell(!constant, mg_options.pre_sweeps) *
                           static_cast<double>(mg_report.cycles) * cells / mg_seconds;
  json << ",\"stream_triad_GB_s\":" << triad * 1e-9
       << ",\"stream_triad_array_MiB\":" << static_cast<double>(triad_n) * 8.0 / (1 << 20)
       << ",\"multigrid_effective_GB_s\":" << effective * 1e-9
       << ",\"multigrid_bandwidth_fraction\":" << effective / triad;
  const double sweep_seconds = smooth_seconds / (kSmootherSweeps * cells);
  const double smoother = sweep_bytes_per_cell(!constant) / sweep_seconds;
  json << ",\"smoother_s_per_sweep_per_cell\":" << sweep_seconds
       << ",\"smoother_effective_GB_s\":" << smoother * 1e-9
       << ",\"smoother_bandwidth_fraction\":" << smoother / triad
       << ",\"smoother_walls_s_per_sweep_per_cell\":" << walled_seconds / (kSmootherSweeps * cells)
       << "}";
  return json.str();
}

}  // namespace sanguis::bench
