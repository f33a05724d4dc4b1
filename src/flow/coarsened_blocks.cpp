#include "flow/coarsened_blocks.hpp"

#include <mpi.h>

#include <algorithm>
#include <stdexcept>

#include "flow/payload_exchange.hpp"

namespace sanguis::flow {

namespace {

constexpr std::size_t D(int d) {
  return static_cast<std::size_t>(d);
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
  auto coarse = std::make_unique<Forest>(fine.spec());
  coarse->assign_coarsened_finest_level(fine);
  return coarse;
}

CoarsenedBlocks::CoarsenedBlocks(const Forest& fine, const Forest& coarse)
    : fine_(fine), b_(fine.block_cells()) {
  if (coarse.block_cells() != b_ || coarse.max_level() + 1 != fine.max_level()) {
    throw std::invalid_argument(
        "coarsened blocks: the forests are not a forest and the same with its finest level "
        "coarsened");
  }
  const int top = fine.max_level();
  // Each block's coarse block: itself, or the parent of a block of the finest level.
  std::vector<BlockTarget> targets(D(fine.local_blocks()));
  for (int f = 0; f < fine.local_blocks(); ++f) {
    const Block& block = fine.block(f);
    const auto& q = block.coord;
    targets[D(f)] = block.level == top
                        ? BlockTarget{block.level - 1,
                                      {q[0] >> 1, q[1] >> 1, q[2] >> 1},
                                      static_cast<std::int32_t>((q[0] & 1) | ((q[1] & 1) << 1) |
                                                                ((q[2] & 1) << 2))}
                        : BlockTarget{block.level, q, -1};
  }
  route_entries(route_blocks(coarse, targets, "coarsened blocks"), targets, local_, send_,
                receive_);
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
