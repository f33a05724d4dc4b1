#include "flow/forest.hpp"

#include <p8est.h>
#include <p8est_extended.h>
#include <p8est_ghost.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "flow/mpi_session.hpp"

namespace sanguis::flow {

struct Forest::P4estObjects {
  struct ConnectivityDeleter {
    void operator()(p8est_connectivity_t* c) const { p8est_connectivity_destroy(c); }
  };
  struct ForestDeleter {
    void operator()(p8est_t* p) const { p8est_destroy(p); }
  };
  struct GhostDeleter {
    void operator()(p8est_ghost_t* g) const { p8est_ghost_destroy(g); }
  };
  // Declared in creation order: destroyed ghost first, connectivity last.
  std::unique_ptr<p8est_connectivity_t, ConnectivityDeleter> connectivity;
  std::unique_ptr<p8est_t, ForestDeleter> forest;
  std::unique_ptr<p8est_ghost_t, GhostDeleter> ghost;
};

namespace {

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

/// Integer position of tree t in the brick (its lowest vertex).
std::array<std::int64_t, 3> tree_position(const p8est_connectivity_t& conn, p4est_topidx_t t) {
  const p4est_topidx_t v = conn.tree_to_vertex[P8EST_CHILDREN * t];
  std::array<std::int64_t, 3> pos{};
  for (int d = 0; d < 3; ++d) {
    pos[static_cast<std::size_t>(d)] = static_cast<std::int64_t>(conn.vertices[3 * v + d] + 0.5);
  }
  return pos;
}

std::array<std::int64_t, 3> block_coord(const std::array<std::int64_t, 3>& tree_pos,
                                        const p8est_quadrant_t& q) {
  const int shift = P8EST_MAXLEVEL - q.level;
  return {(tree_pos[0] << q.level) + (q.x >> shift), (tree_pos[1] << q.level) + (q.y >> shift),
          (tree_pos[2] << q.level) + (q.z >> shift)};
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
  partition();
}

Forest::~Forest() = default;

void Forest::partition() {
  p8est_partition(p4est_->forest.get(), 0, nullptr);
  p4est_->ghost.reset(p8est_ghost_new(p4est_->forest.get(), P8EST_CONNECT_FULL));
  build_blocks();
  build_neighbours();
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
  auto key = [this](int level, const std::array<std::int64_t, 3>& c) {
    const auto n = blocks_per_direction(level);
    return (static_cast<std::uint64_t>(level) << 58) |
           static_cast<std::uint64_t>((c[2] * n[1] + c[1]) * n[0] + c[0]);
  };
  std::unordered_map<std::uint64_t, Neighbour> known;
  known.reserve(blocks_.size() + static_cast<std::size_t>(remote_blocks_));
  for (std::size_t b = 0; b < blocks_.size(); ++b) {
    known[key(blocks_[b].level, blocks_[b].coord)] = {Link::Local, static_cast<std::int32_t>(b)};
  }
  const p8est_ghost_t& ghost = *p4est_->ghost;
  for (std::size_t g = 0; g < ghost.ghosts.elem_count; ++g) {
    const auto* q = static_cast<const p8est_quadrant_t*>(
        sc_array_index(const_cast<sc_array_t*>(&ghost.ghosts), g));
    const auto pos = tree_position(*p4est_->connectivity, q->p.piggy3.which_tree);
    known[key(q->level, block_coord(pos, *q))] = {Link::Remote, static_cast<std::int32_t>(g)};
  }
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
          if (outside) {
            nb = {Link::Boundary, -1};
            continue;
          }
          const auto found = known.find(key(block.level, c));
          if (found == known.end()) {
            // Neighbours at another level come with adaptivity (issue #7).
            throw std::logic_error("forest: a neighbour block is not at the same level");
          }
          nb = found->second;
        }
      }
    }
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

}  // namespace

void Forest::exchange(std::span<BlockField* const> fields, int width, bool faces_only) const {
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

  for_each_block([&](int blk) {
    const Block& block = blocks_[static_cast<std::size_t>(blk)];
    for (int oz = -1; oz <= 1; ++oz) {
      for (int oy = -1; oy <= 1; ++oy) {
        for (int ox = -1; ox <= 1; ++ox) {
          const int nonzero = (ox != 0) + (oy != 0) + (oz != 0);
          if (nonzero == 0 || (faces_only && nonzero > 1)) continue;
          const Neighbour nb =
              block.neighbours[static_cast<std::size_t>(neighbour_slot(ox, oy, oz))];
          if (nb.link == Link::Boundary) continue;
          const Range rx = ghost_range(ox, b, width), ry = ghost_range(oy, b, width),
                      rz = ghost_range(oz, b, width);
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
                  remote.data() + static_cast<std::size_t>(nb.index) * per_block + f * packed;
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
  });
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
