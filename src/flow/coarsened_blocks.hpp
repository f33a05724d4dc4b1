#pragma once
// The level-by-level multigrid hierarchy of a composite forest (issue #7): the forest with
// the families of its finest level merged into their parents, and the transfers between
// the two.
//
// Why: the block-by-block hierarchy (every block halving its own cells, so that every
// in-block level is a composite grid with the same level jumps) converges at 0.74-0.91 of
// the uniform rate per V-cycle at omega 1.15 and 0.43-0.49 at 1.25. Coarsening the finest
// level first, to the next level's cells, makes the level below the finest a forest with
// one level jump fewer (a uniform one for a forest refined once): a 2D model of the cycle
// and a 3D prototype put this hierarchy at 0.96-1.06 of the uniform rate at 1.15 and
// 0.72-0.95 at 1.25 (docs/performance.md, "A 2D model of the composite V-cycle").
//
// The coarsened forest has the same cells per block. A block below the finest level is a
// block of both forests, which the transfers copy; a family of 8 finest blocks becomes its
// parent, each of whose cells covers 2^3 cells of one child (its octant). Blocks may live
// on different ranks in the two forests: the values then travel through one MPI_Alltoallv,
// so one process and several give the same values.

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "flow/block_field.hpp"
#include "flow/forest.hpp"

namespace sanguis::flow {

/// The trilinear prolongation of a correction (weights 3/4 and 1/4 per direction) at a fine
/// cell in coarse cell c of block blk, towards the side s (+-1 per direction), from the active
/// coarse cells only (`active` 1 or 0; nullptr: all of them): the weighted sum and the sum of
/// the weights, for the caller to divide (no weight left: no correction there). Shared by the
/// in-block levels (multigrid.cpp) and the coarsened forest.
struct WeightedSum {
  double value = 0.0, weight = 0.0;
};
inline WeightedSum trilinear_sum(const BlockField& coarse, const BlockField* active, int blk,
                                 const std::array<int, 3>& c, const std::array<int, 3>& s) {
  WeightedSum sum;
  for (int dk = 0; dk < 2; ++dk)
    for (int dj = 0; dj < 2; ++dj)
      for (int di = 0; di < 2; ++di) {
        const int i = c[0] + di * s[0], j = c[1] + dj * s[1], k = c[2] + dk * s[2];
        double w = (di ? 0.25 : 0.75) * (dj ? 0.25 : 0.75) * (dk ? 0.25 : 0.75);
        if (active) w *= (*active)(blk, i, j, k);
        sum.value += w * coarse(blk, i, j, k);
        sum.weight += w;
      }
  return sum;
}

/// The forest `fine` with every family of its finest level coarsened (same spec and
/// ranks; 2:1 balanced as `fine` is), a new one (Forest::assign_coarsened_finest_level
/// makes an existing forest so). `fine` must have blocks below its trees' level.
std::unique_ptr<Forest> coarsen_finest_level(const Forest& fine);

/// Transfers between a composite forest and coarsen_finest_level() of it.
class CoarsenedBlocks {
 public:
  /// Both forests must stay alive and unchanged while this is used.
  CoarsenedBlocks(const Forest& fine, const Forest& coarse);

  /// Cells: a shared block copied, a child's cells averaged by 2^3 into its octant of the
  /// parent (the restriction of the residual, and of alpha).
  void restrict_cells(const BlockField& fine, BlockField& coarse) const;
  /// Component d of a face field (faces 0..b along d, slot b included): a shared block's
  /// faces copied, a parent's face the mean of the 4 child faces that make it up.
  void restrict_faces(const BlockField& fine, int d, BlockField& coarse) const;
  /// fine += the correction `coarse`: a shared block's cells added, a child's cells
  /// trilinearly from the parent's cells and the ghost ring around them (filled by the
  /// caller), each weight times `active` (1 or 0) of its coarse cell and renormalised
  /// (nullptr: every coarse cell active); nothing where no weight is left.
  void prolong_add(const BlockField& coarse, const BlockField* active, BlockField& fine) const;
  /// This rank's fine blocks whose coarse block lives on another rank.
  [[nodiscard]] std::int64_t links_to_other_ranks() const {
    std::int64_t n = 0;
    for (const auto& links : send_) n += static_cast<std::int64_t>(links.size());
    return n;
  }

 private:
  /// One fine block of this rank and where it goes: a coarse block (local on the rank
  /// that holds it) and the octant (x + 2 y + 4 z) of a child, or -1 for a shared block.
  /// On the coarse side of a transfer between ranks the fine block is -1.
  struct Link {
    std::int32_t fine = -1;
    std::int32_t coarse = -1;
    std::int32_t octant = -1;
  };
  enum class Kind { Cells, Faces, Prolong };
  /// Values that travel for one link.
  [[nodiscard]] int payload(const Link& link, Kind kind, int d) const;
  /// Moves every link's payload: produce(link, out) on the side that has the source
  /// (the fine side for restrictions, the coarse side for the prolongation), consume(link,
  /// in) on the other.
  template <typename Produce, typename Consume>
  void move(Kind kind, int d, Produce&& produce, Consume&& consume) const;

  const Forest& fine_;
  int b_ = 0;
  std::vector<Link> local_;  ///< per fine block of this rank; coarse = -1 when elsewhere
  /// Per rank: this rank's fine blocks whose coarse block is there (fine side), and the
  /// (coarse, octant) of that rank's fine blocks here (coarse side), in the same order.
  std::vector<std::vector<Link>> send_, receive_;
};

}  // namespace sanguis::flow
