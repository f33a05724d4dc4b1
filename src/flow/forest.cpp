#include "flow/forest.hpp"

#include <p8est.h>
#include <p8est_communication.h>
#include <p8est_extended.h>
#include <p8est_ghost.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "flow/coarse_fine.hpp"
#include "flow/forest_p4est.hpp"
#include "flow/mpi_session.hpp"

namespace sanguis::flow {

namespace {

/// Index of the tree at brick position pos in Forest::P4estObjects::tree_at (x fastest).
std::size_t tree_slot(const ForestSpec& s, const std::array<std::int64_t, 3>& pos) {
  return static_cast<std::size_t>(pos[0] +
                                  s.trees[0] * (pos[1] + std::int64_t{s.trees[1]} * pos[2]));
}

void check_spec(const ForestSpec& s) {
  for (int d = 0; d < 3; ++d) {
    if (s.trees[static_cast<std::size_t>(d)] < 1) {
      throw std::invalid_argument("forest: trees per direction must be >= 1");
    }
  }
  const int b = s.block_cells;
  if (b < 2 || (b & (b - 1)) != 0) {
    throw std::invalid_argument("forest: block_cells must be a power of two >= 2, got " +
                                std::to_string(b));
  }
  if (s.level < 0 || s.level > P8EST_QMAXLEVEL - 1) {
    throw std::invalid_argument("forest: level out of range: " + std::to_string(s.level));
  }
  if (!(s.tree_length > 0.0)) {
    throw std::invalid_argument("forest: tree_length must be > 0");
  }
}

}  // namespace

Forest::Forest(const ForestSpec& spec) : spec_(spec), p4est_(std::make_unique<P4estObjects>()) {
  check_spec(spec_);
  MpiSession::ensure();
  comm_ = spec_.comm;
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &ranks_);
  p4est_->connectivity.reset(p8est_connectivity_new_brick(
      spec_.trees[0], spec_.trees[1], spec_.trees[2], spec_.periodic[0] ? 1 : 0,
      spec_.periodic[1] ? 1 : 0, spec_.periodic[2] ? 1 : 0));
  // Uniform refinement to `level`, already partitioned evenly.
  p4est_->forest.reset(
      p8est_new_ext(comm_, p4est_->connectivity.get(), 0, spec_.level, 1, 0, nullptr, nullptr));
  p8est_partition(p4est_->forest.get(), 0, nullptr);
  families_partitioned_ = ranks_ == 1;
  const p8est_connectivity_t& conn = *p4est_->connectivity;
  p4est_->tree_at.assign(static_cast<std::size_t>(conn.num_trees), 0);
  for (p4est_topidx_t t = 0; t < conn.num_trees; ++t)
    p4est_->tree_at[tree_slot(spec_, tree_position(conn, t))] = t;
  rebuild_tables();
}

int Forest::owner_of(int level, const std::array<std::int64_t, 3>& coord) const {
  std::array<std::int64_t, 3> tree{};
  p8est_quadrant_t q{};
  q.level = static_cast<std::int8_t>(level);
  const int shift = P8EST_MAXLEVEL - level;
  for (std::size_t d = 0; d < 3; ++d) {
    tree[d] = coord[d] >> level;
    const auto within = static_cast<p4est_qcoord_t>(coord[d] - (tree[d] << level));
    (d == 0 ? q.x : d == 1 ? q.y : q.z) = within << shift;
  }
  const auto t = p4est_->tree_at[tree_slot(spec_, tree)];
  return p8est_comm_find_owner(p4est_->forest.get(), t, &q, rank_);
}

Forest::~Forest() = default;

bool Forest::partition(std::span<BlockField* const> fields) {
  p8est_t* forest = p4est_->forest.get();
  for (const BlockField* f : fields) {
    if (f->blocks() != forest->local_num_quadrants) {
      throw std::invalid_argument("forest: partition: a field does not match the block list");
    }
  }
  const std::vector<p4est_gloidx_t> before(forest->global_first_quadrant,
                                           forest->global_first_quadrant + ranks_ + 1);
  // Families kept on one rank, so that a later adapt() may coarsen them.
  p8est_partition(forest, 1, nullptr);
  families_partitioned_ = true;
  const bool moved = !std::equal(before.begin(), before.end(), forest->global_first_quadrant);
  if (moved && !fields.empty()) migrate_fields(before, fields);
  rebuild_tables();
  return moved;
}

