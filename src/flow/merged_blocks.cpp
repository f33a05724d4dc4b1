#include "flow/merged_blocks.hpp"

#include <mpi.h>

#include <stdexcept>

#include "flow/payload_exchange.hpp"

namespace sanguis::flow {

namespace {

constexpr std::size_t D(int d) {
  return static_cast<std::size_t>(d);
}

int octant_of(const std::array<std::int64_t, 3>& c) {
  return static_cast<int>((c[0] & 1) | ((c[1] & 1) << 1) | ((c[2] & 1) << 2));
}

/// Values a child moves: its cells (face_dir < 0), or its faces along face_dir,
/// the last one (slot b) only for the child on the upper side, so that every
/// merged face has one writer.
std::array<int, 3> child_box(int b, int face_dir, int octant) {
  std::array<int, 3> n{b, b, b};
  if (face_dir >= 0 && ((octant >> face_dir) & 1) != 0) n[D(face_dir)] = b + 1;
  return n;
}

/// Calls body(fine offset, merged offset) for every value of a child's box.
template <typename Body>
void for_child_values(const BlockLayout& fine, const BlockLayout& merged, int face_dir, int octant,
                      Body&& body) {
  const int b = fine.cells;
  const auto n = child_box(b, face_dir, octant);
  const int ox = (octant & 1) * b, oy = ((octant >> 1) & 1) * b, oz = ((octant >> 2) & 1) * b;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j) {
      const std::ptrdiff_t f = fine.index(0, j, k), m = merged.index(ox, oy + j, oz + k);
      for (int i = 0; i < n[0]; ++i) body(f + i, m + i);
    }
}

}  // namespace

std::optional<ForestSpec> merged_forest_spec(const Forest& fine, int max_cells) {
  if (!fine.uniform()) return std::nullopt;
  const ForestSpec& s = fine.spec();
  if (2 * s.block_cells > max_cells) return std::nullopt;
  ForestSpec m = s;
  m.block_cells = 2 * s.block_cells;
  const int level = fine.max_level();
  if (level >= 1) {
    m.level = level - 1;
  } else {
    for (int d = 0; d < 3; ++d) {
      if (s.trees[D(d)] % 2 != 0) return std::nullopt;
      m.trees[D(d)] = s.trees[D(d)] / 2;
    }
    m.tree_length = 2.0 * s.tree_length;
    m.level = 0;
  }
  for (int d = 0; d < 3; ++d) {
    if ((std::int64_t{m.trees[D(d)]} << m.level) < 2) return std::nullopt;
  }
  return m;
}

MergedBlocks::MergedBlocks(const Forest& fine, const Forest& merged)
    : fine_(fine), merged_(merged), b_(fine.block_cells()) {
  if (merged.block_cells() != 2 * b_ || !fine.uniform() || !merged.uniform()) {
    throw std::invalid_argument("merged blocks: the forests are not a uniform one and its merge");
  }
  // Each block's merged block: its parent, where it is a child of octant octant_of.
  std::vector<BlockTarget> targets(D(fine.local_blocks()));
  for (int blk = 0; blk < fine.local_blocks(); ++blk) {
    const auto& c = fine.block(blk).coord;
    targets[D(blk)] = {merged.max_level(), {c[0] >> 1, c[1] >> 1, c[2] >> 1}, octant_of(c)};
  }
  route_entries(route_blocks(merged, targets, "merged blocks"), targets, local_, send_, receive_);
}

template <bool kToMerged>
void MergedBlocks::transfer(const BlockField& from, BlockField& to, int face_dir) const {
  const BlockField& fine_field = kToMerged ? from : to;
  const BlockField& merged_field = kToMerged ? to : from;
  if (fine_field.cells() != b_ || merged_field.cells() != 2 * b_ ||
      fine_field.blocks() != fine_.local_blocks() ||
      merged_field.blocks() != merged_.local_blocks()) {
    throw std::invalid_argument("merged blocks: a field does not match its forest");
  }
  const BlockLayout& F = fine_field.layout();
  const BlockLayout& M = merged_field.layout();
  // This rank's children: one block each, in parallel (each merged value has one writer).
  fine_.for_each_block([&](int blk) {
    const Child& child = local_[D(blk)];
    if (child.merged < 0) return;
    if constexpr (kToMerged) {
      const double* src = from.block(blk);
      double* dst = to.block(child.merged);
      for_child_values(F, M, face_dir, child.octant,
                       [&](std::ptrdiff_t f, std::ptrdiff_t m) { dst[m] = src[f]; });
    } else {
      const double* src = from.block(child.merged);
      double* dst = to.block(blk);
      for_child_values(F, M, face_dir, child.octant,
                       [&](std::ptrdiff_t f, std::ptrdiff_t m) { dst[f] = src[m]; });
    }
  });
  const int ranks = fine_.ranks();
  if (ranks == 1) return;
  // The others: packed in the order of send_ (fine side) and receive_ (merged side).
  const auto values = [&](const Child& c) {
    const auto n = child_box(b_, face_dir, c.octant);
    return n[0] * n[1] * n[2];
  };
  exchange_payloads(
      fine_.comm(), kToMerged ? send_ : receive_, kToMerged ? receive_ : send_, values,
      [&](const Child& c, double* out) {
        const double* src = kToMerged ? from.block(c.block) : from.block(c.merged);
        std::size_t at = 0;
        for_child_values(F, M, face_dir, c.octant, [&](std::ptrdiff_t f, std::ptrdiff_t m) {
          out[at++] = src[kToMerged ? f : m];
        });
      },
      [&](const Child& c, const double* in) {
        double* dst = kToMerged ? to.block(c.merged) : to.block(c.block);
        std::size_t at = 0;
        for_child_values(F, M, face_dir, c.octant, [&](std::ptrdiff_t f, std::ptrdiff_t m) {
          dst[kToMerged ? m : f] = in[at++];
        });
      });
}

std::int64_t MergedBlocks::children_elsewhere() const {
  std::int64_t count = 0;
  for (const auto& list : send_) count += static_cast<std::int64_t>(list.size());
  return count;
}

void MergedBlocks::to_merged(const BlockField& fine, BlockField& merged) const {
  transfer<true>(fine, merged, -1);
}

void MergedBlocks::to_fine(const BlockField& merged, BlockField& fine) const {
  transfer<false>(merged, fine, -1);
}

void MergedBlocks::faces_to_merged(const BlockField& fine, int d, BlockField& merged) const {
  transfer<true>(fine, merged, d);
}

}  // namespace sanguis::flow
