// The fit behind `sanguis calibrate`: crossing of a target by a measured curve.
#include "dem/analysis/calibration_fit.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace sanguis::dem::analysis {
namespace {

const std::vector<double> kNoSem(4, 0.0);

TEST(CalibrationFit, ALineThroughTheRunsCrossesTheTargetWhereTheLineDoes) {
  const std::vector<double> v{1, 2, 3, 4}, m{8, 6, 4, 2};  // m = 10 - 2 v
  const CalibrationFit fit = fit_crossing(v, m, kNoSem, false, 5.0, 0.0);
  EXPECT_TRUE(fit.bracketed);
  EXPECT_FALSE(fit.turns);
  EXPECT_NEAR(fit.value, 2.5, 1e-12);
  EXPECT_NEAR(fit.slope, -2.0, 1e-12);
  EXPECT_NEAR(fit.std, 0.0, 1e-9);  // no scatter about the line, an exact target
}

TEST(CalibrationFit, ScatterAboutTheLineGivesTheUncertaintyAndTwoPointsGiveNone) {
  const std::vector<double> v{1, 2, 3, 4}, m{8.1, 5.9, 4.1, 1.9};
  const CalibrationFit fit = fit_crossing(v, m, kNoSem, false, 5.0, 0.0);
  EXPECT_TRUE(fit.bracketed);
  EXPECT_GT(fit.std, 0.0);
  EXPECT_LT(fit.std, 0.2);
  const CalibrationFit two = fit_crossing({1, 2}, {8, 6}, {0, 0}, false, 7.0, 0.0);
  EXPECT_NEAR(two.value, 1.5, 1e-12);
  EXPECT_TRUE(std::isnan(two.std));
}

TEST(CalibrationFit, ATargetBeyondAMonotoneCurveIsExtrapolatedFromTheNearerEnd) {
  const std::vector<double> v{1, 2, 3, 4}, m{8, 6, 4, 2};
  const CalibrationFit fit = fit_crossing(v, m, kNoSem, false, 0.0, 0.0);
  EXPECT_FALSE(fit.bracketed);
  EXPECT_FALSE(fit.turns);
  EXPECT_EQ(fit.closest, 3u);
  EXPECT_NEAR(fit.value, 5.0, 1e-12);
}

// The crosses' run-out against gamma_t at kt 1e2 (validation/dem/
// crosses_recalibrated.py): lowest near 2e3 1/s, above the target 5.86 there,
// and rising on both sides. A line through the last three points would
// "extrapolate" to 5.7e3, where the run-out is 7.86.
TEST(CalibrationFit, ACurveThatTurnsBeforeTheTargetGivesItsNearestValueNotALine) {
  const std::vector<double> v{1000, 1400, 2000, 3000}, m{7.0, 6.586, 6.172, 6.310};
  const CalibrationFit fit = fit_crossing(v, m, kNoSem, false, 5.8586, 0.0);
  EXPECT_FALSE(fit.bracketed);
  EXPECT_TRUE(fit.turns);
  EXPECT_EQ(fit.closest, 2u);
  EXPECT_EQ(fit.value, 2000.0);
  EXPECT_TRUE(std::isnan(fit.std));
}

TEST(CalibrationFit, AFlatOrTurningEndGivesTheNearestValueNotAnInfiniteOne) {
  // Flat: every run the same.
  const CalibrationFit flat = fit_crossing({1, 2, 3}, {6, 6, 6}, {0, 0, 0}, false, 8.0, 0.0);
  EXPECT_TRUE(flat.turns);
  EXPECT_EQ(flat.value, 1.0);
  // Nearest at the end, but the window around it turns: no extrapolation back into the range.
  const CalibrationFit back = fit_crossing({1, 2, 3}, {7, 6, 7}, {0, 0, 0}, false, 8.0, 0.0);
  EXPECT_TRUE(back.turns);
  EXPECT_TRUE(std::isfinite(back.value));
  EXPECT_EQ(back.value, 1.0);
}

TEST(CalibrationFit, ATurnNextToTheBracketingPairDoesNotPullTheEstimateOutOfIt) {
  // Crosses 6 between v = 1 (7) and v = 2 (5.5); the line through 7, 5.5, 6.5
  // would meet 6 far beyond v = 2. The pair alone gives 1 + 1/1.5.
  const CalibrationFit fit =
      fit_crossing({1, 2, 3, 4}, {7, 5.5, 6.5, 7.5}, {0, 0, 0, 0}, false, 6.0, 0.0);
  EXPECT_TRUE(fit.bracketed);
  EXPECT_NEAR(fit.value, 1.0 + 1.0 / 1.5, 1e-12);
  // A target met exactly at a grid value.
  const CalibrationFit exact = fit_crossing({1, 2, 3}, {7, 6, 5}, {0, 0, 0}, false, 6.0, 0.0);
  EXPECT_TRUE(exact.bracketed);
  EXPECT_NEAR(exact.value, 2.0, 1e-12);
}

TEST(CalibrationFit, FewerThanTwoValuesAreRefused) {
  EXPECT_THROW(fit_crossing({1.0}, {2.0}, {0.0}, false, 1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(fit_crossing({1.0, 2.0}, {2.0}, {0.0, 0.0}, false, 1.0, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace sanguis::dem::analysis
