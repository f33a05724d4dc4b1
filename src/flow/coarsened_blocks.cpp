#include "flow/coarsened_blocks.hpp"

#include <mpi.h>

#include <algorithm>
#include <map>
#include <set>
#include <stdexcept>

#include "flow/payload_exchange.hpp"

namespace sanguis::flow {

namespace {

constexpr std::size_t D(int d) {
  return static_cast<std::size_t>(d);
}

using BlockId = std::array<std::int64_t, 4>;  // level, coord

BlockId id_of(const Block& block) {
  return {block.level, block.coord[0], block.coord[1], block.coord[2]};
}

BlockId parent_of(const BlockId& id) {
  return {id[0] - 1, id[1] >> 1, id[2] >> 1, id[3] >> 1};
}

/// Every rank's ids, in rank order, with their rank and local number.
std::map<BlockId, std::pair<int, std::int32_t>> all_blocks(const Forest& forest) {
  std::vector<std::int64_t> mine;
  for (int b = 0; b < forest.local_blocks(); ++b) {
    const BlockId id = id_of(forest.block(b));
    mine.insert(mine.end(), id.begin(), id.end());
  }
  const int ranks = forest.ranks();
  std::vector<int> counts(D(ranks), 0), offsets(D(ranks), 0);
  const int count = static_cast<int>(mine.size());
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, forest.comm());
  for (std::size_t r = 1; r < counts.size(); ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  std::vector<std::int64_t> all(D(offsets.back() + counts.back()));
  MPI_Allgatherv(mine.data(), count, MPI_INT64_T, all.data(), counts.data(), offsets.data(),
                 MPI_INT64_T, forest.comm());
  std::map<BlockId, std::pair<int, std::int32_t>> owner;
  for (int r = 0; r < ranks; ++r)
    for (int e = 0; e < counts[D(r)]; e += 4) {
      const auto at = D(offsets[D(r)] + e);
      owner[{all[at], all[at + 1], all[at + 2], all[at + 3]}] = {r, e / 4};
    }
  return owner;
}

/// Calls body(i, j, k) over the box n (x fastest).
template <typename Body>
void for_box(const std::array<int, 3>& n, Body&& body) {
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) body(i, j, k);
}

/// Copies the box n of block blk (from its cell 0) to out, x fastest.
void copy_out(const BlockField& f, int blk, const std::array<int, 3>& n, double* out) {
  std::size_t at = 0;
  for_box(n, [&](int i, int j, int k) { out[at++] = f(blk, i, j, k); });
}

/// Writes in, x fastest, into the box n of block blk from offset o.
void copy_in(const double* in, const std::array<int, 3>& n, const std::array<int, 3>& o,
             BlockField& f, int blk) {
  std::size_t at = 0;
  for_box(n, [&](int i, int j, int k) { f(blk, o[0] + i, o[1] + j, o[2] + k) = in[at++]; });
}

std::array<int, 3> octant_offset(int octant, int half) {
  return {(octant & 1) * half, ((octant >> 1) & 1) * half, ((octant >> 2) & 1) * half};
}

/// The parent faces along d that a child of `octant` makes up: b/2 per direction, and
/// the parent's face b as well for the child on the upper side along d.
std::array<int, 3> child_faces(int b, int d, int octant) {
  std::array<int, 3> n{b / 2, b / 2, b / 2};
  if (((octant >> d) & 1) != 0) n[D(d)] += 1;
  return n;
}

}  // namespace

std::unique_ptr<Forest> coarsen_finest_level(const Forest& fine) {
  if (fine.uniform()) throw std::invalid_argument("coarsen_finest_level: a uniform forest");
  auto coarse = std::make_unique<Forest>(fine.spec());
  coarsen_finest_level(fine, *coarse);
  return coarse;
}

