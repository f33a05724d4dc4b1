#pragma once
// Cutting a line of particles into slabs of equal work: a histogram along one axis and
// the bins where each slab starts. Shared by the MPI decomposition (slabs per process,
// from a histogram summed over the processes) and the threaded force loop (slabs per
// thread).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "core/vec3.hpp"

namespace sanguis::dem {

// The bin of `coordinate` among `bins` equal bins over [lo, lo + length); outside values
// go to the end bins, a non-finite one (a blown-up particle) to the first.
inline std::size_t axis_bin(double coordinate, double lo, double length, std::size_t bins) {
  const double u = (coordinate - lo) / length * static_cast<double>(bins);
  if (!(u > 0.0)) return 0;  // also NaN
  return u >= static_cast<double>(bins - 1) ? bins - 1 : static_cast<std::size_t>(u);
}

// The box around points, and the axis along which they spread furthest (a column in a
// long channel is cut across its height, not along the empty channel).
struct Extent {
  Vec3 low, high;
  // Empty: low above high (the first point sets both).
  static Extent empty_in(const Vec3& box_min, const Vec3& box_max) { return {box_max, box_min}; }
  void add(const Vec3& x) {
    for (int k = 0; k < 3; ++k) {
      low[k] = std::min(low[k], x[k]);
      high[k] = std::max(high[k], x[k]);
    }
  }
  int longest_axis() const {
    int axis = 0;
    for (int k = 1; k < 3; ++k) {
      if (high[k] - low[k] > high[axis] - low[axis]) axis = k;
    }
    return axis;
  }
};

// parts + 1 bin indices: part k holds the bins [cut[k], cut[k + 1]), each part about
// 1 / parts of the histogram's weight (a part ends after the bin that reaches its share).
template <typename Count>
std::vector<std::size_t> equal_weight_cuts(const std::vector<Count>& histogram, std::size_t parts) {
  Count total = 0;
  for (Count c : histogram) total += c;
  std::vector<std::size_t> cut(parts + 1, histogram.size());
  cut[0] = 0;
  Count seen = 0;
  std::size_t next = 1;
  for (std::size_t b = 0; b < histogram.size() && next < parts; ++b) {
    seen += histogram[b];
    while (next < parts && seen * static_cast<Count>(parts) >= total * static_cast<Count>(next)) {
      cut[next++] = b + 1;
    }
  }
  return cut;
}

}  // namespace sanguis::dem
