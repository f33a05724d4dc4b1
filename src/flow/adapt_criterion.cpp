#include "flow/adapt_criterion.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace sanguis::flow {

namespace {

/// Faces of a cube that are domain faces (2d + side): slopes there are one-sided.
using DomainFaces = std::array<bool, 6>;

/// Estimate (4.11) of a cube of b^3 cells whose values `u` (offsets of
/// `layout`) include 2 face-ghost layers beyond every face that is not a
/// domain face: the largest |u - P(R(u))| over its cells.
double cube_estimate(const double* u, const BlockLayout& L, const DomainFaces& wall) {
  const int b = L.cells;
  const int n = b / 2;
  // R once per coarse cell: the mean of its 8 cells, for (I,J,K) in
  // [-1, n]^3 with at most one index outside [0, n) (I = -1 or n reads the
  // two ghost layers beside a face; edges and corners are never read).
  const int m = n + 2;
  thread_local std::vector<double> coarse;
  coarse.assign(static_cast<std::size_t>(m) * m * m, 0.0);
  auto at = [m](int ci, int cj, int ck) {
    return static_cast<std::size_t>(((ck + 1) * m + (cj + 1)) * m + (ci + 1));
  };
  for (int ck = -1; ck <= n; ++ck)
    for (int cj = -1; cj <= n; ++cj)
      for (int ci = -1; ci <= n; ++ci) {
        const int outside = (ci < 0 || ci >= n) + (cj < 0 || cj >= n) + (ck < 0 || ck >= n);
        if (outside > 1) continue;
        double sum = 0.0;
        for (int dk = 0; dk < 2; ++dk)
          for (int dj = 0; dj < 2; ++dj)
            for (int di = 0; di < 2; ++di) {
              sum += u[L.index(2 * ci + di, 2 * cj + dj, 2 * ck + dk)];
            }
        coarse[at(ci, cj, ck)] = sum / 8.0;
      }
  // P: the coarse value plus central slopes (one-sided at domain faces).
  const std::array<std::size_t, 3> step{1, static_cast<std::size_t>(m),
                                        static_cast<std::size_t>(m) * m};
  double worst = 0.0;
  for (int k = 0; k < b; ++k)
    for (int j = 0; j < b; ++j)
      for (int i = 0; i < b; ++i) {
        const std::array<int, 3> cell{i >> 1, j >> 1, k >> 1};
        const std::size_t c = at(cell[0], cell[1], cell[2]);
        const double centre = coarse[c];
        double prolonged = centre;
        for (std::size_t d = 0; d < 3; ++d) {
          const double above = coarse[c + step[d]], below = coarse[c - step[d]];
          double slope = 0.0;
          if (cell[d] == 0 && wall[2 * d]) {
            slope = above - centre;
          } else if (cell[d] == n - 1 && wall[2 * d + 1]) {
            slope = centre - below;
          } else {
            slope = 0.5 * (above - below);
          }
          const int fine = d == 0 ? i : (d == 1 ? j : k);
          prolonged += ((fine & 1) ? 0.25 : -0.25) * slope;
        }
        worst = std::max(worst, std::abs(u[L.index(i, j, k)] - prolonged));
      }
  return worst;
}

/// Whether a block of the family at `first` has a finer neighbour across a face.
bool beside_finer_blocks(const Forest& forest, int first) {
  for (int c = 0; c < 8; ++c)
    for (int d = 0; d < 3; ++d)
      for (int side = 0; side < 2; ++side) {
        const Neighbour& nb = forest.block(first + c).neighbours[face_neighbour_slot(d, side)];
        if (nb.link != Link::Boundary && nb.jump == LevelJump::Finer) return true;
      }
  return false;
}

/// The estimate (4.11) the parent of the family at `first` would have after
/// coarsening: the family's cells and 4 face-ghost layers of `deep` (the
/// field with 4 ghost layers, exchanged) averaged onto the parent's cells and
/// 2 ghost layers, then estimated as a block. Coarsening only where this is
/// small keeps the parent from being refined again at the next regrid: a
/// smooth field's estimate grows about 8x per coarser level, so the children's
/// own estimates cannot tell.
double parent_estimate(const Forest& forest, const BlockField& deep, int first,
                       std::vector<double>& scratch) {
  const int b = deep.cells();
  const BlockLayout& F = deep.layout();
  const BlockLayout P{b, 2};
  scratch.assign(static_cast<std::size_t>(P.size()), 0.0);
  // The fine value at family index (x, y, z), each in [-4, 2b + 4) with at
  // most one outside [0, 2b): a cell of child (x >= b, y >= b, z >= b), or of
  // its ghost layers beyond the family's face.
  auto fine = [&](int x, int y, int z) {
    const int cx = x >= b, cy = y >= b, cz = z >= b;
    return deep.block(first + cx + 2 * cy + 4 * cz)[F.index(x - cx * b, y - cy * b, z - cz * b)];
  };
  for (int k = -2; k < b + 2; ++k)
    for (int j = -2; j < b + 2; ++j)
      for (int i = -2; i < b + 2; ++i) {
        const int outside = (i < 0 || i >= b) + (j < 0 || j >= b) + (k < 0 || k >= b);
        if (outside > 1) continue;  // edges and corners: not read by the estimate
        double sum = 0.0;
        for (int dk = 0; dk < 2; ++dk)
          for (int dj = 0; dj < 2; ++dj)
            for (int di = 0; di < 2; ++di) sum += fine(2 * i + di, 2 * j + dj, 2 * k + dk);
        scratch[static_cast<std::size_t>(P.index(i, j, k))] = sum / 8.0;
      }
  // A parent face is a domain face where the children beside it have one.
  DomainFaces wall{};
  for (int d = 0; d < 3; ++d)
    for (int side = 0; side < 2; ++side) {
      const Block& child = forest.block(first + (side << d));
      wall[static_cast<std::size_t>(2 * d + side)] =
          child.neighbours[face_neighbour_slot(d, side)].link == Link::Boundary;
    }
  return cube_estimate(scratch.data(), P, wall);
}

}  // namespace