void Forest::rebuild_tables() {
  p4est_->ghost.reset(p8est_ghost_new(p4est_->forest.get(), P8EST_CONNECT_FULL));
  build_blocks();
  build_ghost_tables();
  build_neighbours();
}

void Forest::migrate_fields(const std::vector<std::int64_t>& before,
                            std::span<BlockField* const> fields) {
  // One fixed-size record per block: the whole storage of all fields in turn.
  std::size_t per_block = 0;
  for (const BlockField* f : fields) per_block += static_cast<std::size_t>(f->layout().size());
  const auto old_blocks = static_cast<std::size_t>(before[static_cast<std::size_t>(rank_) + 1] -
                                                   before[static_cast<std::size_t>(rank_)]);
  const p8est_t* forest = p4est_->forest.get();
  const auto new_blocks = static_cast<std::size_t>(forest->local_num_quadrants);
  std::vector<double> send(old_blocks * per_block), receive(new_blocks * per_block);
  for (std::size_t blk = 0; blk < old_blocks; ++blk) {
    double* out = send.data() + blk * per_block;
    for (const BlockField* f : fields) {
      const double* in = f->block(static_cast<int>(blk));
      out = std::copy(in, in + f->layout().size(), out);
    }
  }
  constexpr int kTransferTag = 0x5a17;
  p8est_transfer_fixed(forest->global_first_quadrant, before.data(), comm_, kTransferTag,
                       receive.data(), send.data(), per_block * sizeof(double));
  for (BlockField* f : fields) {
    *f = BlockField(static_cast<int>(new_blocks), f->cells(), f->layout().ghost);
  }
  for (std::size_t blk = 0; blk < new_blocks; ++blk) {
    const double* in = receive.data() + blk * per_block;
    for (BlockField* f : fields) {
      const std::ptrdiff_t size = f->layout().size();
      std::copy(in, in + size, f->block(static_cast<int>(blk)));
      in += size;
    }
  }
}

bool Forest::is_family(int first) const {
  if (first < 0 || first + 8 > local_blocks()) return false;
  const Block& b0 = block(first);
  if (b0.level == 0 || b0.coord[0] % 2 != 0 || b0.coord[1] % 2 != 0 || b0.coord[2] % 2 != 0) {
    return false;
  }
  for (int c = 1; c < 8; ++c) {
    const Block& child = block(first + c);
    if (child.level != b0.level || child.coord[0] != b0.coord[0] + (c & 1) ||
        child.coord[1] != b0.coord[1] + ((c >> 1) & 1) ||
        child.coord[2] != b0.coord[2] + ((c >> 2) & 1)) {
      return false;
    }
  }
  return true;
}

std::array<std::int64_t, 3> Forest::blocks_per_direction(int level) const {
  return {std::int64_t{spec_.trees[0]} << level, std::int64_t{spec_.trees[1]} << level,
          std::int64_t{spec_.trees[2]} << level};
}

Vec3 Forest::extent() const {
  return {spec_.trees[0] * spec_.tree_length, spec_.trees[1] * spec_.tree_length,
          spec_.trees[2] * spec_.tree_length};
}

void Forest::build_blocks() {
  const p8est_t& forest = *p4est_->forest;
  const p8est_connectivity_t& conn = *p4est_->connectivity;
  blocks_.clear();
  blocks_.reserve(static_cast<std::size_t>(forest.local_num_quadrants));
  for (p4est_topidx_t t = forest.first_local_tree; t <= forest.last_local_tree; ++t) {
    const auto* tree =
        static_cast<const p8est_tree_t*>(sc_array_index(forest.trees, static_cast<std::size_t>(t)));
    const auto tree_pos = tree_position(conn, t);
    for (std::size_t i = 0; i < tree->quadrants.elem_count; ++i) {
      const auto* q = static_cast<const p8est_quadrant_t*>(
          sc_array_index(const_cast<sc_array_t*>(&tree->quadrants), i));
      Block block;
      block.level = q->level;
      block.coord = block_coord(tree_pos, *q);
      block.length = spec_.tree_length / static_cast<double>(std::int64_t{1} << q->level);
      for (int d = 0; d < 3; ++d) {
        block.lower[d] =
            spec_.origin[d] +
            static_cast<double>(block.coord[static_cast<std::size_t>(d)]) * block.length;
      }
      blocks_.push_back(block);
    }
  }
  global_blocks_ = forest.global_num_quadrants;
  first_global_block_ = forest.global_first_quadrant[rank_];
  int lo = P8EST_QMAXLEVEL, hi = 0;
  for (const Block& block : blocks_) {
    lo = std::min(lo, block.level);
    hi = std::max(hi, block.level);
  }
  MPI_Allreduce(&lo, &min_level_, 1, MPI_INT, MPI_MIN, comm_);
  MPI_Allreduce(&hi, &max_level_, 1, MPI_INT, MPI_MAX, comm_);
}

