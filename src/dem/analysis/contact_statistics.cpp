#include "dem/analysis/contact_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

namespace sanguis::dem::analysis {

Histogram histogram(const std::vector<double>& samples, std::vector<double> edges) {
  if (edges.size() < 2) throw std::invalid_argument("histogram: needs at least one bin");
  Histogram h;
  h.edges = std::move(edges);
  h.counts.assign(h.edges.size() - 1, 0.0);
  h.samples = samples.size();
  for (const double s : samples) {
    if (!(s >= h.edges.front()) || s > h.edges.back()) continue;
    auto bin = static_cast<std::size_t>(std::upper_bound(h.edges.begin(), h.edges.end(), s) -
                                        h.edges.begin()) -
               1;
    bin = std::min(bin, h.counts.size() - 1);  // s == last edge
    h.counts[bin] += 1.0;
  }
  h.density.resize(h.counts.size());
  for (std::size_t b = 0; b < h.counts.size(); ++b) {
    const double width = h.edges[b + 1] - h.edges[b];
    h.density[b] = h.samples > 0 ? h.counts[b] / (static_cast<double>(h.samples) * width) : 0.0;
  }
  return h;
}

std::vector<double> linear_edges(double lo, double hi, std::size_t bins) {
  std::vector<double> e(bins + 1);
  for (std::size_t k = 0; k <= bins; ++k) {
    e[k] = lo + (hi - lo) * static_cast<double>(k) / static_cast<double>(bins);
  }
  return e;
}

std::vector<double> log_edges(double lo, double hi, std::size_t bins) {
  std::vector<double> e(bins + 1);
  for (std::size_t k = 0; k <= bins; ++k) {
    e[k] = lo * std::pow(hi / lo, static_cast<double>(k) / static_cast<double>(bins));
  }
  return e;
}

Histogram average(const std::vector<Histogram>& runs) {
  if (runs.empty()) throw std::invalid_argument("average: no histogram");
  Histogram mean = runs.front();
  for (std::size_t r = 1; r < runs.size(); ++r) {
    if (runs[r].edges != mean.edges) throw std::invalid_argument("average: different bins");
    for (std::size_t b = 0; b < mean.counts.size(); ++b) {
      mean.counts[b] += runs[r].counts[b];
      mean.density[b] += runs[r].density[b];
    }
    mean.samples += runs[r].samples;
  }
  for (double& d : mean.density) d /= static_cast<double>(runs.size());
  return mean;
}

std::vector<double> scaled_force_magnitudes(const BranchFrame& branches) {
  std::vector<double> scaled = branches.force_magnitude;
  if (scaled.empty()) return scaled;
  double sum = 0.0;
  for (const double f : scaled) sum += f;
  const double mean = sum / static_cast<double>(scaled.size());
  if (mean > 0) {
    for (double& f : scaled) f /= mean;
  }
  return scaled;
}

Fabric fabric_xz(const BranchFrame& branches, std::size_t bins) {
  std::vector<double> angles;
  double fxx = 0.0, fxz = 0.0, fzz = 0.0;
  for (std::size_t k = 0; k < branches.size(); ++k) {
    const double dx = branches.to[k].x - branches.from[k].x;
    const double dz = branches.to[k].z - branches.from[k].z;
    const double length = std::hypot(dx, dz);
    if (length == 0.0) continue;  // purely along y: no direction in the xz-plane
    double theta = std::atan2(dz, dx) * 180.0 / std::numbers::pi;
    if (theta < 0) theta += 180.0;
    if (theta >= 180.0) theta -= 180.0;
    angles.push_back(theta);
    const double nx = dx / length, nz = dz / length;
    fxx += nx * nx;
    fxz += nx * nz;
    fzz += nz * nz;
  }
  Fabric f;
  f.angles = histogram(angles, linear_edges(0.0, 180.0, bins));
  if (!angles.empty()) {
    // Symmetric 2x2 fabric tensor: l1 - l2 = 2 * radius, l1 + l2 = trace.
    const double radius = std::hypot(0.5 * (fxx - fzz), fxz);
    f.anisotropy = 4.0 * radius / (fxx + fzz);
    double principal = 0.5 * std::atan2(2.0 * fxz, fxx - fzz) * 180.0 / std::numbers::pi;
    if (principal < 0) principal += 180.0;
    f.principal_angle_deg = principal;
  }
  return f;
}

Coordination coordination(const ParticleFrame& particles, const BranchFrame& branches,
                          const ContactPointFrame& contacts, const Region& region) {
  std::unordered_map<std::int64_t, bool> inside;
  Coordination c;
  for (std::size_t k = 0; k < particles.size(); ++k) {
    const bool in = region.contains(particles.position[k]);
    inside[particles.id[k]] = in;
    c.particles += in ? 1 : 0;
  }
  const auto in_region = [&](std::int64_t id) {
    const auto it = inside.find(id);
    return it != inside.end() && it->second;
  };
  double pair_ends = 0.0, point_ends = 0.0;
  std::unordered_map<std::int64_t, std::size_t> pairs_of;  // touching neighbours per particle
  for (std::size_t k = 0; k < branches.size(); ++k) {
    for (const std::int64_t id : {branches.first[k], branches.second[k]}) {
      if (!in_region(id)) continue;
      pair_ends += 1.0;
      ++pairs_of[id];
    }
  }
  std::unordered_set<std::int64_t> on_obstacle;
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    if (ContactPointFrame::is_wall(contacts.kind[k])) {
      if (in_region(contacts.first[k])) {
        ++c.wall_contact_points[contacts.second[k]];
        on_obstacle.insert(contacts.first[k]);
      }
      continue;
    }
    point_ends +=
        (in_region(contacts.first[k]) ? 1.0 : 0.0) + (in_region(contacts.second[k]) ? 1.0 : 0.0);
  }
  c.particles_touching_obstacles = on_obstacle.size();
  if (c.particles > 0) {
    c.pair_coordination = pair_ends / static_cast<double>(c.particles);
    c.contact_point_coordination = point_ends / static_cast<double>(c.particles);
  }
  if (c.particles > c.particles_touching_obstacles) {
    double away_ends = 0.0;
    for (const auto& [id, pairs] : pairs_of) {
      if (!on_obstacle.contains(id)) away_ends += static_cast<double>(pairs);
    }
    c.pair_coordination_away_from_obstacles =
        away_ends / static_cast<double>(c.particles - c.particles_touching_obstacles);
  }
  return c;
}

std::map<std::int64_t, WallLoad> wall_loads(const ParticleFrame& particles,
                                            const ContactPointFrame& contacts, double g) {
  double mass = 0.0;
  for (const double m : particles.mass) mass += m;
  const double weight = mass * g;
  std::map<std::int64_t, WallLoad> loads;
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    if (!ContactPointFrame::is_wall(contacts.kind[k])) continue;
    WallLoad& load = loads[contacts.second[k]];
    ++load.contact_points;
    load.force += contacts.force[k];
  }
  for (auto& [index, load] : loads) {
    load.weight_fraction = weight > 0 ? load.force.z / weight : 0.0;
  }
  return loads;
}

}  // namespace sanguis::dem::analysis
