// The dem-crosses benchmark: a column of cross-shaped particles (thesis §3.2.2,
// Table 3.1) behind the gate of the dam-break box, in contact, timed over a fixed
// number of steps (see bench/README.md).
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <random>
#include <sstream>
#include <stdexcept>

#include "benchmarks.hpp"
#include "dem/domain_decomposition.hpp"
#include "dem/simulation.hpp"
#include "geometry/mass_properties.hpp"
#include "memory_usage.hpp"

namespace sanguis::bench {

namespace {

constexpr double kPi = std::numbers::pi;

dem::DemSetup dem_crosses_setup(const BenchOptions& o) {
  const double length = 0.027, width = 0.002, thickness = 0.003, density = 770.0;
  const double gate = 0.12, box_x = 0.64, box_y = 0.30;
  const double spacing = 0.028;  // > arm length: crosses of one layer never touch
  const int columns = static_cast<int>(gate / spacing), rows = static_cast<int>(box_y / spacing);
  const std::int64_t per_layer = columns * rows;
  const std::int64_t layers = (o.particles + per_layer - 1) / per_layer;

  dem::DemSetup s;
  s.shapes.push_back(
      dem::make_particle_shape("cross", geometry::cross_particle(length, width, thickness), 1e-4));
  const dem::ParticleShape& cross = s.shapes.back();
  const Quaternion principal_axes =
      geometry::composite_mass_properties(geometry::cross_particle(length, width, thickness))
          .principal_axes;
  const double mass = density * cross.volume;

  s.domain.min = {0.0, 0.0, 0.0};
  s.domain.max = {box_x, box_y, std::max(0.2, thickness * static_cast<double>(layers) + 0.05)};
  s.gravity = {0.0, 0.0, -9.81};
  s.time_step = 2.5e-6;  // Table 3.1
  s.threads = o.threads;
  if (o.storage_sort_interval >= 0) s.storage_sort_interval = o.storage_sort_interval;
  s.contact_patches = o.flat_contacts == "patch";
  s.mean_element_contacts = o.element_contacts == "mean";
  s.material_names = {"plastic", "acrylic"};
  // Table 3.1: kn 4.5e5 N/m, en 0.85, kt 3e2 N/m, gamma_t 1e3 1/s, mu 0.46 / 0.62.
  const auto table31 = [&](double reduced_mass, double friction) {
    dem::ContactParameters p;
    p.normal_stiffness = 4.5e5;
    const double omega0 = std::sqrt(p.normal_stiffness / reduced_mass);
    const double log_en = std::log(0.85);
    p.normal_damping =
        -2.0 * reduced_mass * omega0 * log_en / std::sqrt(kPi * kPi + log_en * log_en);
    p.tangential_stiffness = 3e2;
    p.tangential_damping = 2.0 * reduced_mass * 1e3;
    p.friction = friction;
    return p;
  };
  s.contacts = dem::ContactTable(2);
  s.contacts.set(0, 0, table31(0.5 * mass, 0.46));
  s.contacts.set(0, 1, table31(mass, 0.62));
  const auto plane = [&](const Vec3& point, const Vec3& normal) {
    dem::Obstacle o;
    o.material = 1;
    o.shape = dem::PlaneShape{point, normal};
    s.obstacles.push_back(o);
  };
  plane({0, 0, 0}, {0, 0, 1});
  plane({0, 0, 0}, {1, 0, 0});
  plane({gate, 0, 0}, {-1, 0, 0});
  plane({0, 0, 0}, {0, 1, 0});
  plane({0, box_y, 0}, {0, -1, 0});

  // Layers of flat crosses, each turned at random about z, resting on one another: the
  // arms of two crosses stacked at a random angle cross at up to four points.
  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * kPi);
  const double lift = thickness;  // touching (zero overlap): gravity loads the contacts
  for (std::int64_t n = 0; n < o.particles; ++n) {
    const std::int64_t layer = n / per_layer, in_layer = n % per_layer;
    const Vec3 x{(0.5 + static_cast<double>(in_layer % columns)) * (gate / columns),
                 (0.5 + static_cast<double>(in_layer / columns)) * (box_y / rows),
                 0.5 * thickness + lift * static_cast<double>(layer)};
    // Body (principal) frame -> the cross's own frame (thickness along z) -> turned about z.
    const Quaternion q = Quaternion::from_axis_angle({0, 0, 1}, angle(rng)) * principal_axes;
    s.particles.add_body(n, 0, 0, cross.bounding_radius, mass, density * cross.inertia_per_density,
                         normalized(q), x, {}, {});
  }
  return s;
}

}  // namespace

std::string run_dem_crosses(const BenchOptions& o) {
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
  dem::DemSimulation sim(decomposition ? decomposition->local_setup(dem_crosses_setup(o))
                                       : dem_crosses_setup(o));
  if (decomposition) decomposition->attach(sim);
  const double exchange_before = decomposition ? decomposition->exchange_seconds() : 0.0;
  if (decomposition) MPI_Barrier(o.comm);
  const auto start = std::chrono::steady_clock::now();
  for (std::int64_t s = 0; s < o.steps; ++s) sim.step();
  if (decomposition) MPI_Barrier(o.comm);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const dem::DemDiagnostics d = decomposition ? decomposition->diagnostics(sim) : sim.diagnostics();
  long long candidates = static_cast<long long>(sim.body_contacts().size());
  double exchange = decomposition ? decomposition->exchange_seconds() - exchange_before : 0.0;
  if (decomposition) {
    MPI_Allreduce(MPI_IN_PLACE, &candidates, 1, MPI_LONG_LONG, MPI_SUM, o.comm);
    MPI_Allreduce(MPI_IN_PLACE, &exchange, 1, MPI_DOUBLE, MPI_MAX, o.comm);
  }
  std::ostringstream json;
  json.precision(6);
  json << "{\"benchmark\":\"dem-crosses\",\"code\":\"sanguis\",\"particles\":" << o.particles
       << ",\"steps\":" << o.steps << ",\"threads\":" << sim.threads() << ",\"processes\":" << ranks
       << ",\"seconds\":" << seconds << ",\"particle_steps_per_s\":"
       << static_cast<double>(o.particles) * static_cast<double>(o.steps) / seconds
       << ",\"element_pair_candidates\":" << candidates
       << ",\"element_contacts\":" << d.particle_contacts
       << ",\"wall_contacts\":" << d.wall_contacts
       << ",\"max_overlap_over_radius\":" << d.max_overlap_ratio
       << ",\"storage_sort_interval\":" << sim.setup().storage_sort_interval
       << ",\"flat_contacts\":\"" << (sim.setup().contact_patches ? "patch" : "point") << "\""
       << ",\"element_contact_rule\":\"" << (sim.setup().mean_element_contacts ? "mean" : "sum")
       << "\"";
  if (decomposition) json << ",\"exchange_fraction\":" << exchange / seconds;
  json << ",\"peak_rss_mb\":" << static_cast<double>(peak_resident_bytes()) / 1048576.0
       << ",\"bytes_per_particle\":"
       << static_cast<double>(peak_resident_bytes() - rss_before) / static_cast<double>(o.particles)
       << "}";
  return rank == 0 ? json.str() : std::string();
}

}  // namespace sanguis::bench
