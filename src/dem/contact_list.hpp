#pragma once
// Candidate contacts found by the broad phase (within cut-off + skin), sorted by
// (first, second) local index (first < second for pairs), each with the memory of its
// contact (ContactHistory). When the list is rebuilt the histories of pairs that are
// still candidates are carried over, so a rebuild never erases memory (see
// NeighborSearch::rebuild). Local indices follow the storage order, which is the
// particles' (sort key, id) order (ParticleStore::sort_key).
#include <algorithm>
#include <cstdint>
#include <span>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/permutation.hpp"
#include "dem/contact_law.hpp"
#include "geometry/gjk.hpp"

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
  // Sort key (first, second) as one number.
  std::uint64_t key(std::size_t k) const { return (std::uint64_t{first[k]} << 32) | second[k]; }
};

// Copies the histories of `previous` into `fresh` for the keys present in both, for the
// entries begin .. end - 1 of `fresh`, walking `previous` from entry p on. Both lists must
// be sorted by (first, second).
inline void carry_history_range(const ContactList& previous, ContactList& fresh, std::size_t begin,
                                std::size_t end, std::size_t p) {
  const std::size_t np = previous.size();
  for (std::size_t k = begin; k < end && p < np; ++k) {
    const std::uint64_t key = fresh.key(k);
    while (p < np && previous.key(p) < key) ++p;
    if (p < np && previous.key(p) == key) fresh.history[k] = previous.history[p];
  }
}

// The same for the whole of `fresh`.
inline void carry_history(const ContactList& previous, ContactList& fresh) {
  carry_history_range(previous, fresh, 0, fresh.size(), 0);
}

// The same, the fresh list cut into `threads` ranges merged in parallel (each finds where
// its first key falls in `previous` by bisection): the same copies, so the same lists.
inline void carry_history(const ContactList& previous, ContactList& fresh, int threads) {
  const std::size_t n = fresh.size(), np = previous.size();
  if (threads <= 1 || n < 4096) {
    carry_history(previous, fresh);
    return;
  }
  const auto ranges = static_cast<std::size_t>(threads);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (std::size_t r = 0; r < ranges; ++r) {
    const std::size_t begin = n * r / ranges, end = n * (r + 1) / ranges;
    if (begin == end) continue;
    // First entry of `previous` whose key is not below the range's first key.
    std::size_t lo = 0, hi = np;
    const std::uint64_t first_key = fresh.key(begin);
    while (lo < hi) {
      const std::size_t mid = lo + (hi - lo) / 2;
      if (previous.key(mid) < first_key) {
        lo = mid + 1;
      } else {
        hi = mid;
      }
    }
    carry_history_range(previous, fresh, begin, end, lo);
  }
}

// Candidate contacts involving non-spherical bodies, one entry per pair of convex
// elements (two crosses touch at up to four points, each with its own memory),
// sorted by (first, second, element_first, element_second). For obstacle contacts
// `second` is the obstacle index and `element_second` is 0.
struct BodyContactList {
  std::vector<std::uint32_t> first, second;
  std::vector<std::uint16_t> element_first, element_second;
  std::vector<ContactHistory> history;
  std::vector<geometry::GjkWarmStart> warm;  // last GJK simplex: the next call starts there
  // Moment held by the contact patch's torsional spring (body_contacts.hpp), on the first
  // body about the normal [N m]. The same number seen from either body (the normal and
  // the body turn round together), so it is not turned round with the pair.
  std::vector<double> twist;

  std::size_t size() const { return first.size(); }
  void clear() {
    first.clear();
    second.clear();
    element_first.clear();
    element_second.clear();
    history.clear();
    warm.clear();
    twist.clear();
  }
  void push(std::uint32_t a, std::uint32_t b, std::uint16_t ea, std::uint16_t eb) {
    first.push_back(a);
    second.push_back(b);
    element_first.push_back(ea);
    element_second.push_back(eb);
    history.push_back({});
    warm.push_back({});
    twist.push_back(0.0);
  }
  // Sort key (first, second, element_first, element_second), compared lexicographically.
  std::pair<std::uint64_t, std::uint32_t> key(std::size_t k) const {
    return {(std::uint64_t{first[k]} << 32) | second[k],
            (std::uint32_t{element_first[k]} << 16) | element_second[k]};
  }
};