std::uint64_t Forest::block_key(int level, const std::array<std::int64_t, 3>& c) const {
  return flow::block_key(spec_.trees, level, c);
}

void Forest::build_ghost_tables() {
  const p8est_ghost_t& ghost = *p4est_->ghost;
  remote_blocks_ = static_cast<std::int64_t>(ghost.ghosts.elem_count);
  mirror_blocks_.resize(ghost.mirrors.elem_count);
  for (std::size_t m = 0; m < ghost.mirrors.elem_count; ++m) {
    const auto* q = static_cast<const p8est_quadrant_t*>(
        sc_array_index(const_cast<sc_array_t*>(&ghost.mirrors), m));
    mirror_blocks_[m] = q->p.piggy3.local_num;
  }
}

void Forest::build_neighbours() {
  // Blocks of this rank and of the ghost layer by (level, coordinates).
  std::unordered_map<std::uint64_t, BlockRef> known;
  known.reserve(blocks_.size() + static_cast<std::size_t>(remote_blocks_));
  for (std::size_t b = 0; b < blocks_.size(); ++b) {
    known[block_key(blocks_[b].level, blocks_[b].coord)] = {Link::Local,
                                                            static_cast<std::int32_t>(b)};
  }
  const p8est_ghost_t& ghost = *p4est_->ghost;
  for (std::size_t g = 0; g < ghost.ghosts.elem_count; ++g) {
    const auto* q = static_cast<const p8est_quadrant_t*>(
        sc_array_index(const_cast<sc_array_t*>(&ghost.ghosts), g));
    const auto pos = tree_position(*p4est_->connectivity, q->p.piggy3.which_tree);
    known[block_key(q->level, block_coord(pos, *q))] = {Link::Remote, static_cast<std::int32_t>(g)};
  }
  auto find = [&](int level, const std::array<std::int64_t, 3>& c) -> const BlockRef* {
    const auto found = known.find(block_key(level, c));
    return found == known.end() ? nullptr : &found->second;
  };
  for (Block& block : blocks_) {
    const auto n = blocks_per_direction(block.level);
    for (int oz = -1; oz <= 1; ++oz) {
      for (int oy = -1; oy <= 1; ++oy) {
        for (int ox = -1; ox <= 1; ++ox) {
          if (ox == 0 && oy == 0 && oz == 0) continue;
          const std::array<int, 3> o{ox, oy, oz};
          std::array<std::int64_t, 3> c{};
          bool outside = false;
          for (std::size_t d = 0; d < 3; ++d) {
            c[d] = block.coord[d] + o[d];
            if (c[d] < 0 || c[d] >= n[d]) {
              if (spec_.periodic[d]) {
                c[d] = (c[d] + n[d]) % n[d];
              } else {
                outside = true;
              }
            }
          }
          Neighbour& nb = block.neighbours[static_cast<std::size_t>(neighbour_slot(ox, oy, oz))];
          nb = Neighbour{};
          if (outside) continue;
          if (const BlockRef* same = find(block.level, c)) {
            nb.link = same->link;
            nb.index = same->index;
            continue;
          }
          if (block.level > 0) {
            if (const BlockRef* parent = find(block.level - 1, {c[0] >> 1, c[1] >> 1, c[2] >> 1})) {
              nb.link = parent->link;
              nb.index = parent->index;
              nb.jump = LevelJump::Coarser;
              continue;
            }
          }
          // Finer: the children touching this block (child bit 1 on the low
          // side of an offset -1, 0 on the high side of +1, both along 0).
          nb.jump = LevelJump::Finer;
          for (int child = 0; child < 8; ++child) {
            std::array<std::int64_t, 3> cc{};
            bool touching = true;
            for (std::size_t d = 0; d < 3; ++d) {
              const int bit = (child >> d) & 1;
              touching = touching && (o[d] == 0 || bit == (o[d] < 0 ? 1 : 0));
              cc[d] = 2 * c[d] + bit;
            }
            if (!touching) continue;
            const BlockRef* fine = find(block.level + 1, cc);
            if (fine == nullptr) {
              throw std::logic_error("forest: neighbours differ by more than one level (2:1)");
            }
            nb.children[static_cast<std::size_t>(child)] = *fine;
            if (nb.index < 0) {
              nb.link = fine->link;
              nb.index = fine->index;
            }
          }
        }
      }
    }
  }
  list_face_exchanges();
}

