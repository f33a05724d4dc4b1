#pragma once
// The wavelet refinement criterion (thesis eq. 4.11; Popinet 2015, Basilisk's
// adapt_wavelet): the local error estimate of a field is the difference
// between the field and its restriction-then-prolongation,
//
//     e = | u - P(R(u)) |,                                          (4.11)
//
// R the 8-cell volume average onto cells twice as large, P the second-order
// (linear, central slopes) prolongation back. It vanishes for linear fields,
// is O(h^3) for smooth ones (a measure of how well the next coarser grid
// would represent u), and O(1) at fronts. A block is refined where some field
// exceeds its threshold zeta and coarsened where every field stays below
// 2 zeta / 3 (the hysteresis of adapt_wavelet), within [min_level,
// max_level]; cells tagged in the "forced finest" field keep their block at
// max_level. The hysteresis alone does not stop flip-flop: a smooth field's
// estimate grows about 8x per coarser level (its quadratic part has none), so
// a block whose own estimate lies between zeta/8 and 2 zeta/3 would be
// coarsened and its parent refined again at the next regrid (10 % of the
// cells of the steady obstacle wake came and went every regrid). A family of
// 8 blocks therefore coarsens only if the estimate its parent would have,
// computed from the family's cells and 4 ghost layers averaged onto the
// parent, is below 2 zeta / 3 as well. (With blocks of 4 cells, 4 ghost
// layers beside a finer neighbour would reach a block that does not touch
// the family: such a family waits until its finer neighbours have merged.)

#include <span>
#include <vector>

#include "flow/block_field.hpp"
#include "flow/forest.hpp"

namespace sanguis::flow {

struct WaveletCriterion {
  std::vector<double> thresholds;       ///< zeta per field (same units as the field)
  int min_level = 0;                    ///< blocks are refined up to at least this level
  int max_level = 18;                   ///< and never beyond this one
  double coarsen_fraction = 2.0 / 3.0;  ///< coarsen below this fraction of zeta
  /// Optional, one per local block: the block is refined up to at least this
  /// level (at most max_level) and never coarsened below it (refinement
  /// regions). A block at max_level that may not coarsen is not estimated.
  std::vector<int> block_min_level{};
  /// Optional, one per local block: the block is never refined beyond this
  /// level (regions kept coarse, e.g. a far field), and a block above it is
  /// coarsened. Where it is below the block's floor (block_min_level), the
  /// floor wins; cells tagged forced-finest still take their block to
  /// max_level.
  std::vector<int> block_max_level{};
};

/// The estimate (4.11) of every local block: the largest e over its cells.
/// Fills the field's ghosts from the neighbours first (the coarse cells
/// beside the block, for the central slopes); at domain faces the slopes
/// are one-sided. Needs blocks of b >= 4 cells.
std::vector<double> wavelet_estimate(const Forest& forest, BlockField& field);

/// Refine/keep/coarsen flags for Forest::adapt from the estimates of
/// `fields` (one threshold each, one block layout for all) and an optional
/// tag field: a block with a tag cell > 0 is refined up to max_level and
/// never coarsened. A local family asks to coarsen only if its parent's
/// estimate is below coarsen_fraction * zeta too (families split across
/// ranks never merge). Fills the fields' face ghosts (2 layers) from the
/// neighbours, like wavelet_estimate. Blocks may get Coarsen while a sibling
/// stays (the forest then merges nothing there).
std::vector<AdaptFlag> wavelet_flags(const Forest& forest, std::span<BlockField* const> fields,
                                     const WaveletCriterion& criterion,
                                     const BlockField* finest_tag = nullptr);

}  // namespace sanguis::flow