std::vector<double> wavelet_estimate(const Forest& forest, BlockField& field) {
  if (field.cells() < 4 || field.layout().ghost < 2) {
    throw std::invalid_argument("wavelet estimate: needs blocks of >= 4 cells and 2 ghost layers");
  }
  forest.exchange(field, 2, true);  // face ghosts: the slopes are taken along one direction
  std::vector<double> estimate(static_cast<std::size_t>(forest.local_blocks()));
  forest.for_each_block([&](int blk) {
    estimate[static_cast<std::size_t>(blk)] =
        cube_estimate(field.block(blk), field.layout(), domain_faces(forest.block(blk)));
  });
  return estimate;
}

std::vector<AdaptFlag> wavelet_flags(const Forest& forest, std::span<BlockField* const> fields,
                                     const WaveletCriterion& criterion,
                                     const BlockField* finest_tag) {
  if (criterion.thresholds.size() != fields.size()) {
    throw std::invalid_argument("wavelet flags: one threshold per field");
  }
  const auto blocks = static_cast<std::size_t>(forest.local_blocks());
  if (!criterion.block_min_level.empty() && criterion.block_min_level.size() != blocks) {
    throw std::invalid_argument("wavelet flags: block_min_level needs one level per local block");
  }
  if (!criterion.block_max_level.empty() && criterion.block_max_level.size() != blocks) {
    throw std::invalid_argument("wavelet flags: block_max_level needs one level per local block");
  }
  for (const BlockField* f : fields) {
    if (f->cells() < 4 || f->layout().ghost < 2) {
      throw std::invalid_argument("wavelet flags: needs blocks of >= 4 cells and 2 ghost layers");
    }
    if (f->layout().ghost != fields[0]->layout().ghost || f->cells() != fields[0]->cells()) {
      throw std::invalid_argument("wavelet flags: the fields must share one block layout");
    }
  }
  auto floor_of = [&](std::size_t blk) {
    return criterion.block_min_level.empty()
               ? criterion.min_level
               : std::clamp(criterion.block_min_level[blk], criterion.min_level,
                            std::max(criterion.min_level, criterion.max_level));
  };
  // The finest level the criterion may take a block to: max_level, or the
  // block's cap, but never below its floor.
  auto ceiling_of = [&](std::size_t blk) {
    const int cap = criterion.block_max_level.empty()
                        ? criterion.max_level
                        : std::min(criterion.block_max_level[blk], criterion.max_level);
    return std::max(cap, floor_of(blk));
  };
  // A block at its ceiling that may not coarsen either has nothing to decide.
  std::vector<bool> pinned(blocks);
  for (std::size_t blk = 0; blk < blocks; ++blk) {
    const int level = forest.block(static_cast<int>(blk)).level;
    pinned[blk] = level >= ceiling_of(blk) && level <= floor_of(blk);
  }
  std::vector<bool> refine(blocks, false), coarsen(blocks, true);
  forest.exchange(fields, 2, true);  // face ghosts: the slopes are taken along one direction
  std::vector<double> e(blocks);
  for (std::size_t f = 0; f < fields.size(); ++f) {
    forest.for_each_block([&](int blk) {
      e[static_cast<std::size_t>(blk)] =
          pinned[static_cast<std::size_t>(blk)]
              ? 0.0
              : cube_estimate(fields[f]->block(blk), fields[f]->layout(),
                              domain_faces(forest.block(blk)));
    });
    const double zeta = criterion.thresholds[f];
    for (std::size_t blk = 0; blk < blocks; ++blk) {
      refine[blk] = refine[blk] || e[blk] > zeta;
      coarsen[blk] = coarsen[blk] && e[blk] < criterion.coarsen_fraction * zeta;
    }
  }
  for (std::size_t blk = 0; blk < blocks; ++blk) {
    if (forest.block(static_cast<int>(blk)).level <= floor_of(blk)) coarsen[blk] = false;
  }
  // A family whose 8 blocks would all coarsen does so only if its parent's
  // estimate stays below the coarsening threshold too (no flip-flop). The
  // fields with 4 ghost layers are made only when some rank has such a
  // family (the exchange is collective).
  std::vector<int> candidates;
  for (int first = 0; first + 8 <= forest.local_blocks(); ++first) {
    if (!forest.is_family(first)) continue;
    bool all = true;
    for (int c = 0; c < 8; ++c) all = all && coarsen[static_cast<std::size_t>(first + c)];
    if (all) candidates.push_back(first);  // else the forest will not merge it anyway
    first += 7;
  }
  if (forest.max(candidates.empty() ? 0.0 : 1.0) > 0.0) {
    std::vector<BlockField> deep;  // each field with 4 ghost layers, for the parents' estimates
    deep.reserve(fields.size());
    for (const BlockField* field : fields) {
      const int b = field->cells();
      BlockField& copy = deep.emplace_back(forest.local_blocks(), b, 4);
      forest.for_each_block([&](int blk) {
        for (int k = 0; k < b; ++k)
          for (int j = 0; j < b; ++j)
            for (int i = 0; i < b; ++i) copy(blk, i, j, k) = (*field)(blk, i, j, k);
      });
      forest.exchange(copy, 4, true);
    }
    std::vector<double> scratch;
    for (const int first : candidates) {
      const auto f0 = static_cast<std::size_t>(first);
      // With b = 4 the 4 ghost layers reach 2 finer blocks deep beside a finer
      // neighbour, whose second block does not touch the family (the exchange
      // clamps it): such a family waits until its finer neighbours have merged
      // (the 2:1 balance refuses it before that anyway, unless they merge in
      // the same pass).
      bool parent_resolved = fields[0]->cells() >= 8 || !beside_finer_blocks(forest, first);
      for (std::size_t f = 0; f < fields.size() && parent_resolved; ++f) {
        parent_resolved = parent_estimate(forest, deep[f], first, scratch) <
                          criterion.coarsen_fraction * criterion.thresholds[f];
      }
      if (!parent_resolved) {
        for (std::size_t c = 0; c < 8; ++c) coarsen[f0 + c] = false;
      }
    }
  }
  std::vector<AdaptFlag> flags(blocks, AdaptFlag::Keep);
  for (std::size_t blk = 0; blk < blocks; ++blk) {
    const int level = forest.block(static_cast<int>(blk)).level;
    bool tagged = false;
    if (finest_tag != nullptr) {
      const int b = finest_tag->cells();
      for (int k = 0; k < b && !tagged; ++k)
        for (int j = 0; j < b && !tagged; ++j)
          for (int i = 0; i < b && !tagged; ++i)
            tagged = (*finest_tag)(static_cast<int>(blk), i, j, k) > 0.0;
    }
    // Forced-finest cells (immersed-boundary stencils) override a region's cap.
    const int top = tagged ? std::max(criterion.max_level, floor_of(blk)) : ceiling_of(blk);
    if (level > top) {
      flags[blk] = AdaptFlag::Coarsen;
    } else if (level < floor_of(blk) || ((tagged || refine[blk]) && level < top)) {
      flags[blk] = AdaptFlag::Refine;
    } else if (!tagged && !refine[blk] && coarsen[blk]) {
      flags[blk] = AdaptFlag::Coarsen;
    }
  }
  return flags;
}

}  // namespace sanguis::flow