void Forest::list_face_exchanges() {
  faces_apart_blocks_.clear();
  beside_finer_blocks_.clear();
  beside_coarser_blocks_.clear();
  for (auto& list : finer_face_blocks_) list.clear();
  for (std::size_t b = 0; b < blocks_.size(); ++b) {
    const auto blk = static_cast<std::int32_t>(b);
    bool apart = false, finer = false, coarser = false;
    for (int f = 0; f < 6; ++f) {
      const Neighbour& nb = blocks_[b].neighbours[face_neighbour_slot(f / 2, f % 2)];
      if (nb.link == Link::Boundary) continue;
      apart = apart || nb.link != Link::Local || nb.jump != LevelJump::Same;
      finer = finer || nb.jump == LevelJump::Finer;
      coarser = coarser || nb.jump == LevelJump::Coarser;
      if (nb.jump == LevelJump::Finer)
        finer_face_blocks_[static_cast<std::size_t>(f)].push_back(blk);
    }
    if (apart) faces_apart_blocks_.push_back(blk);
    if (finer) beside_finer_blocks_.push_back(blk);
    if (coarser) beside_coarser_blocks_.push_back(blk);
  }
}

namespace {

/// Index range of the ghost region towards offset o (per direction), and the
/// shift from a ghost cell to the neighbour's interior cell it copies.
struct Range {
  int begin, end, shift;
};
Range ghost_range(int o, int b, int width) {
  if (o < 0) return {-width, 0, b};
  if (o > 0) return {b, b + width, -b};
  return {0, b, 0};
}

/// Ghosts of a fine block in the region towards offset o from the coarser
/// neighbour there: quadratic interpolation of its interior. The region's
/// cells, shifted by r.shift, count from the lower corner of the same-level
/// block at coord + o, which is child ((coord + o) & 1) of the coarse block.
/// With centre_axis >= 0 (a region one cell deep along it) the value along
/// that axis is the coarse cell's own, at its centre, not the interpolant at
/// the ghost's (the coarse layer across a face, fill_composite_face_ghosts).
void fill_from_coarser(const Block& block, const std::array<int, 3>& o,
                       const std::array<Range, 3>& r, const CellReader& coarse, BlockField& field,
                       int blk, int centre_axis = -1) {
  const int b = field.cells();
  std::array<int, 3> child_offset{};
  for (std::size_t d = 0; d < 3; ++d) {
    child_offset[d] = static_cast<int>((block.coord[d] + o[d]) & 1) * b;
  }
  double* dst = field.block(blk);
  const BlockLayout& L = field.layout();
  // The tensor-product interpolant of coarse_fine.hpp, one direction at a
  // time (x, then y, then z: the same operations in the same order as
  // interpolate_from_coarse, so the same bits, with ~4x fewer of them on a
  // face region): the weights per fine index, then the coarse rows needed.
  std::array<const AxisWeights*, 3> w{};
  std::array<int, 3> lo{}, hi{};  // coarse cells read, per direction
  const AxisWeights* table = axis_weight_table(b);
  AxisWeights centre;  // the coarse cell under the region, weight 1 (count 1)
  for (std::size_t d = 0; d < 3; ++d) {
    // The fine indices of the region are consecutive, and the weights'
    // first cell grows with them.
    const int fine = child_offset[d] + r[d].begin + r[d].shift;
    if (static_cast<int>(d) == centre_axis) {
      centre.first = fine >> 1;
      w[d] = &centre;
    } else {
      w[d] = table + fine;
    }
    const AxisWeights& last = w[d][r[d].end - r[d].begin - 1];
    lo[d] = w[d][0].first;
    hi[d] = last.first + last.count;
  }
  const int ni = r[0].end - r[0].begin, nj = r[1].end - r[1].begin, nk = r[2].end - r[2].begin;
  const int cy = hi[1] - lo[1], cz = hi[2] - lo[2];
  thread_local std::vector<double> rows, planes;  // [i][y][z] and [i][j][z]
  rows.assign(static_cast<std::size_t>(ni) * cy * cz, 0.0);
  planes.assign(static_cast<std::size_t>(ni) * nj * cz, 0.0);
  for (int i = 0; i < ni; ++i) {
    const AxisWeights& ax = w[0][i];
    for (int y = 0; y < cy; ++y)
      for (int z = 0; z < cz; ++z) {
        double row = 0.0;
        for (int a = 0; a < ax.count; ++a) {
          row += ax.w[static_cast<std::size_t>(a)] * coarse(ax.first + a, lo[1] + y, lo[2] + z);
        }
        rows[(static_cast<std::size_t>(i) * cy + y) * cz + z] = row;
      }
  }
  for (int i = 0; i < ni; ++i)
    for (int j = 0; j < nj; ++j) {
      const AxisWeights& ay = w[1][j];
      for (int z = 0; z < cz; ++z) {
        double plane = 0.0;
        for (int c = 0; c < ay.count; ++c) {
          plane += ay.w[static_cast<std::size_t>(c)] *
                   rows[(static_cast<std::size_t>(i) * cy + (ay.first + c - lo[1])) * cz + z];
        }
        planes[(static_cast<std::size_t>(i) * nj + j) * cz + z] = plane;
      }
    }
  for (int k = 0; k < nk; ++k) {
    const AxisWeights& az = w[2][k];
    for (int j = 0; j < nj; ++j)
      for (int i = 0; i < ni; ++i) {
        double value = 0.0;
        for (int c = 0; c < az.count; ++c) {
          value += az.w[static_cast<std::size_t>(c)] *
                   planes[(static_cast<std::size_t>(i) * nj + j) * cz + (az.first + c - lo[2])];
        }
        dst[L.index(r[0].begin + i, r[1].begin + j, r[2].begin + k)] = value;
      }
  }
}

/// The ghosts of a fine block across the face towards offset o (one nonzero
/// component, along d) from the coarser neighbour there, by the composite
/// operator's rule (CoarseGhosts::Composite): the first layer
/// kGhostCoarse c + kGhostFace x_f + kGhostSecond x_f2, c the coarse layer
/// beside the face interpolated across it (the tensor-product weights of
/// fill_from_coarser with, along d, the coarse cell that holds the ghost: its
/// centre, not the ghost's); deeper layers as fill_from_coarser.
void fill_composite_face_ghosts(const Block& block, const std::array<int, 3>& o,
                                const std::array<Range, 3>& r, const CellReader& coarse,
                                BlockField& field, int blk) {
  int d = 0;
  while (o[static_cast<std::size_t>(d)] == 0) ++d;
  const auto dd = static_cast<std::size_t>(d);
  const int side = o[dd] < 0 ? 0 : 1;
  const int b = field.cells();
  const int first = side == 0 ? -1 : b;  // the first ghost layer along d
  if (r[dd].end - r[dd].begin > 1) {     // the deeper layers: interpolated
    std::array<Range, 3> deeper = r;
    if (side == 0) {
      deeper[dd].end = first;
    } else {
      deeper[dd].begin = first + 1;
    }
    fill_from_coarser(block, o, deeper, coarse, field, blk);
  }
  // The coarse layer beside the face, interpolated across it, into the first
  // ghost layer; then the quadratic along d through it and this block's two
  // cells beside the face.
  std::array<Range, 3> layer = r;
  layer[dd] = {first, first + 1, r[dd].shift};
  fill_from_coarser(block, o, layer, coarse, field, blk, d);
  const int lo = d == 0 ? 1 : 0, hi = d == 2 ? 1 : 2;
  const BlockLayout& L = field.layout();
  double* dst = field.block(blk);
  const std::ptrdiff_t inward = side == 0 ? L.stride(d) : -L.stride(d);
  std::array<int, 3> n{};
  n[dd] = side == 0 ? 0 : b - 1;  // this block's cell beside the face
  for (int q = 0; q < b; ++q)
    for (int p = 0; p < b; ++p) {
      n[static_cast<std::size_t>(lo)] = p;
      n[static_cast<std::size_t>(hi)] = q;
      const std::ptrdiff_t cell = L.index(n[0], n[1], n[2]);
      double& ghost = dst[cell - inward];
      ghost = kGhostCoarse * ghost + kGhostFace * dst[cell] + kGhostSecond * dst[cell + inward];
    }
}

/// Ghosts of a coarse block in the region towards offset o from the finer
/// children there: the mean of the 8 fine cells of each ghost cell. Fine
/// cells that would lie in a child not touching the block (ghosts deeper
/// than b/2 cells: blocks of 1 cell on the coarsest multigrid level, or the
/// 4 layers of the wavelet criterion's parent test with b = 4) are clamped
/// to the touching child's last layer.
void fill_from_finer(const std::array<int, 3>& o, const std::array<Range, 3>& r,
                     const std::array<CellReader, 8>& children, BlockField& field, int blk) {
  const int b = field.cells();
  double* dst = field.block(blk);
  const BlockLayout& L = field.layout();
  // Whether some fine cell needs the clamp: the region reaches deeper than
  // b/2 cells towards a finer neighbour (always for b = 1, whose 2 fine
  // cells per direction lie in 2 children).
  bool clamps = b % 2 != 0;
  for (std::size_t d = 0; d < 3; ++d) {
    if (o[d] > 0) clamps = clamps || 2 * (r[d].end - 1 + r[d].shift) + 1 > b - 1;
    if (o[d] < 0) clamps = clamps || 2 * (r[d].begin + r[d].shift) < b;
  }
  if (!clamps) {
    // The 8 fine cells of a ghost cell (2c, 2c + 1 per direction, b even)
    // then lie in one child: read them there, in the order of the general
    // loop below (so the same bits), without the per-cell clamp.
    for (int k = r[2].begin; k < r[2].end; ++k) {
      const int fz = 2 * (k + r[2].shift), cz = fz >= b ? 1 : 0;
      for (int j = r[1].begin; j < r[1].end; ++j) {
        const int fy = 2 * (j + r[1].shift), cy = fy >= b ? 1 : 0;
        for (int i = r[0].begin; i < r[0].end; ++i) {
          const int fx = 2 * (i + r[0].shift), cx = fx >= b ? 1 : 0;
          const CellReader& child = children[static_cast<std::size_t>(cx + 2 * cy + 4 * cz)];
          const double* c000 = child.origin + (fx - cx * b) * child.stride[0] +
                               (fy - cy * b) * child.stride[1] + (fz - cz * b) * child.stride[2];
          const std::ptrdiff_t sx = child.stride[0], sy = child.stride[1], sz = child.stride[2];
          double sum = 0.0;
          sum += c000[0];
          sum += c000[sx];
          sum += c000[sy];
          sum += c000[sx + sy];
          sum += c000[sz];
          sum += c000[sx + sz];
          sum += c000[sy + sz];
          sum += c000[sx + sy + sz];
          dst[L.index(i, j, k)] = sum / 8.0;
        }
      }
    }
    return;
  }
  auto clamp_fine = [b](int fine, int offset) {
    if (offset > 0) return std::min(fine, b - 1);  // touching children: bit 0
    if (offset < 0) return std::max(fine, b);      // touching children: bit 1
    return fine;
  };
  for (int k = r[2].begin; k < r[2].end; ++k)
    for (int j = r[1].begin; j < r[1].end; ++j)
      for (int i = r[0].begin; i < r[0].end; ++i) {
        const std::array<int, 3> cell{i + r[0].shift, j + r[1].shift, k + r[2].shift};
        double sum = 0.0;
        for (int dk = 0; dk < 2; ++dk)
          for (int dj = 0; dj < 2; ++dj)
            for (int di = 0; di < 2; ++di) {
              const std::array<int, 3> delta{di, dj, dk};
              std::array<int, 3> fine{};
              int child = 0;
              for (std::size_t d = 0; d < 3; ++d) {
                fine[d] = clamp_fine(2 * cell[d] + delta[d], o[d]);
                child |= (fine[d] >= b ? 1 : 0) << d;
                fine[d] -= fine[d] >= b ? b : 0;
              }
              sum += children[static_cast<std::size_t>(child)](fine[0], fine[1], fine[2]);
            }
        dst[L.index(i, j, k)] = sum / 8.0;
      }
}

}  // namespace

