// Forest::adapt: refinement, coarsening, 2:1 balance, repartition, and the
// transfer of cell-centred fields (issue #7).
//
// Data transfer by matching before and after: p8est coarsens, refines and
// balances in place (no replace callbacks), then every new local block is
// matched by (level, coordinates) against the old local blocks: the same
// block (copied), its parent (prolonged) or its 8 children (restricted).
// That is complete because coarsening only merges families held by one rank
// (partition(.., for_coarsening = 1) keeps families together), refinement
// and balance only split local leaves, and each of them moves a leaf by one
// level at most per call (the old forest is 2:1 balanced, so the balance
// ripple refines a leaf once). The repartition that follows moves the data
// with p8est_transfer_fixed (Forest::partition).
#include <p8est_extended.h>

#include <algorithm>
#include <stdexcept>
#include <unordered_map>

#include "flow/coarse_fine.hpp"
#include "flow/forest_p4est.hpp"

namespace sanguis::flow {

namespace {

/// What the p8est callbacks see through p8est::user_pointer.
struct AdaptContext {
  std::array<int, 3> trees{};
  const p8est_connectivity_t* connectivity = nullptr;
  std::unordered_map<std::uint64_t, AdaptFlag> flags;

  [[nodiscard]] AdaptFlag flag(p4est_topidx_t tree, const p8est_quadrant_t& q) const {
    const auto coord = block_coord(tree_position(*connectivity, tree), q);
    const auto found = flags.find(block_key(trees, q.level, coord));
    return found == flags.end() ? AdaptFlag::Keep : found->second;
  }
};

const AdaptContext& context(const p8est_t* forest) {
  return *static_cast<const AdaptContext*>(forest->user_pointer);
}

int refine_callback(p8est_t* forest, p4est_topidx_t tree, p8est_quadrant_t* q) {
  return context(forest).flag(tree, *q) == AdaptFlag::Refine ? 1 : 0;
}

int coarsen_callback(p8est_t* forest, p4est_topidx_t tree, p8est_quadrant_t* family[]) {
  for (int c = 0; c < P8EST_CHILDREN; ++c) {
    if (context(forest).flag(tree, *family[c]) != AdaptFlag::Coarsen) return 0;
  }
  return 1;
}

void copy_block(const BlockField& from, int from_blk, BlockField& to, int to_blk) {
  const int b = to.cells();
  for (int k = 0; k < b; ++k)
    for (int j = 0; j < b; ++j)
      for (int i = 0; i < b; ++i) to(to_blk, i, j, k) = from(from_blk, i, j, k);
}

/// Child `child_bits` (per direction 0 or 1) of the parent block: each child
/// cell is the parent cell plus minmod-limited slopes times the offset of
/// the child cell centre (a quarter of the parent cell). The parent's ghosts
/// must hold its neighbours' cells, except beyond domain faces (`boundary`
/// per face 2d + side), where the one-sided interior difference is used.
void prolong_block(const BlockField& parent, int parent_blk, const std::array<bool, 6>& boundary,
                   const std::array<int, 3>& child_bits, BlockField& child, int child_blk) {
  const int b = child.cells();
  const BlockLayout& L = parent.layout();
  const double* u = parent.block(parent_blk);
  for (int k = 0; k < b; ++k)
    for (int j = 0; j < b; ++j)
      for (int i = 0; i < b; ++i) {
        const std::array<int, 3> fine{child_bits[0] * b + i, child_bits[1] * b + j,
                                      child_bits[2] * b + k};
        const std::array<int, 3> cell{fine[0] >> 1, fine[1] >> 1, fine[2] >> 1};
        const std::ptrdiff_t c = L.index(cell[0], cell[1], cell[2]);
        double value = u[c];
        for (std::size_t d = 0; d < 3; ++d) {
          const std::ptrdiff_t s = L.stride(static_cast<int>(d));
          const bool low_wall = cell[d] == 0 && boundary[2 * d];
          const bool high_wall = cell[d] == b - 1 && boundary[2 * d + 1];
          const double down = u[c] - u[c - s], up = u[c + s] - u[c];
          const double slope = low_wall ? up : (high_wall ? down : minmod(down, up));
          value += ((fine[d] & 1) ? 0.25 : -0.25) * slope;
        }
        child(child_blk, i, j, k) = value;
      }
}

/// Parent cells as the volume average of the 8 child cells they hold.
void restrict_block(const BlockField& old, const std::array<int, 8>& children, BlockField& parent,
                    int parent_blk) {
  const int b = parent.cells();
  for (int k = 0; k < b; ++k)
    for (int j = 0; j < b; ++j)
      for (int i = 0; i < b; ++i) {
        double sum = 0.0;
        for (int dk = 0; dk < 2; ++dk)
          for (int dj = 0; dj < 2; ++dj)
            for (int di = 0; di < 2; ++di) {
              const std::array<int, 3> fine{2 * i + di, 2 * j + dj, 2 * k + dk};
              const int child = (fine[0] / b) + 2 * (fine[1] / b) + 4 * (fine[2] / b);
              sum += old(children[static_cast<std::size_t>(child)], fine[0] % b, fine[1] % b,
                         fine[2] % b);
            }
        parent(parent_blk, i, j, k) = sum / 8.0;
      }
}

void copy_faces(const BlockField& from, int from_blk, int d, BlockField& to, int to_blk) {
  for_each_face(to.cells(), d,
                [&](int i, int j, int k) { to(to_blk, i, j, k) = from(from_blk, i, j, k); });
}

/// Parent faces of component d: the mean of the 4 child faces on each (the
/// flux through the parent face is their sum).
void restrict_faces(const BlockField& old, const std::array<int, 8>& children, int d,
                    BlockField& parent, int parent_blk) {
  const int b = parent.cells();
  const auto dd = static_cast<std::size_t>(d);
  const auto e1 = static_cast<std::size_t>((d + 1) % 3), e2 = static_cast<std::size_t>((d + 2) % 3);
  for_each_face(b, d, [&](int i, int j, int k) {
    const std::array<int, 3> face{i, j, k};
    double sum = 0.0;
    for (int t2 = 0; t2 < 2; ++t2)
      for (int t1 = 0; t1 < 2; ++t1) {
        std::array<int, 3> fine{};
        fine[dd] = 2 * face[dd];  // up to 2b: the upper children's slot b
        fine[e1] = 2 * face[e1] + t1;
        fine[e2] = 2 * face[e2] + t2;
        int child = 0;
        for (std::size_t x = 0; x < 3; ++x) {
          const int bit = std::min(fine[x] / b, 1);
          child |= bit << x;
          fine[x] -= bit * b;
        }
        sum += old(children[static_cast<std::size_t>(child)], fine[0], fine[1], fine[2]);
      }
    parent(parent_blk, face[0], face[1], face[2]) = sum / 4.0;
  });
}

/// Child faces of component d: on a parent face its value, inside a parent
/// cell the mean of the parent's two faces along d. Every child cell then
/// has the parent cell's divergence, and the parent faces' fluxes are kept.
void prolong_faces(const BlockField& parent, int parent_blk, const std::array<int, 3>& child_bits,
                   int d, BlockField& child, int child_blk) {
  const int b = child.cells();
  const auto dd = static_cast<std::size_t>(d);
  for_each_face(b, d, [&](int i, int j, int k) {
    const std::array<int, 3> face{i, j, k};
    std::array<int, 3> cell{};
    for (std::size_t x = 0; x < 3; ++x) cell[x] = (child_bits[x] * b + face[x]) >> 1;
    const int along = child_bits[dd] * b + face[dd];  // fine face number along d, 0..2b
    double value = 0.0;
    if ((along & 1) == 0) {
      cell[dd] = along / 2;
      value = parent(parent_blk, cell[0], cell[1], cell[2]);
    } else {
      cell[dd] = along / 2;
      const double below = parent(parent_blk, cell[0], cell[1], cell[2]);
      cell[dd] += 1;
      value = 0.5 * (below + parent(parent_blk, cell[0], cell[1], cell[2]));
    }
    child(child_blk, face[0], face[1], face[2]) = value;
  });
}

}  // namespace

namespace {

/// p8est_coarsen callback: a family of the level in the forest's user pointer.
int coarsen_level_callback(p8est_t* forest, p4est_topidx_t /*tree*/, p8est_quadrant_t* family[]) {
  return family[0]->level == *static_cast<const int*>(forest->user_pointer) ? 1 : 0;
}

}  // namespace

void Forest::assign_coarsened_finest_level(const Forest& fine) {
  if (!(fine.spec_ == spec_) || fine.max_level_ == 0) {
    throw std::invalid_argument(
        "forest: assign_coarsened_finest_level needs a forest of this spec with blocks below "
        "its trees");
  }
  // The copy borrows fine's connectivity; this forest's own is the same brick.
  std::unique_ptr<p8est_t, P4estObjects::ForestDeleter> copy(
      p8est_copy(fine.p4est_->forest.get(), 0));
  copy->connectivity = p4est_->connectivity.get();
  // A forest split evenly (as built, not yet adapted) may split a family over two ranks:
  // the copy is split as partition() splits it first (it carries no data).
  if (ranks_ > 1 && !fine.families_partitioned_) p8est_partition(copy.get(), 1, nullptr);
  int top = fine.max_level_;
  copy->user_pointer = &top;
  p8est_coarsen_ext(copy.get(), 0, 0, coarsen_level_callback, nullptr, nullptr);
  copy->user_pointer = nullptr;
  p4est_->ghost.reset();
  p4est_->forest = std::move(copy);
  // Merging the finest level keeps the 2:1 balance: no block there had a neighbour
  // more than one level coarser, and those of other levels do not change.
  if (ranks_ > 1) p8est_partition(p4est_->forest.get(), 1, nullptr);
  families_partitioned_ = true;
  rebuild_tables();
  if (max_level_ != top - 1) {
    throw std::logic_error(
        "forest: a family of the finest level is split over ranks; adapt() or partition() "
        "keep them whole");
  }
}

bool Forest::adapt(const std::function<AdaptFlag(const Block&)>& decide,
                   std::span<BlockField* const> fields, std::span<FaceField* const> face_fields,
                   int max_level) {
  std::vector<AdaptFlag> flags(blocks_.size());
  for (std::size_t b = 0; b < blocks_.size(); ++b) flags[b] = decide(blocks_[b]);
  return adapt(flags, fields, face_fields, max_level);
}

bool Forest::adapt(std::span<const AdaptFlag> flags, std::span<BlockField* const> fields,
                   std::span<FaceField* const> face_fields, int max_level) {
  if (flags.size() != blocks_.size()) {
    throw std::invalid_argument("forest: adapt needs one flag per local block");
  }
  for (const BlockField* f : fields) {
    if (f->blocks() != local_blocks()) {
      throw std::invalid_argument("forest: adapt: a field does not match the block list");
    }
  }
  for (const FaceField* uf : face_fields) {
    for (const BlockField& component : *uf) {
      if (component.blocks() != local_blocks() || component.layout().ghost < 1) {
        throw std::invalid_argument("forest: adapt: a face field does not match the block list");
      }
    }
  }
  // No rank has a family of 8 that all ask to merge (the only merge p8est
  // makes) or a block asking for a split below max_level, and the blocks are
  // already split over the ranks as adapt() splits them: nothing would
  // change, so the forest, its tables and the fields stay as they are (a
  // regrid of a settled grid then costs only its criterion).
  const int deepest = std::min(max_level, P8EST_QMAXLEVEL - 1);
  bool may_change = !families_partitioned_;
  for (std::size_t b = 0; b < blocks_.size() && !may_change; ++b) {
    may_change = (flags[b] == AdaptFlag::Refine && blocks_[b].level < deepest) ||
                 (is_family(static_cast<int>(b)) &&
                  std::all_of(flags.begin() + static_cast<std::ptrdiff_t>(b),
                              flags.begin() + static_cast<std::ptrdiff_t>(b) + 8,
                              [](AdaptFlag f) { return f == AdaptFlag::Coarsen; }));
  }
  if (max(may_change ? 1.0 : 0.0) == 0.0) return false;
  for (BlockField* f : fields) exchange(*f, 1);  // neighbours' cells for the prolongation slopes
  AdaptContext ctx;
  ctx.trees = spec_.trees;
  ctx.connectivity = p4est_->connectivity.get();
  std::unordered_map<std::uint64_t, int> old_index;
  for (std::size_t b = 0; b < blocks_.size(); ++b) {
    const std::uint64_t key = block_key(blocks_[b].level, blocks_[b].coord);
    ctx.flags[key] = flags[b];
    old_index[key] = static_cast<int>(b);
  }
  const std::vector<Block> old_blocks = blocks_;

  p8est_t* forest = p4est_->forest.get();
  void* const saved_pointer = forest->user_pointer;
  forest->user_pointer = &ctx;
  // Coarsen first, so that the flags still name the blocks they were given for.
  p8est_coarsen_ext(forest, 0, 0, coarsen_callback, nullptr, nullptr);
  p8est_refine_ext(forest, 0, deepest, refine_callback, nullptr, nullptr);
  p8est_balance_ext(forest, P8EST_CONNECT_FULL, nullptr, nullptr);
  forest->user_pointer = saved_pointer;
  build_blocks();  // the new local blocks (ghost tables follow in partition)

  // Match every new block with its source among the old ones.
  struct Source {
    enum class Kind { Copy, Prolong, Restrict } kind = Kind::Copy;
    std::array<int, 8> blocks{};  ///< old block(s): one for Copy and Prolong, 8 for Restrict
    std::array<int, 3> child_bits{};
  };
  std::vector<Source> sources(blocks_.size());
  int changed = blocks_.size() != old_blocks.size() ? 1 : 0;
  for (std::size_t n = 0; n < blocks_.size(); ++n) {
    const Block& block = blocks_[n];
    const auto& c = block.coord;
    Source& src = sources[n];
    if (const auto same = old_index.find(block_key(block.level, c)); same != old_index.end()) {
      src.blocks[0] = same->second;
      continue;
    }
    changed = 1;
    if (block.level > 0) {
      const auto parent =
          old_index.find(block_key(block.level - 1, {c[0] >> 1, c[1] >> 1, c[2] >> 1}));
      if (parent != old_index.end()) {
        src.kind = Source::Kind::Prolong;
        src.blocks[0] = parent->second;
        src.child_bits = {static_cast<int>(c[0] & 1), static_cast<int>(c[1] & 1),
                          static_cast<int>(c[2] & 1)};
        continue;
      }
    }
    src.kind = Source::Kind::Restrict;
    for (int child = 0; child < 8; ++child) {
      const auto found = old_index.find(block_key(
          block.level + 1,
          {2 * c[0] + (child & 1), 2 * c[1] + ((child >> 1) & 1), 2 * c[2] + ((child >> 2) & 1)}));
      if (found == old_index.end()) {
        throw std::logic_error("forest: adapt moved a block by more than one level");
      }
      src.blocks[static_cast<std::size_t>(child)] = found->second;
    }
  }
  for (BlockField* f : fields) {
    const BlockField old = std::move(*f);
    *f = BlockField(local_blocks(), old.cells(), old.layout().ghost);
    for (std::size_t n = 0; n < blocks_.size(); ++n) {
      const Source& src = sources[n];
      const int blk = static_cast<int>(n);
      switch (src.kind) {
        case Source::Kind::Copy:
          copy_block(old, src.blocks[0], *f, blk);
          break;
        case Source::Kind::Prolong:
          prolong_block(old, src.blocks[0],
                        domain_faces(old_blocks[static_cast<std::size_t>(src.blocks[0])]),
                        src.child_bits, *f, blk);
          break;
        case Source::Kind::Restrict:
          restrict_block(old, src.blocks, *f, blk);
          break;
      }
    }
  }
  for (FaceField* uf : face_fields) {
    for (int d = 0; d < 3; ++d) {
      BlockField& component = (*uf)[static_cast<std::size_t>(d)];
      const BlockField old = std::move(component);
      component = BlockField(local_blocks(), old.cells(), old.layout().ghost);
      for (std::size_t n = 0; n < blocks_.size(); ++n) {
        const Source& src = sources[n];
        const int blk = static_cast<int>(n);
        switch (src.kind) {
          case Source::Kind::Copy:
            copy_faces(old, src.blocks[0], d, component, blk);
            break;
          case Source::Kind::Prolong:
            prolong_faces(old, src.blocks[0], src.child_bits, d, component, blk);
            break;
          case Source::Kind::Restrict:
            restrict_faces(old, src.blocks, d, component, blk);
            break;
        }
      }
    }
  }
  MPI_Allreduce(MPI_IN_PLACE, &changed, 1, MPI_INT, MPI_MAX, comm_);
  std::vector<BlockField*> moving(fields.begin(), fields.end());
  for (FaceField* uf : face_fields) {
    for (BlockField& component : *uf) moving.push_back(&component);
  }
  // A repartition alone also changes the local block lists (the forests
  // built uniform are split evenly, adapt() keeps families together).
  const bool moved = partition(moving);
  return changed != 0 || moved;
}

}  // namespace sanguis::flow
