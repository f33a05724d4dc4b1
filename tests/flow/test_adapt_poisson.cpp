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

using testing::RefinedPoissonResult;
using testing::solve_refined_manufactured;

void report(const char* name, const RefinedPoissonResult& coarse,
            const RefinedPoissonResult& fine) {
  std::printf(
      "%s: max error %.3e -> %.3e (order %.2f), beside coarse-fine faces %.3e -> %.3e (order "
      "%.2f); %.1fx / %.1fx per V-cycle (%d / %d cycles)\n",
      name, coarse.error, fine.error, std::log2(coarse.error / fine.error), coarse.interface_error,
      fine.interface_error, std::log2(coarse.interface_error / fine.interface_error),
      coarse.report.mean_reduction(), fine.report.mean_reduction(), coarse.report.cycles,
      fine.report.cycles);
}

/// Orders and rates shared by both boundary conditions.
void expect_second_order_and_fast(const RefinedPoissonResult& coarse,
                                  const RefinedPoissonResult& fine) {
  ASSERT_TRUE(coarse.report.converged);
  ASSERT_TRUE(fine.report.converged);
  // Second order: the error falls by 4 when h halves (measured 1.94 and 2.02
  // overall); 1.8 leaves room for the pre-asymptotic mix of two grid sizes.
  EXPECT_GT(std::log2(coarse.error / fine.error), 1.8);
  // The same at the cells beside the coarse-fine faces, where the quadratic
  // ghost interpolation and the flux matching act (first order would be 1).
  EXPECT_GT(std::log2(coarse.interface_error / fine.interface_error), 1.8);
  // The composite V(2,2) cycle: measured 11.6-17.8x per cycle (uniform
  // grids: 14-20x); 10x is the milestone's target.
  EXPECT_GT(coarse.report.mean_reduction(), 10.0);
  EXPECT_GT(fine.report.mean_reduction(), 10.0);
}

TEST(AdaptPoisson, PeriodicSecondOrderAcrossCoarseFineFaces) {
  // 16^3 with the octant at 32^3, then 32^3 with the octant at 64^3.
  const auto coarse = solve_refined_manufactured(true, 1);
  const auto fine = solve_refined_manufactured(true, 2);
  report("periodic", coarse, fine);
  expect_second_order_and_fast(coarse, fine);
}

TEST(AdaptPoisson, DirichletSecondOrderAcrossCoarseFineFaces) {
  const auto coarse = solve_refined_manufactured(false, 1);
  const auto fine = solve_refined_manufactured(false, 2);
  report("Dirichlet", coarse, fine);
  expect_second_order_and_fast(coarse, fine);
}

TEST(AdaptPoisson, TwoThreadsGiveTheOneThreadAnswerBitForBit) {
  // Blocks relax independently within a colour (ghosts are filled before),
  // so the thread count must not change a single bit.
  const auto one = solve_refined_manufactured(true, 1, MPI_COMM_WORLD, 1e-10, 50, 1);
  const auto two = solve_refined_manufactured(true, 1, MPI_COMM_WORLD, 1e-10, 50, 2);
  ASSERT_EQ(one.solution.raw().size(), two.solution.raw().size());
  EXPECT_EQ(one.solution.raw(), two.solution.raw());
  EXPECT_EQ(one.report.cycles, two.report.cycles);
}

}  // namespace
}  // namespace sanguis::flow
