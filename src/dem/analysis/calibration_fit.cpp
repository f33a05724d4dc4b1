#include "dem/analysis/calibration_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace sanguis::dem::analysis {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Line {
  double value, std, slope;  // where it meets the target, its uncertainty, its slope
};

// The weighted straight line m = a + b v through the points lo..hi and where
// it meets the target (see fit_crossing).
Line line_through(const std::vector<double>& v, const std::vector<double>& mean,
                  const std::vector<double>& sem, bool replicates, std::size_t lo, std::size_t hi,
                  double target, double target_std) {
  double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t k = lo; k <= hi; ++k) {
    const double w =
        replicates ? 1.0 / std::max(sem[k] * sem[k], 1e-12 * (1.0 + mean[k] * mean[k])) : 1.0;
    sw += w;
    sx += w * v[k];
    sy += w * mean[k];
    sxx += w * v[k] * v[k];
    sxy += w * v[k] * mean[k];
  }
  const double det = sw * sxx - sx * sx;
  const double b = (sw * sxy - sx * sy) / det;
  const double a = (sy - b * sx) / sw;
  double scale = 1.0;  // the variance of one point, in units of 1/w
  if (!replicates) {
    double squares = 0.0;
    for (std::size_t k = lo; k <= hi; ++k) squares += std::pow(mean[k] - a - b * v[k], 2);
    const double points = static_cast<double>(hi - lo + 1);
    scale = points > 2 ? squares / (points - 2) : kNaN;
  }
  const double var_a = scale * sxx / det, var_b = scale * sw / det, cov_ab = -scale * sx / det;
  Line line{(target - a) / b, kNaN, b};
  // v* = (t - a) / b: derivatives -1/b (a), -(t - a)/b^2 (b), 1/b (t).
  const double da = -1.0 / b, db = -(target - a) / (b * b), dt = 1.0 / b;
  const double variance =
      da * da * var_a + db * db * var_b + 2 * da * db * cov_ab + dt * dt * target_std * target_std;
  // NaN stays NaN (std::max would turn it into 0): nothing measured the noise.
  if (!std::isnan(variance)) line.std = std::sqrt(std::max(0.0, variance));
  return line;
}

}  // namespace

CalibrationFit fit_crossing(const std::vector<double>& v, const std::vector<double>& mean,
                            const std::vector<double>& sem, bool replicates, double target,
                            double target_std) {
  if (v.size() < 2 || mean.size() != v.size() || sem.size() != v.size()) {
    throw std::invalid_argument("fit_crossing: needs two or more values, one mean and sem each");
  }
  CalibrationFit fit;
  for (std::size_t k = 1; k < v.size(); ++k) {
    if (std::abs(mean[k] - target) < std::abs(mean[fit.closest] - target)) fit.closest = k;
  }
  const auto nearest = [&] {  // no crossing a line can locate: the nearest grid value
    fit.turns = true;
    fit.value = v[fit.closest];
    fit.std = kNaN;
    fit.slope = kNaN;
    return fit;
  };
  std::size_t cross = v.size();
  for (std::size_t k = 0; k + 1 < v.size(); ++k) {
    if ((mean[k] - target) * (mean[k + 1] - target) <= 0) {
      cross = k;
      break;
    }
  }
  fit.bracketed = cross < v.size();
  if (!fit.bracketed && fit.closest > 0 && fit.closest + 1 < v.size()) return nearest();
  if (!fit.bracketed) cross = fit.closest == 0 ? 0 : v.size() - 2;  // the nearer end
  const std::size_t lo = cross > 0 ? cross - 1 : 0;
  const std::size_t hi = std::min(v.size() - 1, cross + 2);
  Line line = line_through(v, mean, sem, replicates, lo, hi, target, target_std);
  if (fit.bracketed) {
    // A line through a window that holds a turn can meet the target outside
    // the bracketing pair: then the pair alone.
    if (!(line.value >= v[cross] && line.value <= v[cross + 1])) {
      line = line_through(v, mean, sem, replicates, cross, cross + 1, target, target_std);
    }
    if (mean[cross] == target) line.value = v[cross];  // also a flat pair on the target
  } else {
    // Extrapolation must land beyond the nearer end; a flat or turning window does not.
    const bool beyond = fit.closest == 0 ? line.value < v.front() : line.value > v.back();
    if (!std::isfinite(line.value) || !beyond) return nearest();
  }
  fit.value = line.value;
  fit.std = line.std;
  fit.slope = line.slope;
  return fit;
}

}  // namespace sanguis::dem::analysis