void coarsen_finest_level(const Forest& fine, Forest& coarse) {
  if (fine.uniform()) throw std::invalid_argument("coarsen_finest_level: a uniform forest");
  const int top = fine.max_level();
  // The target's leaves: the fine forest's below the finest level and the parents of its
  // finest blocks.
  std::set<BlockId> target;
  for (const auto& [id, where] : all_blocks(fine)) {
    target.insert(id[0] == top ? parent_of(id) : id);
  }
  const auto under_a_target_leaf = [&](BlockId id) {
    while (id[0] > 0) {
      id = parent_of(id);
      if (target.count(id) != 0) return true;
    }
    return false;
  };
  // Towards the target, one level per pass each way (from the spec's uniform forest, or
  // from the last coarsened forest of a regridded one).
  const int passes = 2 * (std::max(top, coarse.max_level()) + 1);
  for (int pass = 0; pass < passes; ++pass) {
    const bool changed = coarse.adapt(
        [&](const Block& block) {
          const BlockId id = id_of(block);
          if (target.count(id) != 0) return AdaptFlag::Keep;
          return under_a_target_leaf(id) ? AdaptFlag::Coarsen : AdaptFlag::Refine;
        },
        {});
    if (!changed) break;
  }
  if (coarse.global_blocks() != static_cast<std::int64_t>(target.size())) {
    throw std::logic_error("coarsen_finest_level: the coarsened forest missed its target");
  }
}

CoarsenedBlocks::CoarsenedBlocks(const Forest& fine, const Forest& coarse)
    : fine_(fine), b_(fine.block_cells()) {
  if (coarse.block_cells() != b_ || fine.uniform() || coarse.max_level() + 1 != fine.max_level()) {
    throw std::invalid_argument(
        "coarsened blocks: the forests are not a composite one and its "
        "finest level coarsened");
  }
  const int top = fine.max_level();
  const auto owner = all_blocks(coarse);
  const int ranks = fine.ranks();
  send_.assign(D(ranks), {});
  receive_.assign(D(ranks), {});
  local_.assign(D(fine.local_blocks()), Link{});
  for (int f = 0; f < fine.local_blocks(); ++f) {
    const Block& block = fine.block(f);
    const bool child = block.level == top;
    const auto found = owner.find(child ? parent_of(id_of(block)) : id_of(block));
    if (found == owner.end()) throw std::logic_error("coarsened blocks: a block has no match");
    const auto [rank, c] = found->second;
    const auto& q = block.coord;
    const Link link{
        f, c,
        child ? static_cast<std::int32_t>((q[0] & 1) | ((q[1] & 1) << 1) | ((q[2] & 1) << 2)) : -1};
    if (rank == fine.rank()) {
      local_[D(f)] = link;
    } else {
      local_[D(f)] = Link{f, -1, link.octant};
      send_[D(rank)].push_back(link);
    }
  }
  if (ranks == 1) return;
  // Each rank tells the coarse blocks' ranks which (coarse block, octant) its blocks
  // feed, in the order their values will travel.
  std::vector<std::vector<std::array<std::int32_t, 2>>> headers(D(ranks));
  for (int r = 0; r < ranks; ++r)
    for (const Link& link : send_[D(r)]) headers[D(r)].push_back({link.coarse, link.octant});
  const auto received = exchange_pairs(fine.comm(), headers);
  for (int r = 0; r < ranks; ++r)
    for (const auto& [coarse_block, octant] : received[D(r)])
      receive_[D(r)].push_back(Link{-1, coarse_block, octant});
}

int CoarsenedBlocks::payload(const Link& link, Kind kind, int d) const {
  const int b = b_, h = b_ / 2;
  if (kind == Kind::Prolong) return b * b * b;
  if (kind == Kind::Cells) return link.octant < 0 ? b * b * b : h * h * h;
  if (link.octant < 0) return (b + 1) * b * b;
  const auto n = child_faces(b, d, link.octant);
  return n[0] * n[1] * n[2];
}

template <typename Produce, typename Consume>
void CoarsenedBlocks::move(Kind kind, int d, Produce&& produce, Consume&& consume) const {
  const std::size_t largest = D((b_ + 1) * b_ * b_);
  // This rank's links, one fine block each, in parallel (each value has one writer).
  fine_.for_each_block([&](int f) {
    const Link& link = local_[D(f)];
    if (link.coarse < 0) return;
    thread_local std::vector<double> scratch;
    scratch.resize(largest);
    produce(link, scratch.data());
    consume(link, scratch.data());
  });
  const int ranks = fine_.ranks();
  if (ranks == 1) return;
  const bool from_fine = kind != Kind::Prolong;
  exchange_payloads(
      fine_.comm(), from_fine ? send_ : receive_, from_fine ? receive_ : send_,
      [&](const Link& link) { return payload(link, kind, d); }, produce, consume);
}

