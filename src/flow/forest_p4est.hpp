#pragma once
// The p8est objects behind a Forest and the integer geometry of its
// quadrants, shared by forest.cpp and adapt.cpp (not part of the public API).

#include <p8est.h>
#include <p8est_ghost.h>

#include <array>
#include <cstdint>
#include <memory>
#include <type_traits>
#include <vector>

#include "flow/forest.hpp"

namespace sanguis::flow {

static_assert(std::is_same_v<p4est_gloidx_t, std::int64_t>,
              "Forest stores p8est global quadrant numbers as std::int64_t");

struct Forest::P4estObjects {
  struct ConnectivityDeleter {
    void operator()(p8est_connectivity_t* c) const { p8est_connectivity_destroy(c); }
  };
  struct ForestDeleter {
    void operator()(p8est_t* p) const { p8est_destroy(p); }
  };
  struct GhostDeleter {
    void operator()(p8est_ghost_t* g) const { p8est_ghost_destroy(g); }
  };
  // Declared in creation order: destroyed ghost first, connectivity last.
  std::unique_ptr<p8est_connectivity_t, ConnectivityDeleter> connectivity;
  std::unique_ptr<p8est_t, ForestDeleter> forest;
  std::unique_ptr<p8est_ghost_t, GhostDeleter> ghost;
  /// The tree at each brick position, x fastest (Forest::owner_of).
  std::vector<p4est_topidx_t> tree_at;
};

/// Integer position of tree t in the brick (its lowest vertex).
inline std::array<std::int64_t, 3> tree_position(const p8est_connectivity_t& conn,
                                                 p4est_topidx_t t) {
  const p4est_topidx_t v = conn.tree_to_vertex[P8EST_CHILDREN * t];
  std::array<std::int64_t, 3> pos{};
  for (int d = 0; d < 3; ++d) {
    pos[static_cast<std::size_t>(d)] = static_cast<std::int64_t>(conn.vertices[3 * v + d] + 0.5);
  }
  return pos;
}

/// Integer position of quadrant q among the blocks of its level.
inline std::array<std::int64_t, 3> block_coord(const std::array<std::int64_t, 3>& tree_pos,
                                               const p8est_quadrant_t& q) {
  const int shift = P8EST_MAXLEVEL - q.level;
  return {(tree_pos[0] << q.level) + (q.x >> shift), (tree_pos[1] << q.level) + (q.y >> shift),
          (tree_pos[2] << q.level) + (q.z >> shift)};
}

/// Key of the block at (level, c) in a brick of `trees`: unique over levels
/// (the level in the top bits, the number among that level's blocks below).
inline std::uint64_t block_key(const std::array<int, 3>& trees, int level,
                               const std::array<std::int64_t, 3>& c) {
  const std::int64_t nx = std::int64_t{trees[0]} << level, ny = std::int64_t{trees[1]} << level;
  return (static_cast<std::uint64_t>(level) << 58) |
         static_cast<std::uint64_t>((c[2] * ny + c[1]) * nx + c[0]);
}

}  // namespace sanguis::flow
