#pragma once
// Candidate contacts found by the broad phase (within cut-off + skin), each with the
// memory of its contact (ContactHistory). A list holds local particle indices but is
// sorted by the particles' ids, (id of first, id of second), and a pair's first particle
// is the one with the smaller id: the order in which each particle sums its contacts,
// and so every result, does not depend on where the particles are stored (the storage
// is re-sorted along space, see DemSimulation). When the list is rebuilt the histories
// of pairs that are still candidates are carried over, so a rebuild never erases
// memory (see NeighborSearch::rebuild).
#include <cstdint>
#include <span>
#include <tuple>
#include <utility>
#include <vector>

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
};

// The sort key of contact k of a list: (id of first, id of second) for particle pairs,
// (id of first, obstacle index) for particle-obstacle pairs (`pair_list` false).
inline std::pair<std::int64_t, std::int64_t> contact_key(const std::vector<std::uint32_t>& first,
                                                         const std::vector<std::uint32_t>& second,
                                                         std::size_t k, const std::int64_t* id,
                                                         bool pair_list) {
  return {id[first[k]], pair_list ? id[second[k]] : std::int64_t{second[k]}};
}

// Copies the histories of `previous` into `fresh` for the keys present in both. Both
// lists must be sorted by contact_key, and their indices refer to the same storage.
inline void carry_history(const ContactList& previous, ContactList& fresh, const std::int64_t* id,
                          bool pair_list) {
  std::size_t p = 0;
  const std::size_t np = previous.size();
  const auto old_key = [&](std::size_t q) {
    return contact_key(previous.first, previous.second, q, id, pair_list);
  };
  for (std::size_t k = 0; k < fresh.size() && p < np; ++k) {
    const auto key = contact_key(fresh.first, fresh.second, k, id, pair_list);
    while (p < np && old_key(p) < key) ++p;
    if (p < np && old_key(p) == key) fresh.history[k] = previous.history[p];
  }
}

// The storage was reordered (ParticleStore::permute): particle i is now new_index[i].
// The entries keep their order, which is by id.
inline void renumber(std::vector<std::uint32_t>& particle_index,
                     std::span<const std::uint32_t> new_index) {
  for (std::uint32_t& i : particle_index) i = new_index[i];
}

// Candidate contacts involving non-spherical bodies, one entry per pair of convex
// elements (two crosses touch at up to four points, each with its own memory),
// sorted by (contact_key, element_first, element_second). For obstacle contacts
// `second` is the obstacle index and `element_second` is 0.
struct BodyContactList {
  std::vector<std::uint32_t> first, second;
  std::vector<std::uint16_t> element_first, element_second;
  std::vector<ContactHistory> history;
  std::vector<geometry::GjkWarmStart> warm;  // last GJK simplex: the next call starts there

  std::size_t size() const { return first.size(); }
  void clear() {
    first.clear();
    second.clear();
    element_first.clear();
    element_second.clear();
    history.clear();
    warm.clear();
  }
  void push(std::uint32_t a, std::uint32_t b, std::uint16_t ea, std::uint16_t eb) {
    first.push_back(a);
    second.push_back(b);
    element_first.push_back(ea);
    element_second.push_back(eb);
    history.push_back({});
    warm.push_back({});
  }
  // Sort key (contact_key, element_first, element_second), compared lexicographically.
  std::tuple<std::int64_t, std::int64_t, std::uint32_t> key(std::size_t k, const std::int64_t* id,
                                                            bool pair_list) const {
    const auto [a, b] = contact_key(first, second, k, id, pair_list);
    return {a, b, (std::uint32_t{element_first[k]} << 16) | element_second[k]};
  }
};

inline void carry_history(const BodyContactList& previous, BodyContactList& fresh,
                          const std::int64_t* id, bool pair_list) {
  std::size_t p = 0;
  const std::size_t np = previous.size();
  for (std::size_t k = 0; k < fresh.size() && p < np; ++k) {
    const auto key = fresh.key(k, id, pair_list);
    while (p < np && previous.key(p, id, pair_list) < key) ++p;
    if (p < np && previous.key(p, id, pair_list) == key) {
      fresh.history[k] = previous.history[p];
      fresh.warm[k] = previous.warm[p];
    }
  }
}

// One contact and its memory keyed by particle ids instead of local indices, so that
// it survives a renumbering of the particles (domain decomposition: particles move
// between processes with the memories of their contacts).
struct ContactMemory {
  enum Kind : std::uint8_t { kSpherePair = 0, kSphereWall = 1, kBodyPair = 2, kBodyWall = 3 };
  std::uint8_t kind = kSpherePair;
  std::uint16_t element_first = 0, element_second = 0;
  std::int64_t first_id = 0;   // particle id (the smaller one for pairs)
  std::int64_t second_id = 0;  // particle id, or obstacle index for walls
  ContactHistory history;
  geometry::GjkWarmStart warm;  // body contacts only

  auto key() const { return std::tuple{kind, first_id, second_id, element_first, element_second}; }
};

}  // namespace sanguis::dem
