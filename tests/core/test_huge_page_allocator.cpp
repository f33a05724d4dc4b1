#include "core/huge_page_allocator.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <vector>

namespace sanguis {
namespace {

using HugeVector = std::vector<double, HugePageAllocator<double>>;

TEST(HugePageAllocator, LargeArraysStartOnAHugePageAndHoldTheirValues) {
  const std::size_t n = HugePageAllocator<double>::kThreshold / sizeof(double) + 12345;
  HugeVector values(n, 0.0);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(values.data()) % HugePageAllocator<double>::kHugePage,
            0u);
  std::iota(values.begin(), values.end(), 0.0);
  EXPECT_EQ(values.front(), 0.0);
  EXPECT_EQ(values.back(), static_cast<double>(n - 1));
  // Growing past the capacity moves the values to a new (also aligned) array.
  values.resize(2 * n, -1.0);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(values.data()) % HugePageAllocator<double>::kHugePage,
            0u);
  EXPECT_EQ(values[n - 1], static_cast<double>(n - 1));
  EXPECT_EQ(values[n], -1.0);
}

TEST(HugePageAllocator, SmallArraysBehaveAsWithTheStandardAllocator) {
  HugeVector small(100, 2.5);
  EXPECT_EQ(small.size(), 100u);
  EXPECT_EQ(small[99], 2.5);
  small.assign(1000, 1.0);  // still below the threshold
  EXPECT_EQ(small[999], 1.0);
  // Across the threshold both ways: each array is freed by the path that made it.
  small.resize(HugePageAllocator<double>::kThreshold / sizeof(double), 3.0);
  HugeVector copy(small.begin(), small.begin() + 10);
  small = copy;
  small.shrink_to_fit();
  EXPECT_EQ(small.size(), 10u);
  EXPECT_EQ(small[0], 1.0);
}

TEST(HugePageAllocator, ContainersOfItCompareEqual) {
  EXPECT_TRUE(HugePageAllocator<double>{} == HugePageAllocator<int>{});
  HugeVector a(5, 1.0), b(5, 1.0);
  EXPECT_EQ(a, b);
}

}  // namespace
}  // namespace sanguis
