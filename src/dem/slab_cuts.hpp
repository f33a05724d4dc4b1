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

// What a unit of work (a contact) costs along the cut axis, learnt from the threads'
// clocks. The slabs are cut by contact counts, but a contact's cost depends on where it
// is (an element pair whose bounding balls are apart skips GJK; the contacts of shared
// particles pass through the gather) and on how fast each thread's core runs. The box
// along the axis is split into kCells cells, each with a cost factor (1 at first); after
// each cut the time each slab took, against the time its weighted work predicted,
// scales the factors of the cells it covered. The updates compound, so the factors
// resolve the cost within a slab as the cuts move; each is damped (a square root,
// within [1/2, 2]) so that a core's passing stall moves the next cut only so far.
class SlabCostProfile {
 public:
  static constexpr std::size_t kCells = 256;

  SlabCostProfile() = default;
  // Along `axis` of the box [low, high].
  SlabCostProfile(int axis, double low, double high)
      : axis_(axis),
        low_(low),
        width_(std::max((high - low) / static_cast<double>(kCells), 1e-300)),
        factor_(kCells, 1.0) {}

  int axis() const { return axis_; }
  bool empty() const { return factor_.empty(); }
  double factor_at(double coordinate) const {
    const double u = (coordinate - low_) / width_;
    if (!(u > 0.0)) return factor_.front();  // also NaN
    return u >= static_cast<double>(kCells - 1) ? factor_.back()
                                                : factor_[static_cast<std::size_t>(u)];
  }
  // One cut measured: slab b held the coordinates [bound[b], bound[b + 1]), its work
  // weighted by these factors was predicted[b], and it took seconds[b].
  void update(const std::vector<double>& bound, const std::vector<double>& predicted,
              const std::vector<double>& seconds) {
    double total_predicted = 0.0, total_seconds = 0.0;
    for (std::size_t b = 0; b < seconds.size(); ++b) {
      total_predicted += predicted[b];
      total_seconds += seconds[b];
    }
    if (!(total_predicted > 0.0 && total_seconds > 0.0)) return;
    for (std::size_t b = 0; b < seconds.size(); ++b) {
      if (!(predicted[b] > 0.0)) continue;  // no work there: nothing learnt
      const double ratio = (seconds[b] / total_seconds) / (predicted[b] / total_predicted);
      const double scale = std::clamp(std::sqrt(ratio), 0.5, 2.0);
      for (std::size_t c = 0; c < kCells; ++c) {
        const double centre = low_ + (static_cast<double>(c) + 0.5) * width_;
        if (centre >= bound[b] && centre < bound[b + 1]) factor_[c] *= scale;
      }
    }
    // Only ratios matter; keep the factors near 1.
    double mean = 0.0;
    for (const double f : factor_) mean += f;
    mean /= static_cast<double>(kCells);
    for (double& f : factor_) f = std::clamp(f / mean, 1e-3, 1e3);
  }

 private:
  int axis_ = -1;
  double low_ = 0.0, width_ = 1.0;
  std::vector<double> factor_;
};

}  // namespace sanguis::dem
