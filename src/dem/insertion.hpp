#pragma once
// Initial placement of spheres: seeded random non-overlapping positions in a
// box-shaped region, simple-cubic lattice filling, and overlap checks of a
// finished configuration.
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "core/vec3.hpp"
#include "dem/domain.hpp"
#include "dem/obstacles.hpp"

namespace sanguis::dem {

struct SphereSeed {
  Vec3 position;
  double radius = 0.0;
};

// Random sequential addition: draws centres uniformly so that each sphere lies fully
// inside [region_min, region_max], rejects overlaps with `existing`, already placed
// spheres and active obstacles. Radii are drawn uniformly in [r_min, r_max].
// Throws std::runtime_error if `count` spheres do not fit after many attempts.
std::vector<SphereSeed> random_spheres(std::size_t count, double r_min, double r_max,
                                       const Vec3& region_min, const Vec3& region_max,
                                       const std::vector<SphereSeed>& existing,
                                       const std::vector<Obstacle>& obstacles, const Domain& domain,
                                       std::mt19937_64& rng);

// Simple cubic lattice of the given spacing starting at region_min + r, filling x
// first, then y, then z, at most `max_count` sites (0: no limit).
std::vector<Vec3> lattice_sites(const Vec3& region_min, const Vec3& region_max, double spacing,
                                double radius, std::size_t max_count);

// First pair of spheres (or sphere/obstacle) overlapping by more than `tolerance` x
// the smaller radius, described in words; nullopt when none.
std::optional<std::string> find_overlap(const std::vector<SphereSeed>& spheres,
                                        const std::vector<Obstacle>& obstacles,
                                        const Domain& domain, double tolerance);

}  // namespace sanguis::dem
