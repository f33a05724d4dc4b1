// Cutting work into slabs of equal weight, and the cost profile the threads' clocks
// teach (dem/slab_cuts.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "dem/slab_cuts.hpp"

namespace sanguis::dem {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(SlabCuts, EqualWeightCutsSplitAtTheHalfOfTheWeight) {
  const std::vector<double> work(100, 1.0);
  const std::vector<std::size_t> cut = equal_weight_cuts(work, 2);
  ASSERT_EQ(cut.size(), 3u);
  EXPECT_EQ(cut[0], 0u);
  EXPECT_EQ(cut[1], 50u);
  EXPECT_EQ(cut[2], 100u);
}

TEST(SlabCuts, ProfileStartsFlatAndLearnsWhichSlabWasSlow) {
  SlabCostProfile profile(2, 0.0, 1.0);
  EXPECT_EQ(profile.axis(), 2);
  EXPECT_DOUBLE_EQ(profile.factor_at(0.1), 1.0);
  EXPECT_DOUBLE_EQ(profile.factor_at(0.9), 1.0);
  // Two slabs predicted equal; the lower one took three times as long.
  profile.update({-kInf, 0.5, kInf}, {1.0, 1.0}, {3.0, 1.0});
  const double low = profile.factor_at(0.25), high = profile.factor_at(0.75);
  // Damped: the square root of the measured ratio 3.
  EXPECT_NEAR(low / high, std::sqrt(3.0), 1e-12);
  EXPECT_DOUBLE_EQ(profile.factor_at(0.0), low);
  EXPECT_DOUBLE_EQ(profile.factor_at(0.499), low);
  EXPECT_DOUBLE_EQ(profile.factor_at(0.501), high);
  // Outside the box: the end cells.
  EXPECT_DOUBLE_EQ(profile.factor_at(-5.0), low);
  EXPECT_DOUBLE_EQ(profile.factor_at(5.0), high);
  EXPECT_DOUBLE_EQ(profile.factor_at(std::nan("")), low);
}

TEST(SlabCuts, UpdatesCompoundAndResolveTheCostWithinASlab) {
  SlabCostProfile profile(0, 0.0, 1.0);
  profile.update({-kInf, 0.5, kInf}, {1.0, 1.0}, {4.0, 1.0});  // x < 0.5 slow: ratio 4
  // The next cut measured [0, 0.25) against the rest as predicted: nothing changes
  // there; then the quarter [0.25, 0.5) alone turns out slow.
  profile.update({-kInf, 0.25, kInf}, {1.0, 3.0}, {1.0, 3.0});
  EXPECT_NEAR(profile.factor_at(0.1) / profile.factor_at(0.9), 2.0, 1e-12);
  profile.update({-kInf, 0.25, 0.5, kInf}, {1.0, 1.0, 1.0}, {1.0, 4.0, 1.0});
  EXPECT_NEAR(profile.factor_at(0.3) / profile.factor_at(0.1), 2.0, 1e-12);
  EXPECT_NEAR(profile.factor_at(0.1) / profile.factor_at(0.9), 2.0, 1e-12);
}

TEST(SlabCuts, OneStallMovesTheProfileOnlySoFar) {
  SlabCostProfile profile(1, 0.0, 1.0);
  // The lower slab was given a tenth of the work and took all the time (ratio 10 and
  // nearly 0): each slab's factor moves by at most 2x per update.
  profile.update({-kInf, 0.5, kInf}, {1.0, 9.0}, {1e6, 1e-6});
  EXPECT_NEAR(profile.factor_at(0.25) / profile.factor_at(0.75), 4.0, 1e-12);
}

TEST(SlabCuts, NothingMeasuredTeachesNothing) {
  SlabCostProfile profile(1, 0.0, 1.0);
  profile.update({-kInf, 0.5, kInf}, {1.0, 1.0}, {0.0, 0.0});
  profile.update({-kInf, 0.5, kInf}, {0.0, 0.0}, {1.0, 2.0});
  EXPECT_DOUBLE_EQ(profile.factor_at(0.25), 1.0);
  EXPECT_DOUBLE_EQ(profile.factor_at(0.75), 1.0);
  EXPECT_TRUE(SlabCostProfile{}.empty());
}

TEST(SlabCuts, WeightedWorkMovesTheCutAwayFromTheSlowSide) {
  SlabCostProfile profile(2, 0.0, 1.0);
  // The lower half took 3x the time of the upper: damped, it now weighs k = sqrt(3)
  // times as much per unit of work.
  profile.update({-kInf, 0.5, kInf}, {1.0, 1.0}, {3.0, 1.0});
  std::vector<double> work(1000, 1.0);
  for (std::size_t k = 0; k < work.size(); ++k) work[k] *= profile.factor_at((k + 0.5) / 1000.0);
  const std::vector<std::size_t> cut = equal_weight_cuts(work, 2);
  // Equal weight on both sides of the cut x: k x = k (0.5 - x) + 0.5.
  const double k = std::sqrt(3.0);
  EXPECT_NEAR(static_cast<double>(cut[1]) / 1000.0, (0.5 * k + 0.5) / (2.0 * k), 2e-3);
}

}  // namespace
}  // namespace sanguis::dem
