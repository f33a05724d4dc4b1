// The DEM domain decomposition (src/dem/domain_decomposition.hpp) against one process,
// run under mpirun with any number of processes. Every process also runs the whole
// system alone and compares its owned particles with it, id by id. Particles are summed
// in the same order in both (increasing ids), so positions, velocities and angular
// velocities must agree bit for bit; only the diagnostics' reductions may differ
// (checked to 1e-12 relative).
//
// Scenarios: the tiny sphere dam break of the integration tests through its gate
// removal (walls, a removed obstacle, slabs along x); spheres in a box periodic along
// the slab axis (particles and contacts crossing the periodic seam between the first
// and the last process); crosses (element contacts with GJK warm starts) colliding.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <sstream>
#include <string>

#include <mpi.h>

#include "dem/dem_case.hpp"
#include "dem/dem_run.hpp"
#include "dem/domain_decomposition.hpp"
#include "dem/simulation.hpp"

using namespace sanguis;
using namespace sanguis::dem;

namespace {

double largest_difference(const DemSimulation& mine, const ParticleStore& alone) {
  const ParticleStore& p = mine.particles();
  // The single process sorts its storage along space: find its particles by id.
  const std::vector<std::uint32_t> by_id = id_order(alone.id);
  double worst = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (mine.is_ghost(i)) continue;
    const auto it =
        std::lower_bound(by_id.begin(), by_id.end(), p.id[i],
                         [&](std::uint32_t k, std::int64_t id) { return alone.id[k] < id; });
    if (it == by_id.end() || alone.id[*it] != p.id[i]) return INFINITY;
    const std::size_t j = *it;
    worst = std::max({worst, norm(p.position[i] - alone.position[j]),
                      norm(p.velocity[i] - alone.velocity[j]),
                      norm(p.angular_velocity[i] - alone.angular_velocity[j])});
  }
  return worst;
}

