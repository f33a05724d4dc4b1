#pragma once
// The simulation box: bounds used by the linked-cell grid, and periodicity per
// axis. Along a periodic axis, positions are wrapped into [min, max) and
// separations use the minimum image.
#include <array>
#include <cmath>

#include "core/vec3.hpp"

namespace sanguis::dem {

struct Domain {
  Vec3 min, max;
  std::array<bool, 3> periodic{false, false, false};

  Vec3 length() const { return max - min; }

  // Minimum image of a separation that is at most 1.5 box lengths long (true between two
  // neighbour-list builds, which wrap positions): a compare and a subtraction per axis,
  // no rounding call in the contact loop.
  [[gnu::always_inline]] Vec3 near_image(Vec3 d) const {
    for (int k = 0; k < 3; ++k) {
      if (periodic[static_cast<std::size_t>(k)]) {
        const double l = max[k] - min[k];
        if (d[k] > 0.5 * l) {
          d[k] -= l;
        } else if (d[k] < -0.5 * l) {
          d[k] += l;
        }
      }
    }
    return d;
  }

  Vec3 minimum_image(Vec3 d) const {
    for (int k = 0; k < 3; ++k) {
      if (periodic[static_cast<std::size_t>(k)]) {
        const double l = max[k] - min[k];
        d[k] -= l * std::nearbyint(d[k] / l);
      }
    }
    return d;
  }

  void wrap(Vec3& x) const {
    for (int k = 0; k < 3; ++k) {
      if (periodic[static_cast<std::size_t>(k)]) {
        const double l = max[k] - min[k];
        if (x[k] < min[k] || x[k] >= max[k]) {
          x[k] -= l * std::floor((x[k] - min[k]) / l);
          if (x[k] >= max[k]) x[k] = min[k];  // round-off at the upper edge
        }
      }
    }
  }
};

}  // namespace sanguis::dem
