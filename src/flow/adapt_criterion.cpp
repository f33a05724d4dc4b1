#include "flow/adapt_criterion.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sanguis::flow {

namespace {

/// Estimate (4.11) of one block whose ghosts hold its neighbours' cells.
double block_estimate(const Block& block, const BlockField& field, int blk) {
  const int b = field.cells();
  const BlockLayout& L = field.layout();
  const double* u = field.block(blk);
  // R: the mean of the 8 cells of coarse cell (I,J,K); I = -1 or b/2 reads
  // the two ghost layers beside a face.
  auto coarse = [&](int ci, int cj, int ck) {
    double sum = 0.0;
    for (int dk = 0; dk < 2; ++dk)
      for (int dj = 0; dj < 2; ++dj)
        for (int di = 0; di < 2; ++di) sum += u[L.index(2 * ci + di, 2 * cj + dj, 2 * ck + dk)];
    return sum / 8.0;
  };
  std::array<bool, 6> wall{};
  for (int d = 0; d < 3; ++d)
    for (int side = 0; side < 2; ++side) {
      std::array<int, 3> o{0, 0, 0};
      o[static_cast<std::size_t>(d)] = side == 0 ? -1 : 1;
      wall[static_cast<std::size_t>(2 * d + side)] =
          block.neighbours[static_cast<std::size_t>(neighbour_slot(o[0], o[1], o[2]))].link ==
          Link::Boundary;
    }
  const int n = b / 2;
  double worst = 0.0;
  for (int k = 0; k < b; ++k)
    for (int j = 0; j < b; ++j)
      for (int i = 0; i < b; ++i) {
        const std::array<int, 3> cell{i >> 1, j >> 1, k >> 1};
        const double centre = coarse(cell[0], cell[1], cell[2]);
        double prolonged = centre;
        for (std::size_t d = 0; d < 3; ++d) {
          auto shifted = [&](int by) {
            std::array<int, 3> c = cell;
            c[d] += by;
            return coarse(c[0], c[1], c[2]);
          };
          double slope = 0.0;
          if (cell[d] == 0 && wall[2 * d]) {
            slope = shifted(1) - centre;
          } else if (cell[d] == n - 1 && wall[2 * d + 1]) {
            slope = centre - shifted(-1);
          } else {
            slope = 0.5 * (shifted(1) - shifted(-1));
          }
          const int fine = d == 0 ? i : (d == 1 ? j : k);
          prolonged += ((fine & 1) ? 0.25 : -0.25) * slope;
        }
        worst = std::max(worst, std::abs(u[L.index(i, j, k)] - prolonged));
      }
  return worst;
}

}  // namespace

std::vector<double> wavelet_estimate(const Forest& forest, BlockField& field) {
  if (field.cells() < 4 || field.layout().ghost < 2) {
    throw std::invalid_argument("wavelet estimate: needs blocks of >= 4 cells and 2 ghost layers");
  }
  forest.exchange(field, 2, true);  // face ghosts: the slopes are taken along one direction
  std::vector<double> estimate(static_cast<std::size_t>(forest.local_blocks()));
  forest.for_each_block([&](int blk) {
    estimate[static_cast<std::size_t>(blk)] = block_estimate(forest.block(blk), field, blk);
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
  std::vector<bool> refine(blocks, false), coarsen(blocks, true);
  for (std::size_t f = 0; f < fields.size(); ++f) {
    const std::vector<double> e = wavelet_estimate(forest, *fields[f]);
    const double zeta = criterion.thresholds[f];
    for (std::size_t blk = 0; blk < blocks; ++blk) {
      refine[blk] = refine[blk] || e[blk] > zeta;
      coarsen[blk] = coarsen[blk] && e[blk] < criterion.coarsen_fraction * zeta;
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
    if (level > criterion.max_level) {
      flags[blk] = AdaptFlag::Coarsen;
    } else if (level < criterion.min_level ||
               ((tagged || refine[blk]) && level < criterion.max_level)) {
      flags[blk] = AdaptFlag::Refine;
    } else if (!tagged && !refine[blk] && coarsen[blk] && level > criterion.min_level) {
      flags[blk] = AdaptFlag::Coarsen;
    }
  }
  return flags;
}

}  // namespace sanguis::flow