inline void carry_history(const BodyContactList& previous, BodyContactList& fresh) {
  std::size_t p = 0;
  const std::size_t np = previous.size();
  for (std::size_t k = 0; k < fresh.size() && p < np; ++k) {
    const auto key = fresh.key(k);
    while (p < np && previous.key(p) < key) ++p;
    if (p < np && previous.key(p) == key) {
      fresh.history[k] = previous.history[p];
      fresh.warm[k] = previous.warm[p];
      fresh.twist[k] = previous.twist[p];
    }
  }
}

// The memory of a contact seen from its other particle: what it stores relative to its
// first particle (eq. 2.8-2.10: the tangential spring, the rolling spring torque, the
// normal) is negated, exactly, and so are the forces it then gives (every operation of
// evaluate_contact is mirrored).
inline ContactHistory turned_round(const ContactHistory& h) {
  return {-h.tangential_displacement, -h.rolling_spring_torque, -h.normal};
}

// One contact and its memory keyed by particle ids instead of local indices, so that
// it survives a renumbering of the particles: particles moving between processes
// (domain decomposition) or re-sorted along space (DemSimulation). A pair's first
// particle is the one stored first when the memory was taken; key() names the pair
// whichever its order, and as_oriented() turns the memory round when the new storage
// order puts the other particle first.
struct ContactMemory {
  enum Kind : std::uint8_t { kSpherePair = 0, kSphereWall = 1, kBodyPair = 2, kBodyWall = 3 };
  std::uint8_t kind = kSpherePair;
  std::uint16_t element_first = 0, element_second = 0;
  std::int64_t first_id = 0;   // particle id (the pair's first particle)
  std::int64_t second_id = 0;  // particle id, or obstacle index for walls
  ContactHistory history;
  geometry::GjkWarmStart warm;  // body contacts only
  double twist = 0.0;           // body contacts only (BodyContactList::twist)

  bool is_pair() const { return kind == kSpherePair || kind == kBodyPair; }
  // (kind, smaller id, larger id, element of the smaller, element of the larger) for
  // pairs; (kind, particle id, obstacle, elements) for walls.
  auto key() const {
    if (is_pair() && second_id < first_id) {
      return std::tuple{kind, second_id, first_id, element_second, element_first};
    }
    return std::tuple{kind, first_id, second_id, element_first, element_second};
  }
  // This memory as seen from a pair stored with `first` first (turned_round); the GJK
  // simplex then starts cold.
  ContactMemory as_oriented(std::int64_t first) const {
    if (!is_pair() || first == first_id) return *this;
    ContactMemory m = *this;
    std::swap(m.first_id, m.second_id);
    std::swap(m.element_first, m.element_second);
    m.history = turned_round(history);
    m.warm = {};
    return m;
  }
};

// The storage was reordered: particle i is now new_index[i]. Each entry keeps its
// memory; a pair whose order flips is turned round as ContactMemory::as_oriented does
// (so one process ends up as a decomposed run that exchanged the memories); the list
// is sorted again. `pair_list` false: `second` is an obstacle, never renumbered.
template <typename List>
void renumber(List& list, std::span<const std::uint32_t> new_index, bool pair_list) {
  constexpr bool kBodies = std::is_same_v<List, BodyContactList>;
  const std::size_t n = list.size();
  for (std::size_t k = 0; k < n; ++k) {
    std::uint32_t a = new_index[list.first[k]];
    std::uint32_t b = pair_list ? new_index[list.second[k]] : list.second[k];
    if (pair_list && b < a) {
      std::swap(a, b);
      list.history[k] = turned_round(list.history[k]);
      if constexpr (kBodies) {
        std::swap(list.element_first[k], list.element_second[k]);
        list.warm[k] = {};
      }
    }
    list.first[k] = a;
    list.second[k] = b;
  }
  std::vector<std::uint32_t> order(n);
  for (std::size_t k = 0; k < n; ++k) order[k] = static_cast<std::uint32_t>(k);
  std::sort(order.begin(), order.end(),
            [&](std::uint32_t x, std::uint32_t y) { return list.key(x) < list.key(y); });
  std::vector<std::uint8_t> visited;
  permute_in_place(list.first, order, visited);
  permute_in_place(list.second, order, visited);
  permute_in_place(list.history, order, visited);
  if constexpr (kBodies) {
    permute_in_place(list.element_first, order, visited);
    permute_in_place(list.element_second, order, visited);
    permute_in_place(list.warm, order, visited);
    permute_in_place(list.twist, order, visited);
  }
}

}  // namespace sanguis::dem