void Forest::exchange(std::span<BlockField* const> fields, int width, bool faces_only,
                      CoarseGhosts coarse_ghosts) const {
  exchange_scoped(fields, width, faces_only, -1, false, coarse_ghosts);
}

void Forest::copy_face_ghosts(BlockField& field, int blk, int colour) const {
  const BlockLayout L = field.layout();
  const int b = L.cells;
  const Block& block = blocks_[static_cast<std::size_t>(blk)];
  const int parity = static_cast<int>((block.coord[0] + block.coord[1] + block.coord[2]) * b) & 1;
  double* dst = field.block(blk);
  for (int d = 0; d < 3; ++d) {
    // The face's cells by (t1, t2), t1 the faster-varying of the other two directions.
    const int a1 = d == 0 ? 1 : 0, a2 = d == 2 ? 1 : 2;
    const std::ptrdiff_t s1 = L.stride(a1), s2 = L.stride(a2), sd = L.stride(d);
    for (int side = 0; side < 2; ++side) {
      const Neighbour& nb = block.neighbours[face_neighbour_slot(d, side)];
      if (nb.link != Link::Local || nb.jump != LevelJump::Same) continue;
      const int ghost = side == 0 ? -1 : b, from = side == 0 ? b - 1 : 0;
      double* to = dst + L.index(0, 0, 0) + ghost * sd;
      const double* src = field.block(nb.index) + L.index(0, 0, 0) + from * sd;
      const int step = colour < 0 ? 1 : 2;
      for (int t2 = 0; t2 < b; ++t2) {
        // (ghost + t1 + t2 + parity) & 1 == colour
        const int first = colour < 0 ? 0 : (colour + ghost + t2 + parity) & 1;
        for (int t1 = first; t1 < b; t1 += step) {
          const std::ptrdiff_t c = t1 * s1 + t2 * s2;
          to[c] = src[c];
        }
      }
    }
  }
}

