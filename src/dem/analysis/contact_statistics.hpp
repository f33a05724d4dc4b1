#pragma once
// Statistics of the contact network of one frame (thesis §3.3.3-3.4.1,
// app. B): force distributions, fabric anisotropy, coordination numbers,
// contacts and loads on the walls.
#include <cstdint>
#include <map>
#include <vector>

#include "core/vec3.hpp"
#include "dem/analysis/run_output.hpp"

namespace sanguis::dem::analysis {

// A histogram normalised as a probability density (sum of density * width = 1
// over the samples that fall inside the edges).
struct Histogram {
  std::vector<double> edges;    // bins + 1 increasing values
  std::vector<double> counts;   // samples per bin
  std::vector<double> density;  // counts / (samples * width)
  std::size_t samples = 0;      // all samples, inside the edges or not
};

Histogram histogram(const std::vector<double>& samples, std::vector<double> edges);
std::vector<double> linear_edges(double lo, double hi, std::size_t bins);
std::vector<double> log_edges(double lo, double hi, std::size_t bins);
// Bin-wise mean of densities on the same edges (the average PDF over runs, Fig. B.3).
Histogram average(const std::vector<Histogram>& runs);

// Fc / <Fc> of every pair of touching particles (walls excluded): the pair's
// total force magnitude over the mean of the frame (Fig. 3.12).
std::vector<double> scaled_force_magnitudes(const BranchFrame& branches);

// Fabric in the vertical xz-plane (Fig. 3.13-3.14): angle theta in [0, 180)
// degrees between +x and the branch vector projected on xz (a branch has no
// sign), histogram and the second-order fabric tensor of the projected unit
// vectors: anisotropy 2 (l1 - l2) / (l1 + l2) and principal direction.
struct Fabric {
  Histogram angles;         // degrees
  double anisotropy = 0.0;  // 0 isotropic, 2 all aligned
  double principal_angle_deg = 0.0;
};
Fabric fabric_xz(const BranchFrame& branches, std::size_t bins);

// An axis-aligned region selecting particles by their centre of mass.
struct Region {
  Vec3 min{-1e300, -1e300, -1e300};
  Vec3 max{1e300, 1e300, 1e300};
  bool contains(const Vec3& x) const {
    return x.x >= min.x && x.x <= max.x && x.y >= min.y && x.y <= max.y && x.z >= min.z &&
           x.z <= max.z;
  }
};

// Coordination of the particles of a region (§3.3.3, Table B.1): mean number
// of touching neighbours (pairs), mean number of contact points with other
// particles (an element contact counts once: crosses touch a neighbour at up
// to several points), and the contact points with each obstacle. A particle
// against a wall has a wall where it would have neighbours, so a small column
// (mostly wall particles) has a lower mean than a large one: the particles
// that touch an obstacle are counted, and the pair coordination of the others
// given apart (0 when there are none).
struct Coordination {
  std::size_t particles = 0;
  double pair_coordination = 0.0;
  double contact_point_coordination = 0.0;
  std::map<std::int64_t, std::size_t> wall_contact_points;  // by obstacle index
  std::size_t particles_touching_obstacles = 0;        // with at least one obstacle contact point
  double pair_coordination_away_from_obstacles = 0.0;  // of the particles touching none
};
Coordination coordination(const ParticleFrame& particles, const BranchFrame& branches,
                          const ContactPointFrame& contacts, const Region& region);

// The force each obstacle exerts on the particles, and its vertical part as a
// fraction of the weight of all particles (the Janssen effect: the share of
// the weight that the side walls carry, §3.4.1, app. B.3).
struct WallLoad {
  std::size_t contact_points = 0;
  Vec3 force;                    // sum over its contacts of the force on the particle [N]
  double weight_fraction = 0.0;  // force.z / (total mass * g)
};
std::map<std::int64_t, WallLoad> wall_loads(const ParticleFrame& particles,
                                            const ContactPointFrame& contacts, double g);

}  // namespace sanguis::dem::analysis
