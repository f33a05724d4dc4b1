#pragma once
// Reordering arrays in place by a permutation (the particle storage sort reorders every
// per-particle and per-contact array with one permutation).
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace sanguis {

// values[k] = old values[order[k]] (`order` a permutation of 0..size-1), in place, cycle
// by cycle: no copy of the array. `visited` is scratch, reused across calls.
template <typename T>
void permute_in_place(std::vector<T>& values, std::span<const std::uint32_t> order,
                      std::vector<std::uint8_t>& visited) {
  visited.assign(order.size(), 0);
  for (std::size_t start = 0; start < order.size(); ++start) {
    if (visited[start]) continue;
    T held = values[start];
    std::size_t k = start;
    while (true) {
      visited[k] = 1;
      const std::size_t from = order[k];
      if (from == start) {
        values[k] = held;
        break;
      }
      values[k] = values[from];
      k = from;
    }
  }
}

}  // namespace sanguis
