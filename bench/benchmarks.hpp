#pragma once
// Throughput benchmarks behind `sanguis bench NAME`. Each builds its case in code
// (documented in bench/README.md), times the time loop only (set-up excluded, as
// LAMMPS reports its loop time) and returns one JSON line.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>

#include "flow/navier_stokes.hpp"

namespace sanguis::bench {

struct BenchOptions {
  std::int64_t particles = 32000;
  std::int64_t steps = 2000;
  int threads = 1;
  std::uint64_t seed = 4928459;
  std::int64_t triangles = 5120;     // membrane: triangles per capsule (20 * 4^k)
  std::int64_t capsules = 100;       // membrane: number of capsules
  std::int64_t cells_per_side = 64;  // flow-cavity: cells along each edge (multiple of the block)
  int block_cells = 0;  // flow-cavity: cells per block edge (a power of two); 0: as a case file
                        // without block_cells (flow::automatic_block_cells)
  // flow-cavity: multigrid kernels that read the coefficient arrays even where they
  // are constant (MultigridOptions::uniform_coefficient_kernels = false), for A/B runs.
  bool general_kernels = false;
  // flow-cavity: the multigrids on the flow's own blocks instead of their families of 8
  // merged (NavierStokesOptions::merge_solver_blocks = false), for A/B runs.
  bool unmerged_solver = false;
  // flow-cavity: when the multigrid prefetches the next block ("out-of-cache", "always",
  // "never"; MultigridOptions::prefetch), for A/B runs.
  std::string prefetch = "out-of-cache";
  // flow-cavity: over-relaxation of the red-black smoother in the pressure and viscous
  // solves (0: the solver's, NavierStokesOptions), for A/B runs.
  double relaxation = 0.0;
  // flow-cavity: the same for the projections' (pressure) solves only, after `relaxation`.
  double pressure_relaxation = 0.0;
  // flow-adaptive: MultigridOptions::beside_finer_relaxation of both solves (0: the solver's),
  // for A/B runs (at least the relaxation: the cells beside finer blocks relax as the rest).
  double beside_finer_relaxation = 0.0;
  // flow-cavity: red-black sweeps before and after the coarse correction (0: the solver's).
  int sweeps = 0;
  // dem-spheres: lattice sites filled in random order, so that ids (and the storage
  // until it is sorted) are scattered in space, as a random fill leaves them.
  bool scatter = false;
  // dem-spheres, dem-crosses: DemSetup::storage_sort_interval; -1: its default.
  std::int64_t storage_sort_interval = -1;
  // dem-crosses: DemSetup::contact_patches ("patch", the default, or "point").
  std::string flat_contacts = "patch";
  // dem-crosses: DemSetup::mean_element_contacts ("sum", the default, or "mean").
  std::string element_contacts = "sum";
  // dem-spheres under mpirun: the processes share the system (domain decomposition).
  MPI_Comm comm = MPI_COMM_NULL;
};

// dem-spheres: 32,000 spheres on a tilted chute, Table 2.1 contact parameters,
// matched to LAMMPS gran/hooke/history (bench/lammps/in.dem-spheres). On several MPI
// processes (options.comm) it also reports the communication: bytes sent and time in
// the exchanges per step, ghosts per process (docs/performance.md, weak-scaling model).
// Returns an empty string on every process but the first.
std::string run_dem_spheres(const BenchOptions& options);

// dem-crosses: a column of crosses (thesis §3.2.2, Table 3.1) behind the gate of the
// 64 x 30 cm dam-break box, stacked flat at random angles so that they touch. Also on
// several MPI processes (options.comm); empty string on all but the first.
std::string run_dem_crosses(const BenchOptions& options);

// membrane: elastic (Skalak, C = 10) and Helfrich bending nodal forces of
// `capsules` biconcave red blood cells of `triangles` triangles each, slightly
// deformed; one step = one force evaluation of every capsule. Reports
// seconds_per_step (default 20 steps, after one untimed warm-up evaluation).
std::string run_membrane(const BenchOptions& options);

// flow-cavity: lid-driven cubic cavity at Re = 100, cells_per_side^3 cells,
// dt = 0.01, multigrid tolerance 1e-3; also times V-cycles of the multigrid alone.
std::string run_flow_cavity(const BenchOptions& options);

// flow-adaptive: the adaptive obstacle wake (cases/flow/obstacle-wake.toml, or
// another flow case with [flow.adapt]) run for options.steps steps from its start;
// reports the leaf cells at the end, the cells of the uniform finest grid, seconds
// per step and the share of the time loop spent regridding.
std::string run_flow_adaptive(const BenchOptions& options, const std::filesystem::path& case_file);

/// Walls all round, the one at y = max moving along x (the cavity's lid).
std::array<flow::FlowBoundary, 6> cavity_boundaries(double lid_velocity);

}  // namespace sanguis::bench
