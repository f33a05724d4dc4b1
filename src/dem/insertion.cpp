#include "dem/insertion.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

namespace sanguis::dem {

namespace {

// Hash grid of placed spheres for O(1) overlap checks during insertion. Along a
// periodic axis the cell index wraps, so images across the boundary are found.
class SphereHash {
 public:
  SphereHash(double cell, const Domain& domain) : domain_(domain) {
    for (std::size_t k = 0; k < 3; ++k) {
      size_[k] = cell;
      const int ki = static_cast<int>(k);
      if (domain.periodic[k]) {
        const double length = domain.max[ki] - domain.min[ki];
        wrap_[k] = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::floor(length / cell)));
        size_[k] = length / static_cast<double>(wrap_[k]);
      }
    }
  }

  void add(const SphereSeed& s, std::size_t index) {
    cells_[key(cell_index(s.position))].push_back(index);
  }

  template <typename F>
  bool any_near(const Vec3& x, F&& overlaps) const {
    const auto c = cell_index(x);
    std::array<std::int64_t, 27> seen{};
    int n_seen = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const std::uint64_t k = key(wrapped({c[0] + dx, c[1] + dy, c[2] + dz}));
          // With fewer than 3 cells along a periodic axis two offsets hit one cell.
          bool duplicate = false;
          for (int s = 0; s < n_seen; ++s)
            duplicate |= seen[static_cast<std::size_t>(s)] == static_cast<std::int64_t>(k);
          if (duplicate) continue;
          seen[static_cast<std::size_t>(n_seen++)] = static_cast<std::int64_t>(k);
          auto it = cells_.find(k);
          if (it == cells_.end()) continue;
          for (std::size_t j : it->second)
            if (overlaps(j)) return true;
        }
    return false;
  }

 private:
  std::array<std::int64_t, 3> wrapped(std::array<std::int64_t, 3> c) const {
    for (std::size_t k = 0; k < 3; ++k) {
      if (wrap_[k] > 0) c[k] = ((c[k] % wrap_[k]) + wrap_[k]) % wrap_[k];
    }
    return c;
  }
  std::array<std::int64_t, 3> cell_index(const Vec3& x) const {
    std::array<std::int64_t, 3> c{};
    for (std::size_t k = 0; k < 3; ++k) {
      const int ki = static_cast<int>(k);
      c[k] = static_cast<std::int64_t>(std::floor((x[ki] - domain_.min[ki]) / size_[k]));
    }
    return wrapped(c);
  }
  static std::uint64_t key(const std::array<std::int64_t, 3>& c) {
    const auto h = [](std::int64_t v) {
      return static_cast<std::uint64_t>(v + (1 << 20)) & 0x1FFFFF;
    };
    return (h(c[2]) << 42) | (h(c[1]) << 21) | h(c[0]);
  }

  Domain domain_;
  std::array<double, 3> size_{};
  std::array<std::int64_t, 3> wrap_{0, 0, 0};  // number of cells along periodic axes, else 0
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells_;
};

bool overlaps_obstacle(const Vec3& x, double r, const std::vector<Obstacle>& obstacles) {
  for (const Obstacle& o : obstacles) {
    if (o.active(0.0) && sphere_gap(o, 0.0, x, r).overlap > 0.0) return true;
  }
  return false;
}

}  // namespace

std::vector<SphereSeed> random_spheres(std::size_t count, double r_min, double r_max,
                                       const Vec3& region_min, const Vec3& region_max,
                                       const std::vector<SphereSeed>& existing,
                                       const std::vector<Obstacle>& obstacles, const Domain& domain,
                                       std::mt19937_64& rng) {
  for (int k = 0; k < 3; ++k) {
    if (region_max[k] - region_min[k] < 2.0 * r_max) {
      throw std::runtime_error("region is thinner than one particle diameter");
    }
  }
  std::vector<SphereSeed> all = existing;
  SphereHash hash(2.0 * r_max, domain);
  for (std::size_t i = 0; i < all.size(); ++i) hash.add(all[i], i);

  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const std::size_t max_attempts = 2000 * count + 10000;
  std::size_t attempts = 0, placed = 0;
  while (placed < count) {
    if (++attempts > max_attempts) {
      std::ostringstream msg;
      msg << "could place only " << placed << " of " << count
          << " non-overlapping particles in the region (too dense for random insertion; "
             "enlarge the region or use a lattice)";
      throw std::runtime_error(msg.str());
    }
    SphereSeed s;
    s.radius = r_min + (r_max - r_min) * unit(rng);
    for (int k = 0; k < 3; ++k) {
      s.position[k] =
          region_min[k] + s.radius + (region_max[k] - region_min[k] - 2 * s.radius) * unit(rng);
    }
    const bool blocked = hash.any_near(s.position, [&](std::size_t j) {
      const Vec3 d = domain.minimum_image(all[j].position - s.position);
      const double cut = all[j].radius + s.radius;
      return norm2(d) < cut * cut;
    });
    if (blocked || overlaps_obstacle(s.position, s.radius, obstacles)) continue;
    hash.add(s, all.size());
    all.push_back(s);
    ++placed;
  }
  return {all.begin() + static_cast<std::ptrdiff_t>(existing.size()), all.end()};
}

std::vector<Vec3> lattice_sites(const Vec3& region_min, const Vec3& region_max, double spacing,
                                double radius, std::size_t max_count) {
  std::vector<Vec3> sites;
  std::array<std::int64_t, 3> n{};
  for (int k = 0; k < 3; ++k) {
    const double room = region_max[k] - region_min[k] - 2.0 * radius;
    n[static_cast<std::size_t>(k)] =
        room < 0 ? 0 : static_cast<std::int64_t>(std::floor(room / spacing + 1e-9)) + 1;
  }
  for (std::int64_t iz = 0; iz < n[2]; ++iz)
    for (std::int64_t iy = 0; iy < n[1]; ++iy)
      for (std::int64_t ix = 0; ix < n[0]; ++ix) {
        if (max_count > 0 && sites.size() >= max_count) return sites;
        sites.push_back({region_min.x + radius + spacing * static_cast<double>(ix),
                         region_min.y + radius + spacing * static_cast<double>(iy),
                         region_min.z + radius + spacing * static_cast<double>(iz)});
      }
  return sites;
}

std::optional<std::string> find_overlap(const std::vector<SphereSeed>& spheres,
                                        const std::vector<Obstacle>& obstacles,
                                        const Domain& domain, double tolerance) {
  double r_max = 0.0;
  for (const auto& s : spheres) r_max = std::max(r_max, s.radius);
  SphereHash hash(2.0 * r_max, domain);
  std::optional<std::string> found;
  for (std::size_t i = 0; i < spheres.size() && !found; ++i) {
    const SphereSeed& s = spheres[i];
    hash.any_near(s.position, [&](std::size_t j) {
      const Vec3 d = domain.minimum_image(spheres[j].position - s.position);
      const double overlap = spheres[j].radius + s.radius - norm(d);
      if (overlap > tolerance * std::min(s.radius, spheres[j].radius)) {
        std::ostringstream msg;
        msg << "particles " << j << " and " << i << " overlap by " << overlap << " m";
        found = msg.str();
        return true;
      }
      return false;
    });
    hash.add(s, i);
    for (const Obstacle& o : obstacles) {
      if (!found && o.active(0.0) &&
          sphere_gap(o, 0.0, s.position, s.radius).overlap > tolerance * s.radius) {
        found = "particle " + std::to_string(i) + " overlaps obstacle '" + o.name + "'";
      }
    }
  }
  return found;
}

}  // namespace sanguis::dem
