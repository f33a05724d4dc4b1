// The dem-spheres benchmark case, built to match bench/lammps/in.dem-spheres
// (see bench/README.md for the definition and the parameter mapping).
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <numeric>
#include <random>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "benchmarks.hpp"
#include "dem/domain_decomposition.hpp"
#include "dem/simulation.hpp"
#include "memory_usage.hpp"

namespace sanguis::bench {

namespace {

dem::DemSetup dem_spheres_setup(const BenchOptions& o) {
  constexpr double kPi = std::numbers::pi;
  const double radius = 1e-3, density = 2500.0, spacing = 2e-3;
  const double mass = 4.0 / 3.0 * kPi * radius * radius * radius * density;
  const std::int64_t per_layer = 400;
  const std::int64_t layers = (o.particles + per_layer - 1) / per_layer;

  dem::DemSetup s;
  s.domain.min = {0.0, 0.0, 0.0};
  s.domain.max = {0.04, 0.04, std::max(0.2, 1.25 * spacing * static_cast<double>(layers))};
  s.domain.periodic = {true, true, false};
  const double tilt = 26.0 * kPi / 180.0;
  s.gravity = {9.81 * std::sin(tilt), 0.0, -9.81 * std::cos(tilt)};
  s.time_step = 5e-7;
  s.integrator = dem::IntegratorKind::kLeapfrog;  // velocity Verlet, as fix nve/sphere
  s.skin = 2e-4;
  s.threads = o.threads;
  s.material_names = {"glass", "floor"};

  // Table 2.1 stiffnesses; damping from en = 0.45, et = 0.3 with the pair reduced mass,
  // and LAMMPS' single gamma = eta / m_eff applied with m_eff = m for the floor.
  const double kn = 7.34e5, kt = 2.26e5, en = 0.45, et = 0.3;
  const double m_pair = 0.5 * mass;
  const double omega0 = std::sqrt(kn / m_pair);
  const double eta_n =
      -2.0 * m_pair * omega0 * std::log(en) / std::sqrt(kPi * kPi + std::log(en) * std::log(en));
  const double eta_t = eta_n / 3.5 * std::log(et) / std::log(en);
  dem::ContactParameters pair;
  pair.normal_stiffness = kn;
  pair.tangential_stiffness = kt;
  pair.normal_damping = eta_n;
  pair.tangential_damping = eta_t;
  pair.friction = 0.5;
  dem::ContactParameters wall = pair;
  wall.normal_damping = eta_n / m_pair * mass;
  wall.tangential_damping = eta_t / m_pair * mass;
  s.contacts = dem::ContactTable(2);
  s.contacts.set(0, 0, pair);
  s.contacts.set(0, 1, wall);

  dem::Obstacle floor;
  floor.name = "floor";
  floor.material = 1;
  floor.shape = dem::PlaneShape{{0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}};
  s.obstacles.push_back(floor);

  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double vmax = 0.1 / std::sqrt(3.0);
  std::vector<std::int64_t> site(static_cast<std::size_t>(o.particles));
  std::iota(site.begin(), site.end(), 0);
  if (o.scatter) std::shuffle(site.begin(), site.end(), std::mt19937_64(o.seed + 1));
  if (o.storage_sort_interval >= 0) s.storage_sort_interval = o.storage_sort_interval;
  for (std::int64_t n = 0; n < o.particles; ++n) {
    const std::int64_t m = site[static_cast<std::size_t>(n)];
    const auto i = static_cast<double>(m % 20), j = static_cast<double>((m / 20) % 20),
               k = static_cast<double>(m / per_layer);
    const Vec3 x{(1 + 2 * i) * 1e-3, (1 + 2 * j) * 1e-3, (1 + 2 * k) * 1e-3};
    const Vec3 v{vmax * unit(rng), vmax * unit(rng), vmax * unit(rng)};
    s.particles.add_sphere(n, 0, radius, density, x, v, {});
  }
  return s;
}

}  // namespace

std::string run_dem_spheres(const BenchOptions& o) {
  if (o.particles <= 0 || o.steps <= 0)
    throw std::invalid_argument("particles and steps must be > 0");
  int rank = 0, ranks = 1;
  if (o.comm != MPI_COMM_NULL) {
    MPI_Comm_rank(o.comm, &rank);
    MPI_Comm_size(o.comm, &ranks);
  }
  const std::int64_t rss_before = resident_bytes();
  std::unique_ptr<dem::SlabDecomposition> decomposition;
  if (ranks > 1) decomposition = std::make_unique<dem::SlabDecomposition>(o.comm);
  dem::DemSimulation sim(decomposition ? decomposition->local_setup(dem_spheres_setup(o))
                                       : dem_spheres_setup(o));
  if (decomposition) decomposition->attach(sim);
  const std::int64_t rebuilds_before = sim.neighbor_search().rebuild_count();
  const std::int64_t bytes_before = decomposition ? decomposition->bytes_sent() : 0;
  const double exchange_before = decomposition ? decomposition->exchange_seconds() : 0.0;
  if (decomposition) MPI_Barrier(o.comm);
  const auto start = std::chrono::steady_clock::now();
  for (std::int64_t s = 0; s < o.steps; ++s) sim.step();
  if (decomposition) MPI_Barrier(o.comm);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::ostringstream json;
  json.precision(6);
  json << "{\"benchmark\":\"dem-spheres\",\"code\":\"sanguis\",\"particles\":" << o.particles
       << ",\"steps\":" << o.steps << ",\"threads\":" << o.threads << ",\"processes\":" << ranks
       << ",\"seconds\":" << seconds << ",\"particle_steps_per_s\":"
       << static_cast<double>(o.particles) * static_cast<double>(o.steps) / seconds
       << ",\"neighbor_rebuilds\":" << sim.neighbor_search().rebuild_count() - rebuilds_before
       << ",\"scattered\":" << (o.scatter ? "true" : "false")
       << ",\"storage_sort_interval\":" << sim.setup().storage_sort_interval;
  if (decomposition) {
    // Per process per step: the largest over the processes (the slowest sets the pace).
    double figures[3] = {
        static_cast<double>(decomposition->bytes_sent() - bytes_before) /
            static_cast<double>(o.steps),
        (decomposition->exchange_seconds() - exchange_before) / static_cast<double>(o.steps),
        static_cast<double>(decomposition->ghosts())};
    MPI_Allreduce(MPI_IN_PLACE, figures, 3, MPI_DOUBLE, MPI_MAX, o.comm);
    json << ",\"bytes_sent_per_step_per_process\":" << figures[0]
         << ",\"exchange_s_per_step\":" << figures[1]
         << ",\"exchange_fraction\":" << figures[1] * static_cast<double>(o.steps) / seconds
         << ",\"ghosts_per_process\":" << figures[2];
  }
  json << ",\"peak_rss_mb\":" << static_cast<double>(peak_resident_bytes()) / 1048576.0
       << ",\"bytes_per_particle\":"
       << static_cast<double>(peak_resident_bytes() - rss_before) / static_cast<double>(o.particles)
       << "}";
  return rank == 0 ? json.str() : std::string();
}

}  // namespace sanguis::bench