void CoarsenedBlocks::restrict_cells(const BlockField& fine, BlockField& coarse) const {
  const int b = b_, h = b_ / 2;
  const auto produce = [&](const Link& link, double* out) {
    if (link.octant < 0) {
      copy_out(fine, link.fine, {b, b, b}, out);
      return;
    }
    std::size_t at = 0;
    for_box({h, h, h}, [&](int i, int j, int k) {
      double sum = 0.0;
      for_box({2, 2, 2}, [&](int a, int c, int e) {
        sum += fine(link.fine, 2 * i + a, 2 * j + c, 2 * k + e);
      });
      out[at++] = sum / 8.0;
    });
  };
  const auto consume = [&](const Link& link, const double* in) {
    if (link.octant < 0) {
      copy_in(in, {b, b, b}, {0, 0, 0}, coarse, link.coarse);
    } else {
      copy_in(in, {h, h, h}, octant_offset(link.octant, h), coarse, link.coarse);
    }
  };
  move(Kind::Cells, -1, produce, consume);
}

void CoarsenedBlocks::restrict_faces(const BlockField& fine, int d, BlockField& coarse) const {
  const int b = b_, h = b_ / 2;
  const int t1 = (d + 1) % 3, t2 = (d + 2) % 3;
  std::array<int, 3> whole{b, b, b};
  whole[D(d)] = b + 1;
  const auto produce = [&](const Link& link, double* out) {
    if (link.octant < 0) {
      copy_out(fine, link.fine, whole, out);
      return;
    }
    std::size_t at = 0;
    for_box(child_faces(b, d, link.octant), [&](int i, int j, int k) {
      double sum = 0.0;
      for (int s2 = 0; s2 < 2; ++s2)
        for (int s1 = 0; s1 < 2; ++s1) {
          std::array<int, 3> c{2 * i, 2 * j, 2 * k};
          c[D(t1)] += s1;
          c[D(t2)] += s2;
          sum += fine(link.fine, c[0], c[1], c[2]);
        }
      out[at++] = sum / 4.0;
    });
  };
  const auto consume = [&](const Link& link, const double* in) {
    if (link.octant < 0) {
      copy_in(in, whole, {0, 0, 0}, coarse, link.coarse);
    } else {
      copy_in(in, child_faces(b, d, link.octant), octant_offset(link.octant, h), coarse,
              link.coarse);
    }
  };
  move(Kind::Faces, d, produce, consume);
}

void CoarsenedBlocks::prolong_add(const BlockField& coarse, const BlockField* active,
                                  BlockField& fine) const {
  const int b = b_, h = b_ / 2;
  const auto produce = [&](const Link& link, double* out) {
    if (link.octant < 0) {
      copy_out(coarse, link.coarse, {b, b, b}, out);
      return;
    }
    std::size_t at = 0;
    const auto o = octant_offset(link.octant, h);
    for_box({b, b, b}, [&](int i, int j, int k) {
      const WeightedSum sum = trilinear_sum(coarse, active, link.coarse,
                                            {o[0] + (i >> 1), o[1] + (j >> 1), o[2] + (k >> 1)},
                                            {(i & 1) ? 1 : -1, (j & 1) ? 1 : -1, (k & 1) ? 1 : -1});
      out[at++] = sum.weight > 0.0 ? sum.value / sum.weight : 0.0;
    });
  };
  const auto consume = [&](const Link& link, const double* in) {
    std::size_t at = 0;
    for_box({b, b, b}, [&](int i, int j, int k) { fine(link.fine, i, j, k) += in[at++]; });
  };
  move(Kind::Prolong, -1, produce, consume);
}

}  // namespace sanguis::flow