void Forest::exchange_from_finer(BlockField& field, int face) const {
  BlockField* one[] = {&field};
  exchange_scoped(one, 1, true, face);
}

void Forest::exchange_face_ghosts_but_local_same_level(BlockField& field,
                                                       CoarseGhosts coarse_ghosts) const {
  BlockField* one[] = {&field};
  exchange_scoped(one, 1, true, -1, true, coarse_ghosts);
}

void Forest::fill_block_ghosts(std::span<BlockField* const> fields, int blk, int width,
                               GhostExtent extent, int finer_face, bool skip_local_same_level,
                               CoarseGhosts coarse_ghosts, const double* remote) const {
  const BlockLayout layout = fields[0]->layout();
  const int b = layout.cells;
  const std::size_t nf = fields.size();
  const std::size_t packed = static_cast<std::size_t>(b) * b * b;  // one field of one block
  const std::size_t per_block = nf * packed;
  const Block& block = blocks_[static_cast<std::size_t>(blk)];
  for (int oz = -1; oz <= 1; ++oz) {
    for (int oy = -1; oy <= 1; ++oy) {
      for (int ox = -1; ox <= 1; ++ox) {
        const int nonzero = (ox != 0) + (oy != 0) + (oz != 0);
        if (nonzero == 0 || (extent == GhostExtent::Faces && nonzero > 1)) continue;
        if (extent == GhostExtent::Stencil && nonzero == 3) continue;
        if (finer_face >= 0 && (nonzero != 1 || offset_face(ox, oy, oz) != finer_face)) continue;
        const Neighbour& nb =
            block.neighbours[static_cast<std::size_t>(neighbour_slot(ox, oy, oz))];
        if (nb.link == Link::Boundary) continue;
        if (finer_face >= 0 && nb.jump != LevelJump::Finer) continue;
        if (skip_local_same_level && nb.jump == LevelJump::Same && nb.link == Link::Local) {
          continue;
        }
        // The stencil's edges one layer deep (what a stencil reading one
        // transverse neighbour of a face ghost needs).
        const int deep = extent == GhostExtent::Stencil && nonzero == 2 ? 1 : width;
        const Range rx = ghost_range(ox, b, deep), ry = ghost_range(oy, b, deep),
                    rz = ghost_range(oz, b, deep);
        if (nb.jump != LevelJump::Same) {
          const std::array<Range, 3> r{rx, ry, rz};
          const std::array<int, 3> o{ox, oy, oz};
          for (std::size_t f = 0; f < nf; ++f) {
            auto reader = [&](const BlockRef& ref) {
              if (ref.link == Link::Local) {
                return CellReader{fields[f]->block(ref.index) + layout.index(0, 0, 0),
                                  {1, layout.stride(1), layout.stride(2)}};
              }
              return CellReader{
                  remote + static_cast<std::size_t>(ref.index) * per_block + f * packed,
                  {1, b, std::ptrdiff_t{b} * b}};
            };
            if (nb.jump == LevelJump::Coarser) {
              if (coarse_ghosts == CoarseGhosts::Composite && nonzero == 1 &&
                  composite_ghost_fits(b)) {
                fill_composite_face_ghosts(block, o, r, reader({nb.link, nb.index}), *fields[f],
                                           blk);
              } else {
                fill_from_coarser(block, o, r, reader({nb.link, nb.index}), *fields[f], blk);
              }
            } else {
              std::array<CellReader, 8> children{};
              for (std::size_t c = 0; c < 8; ++c) {
                if (nb.children[c].link != Link::Boundary) children[c] = reader(nb.children[c]);
              }
              fill_from_finer(o, r, children, *fields[f], blk);
            }
          }
          continue;
        }
        for (std::size_t f = 0; f < nf; ++f) {
          double* dst = fields[f]->block(blk);
          if (nb.link == Link::Local) {
            const double* src = fields[f]->block(nb.index);
            const int row = rx.end - rx.begin;  // short rows: a plain loop, no memmove call
            for (int k = rz.begin; k < rz.end; ++k)
              for (int j = ry.begin; j < ry.end; ++j) {
                const double* from =
                    src + layout.index(rx.begin + rx.shift, j + ry.shift, k + rz.shift);
                double* to = dst + layout.index(rx.begin, j, k);
                for (int i = 0; i < row; ++i) to[i] = from[i];
              }
          } else {
            const double* src =
                remote + static_cast<std::size_t>(nb.index) * per_block + f * packed;
            for (int k = rz.begin; k < rz.end; ++k)
              for (int j = ry.begin; j < ry.end; ++j)
                for (int i = rx.begin; i < rx.end; ++i)
                  dst[layout.index(i, j, k)] = src[(static_cast<std::size_t>(k + rz.shift) * b +
                                                    static_cast<std::size_t>(j + ry.shift)) *
                                                       b +
                                                   static_cast<std::size_t>(i + rx.shift)];
          }
        }
      }
    }
  }
}

