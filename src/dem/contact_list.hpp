#pragma once
// Candidate contacts found by the broad phase (within cut-off + skin), sorted by
// (first, second), each with the memory of its contact (ContactHistory). When the
// list is rebuilt the histories of pairs that are still candidates are carried
// over, so a rebuild never erases memory (see NeighborSearch::rebuild).
#include <cstdint>
#include <vector>

#include "dem/contact_law.hpp"

namespace sanguis::dem {

struct ContactList {
  std::vector<std::uint32_t> first;   // particle index
  std::vector<std::uint32_t> second;  // particle index (> first) or obstacle index
  std::vector<ContactHistory> history;

  std::size_t size() const { return first.size(); }
  void clear() {
    first.clear();
    second.clear();
    history.clear();
  }
  void push(std::uint32_t a, std::uint32_t b, const ContactHistory& h) {
    first.push_back(a);
    second.push_back(b);
    history.push_back(h);
  }
};

// Copies the histories of `previous` into `fresh` for the keys present in both.
// Both lists must be sorted by (first, second).
inline void carry_history(const ContactList& previous, ContactList& fresh) {
  std::size_t p = 0;
  const std::size_t np = previous.size();
  for (std::size_t k = 0; k < fresh.size() && p < np; ++k) {
    const std::uint64_t key = (std::uint64_t{fresh.first[k]} << 32) | fresh.second[k];
    while (p < np && ((std::uint64_t{previous.first[p]} << 32) | previous.second[p]) < key) ++p;
    if (p < np && ((std::uint64_t{previous.first[p]} << 32) | previous.second[p]) == key) {
      fresh.history[k] = previous.history[p];
    }
  }
}

}  // namespace sanguis::dem
