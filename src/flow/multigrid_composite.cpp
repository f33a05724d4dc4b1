// The parts of the multigrid that only composite grids (blocks at several
// levels, issue #7) use: the conservative flux correction at coarse-fine
// faces and the bottom solve on the graph of leaves.
#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <vector>

#include "flow/conjugate_gradients.hpp"
#include "flow/multigrid.hpp"

namespace sanguis::flow {

namespace {

constexpr std::size_t D(int d) {
  return static_cast<std::size_t>(d);
}

/// body(blk, nb, d, side) for each face (d, side) of each local block with
/// finer blocks across it (nb: that neighbour), on the forest's threads.
template <typename Body>
void for_each_face_to_finer(const Forest& forest, Body&& body) {
  forest.for_each_listed(forest.blocks_beside_finer(), [&](int blk) {
    const Block& block = forest.block(blk);
    for (int d = 0; d < 3; ++d)
      for (int side = 0; side < 2; ++side) {
        const Neighbour& nb = block.neighbours[face_neighbour_slot(d, side)];
        if (nb.jump == LevelJump::Finer) body(blk, nb, d, side);
      }
  });
}

}  // namespace

// Flux matching at coarse-fine faces. A cell's residual is
// r = f - alpha x + (1/h) sum_faces G with G = beta (x_beyond - x) / h the
// gradient flux through each face. A fine cell beside a coarser block takes
// its G from the interpolated ghost; the coarse cell across the face must
// see exactly the mean of those 4 fine fluxes (with the opposite sign), so
// that the composite operator is conservative (the coarse cell's flux is the
// sum of the fine ones). The fine fluxes are stored in the fine block's face
// layer of face_flux[face] and sent to the coarse block by the exchange,
// whose restriction averages the 8 fine cells of a ghost cell: the 4 of the
// face layer and 4 zeros, hence the factor 2. The coarse ghost becomes the
// value x + h G / beta that yields that flux through the coarse stencil.
void Multigrid::match_fluxes(int level, BlockField& x) {
  Level& lv = levels_[D(level)];
  if (lv.cells < 2) return;  // one cell per block: the gathered bottom level
  if (forest_.ranks() == 1) {
    match_fluxes_local(level, x);
    return;
  }
  const BlockLayout L = x.layout();
  const int b = L.cells;
  forest_.for_each_listed(forest_.blocks_beside_coarser(), [&](int blk) {
    const Block& block = forest_.block(blk);
    const double h = block.length / b;
    for (int d = 0; d < 3; ++d)
      for (int side = 0; side < 2; ++side) {
        // Only the face layer beside a coarser block is ever written (the
        // same cells at every call while the forest stands); the rest of
        // the array keeps the zeros it was allocated with, which the 8-cell
        // mean relies on.
        if (block.neighbours[face_neighbour_slot(d, side)].jump != LevelJump::Coarser) continue;
        double* flux = lv.face_flux[D(face_index(d, side))].block(blk);
        const double* xb = x.block(blk);
        const double* beta = lv.beta[D(d)].block(blk);
        for_face_cells(L, d, side, [&](std::ptrdiff_t c, std::ptrdiff_t g) {
          const double beta_face = side == 0 ? beta[c] : beta[g];
          flux[c] = beta_face * (xb[g] - xb[c]) / h;
        });
      }
  });
  // Only the coarse blocks' ghosts across coarse-fine faces are read below:
  // face_flux[face of the fine block] is needed beyond the opposite face of
  // the coarse one (a full exchange of the 6 fields took half the run time).
  for (int d = 0; d < 3; ++d)
    for (int side = 0; side < 2; ++side) {
      forest_.exchange_from_finer(lv.face_flux[D(face_index(d, side))], face_index(d, 1 - side));
    }
  for_each_face_to_finer(forest_, [&](int blk, const Neighbour&, int d, int side) {
    const double h = forest_.block(blk).length / b;
    double* xb = x.block(blk);
    // The fine blocks stored their fluxes under their own face: the opposite one.
    const double* fine = lv.face_flux[D(face_index(d, 1 - side))].block(blk);
    const double* beta = lv.beta[D(d)].block(blk);
    for_face_cells(L, d, side, [&](std::ptrdiff_t c, std::ptrdiff_t g) {
      const double beta_face = side == 0 ? beta[c] : beta[g];
      const double fine_flux = -2.0 * fine[g];
      if (beta_face > 0.0) xb[g] = xb[c] + h * fine_flux / beta_face;
    });
  });
}

// match_fluxes() where every block is local (one process): each coarse block
// reads the 4 fine fluxes of a face cell straight from its finer neighbours'
// cells and ghosts, instead of each fine block writing them into face_flux
// and an exchange restricting them back (a pass over 6 more fields, whose
// cache misses made match_fluxes and that exchange about a third of a
// composite V-cycle). The same operations in the same order as that path
// (the 8-cell mean of the exchange skips its 4 zeros, which adds nothing),
// so the same bits.
void Multigrid::match_fluxes_local(int level, BlockField& x) {
  Level& lv = levels_[D(level)];
  const BlockLayout L = x.layout();
  const int b = L.cells;
  for_each_face_to_finer(forest_, [&](int blk, const Neighbour& nb, int d, int side) {
    const double h = forest_.block(blk).length / b;
    double* xb = x.block(blk);
    const double* beta = lv.beta[D(d)].block(blk);
    // The face's cells by (p, q), p along its lower tangential axis (lo), q
    // along the higher (hi). This block's face layer is 0 along d for a lower
    // face, b - 1 for an upper one; its ghost lies one step outward. The
    // fine children's layer is the opposite one, their ghost one step back
    // towards this block; beta of a cell's lower face sits at the cell, of
    // its upper face one step up.
    const int lo = d == 0 ? 1 : 0, hi = d == 2 ? 1 : 2;
    const std::ptrdiff_t s_lo = L.stride(lo), s_hi = L.stride(hi);
    const std::ptrdiff_t outward = side == 0 ? -L.stride(d) : L.stride(d);
    const auto layer_start = [&](int layer) {
      std::array<int, 3> n{};
      n[D(d)] = layer;
      return L.index(n[0], n[1], n[2]);
    };
    const std::ptrdiff_t coarse_start = layer_start(side == 0 ? 0 : b - 1);
    const std::ptrdiff_t fine_start = layer_start(side == 0 ? b - 1 : 0);
    const std::ptrdiff_t coarse_beta_shift = side == 0 ? 0 : L.stride(d);
    const std::ptrdiff_t fine_beta_shift = side == 0 ? L.stride(d) : 0;
    const int layer_bit = side == 0 ? 1 : 0;  // the children's bit along d
    // The fine fluxes of the 4 children, by fine cell (2b per axis).
    const int w = 2 * b;
    thread_local std::vector<double> fine_flux;
    fine_flux.resize(static_cast<std::size_t>(w) * w);
    for (int c_hi = 0; c_hi < 2; ++c_hi)
      for (int c_lo = 0; c_lo < 2; ++c_lo) {
        const int child = (layer_bit << d) | (c_lo << lo) | (c_hi << hi);
        const int fine_blk = nb.children[D(child)].index;
        const double* xf = x.block(fine_blk);
        const double* beta_f = lv.beta[D(d)].block(fine_blk) + fine_beta_shift;
        const double h_f = forest_.block(fine_blk).length / b;
        // A constant-coefficient block's beta is one value: the same
        // number, without a pass over its face array.
        const bool constant = lv.block_constant[D(fine_blk)] != 0;
        const double beta_constant = lv.block_beta[D(fine_blk)];
        double* row = fine_flux.data() + D(c_hi * b * w + c_lo * b);
        for (int q = 0; q < b; ++q, row += w)
          for (int p = 0; p < b; ++p) {
            const std::ptrdiff_t f = fine_start + p * s_lo + q * s_hi;
            const double beta_face = constant ? beta_constant : beta_f[f];
            row[p] = beta_face * (xf[f - outward] - xf[f]) / h_f;
          }
      }
    const bool constant = lv.block_constant[D(blk)] != 0;
    const double beta_constant = lv.block_beta[D(blk)];
    for (int q = 0; q < b; ++q)
      for (int p = 0; p < b; ++p) {
        const std::ptrdiff_t c = coarse_start + p * s_lo + q * s_hi;
        // The exchange's order: the higher axis' offset outer, the lower's inner.
        const double* row0 = fine_flux.data() + D(2 * q * w + 2 * p);
        const double* row1 = row0 + w;
        double sum = 0.0;
        sum += row0[0];
        sum += row0[1];
        sum += row1[0];
        sum += row1[1];
        const double beta_face = constant ? beta_constant : beta[c + coarse_beta_shift];
        const double matched = -2.0 * (sum / 8.0);
        if (beta_face > 0.0) xb[c + outward] = xb[c] + h * matched / beta_face;
      }
  });
}

// The bottom level: one cell per leaf. Every rank gathers the leaves (level,
// coordinates, alpha, activity, the 6 face betas) in global p8est order and
// assembles the same volume-weighted operator V A: symmetric, so CG applies,
// and identical on every rank, so the answer does not depend on the
// partition. Between blocks of one level the flux is beta (x_j - x_i) h; at
// a coarse-fine face (area h_f^2, centres 1.5 h_f apart along the normal) it
// is beta (x_j - x_i) h_f / 1.5, counted once from the fine side, so that
// the coarse cell's flux is the sum of its fine neighbours' fluxes.
void Multigrid::build_composite_operator() {
  constexpr int kRecord = 12;  // level, coord x3, alpha, active, beta lower x3, beta upper x3
  const Level& c = levels_.back();
  const int local = forest_.local_blocks();
  std::vector<double> mine(static_cast<std::size_t>(local) * kRecord);
  for (int blk = 0; blk < local; ++blk) {
    const Block& block = forest_.block(blk);
    double* rec = mine.data() + static_cast<std::size_t>(blk) * kRecord;
    rec[0] = block.level;
    for (int d = 0; d < 3; ++d) rec[1 + d] = static_cast<double>(block.coord[D(d)]);
    rec[4] = c.alpha(blk, 0, 0, 0);
    rec[5] = c.active(blk, 0, 0, 0);
    for (int d = 0; d < 3; ++d) {
      std::array<int, 3> up{0, 0, 0};
      up[D(d)] = 1;
      rec[6 + d] = c.beta[D(d)](blk, 0, 0, 0);
      rec[9 + d] = c.beta[D(d)](blk, up[0], up[1], up[2]);
    }
  }
  const int ranks = forest_.ranks();
  std::vector<int> counts(static_cast<std::size_t>(ranks)),
      offsets(static_cast<std::size_t>(ranks));
  const int my_count = local * kRecord;
  MPI_Allgather(&my_count, 1, MPI_INT, counts.data(), 1, MPI_INT, forest_.comm());
  int total = 0;
  for (int r = 0; r < ranks; ++r) {
    offsets[D(r)] = total;
    total += counts[D(r)];
  }
  std::vector<double> all(static_cast<std::size_t>(total));
  MPI_Allgatherv(mine.data(), my_count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(),
                 MPI_DOUBLE, forest_.comm());
  const std::size_t leaves = static_cast<std::size_t>(total / kRecord);

  const auto& spec = forest_.spec();
  auto key = [&](int level, const std::array<std::int64_t, 3>& p) {
    const auto n = forest_.blocks_per_direction(level);
    return (static_cast<std::uint64_t>(level) << 58) |
           static_cast<std::uint64_t>((p[2] * n[1] + p[1]) * n[0] + p[0]);
  };
  auto record = [&](std::size_t i) { return all.data() + i * kRecord; };
  std::unordered_map<std::uint64_t, std::size_t> index;
  index.reserve(leaves);
  for (std::size_t i = 0; i < leaves; ++i) {
    const double* rec = record(i);
    index[key(static_cast<int>(rec[0]),
              {static_cast<std::int64_t>(rec[1]), static_cast<std::int64_t>(rec[2]),
               static_cast<std::int64_t>(rec[3])})] = i;
  }
  CompositeOperator& op = composite_op_;
  op.volume.assign(leaves, 0.0);
  op.active.assign(leaves, 0.0);
  op.diagonal.assign(leaves, 0.0);
  std::vector<std::vector<std::pair<std::size_t, double>>> rows(leaves);
  auto couple = [&](std::size_t i, std::size_t j, double a) {
    op.diagonal[i] += a;
    op.diagonal[j] += a;
    rows[i].emplace_back(j, -a);
    rows[j].emplace_back(i, -a);
  };
  for (std::size_t i = 0; i < leaves; ++i) {
    const double* rec = record(i);
    const int level = static_cast<int>(rec[0]);
    const std::array<std::int64_t, 3> p{static_cast<std::int64_t>(rec[1]),
                                        static_cast<std::int64_t>(rec[2]),
                                        static_cast<std::int64_t>(rec[3])};
    const double h = spec.tree_length / static_cast<double>(std::int64_t{1} << level);
    op.volume[i] = h * h * h;
    op.active[i] = rec[5];
    op.diagonal[i] += rec[4] * op.volume[i];
    const auto n = forest_.blocks_per_direction(level);
    for (int d = 0; d < 3; ++d)
      for (int side = 0; side < 2; ++side) {
        const double beta = rec[(side == 0 ? 6 : 9) + d];
        auto q = p;
        q[D(d)] += side == 0 ? -1 : 1;
        if (q[D(d)] < 0 || q[D(d)] >= n[D(d)]) {
          if (!spec.periodic[D(d)]) {
            if (kinds_[D(face_index(d, side))] == BcKind::Dirichlet) {
              op.diagonal[i] += 2.0 * h * beta;  // ghost -x at h/2 beyond the face
            }
            continue;
          }
          q[D(d)] = (q[D(d)] + n[D(d)]) % n[D(d)];
        }
        if (const auto same = index.find(key(level, q)); same != index.end()) {
          // Each face once, from its lower cell (a block its own periodic image: no flux).
          if (side == 1 && same->second != i) couple(i, same->second, h * beta);
          continue;
        }
        if (level > 0) {
          const auto coarse = index.find(key(level - 1, {q[0] >> 1, q[1] >> 1, q[2] >> 1}));
          if (coarse != index.end()) couple(i, coarse->second, h * beta / 1.5);
        }
        // A finer neighbour: counted from its side.
      }
  }
  op.row_start.assign(leaves + 1, 0);
  op.column.clear();
  op.value.clear();
  for (std::size_t i = 0; i < leaves; ++i) {
    if (op.active[i] == 0.0) {
      op.diagonal[i] = 1.0;  // a closed leaf: x = 0, no coupling (its betas are 0)
      rows[i].clear();
    }
    for (const auto& [j, a] : rows[i]) {
      if (op.active[j] == 0.0) continue;
      op.column.push_back(static_cast<std::int64_t>(j));
      op.value.push_back(a);
    }
    op.row_start[i + 1] = static_cast<std::int64_t>(op.column.size());
  }
}

void Multigrid::composite_solve() {
  Level& c = levels_.back();
  const CompositeOperator& op = composite_op_;
  const std::size_t cells = op.volume.size();
  const auto first = static_cast<std::size_t>(forest_.first_global_block());
  std::vector<double> rhs(cells, 0.0);
  for (int blk = 0; blk < forest_.local_blocks(); ++blk) {
    rhs[first + static_cast<std::size_t>(blk)] = c.rhs(blk, 0, 0, 0);
  }
  MPI_Allreduce(MPI_IN_PLACE, rhs.data(), static_cast<int>(cells), MPI_DOUBLE, MPI_SUM,
                forest_.comm());
  double active_volume = 0.0;
  for (std::size_t i = 0; i < cells; ++i) {
    rhs[i] *= op.volume[i] * op.active[i];
    active_volume += op.volume[i] * op.active[i];
  }
  // Singular problems: the constants are the null space of V A (its rows sum
  // to zero), so the volume-weighted rhs and residuals are kept summing to 0.
  auto project_sum = [&](std::vector<double>& v) {
    double sum = 0.0;
    for (std::size_t i = 0; i < cells; ++i) sum += op.active[i] * v[i];
    for (std::size_t i = 0; i < cells; ++i)
      v[i] -= op.active[i] * op.volume[i] * sum / active_volume;
  };
  if (singular_ && active_volume > 0.0) project_sum(rhs);
  auto apply = [&](const std::vector<double>& x, std::vector<double>& ax) {
    for (std::size_t i = 0; i < cells; ++i) {
      double sum = op.diagonal[i] * x[i];
      for (auto e = op.row_start[i]; e < op.row_start[i + 1]; ++e) {
        sum += op.value[static_cast<std::size_t>(e)] *
               x[static_cast<std::size_t>(op.column[static_cast<std::size_t>(e)])];
      }
      ax[i] = sum;
    }
  };
  std::vector<double> x = conjugate_gradients(rhs, apply, [&](std::vector<double>& r) {
    if (singular_ && active_volume > 0.0) project_sum(r);
  });
  if (singular_ && active_volume > 0.0) {
    double mean = 0.0;
    for (std::size_t i = 0; i < cells; ++i) mean += op.active[i] * op.volume[i] * x[i];
    mean /= active_volume;
    for (std::size_t i = 0; i < cells; ++i) x[i] -= op.active[i] * mean;
  }
  for (int blk = 0; blk < forest_.local_blocks(); ++blk) {
    c.x(blk, 0, 0, 0) = x[first + static_cast<std::size_t>(blk)];
  }
}

}  // namespace sanguis::flow
