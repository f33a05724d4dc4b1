#pragma once
// The fit behind `sanguis calibrate`: the parameter value at which a measured
// quantity (mean over seeds, per grid value) reaches a target.
#include <cstddef>
#include <vector>

namespace sanguis::dem::analysis {

struct CalibrationFit {
  double value = 0.0;  ///< the parameter estimate (NaN-free only when the fit means something)
  double std = 0.0;    ///< its standard uncertainty (NaN when nothing measures it)
  double slope = 0.0;  ///< d measure / d parameter of the fitted line
  /// The target lies between two neighbouring grid values' measures.
  bool bracketed = false;
  /// Not bracketed, and no line can locate a crossing: the measure is nearest
  /// the target at an inner grid value (the curve turns there without
  /// reaching it), or the line at the nearer end is flat or points back into
  /// the range. `value` is then the nearest grid value, `std` and `slope` NaN.
  bool turns = false;
  std::size_t closest = 0;  ///< index of the grid value whose measure is nearest the target
};

/// Solves m(v) = target with a weighted straight line m = a + b v through the
/// grid values around the first crossing of the target by the mean curve
/// (`v` increasing; the bracketing pair alone when the wider line meets the
/// target outside it); extrapolates from the end nearer the target when no
/// pair brackets it, unless the curve turns (see CalibrationFit::turns). The
/// uncertainty propagates the line's covariance and the target's spread.
/// With `replicates` the points weigh 1/sem^2; without (one run per value)
/// they weigh the same and their scatter about the line stands for the noise
/// (NaN with two points: nothing measures it).
CalibrationFit fit_crossing(const std::vector<double>& v, const std::vector<double>& mean,
                            const std::vector<double>& sem, bool replicates, double target,
                            double target_std);

}  // namespace sanguis::dem::analysis