void Forest::exchange_scoped(std::span<BlockField* const> fields, int width, bool faces_only,
                             int finer_face, bool skip_local_same_level,
                             CoarseGhosts coarse_ghosts) const {
  if (fields.empty()) return;
  const BlockLayout layout = fields[0]->layout();
  const int b = layout.cells;
  width = std::min({width, b, layout.ghost});
  const std::size_t nf = fields.size();
  const std::size_t packed = static_cast<std::size_t>(b) * b * b;  // one field of one block
  const std::size_t per_block = nf * packed;

  // Remote neighbours: the interiors of our mirror blocks travel to the ranks
  // that hold them in their ghost layer.
  std::vector<double> remote;
  if (ranks_ > 1) {
    std::vector<double> mirror_data(mirror_blocks_.size() * per_block);
    std::vector<void*> mirror_ptrs(mirror_blocks_.size());
    for (std::size_t m = 0; m < mirror_blocks_.size(); ++m) {
      double* out = mirror_data.data() + m * per_block;
      mirror_ptrs[m] = out;
      for (std::size_t f = 0; f < nf; ++f) {
        const double* in = fields[f]->block(mirror_blocks_[m]);
        for (int k = 0; k < b; ++k)
          for (int j = 0; j < b; ++j)
            for (int i = 0; i < b; ++i) *out++ = in[layout.index(i, j, k)];
      }
    }
    remote.resize(static_cast<std::size_t>(remote_blocks_) * per_block);
    p8est_ghost_exchange_custom(p4est_->forest.get(), p4est_->ghost.get(),
                                per_block * sizeof(double), mirror_ptrs.data(), remote.data());
  }

  const auto fill = [&](int blk) {
    fill_block_ghosts(fields, blk, width, faces_only ? GhostExtent::Faces : GhostExtent::All,
                      finer_face, skip_local_same_level, coarse_ghosts, remote.data());
  };
  // Only the blocks with something to fill when the exchange is narrowed.
  if (finer_face >= 0) {
    for_each_listed(finer_face_blocks_[static_cast<std::size_t>(finer_face)], fill);
  } else if (skip_local_same_level && faces_only) {
    for_each_listed(faces_apart_blocks_, fill);
  } else {
    for_each_block(fill);
  }
}

bool Forest::uniform_local() const {
  return ranks_ == 1 && min_level_ == max_level_;
}

void Forest::fill_same_level_ghosts(std::span<BlockField* const> fields, int blk, int width,
                                    bool stencil_only) const {
  if (fields.empty()) return;
  const BlockLayout layout = fields[0]->layout();
  width = std::min({width, layout.cells, layout.ghost});
  fill_block_ghosts(fields, blk, width, stencil_only ? GhostExtent::Stencil : GhostExtent::All, -1,
                    false, CoarseGhosts::Interpolated, nullptr);
}

double Forest::sum(double local) const {
  double global = 0.0;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_SUM, comm_);
  return global;
}

double Forest::max(double local) const {
  double global = 0.0;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_MAX, comm_);
  return global;
}

}  // namespace sanguis::flow