// Runs `setup` alone and decomposed for `steps` steps; returns true when they agree.
bool compare(const std::string& name, const DemSetup& setup, std::int64_t steps, int axis) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  DemSimulation alone(setup);
  SlabDecomposition decomposition(MPI_COMM_WORLD, axis);
  DemSimulation mine(decomposition.local_setup(setup));
  decomposition.attach(mine);
  // Touching contacts summed over the steps: at least 1000 evaluations, so that a memory
  // lost or duplicated on the way between processes would show in the states.
  long long contact_steps = 0;
  for (std::int64_t s = 0; s < steps; ++s) {
    alone.step();
    mine.step();
    const DemDiagnostics d = alone.diagnostics();
    contact_steps += d.particle_contacts + d.wall_contacts;
  }
  double worst = largest_difference(mine, alone.particles());
  MPI_Allreduce(MPI_IN_PLACE, &worst, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  long long owned = static_cast<long long>(mine.owned_count());
  MPI_Allreduce(MPI_IN_PLACE, &owned, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  const DemDiagnostics a = alone.diagnostics();
  const DemDiagnostics b = decomposition.diagnostics(mine);
  const double energy_error =
      std::abs(a.kinetic_energy_translational - b.kinetic_energy_translational) /
      std::max(a.kinetic_energy_translational, 1e-300);
  const bool counts_agree = owned == static_cast<long long>(alone.particles().size()) &&
                            a.particle_contacts == b.particle_contacts &&
                            a.wall_contacts == b.wall_contacts;
  long long ghosts = decomposition.ghosts();
  MPI_Allreduce(MPI_IN_PLACE, &ghosts, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  const bool ok = worst == 0.0 && energy_error < 1e-12 && counts_agree && contact_steps >= 1000;
  if (rank == 0) {
    std::printf(
        "%s %s: %d processes, %lld particles, %lld ghosts, %lld steps, %lld rebuilds, "
        "largest state difference %.3g, kinetic energy %.3g relative, contacts %lld/%lld "
        "pairs %lld/%lld walls at the end, %.1f contacts per step on average\n",
        ok ? "PASS" : "FAIL", name.c_str(), ranks, owned, ghosts, static_cast<long long>(steps),
        static_cast<long long>(mine.neighbor_search().rebuild_count()), worst, energy_error,
        static_cast<long long>(a.particle_contacts), static_cast<long long>(b.particle_contacts),
        static_cast<long long>(a.wall_contacts), static_cast<long long>(b.wall_contacts),
        static_cast<double>(contact_steps) / static_cast<double>(steps));
  }
  return ok;
}

DemSetup dam_break() {
  DemCase c = load_dem_case(std::string(SANGUIS_SOURCE_DIR) +
                            "/tests/integration/data/dam-break-tiny.toml");
  return c.setup;
}

// Spheres with random velocities in a box periodic along x, on a floor, under gravity.
DemSetup periodic_spheres() {
  DemSetup s = dam_break();
  s.obstacles.resize(1);  // the floor only
  s.domain.periodic = {true, true, false};
  s.domain.min = {0.0, 0.0, 0.0};
  s.domain.max = {0.06, 0.016, 0.1};
  s.particles = ParticleStore{};
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  std::int64_t id = 0;
  const double r = 0.002;
  for (int k = 0; k < 4; ++k) {
    for (int j = 0; j < 3; ++j) {
      for (int i = 0; i < 13; ++i) {
        const Vec3 x{(i + 0.5) * 0.06 / 13, (j + 0.5) * 0.016 / 3, r + 0.0043 * k};
        s.particles.add_sphere(id++, 0, r * (0.9 + 0.1 * ((i + j + k) % 2)), 2500.0, x,
                               {u(rng), u(rng), u(rng)}, {});
      }
    }
  }
  return s;
}

// The same spheres drifting along x at 0.5 m/s: particles cross the periodic seam between
// the last and the first process all the time, and are owned by the slab they wrap into.
DemSetup periodic_drift() {
  DemSetup s = periodic_spheres();
  for (Vec3& v : s.particles.velocity) v.x += 0.5;
  return s;
}

// Crosses (Table 3.1 shape and contacts) on a lattice, random orientations and velocities.
// `with_spheres`: the lower half in x are spheres (6 mm) instead of crosses, so the first
// process starts with spheres only and receives crosses as they converge.
DemSetup crosses(bool with_spheres = false) {
  // The Table 3.1 crosses and contacts of the dam-break case, in a smaller box with its
  // floor only; the poured column is replaced by the lattice below.
  DemSetup s =
      load_dem_case(std::string(SANGUIS_SOURCE_DIR) + "/cases/dem/dam-break-crosses-memory.toml")
          .setup;
  s.domain.max = {0.18, 0.06, 0.12};
  s.obstacles.resize(1);  // the floor
  s.pour.clear();
  s.particles = ParticleStore{};  // replaced by the lattice below
  const ParticleShape& cross = s.shapes.at(0);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::int64_t id = 0;
  const double spacing = 2.0 * cross.bounding_radius + 0.001;
  const Vec3 centre{3.0 * spacing, spacing, 0.015 + spacing};
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 2; ++j) {
      for (int i = 0; i < 6; ++i) {
        const Vec3 x{(i + 0.5) * spacing, (j + 0.5) * spacing, 0.015 + k * spacing};
        const Quaternion q = normalized({g(rng), g(rng), g(rng), g(rng)});
        // Converging on the lattice's centre: the crosses collide and entangle.
        const Vec3 v = 60.0 * (centre - x) + Vec3{0.3 * u(rng), 0.3 * u(rng), 0.3 * u(rng)};
        const Vec3 w{20.0 * u(rng), 20.0 * u(rng), 20.0 * u(rng)};
        if (with_spheres && i < 3) {
          s.particles.add_sphere(id++, 0, 0.006, 770.0, x, v, w);
        } else {
          s.particles.add_body(id++, 0, 0, cross.bounding_radius, 770.0 * cross.volume,
                               770.0 * cross.inertia_per_density, q, x, v, w);
        }
      }
    }
  }
  return s;
}

