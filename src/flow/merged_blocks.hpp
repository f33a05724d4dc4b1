#pragma once
// Families of 8 blocks seen as one block of twice the cells per edge, for the
// multigrid on uniform forests.
//
// Why: a V-cycle on small blocks pays per block (ghost fills, loop heads,
// the coarser in-block levels of 4^3 and 2^3 cells whose ghost layers
// outweigh their cells): on the 64^3 cavity a V-cycle over 8^3 blocks costs
// about 3x one over 16^3 blocks, with the same residual reduction
// (docs/performance.md, "Solver blocks"). The flow keeps its blocks (8^3 by
// default, what adaptivity wants: refined regions stay tight); the
// multigrid of a uniform forest works on a second forest of blocks twice as
// large over the same domain, and its solves copy the right-hand side and
// the guess in and the solution out (three passes over the cells against
// the hundreds of bytes per cell of every V-cycle).
//
// The merged forest is one level coarser over the same trees, or, at level
// 0, a brick of half the trees twice as long; each merged block's 8 children
// are the fine blocks at coord 2 C + (0|1) per direction. Blocks may live on
// different ranks in the two forests: the transfers then go through one
// MPI_Alltoallv, so one process and several give the same values.

#include <cstdint>
#include <optional>
#include <vector>

#include "flow/block_field.hpp"
#include "flow/forest.hpp"

namespace sanguis::flow {

/// The spec of the forest whose blocks are `fine`'s families of 8 merged,
/// or nothing when `fine` is not uniform, its blocks already have
/// `max_cells` cells per edge or more, or the merged forest would have fewer
/// than 2 blocks along a direction.
std::optional<ForestSpec> merged_forest_spec(const Forest& fine, int max_cells = 16);

/// Copies between fields on a uniform forest and fields on its merged forest.
class MergedBlocks {
 public:
  /// Both forests must stay alive and unchanged while this is used.
  MergedBlocks(const Forest& fine, const Forest& merged);

  /// Interior cells of `fine` (b^3 per block) into `merged` ((2b)^3 per block).
  void to_merged(const BlockField& fine, BlockField& merged) const;
  /// Interior cells back.
  void to_fine(const BlockField& merged, BlockField& fine) const;
  /// Component d of a face field, faces 0..b along d of every fine block
  /// (slot b included): faces 0..2b along d of the merged blocks.
  void faces_to_merged(const BlockField& fine, int d, BlockField& merged) const;

  /// Fine blocks of this rank whose merged block is on another rank.
  [[nodiscard]] std::int64_t children_elsewhere() const;

 private:
  /// One child: a fine block of this rank and its (merged block, octant); on
  /// the merged side of a transfer between ranks the fine block is -1.
  struct Child {
    std::int32_t block = 0;   ///< local fine block
    std::int32_t merged = 0;  ///< local merged block (on the rank that holds it)
    int octant = 0;           ///< x + 2 y + 4 z
  };
  /// Cells (face_dir < 0) or faces along face_dir, from fine to merged or back.
  template <bool kToMerged>
  void transfer(const BlockField& from, BlockField& to, int face_dir) const;

  const Forest& fine_;
  const Forest& merged_;
  int b_ = 0;  ///< cells per fine block edge
  /// Per fine block of this rank: its child entry when the merged block is on
  /// this rank too (copied directly), else merged = -1.
  std::vector<Child> local_;
  /// Per rank: the fine blocks of this rank sent there (block set), in order,
  /// and the (merged, octant) of this rank received from there, in the same order.
  std::vector<std::vector<Child>> send_, receive_;
};

}  // namespace sanguis::flow
