// The membrane benchmark (issue 8; thesis §7.2 finds its front tracking
// unusable beyond about 100 capsules): `capsules` human red blood cells
// (biconcave, eq. 4.21, largest radius 3.91 um) of `triangles` triangles, on a
// cubic lattice 10 um apart with random orientations, pre-inflated by 2 % and
// randomly perturbed by 1 % of an edge so that every force term is active.
// Skalak law (Es = 5 uN/m, C = 10) and Helfrich bending (Eb = 2e-19 J,
// kappa0 = 0); one step = one evaluation of all nodal forces.
#include <chrono>
#include <cmath>
#include <numbers>
#include <random>
#include <sstream>
#include <stdexcept>

#include "benchmarks.hpp"
#include "membrane/capsules.hpp"

namespace sanguis::bench {

std::string run_membrane(const BenchOptions& o) {
  using namespace membrane;
  if (o.capsules <= 0 || o.steps <= 0 || o.threads <= 0)
    throw std::invalid_argument("capsules, steps and threads must be > 0");
  const int k = subdivisions_for_triangles(o.triangles);
  const double radius = 3.91e-6, spacing = 10e-6;
  TriangleMesh shape = icosphere(k);
  map_to_biconcave(shape, {radius, 0.207, 2.003, -1.123});

  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const auto side =
      static_cast<std::int64_t>(std::ceil(std::cbrt(static_cast<double>(o.capsules))));
  std::vector<CapsulePlacement> placements;
  for (std::int64_t c = 0; c < o.capsules; ++c) {
    const Vec3 at{spacing * static_cast<double>(c % side),
                  spacing * static_cast<double>((c / side) % side),
                  spacing * static_cast<double>(c / (side * side))};
    const Quaternion q = normalized(Quaternion{gauss(rng), gauss(rng), gauss(rng), gauss(rng)});
    placements.push_back({at, q});
  }
  CapsuleSet set(shape, 1.02, placements);
  const double jitter = 0.01 * radius * 4.0 / std::sqrt(static_cast<double>(o.triangles));
  for (auto& x : set.all_positions()) x += jitter * Vec3{gauss(rng), gauss(rng), gauss(rng)};

  const ElasticLaw law = SkalakLaw{5e-6, 10.0};
  const HelfrichParameters bending{2e-19, 0.0, 4};
  set.compute_forces(law, bending, o.threads);  // warm-up: workspaces allocated
  const auto start = std::chrono::steady_clock::now();
  for (std::int64_t s = 0; s < o.steps; ++s) set.compute_forces(law, bending, o.threads);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::ostringstream json;
  json.precision(6);
  json << "{\"benchmark\":\"membrane\",\"code\":\"sanguis\",\"triangles\":" << o.triangles
       << ",\"capsules\":" << o.capsules << ",\"threads\":" << o.threads << ",\"steps\":" << o.steps
       << ",\"seconds\":" << seconds
       << ",\"seconds_per_step\":" << seconds / static_cast<double>(o.steps) << "}";
  return json.str();
}

}  // namespace sanguis::bench