// Largest difference of position, velocity and angular velocity between two checkpoints
// of the same case (loaded into simulations of `c`).
double checkpoint_difference(const DemCase& c, const std::filesystem::path& a,
                             const std::filesystem::path& b) {
  DemSimulation x(c.setup), y(c.setup);
  x.load_checkpoint(a);
  y.load_checkpoint(b);
  if (x.step_index() != y.step_index() || x.particles().size() != y.particles().size()) {
    return INFINITY;
  }
  return largest_difference(x, y.particles());
}

// Checkpoints are in the one-process format whatever the process count: a run split at
// 0.3 s continues on another count. Split 1 -> N and N -> 1 against an unsplit run.
bool restart_across_process_counts() {
  namespace fs = std::filesystem;
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  const DemCase c = load_dem_case(std::string(SANGUIS_SOURCE_DIR) +
                                  "/tests/integration/data/dam-break-tiny.toml");
  const fs::path base =
      fs::temp_directory_path() / ("sanguis_dem_mpi_check_restart_" + std::to_string(ranks));
  if (rank == 0) fs::remove_all(base);
  MPI_Barrier(MPI_COMM_WORLD);
  std::ostringstream quiet_console;
  const auto run = [&](const fs::path& dir, bool restart, double stop_at, MPI_Comm comm) {
    RunOptions o;
    o.output_dir = dir;
    o.restart = restart;
    o.quiet = true;
    o.stop_at = stop_at;
    o.comm = comm;
    run_dem_case(c, o, quiet_console);
  };
  if (rank == 0) {
    run(base / "whole", false, -1.0, MPI_COMM_NULL);
    run(base / "one_then_all", false, 0.3, MPI_COMM_NULL);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  run(base / "one_then_all", true, -1.0, MPI_COMM_WORLD);
  run(base / "all_then_one", false, 0.3, MPI_COMM_WORLD);
  MPI_Barrier(MPI_COMM_WORLD);
  bool ok = true;
  if (rank == 0) {
    run(base / "all_then_one", true, -1.0, MPI_COMM_NULL);
    const double d1 = checkpoint_difference(c, base / "whole" / "checkpoint.bin",
                                            base / "one_then_all" / "checkpoint.bin");
    const double d2 = checkpoint_difference(c, base / "whole" / "checkpoint.bin",
                                            base / "all_then_one" / "checkpoint.bin");
    ok = d1 == 0.0 && d2 == 0.0;
    std::printf(
        "%s restart across process counts: split at 0.3 s of 0.6 s, 1 -> %d processes: largest "
        "state difference %.3g; %d -> 1: %.3g\n",
        ok ? "PASS" : "FAIL", ranks, d1, ranks, d2);
    fs::remove_all(base);
  }
  int flag = ok ? 1 : 0;
  MPI_Bcast(&flag, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return flag != 0;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  bool ok = true;
  try {
    // 0.35 s: the column settles, the gate goes at 0.25 s and the front runs out.
    const DemSetup d = dam_break();
    ok &= compare("sphere dam break", d, static_cast<std::int64_t>(0.35 / d.time_step), 0);
    ok &= compare("periodic spheres", periodic_spheres(), 20000, 0);
    ok &= compare("spheres drifting across the periodic seam", periodic_drift(), 20000, 0);
    ok &= compare("crosses", crosses(), 10000, 0);
    ok &= compare("spheres meeting crosses", crosses(true), 10000, 0);
    DemSetup averaged = crosses();
    averaged.mean_element_contacts = true;  // element_contacts = "mean"
    ok &= compare("crosses, element contacts averaged", averaged, 10000, 0);
    ok &= restart_across_process_counts();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dem_mpi_check: %s\n", e.what());
    ok = false;
  }
  int all_ok = ok ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &all_ok, 1, MPI_INT, MPI_LAND, MPI_COMM_WORLD);
  MPI_Finalize();
  return all_ok ? 0 : 1;
}
