// Poisson on a statically refined forest (issue #7): the composite operator
// with flux matching at coarse-fine faces converges at second order across
// the interface, and the multigrid reduces the residual by a fixed factor
// per V-cycle.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "adapt_poisson.hpp"

namespace sanguis::flow {
namespace {

using testing::solve_refined_manufactured;

void report(const char* name, const testing::PoissonResult& coarse,
            const testing::PoissonResult& fine) {
  std::printf(
      "%s: max error %.3e -> %.3e (order %.2f); %.1fx / %.1fx per V-cycle (%d / %d cycles)\n", name,
      coarse.error, fine.error, std::log2(coarse.error / fine.error),
      coarse.report.mean_reduction(), fine.report.mean_reduction(), coarse.report.cycles,
      fine.report.cycles);
}

TEST(AdaptPoisson, PeriodicSecondOrderAcrossCoarseFineFaces) {
  // 16^3 with the octant at 32^3, then 32^3 with the octant at 64^3.
  const auto coarse = solve_refined_manufactured(true, 1);
  const auto fine = solve_refined_manufactured(true, 2);
  report("periodic", coarse, fine);
  ASSERT_TRUE(coarse.report.converged);
  ASSERT_TRUE(fine.report.converged);
  // Second order: the error falls by 4 when h halves; 1.8 leaves room for the
  // pre-asymptotic mix of the two grid sizes.
  EXPECT_GT(std::log2(coarse.error / fine.error), 1.8);
  EXPECT_GT(fine.report.mean_reduction(), 10.0);
}

TEST(AdaptPoisson, DirichletSecondOrderAcrossCoarseFineFaces) {
  const auto coarse = solve_refined_manufactured(false, 1);
  const auto fine = solve_refined_manufactured(false, 2);
  report("Dirichlet", coarse, fine);
  ASSERT_TRUE(coarse.report.converged);
  ASSERT_TRUE(fine.report.converged);
  EXPECT_GT(std::log2(coarse.error / fine.error), 1.8);
  EXPECT_GT(fine.report.mean_reduction(), 10.0);
}

}  // namespace
}  // namespace sanguis::flow
