#include "dem/analysis/calibration_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace sanguis::dem::analysis {

CalibrationFit fit_crossing(const std::vector<double>& v, const std::vector<double>& mean,
                            const std::vector<double>& sem, bool replicates, double target,
                            double target_std) {
  if (v.size() < 2 || mean.size() != v.size() || sem.size() != v.size()) {
    throw std::invalid_argument("fit_crossing: needs two or more values, one mean and sem each");
  }
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  CalibrationFit fit;
  for (std::size_t k = 1; k < v.size(); ++k) {
    if (std::abs(mean[k] - target) < std::abs(mean[fit.closest] - target)) fit.closest = k;
  }
  std::size_t cross = v.size();
  for (std::size_t k = 0; k + 1 < v.size(); ++k) {
    if ((mean[k] - target) * (mean[k + 1] - target) <= 0) {
      cross = k;
      break;
    }
  }
  fit.bracketed = cross < v.size();
  if (!fit.bracketed) {
    fit.turns = fit.closest > 0 && fit.closest + 1 < v.size();
    if (fit.turns) {
      fit.value = v[fit.closest];
      fit.std = kNaN;
      fit.slope = kNaN;
      return fit;
    }
    cross = fit.closest == 0 ? 0 : v.size() - 2;  // extrapolate from the nearer end
  }
  const std::size_t lo = cross > 0 ? cross - 1 : 0;
  const std::size_t hi = std::min(v.size() - 1, cross + 2);
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
  fit.slope = b;
  fit.value = (target - a) / b;
  // v* = (t - a) / b: derivatives -1/b (a), -(t - a)/b^2 (b), 1/b (t).
  const double da = -1.0 / b, db = -(target - a) / (b * b), dt = 1.0 / b;
  const double variance =
      da * da * var_a + db * db * var_b + 2 * da * db * cov_ab + dt * dt * target_std * target_std;
  // NaN stays NaN (std::max would turn it into 0): nothing measured the noise.
  fit.std = std::isnan(variance) ? kNaN : std::sqrt(std::max(0.0, variance));
  return fit;
}

}  // namespace sanguis::dem::analysis
