#include "core/permutation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

namespace sanguis {
namespace {

TEST(Permutation, InPlaceMatchesACopyingGatherOnRandomPermutations) {
  std::mt19937_64 rng(7);
  std::vector<std::uint8_t> visited;
  for (std::size_t n : {0u, 1u, 2u, 7u, 1000u}) {
    std::vector<std::uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    std::shuffle(order.begin(), order.end(), rng);
    std::vector<long> values(n);
    for (std::size_t k = 0; k < n; ++k) values[k] = 10 * static_cast<long>(k) + 3;
    std::vector<long> expected(n);
    for (std::size_t k = 0; k < n; ++k) expected[k] = values[order[k]];
    permute_in_place(values, order, visited);
    EXPECT_EQ(values, expected) << n << " values";
  }
}

TEST(Permutation, IdentityAndOneCycle) {
  std::vector<std::uint8_t> visited;
  std::vector<int> v{10, 11, 12, 13};
  permute_in_place(v, std::vector<std::uint32_t>{0, 1, 2, 3}, visited);
  EXPECT_EQ(v, (std::vector<int>{10, 11, 12, 13}));
  permute_in_place(v, std::vector<std::uint32_t>{1, 2, 3, 0}, visited);
  EXPECT_EQ(v, (std::vector<int>{11, 12, 13, 10}));
}

}  // namespace
}  // namespace sanguis
