#pragma once
// Statically refined forests and ghost checks shared by the adaptivity tests
// (test_adapt.cpp) and the 2-rank check (flow_mpi_check.cpp).

#include <algorithm>
#include <cmath>
#include <vector>

#include "flow/forest.hpp"

namespace sanguis::flow::testing {

/// Centre of a block.
inline Vec3 block_centre(const Block& block) {
  const double half = 0.5 * block.length;
  return {block.lower.x + half, block.lower.y + half, block.lower.z + half};
}

/// Refines (once) every block whose centre satisfies `inside`.
template <typename Inside>
void refine_where(Forest& forest, Inside&& inside, std::span<BlockField* const> fields = {}) {
  forest.adapt(
      [&](const Block& block) {
        return inside(block_centre(block)) ? AdaptFlag::Refine : AdaptFlag::Keep;
      },
      fields);
}

/// Sets every interior cell of `field` to f(cell centre).
template <typename F>
void fill_cells(const Forest& forest, BlockField& field, F&& f) {
  const int b = field.cells();
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const Block& block = forest.block(blk);
    const double h = block.length / b;
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i)
          field(blk, i, j, k) = f(Vec3{block.lower.x + (i + 0.5) * h, block.lower.y + (j + 0.5) * h,
                                       block.lower.z + (k + 0.5) * h});
  }
}

/// Component d of a face field set to f_d at the face centres (faces 0..b along d).
template <typename F>
void fill_faces(const Forest& forest, FaceField& uf, F&& f) {
  const int b = uf[0].cells();
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const Block& block = forest.block(blk);
    const double h = block.length / b;
    for (int d = 0; d < 3; ++d) {
      std::array<int, 3> end{b, b, b};
      end[static_cast<std::size_t>(d)] = b + 1;
      for (int k = 0; k < end[2]; ++k)
        for (int j = 0; j < end[1]; ++j)
          for (int i = 0; i < end[0]; ++i) {
            Vec3 x{block.lower.x + (i + 0.5) * h, block.lower.y + (j + 0.5) * h,
                   block.lower.z + (k + 0.5) * h};
            x[d] -= 0.5 * h;
            uf[static_cast<std::size_t>(d)](blk, i, j, k) = f(x)[d];
          }
    }
  }
}

/// Largest |face - f_d(face centre)| over the faces 0..b of every block (all ranks).
template <typename F>
double face_error(const Forest& forest, const FaceField& uf, F&& f) {
  FaceField expected = make_vector_field(forest.local_blocks(), uf[0].cells());
  fill_faces(forest, expected, f);
  const int b = uf[0].cells();
  double error = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk)
    for (std::size_t d = 0; d < 3; ++d) {
      std::array<int, 3> end{b, b, b};
      end[d] = b + 1;
      for (int k = 0; k < end[2]; ++k)
        for (int j = 0; j < end[1]; ++j)
          for (int i = 0; i < end[0]; ++i)
            error = std::max(error, std::abs(uf[d](blk, i, j, k) - expected[d](blk, i, j, k)));
    }
  return forest.max(error);
}

/// Largest |ghost - f(ghost centre)| over the ghost cells, `width` deep, of
/// the neighbour regions whose level relation is `jump` (all ranks).
template <typename F>
double ghost_error(const Forest& forest, const BlockField& field, F&& f, LevelJump jump,
                   int width) {
  const int b = field.cells();
  double error = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const Block& block = forest.block(blk);
    const double h = block.length / b;
    for (int oz = -1; oz <= 1; ++oz)
      for (int oy = -1; oy <= 1; ++oy)
        for (int ox = -1; ox <= 1; ++ox) {
          if (ox == 0 && oy == 0 && oz == 0) continue;
          const Neighbour& nb =
              block.neighbours[static_cast<std::size_t>(neighbour_slot(ox, oy, oz))];
          if (nb.link == Link::Boundary || nb.jump != jump) continue;
          auto range = [&](int o, int& lo, int& hi) {
            lo = o < 0 ? -width : (o > 0 ? b : 0);
            hi = o < 0 ? 0 : (o > 0 ? b + width : b);
          };
          int i0, i1, j0, j1, k0, k1;
          range(ox, i0, i1);
          range(oy, j0, j1);
          range(oz, k0, k1);
          for (int k = k0; k < k1; ++k)
            for (int j = j0; j < j1; ++j)
              for (int i = i0; i < i1; ++i) {
                const Vec3 x{block.lower.x + (i + 0.5) * h, block.lower.y + (j + 0.5) * h,
                             block.lower.z + (k + 0.5) * h};
                error = std::max(error, std::abs(field(blk, i, j, k) - f(x)));
              }
        }
  }
  return forest.max(error);
}

/// Global number of blocks that have at least one neighbour of relation `jump`.
inline double blocks_with(const Forest& forest, LevelJump jump) {
  double count = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const auto& nbs = forest.block(blk).neighbours;
    count +=
        std::any_of(nbs.begin(), nbs.end(),
                    [&](const Neighbour& n) { return n.link != Link::Boundary && n.jump == jump; })
            ? 1.0
            : 0.0;
  }
  return forest.sum(count);
}

}  // namespace sanguis::flow::testing
