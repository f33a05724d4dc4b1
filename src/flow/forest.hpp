#pragma once
// A forest of blocks: a p8est forest of octrees over a brick of trees (a
// rectangular domain of any aspect ratio, periodic per direction) whose leaves
// each carry a block of b^3 cells with ghost layers (see block_field.hpp).
//
// The forest owns the p4est objects (connectivity, forest, ghost layer) and
// answers for every local block: its level, its integer coordinates among the
// blocks of that level, its position, and its 26 neighbours (a local block, a
// remote block from the ghost layer, or the domain boundary). Ghost exchange
// copies neighbour interiors into the ghost layers, within one rank and
// across ranks (p8est_ghost_exchange_custom over the mirror blocks).
//
// Adaptivity (issue #7, first milestone): blocks may differ by one level
// across faces, edges and corners (p8est 2:1 balance, P8EST_CONNECT_FULL).
// A neighbour is then one level coarser (its parent region is a leaf) or
// finer (the children of the same-level region that touch the block are
// leaves); `Neighbour::jump` says which. The exchange fills ghosts of a fine
// block from a coarser neighbour by quadratic interpolation of the coarse
// interior and ghosts of a coarse block by averaging the 8 fine cells that
// make up each ghost cell (coarse_fine.hpp). `adapt()` refines and coarsens
// blocks and carries field data along; `partition()` moves field data.

#include <omp.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include <mpi.h>

#include "core/vec3.hpp"
#include "flow/block_field.hpp"

namespace sanguis::flow {

/// The shape of a forest of uniform resolution.
struct ForestSpec {
  std::array<int, 3> trees{1, 1, 1};                  ///< trees per direction (brick)
  std::array<bool, 3> periodic{false, false, false};  ///< periodicity per direction
  int level = 0;                                      ///< refinement level of every leaf
  int block_cells = 8;             ///< cells per block edge b (a power of two, >= 2)
  double tree_length = 1.0;        ///< edge length of one tree (m)
  Vec3 origin{};                   ///< lower corner of the domain (m)
  int threads = 1;                 ///< OpenMP threads over blocks
  MPI_Comm comm = MPI_COMM_WORLD;  ///< ranks sharing the forest (MPI_COMM_SELF: this rank alone)

  bool operator==(const ForestSpec&) const = default;
};

/// How a block reaches one of its 26 neighbours.
enum class Link : std::uint8_t {
  Local,     ///< a block of this rank; index is the local block number
  Remote,    ///< a block of another rank; index is its number in the ghost layer
  Boundary,  ///< outside a non-periodic domain face
};

/// Level of a neighbour relative to the block (2:1 balance: at most one apart).
enum class LevelJump : std::int8_t {
  Coarser = -1,  ///< the neighbour is the parent of the same-level region
  Same = 0,      ///< the neighbour is the same-level region itself
  Finer = 1,     ///< the same-level region is split; its children touching the block are leaves
};

/// Where one block lives: this rank's block list or the ghost layer.
struct BlockRef {
  Link link = Link::Boundary;
  std::int32_t index = -1;
};

struct Neighbour {
  Link link = Link::Boundary;  ///< where the neighbour lives
  std::int32_t index = -1;     ///< local or ghost-layer number, -1 for Boundary
  LevelJump jump = LevelJump::Same;
  /// Finer neighbours: the 8 children of the same-level region at this
  /// offset, by child number cx + 2 cy + 4 cz; only the children that touch
  /// the block are set (4 across a face, 2 across an edge, 1 across a
  /// corner), the others stay Boundary. link/index above name the first set one.
  std::array<BlockRef, 8> children{};
};

/// How exchange() fills the first ghost layer of a fine block across a face
/// towards a coarser block. Interpolated: from the coarse block alone
/// (quadratic per direction, interpolate_from_coarse), what every field's
/// stencils read. Composite: the multigrid operator's ghost, the quadratic
/// along the normal through the coarse layer (interpolated across the face)
/// and the block's own two cells beside the face (kGhostCoarse, coarse_fine.hpp);
/// deeper layers, edges and corners as Interpolated.
enum class CoarseGhosts : std::uint8_t { Interpolated, Composite };

/// The deepest level p8est blocks may reach (P8EST_QMAXLEVEL).
inline constexpr int kForestMaxLevel = 18;

/// Per-block request to `Forest::adapt`.
enum class AdaptFlag : std::int8_t {
  Coarsen = -1,  ///< merge with its 7 siblings (only when all 8 ask and sit on one rank)
  Keep = 0,
  Refine = 1,  ///< split into 8 children
};

/// Offset number of neighbour (ox,oy,oz), each in {-1,0,1}.
constexpr int neighbour_slot(int ox, int oy, int oz) {
  return (ox + 1) + 3 * (oy + 1) + 9 * (oz + 1);
}

/// Face index 2 d + side of a face offset (exactly one of ox, oy, oz nonzero).
constexpr int offset_face(int ox, int oy, int oz) {
  const int d = ox != 0 ? 0 : (oy != 0 ? 1 : 2);
  const int o = ox + oy + oz;
  return 2 * d + (o > 0 ? 1 : 0);
}

/// Slot of the neighbour across face (d, side) (side 0: the lower face).
constexpr std::size_t face_neighbour_slot(int d, int side) {
  const int o = side == 0 ? -1 : 1;
  return static_cast<std::size_t>(neighbour_slot(d == 0 ? o : 0, d == 1 ? o : 0, d == 2 ? o : 0));
}

/// One local leaf of the forest.
struct Block {
  int level = 0;                           ///< p8est refinement level
  std::array<std::int64_t, 3> coord{};     ///< integer position among blocks of this level
  Vec3 lower{};                            ///< physical lower corner (m)
  double length = 0.0;                     ///< edge length (m)
  std::array<Neighbour, 27> neighbours{};  ///< by neighbour_slot; the centre slot is unused
};

/// Which faces of a block (2 d + side) are domain faces (no neighbour there).
inline std::array<bool, 6> domain_faces(const Block& block) {
  std::array<bool, 6> wall{};
  for (int d = 0; d < 3; ++d)
    for (int side = 0; side < 2; ++side) {
      wall[static_cast<std::size_t>(2 * d + side)] =
          block.neighbours[face_neighbour_slot(d, side)].link == Link::Boundary;
    }
  return wall;
}

class Forest {
 public:
  explicit Forest(const ForestSpec& spec);
  ~Forest();
  Forest(const Forest&) = delete;
  Forest& operator=(const Forest&) = delete;

  [[nodiscard]] const ForestSpec& spec() const { return spec_; }
  [[nodiscard]] int block_cells() const { return spec_.block_cells; }
  [[nodiscard]] int local_blocks() const { return static_cast<int>(blocks_.size()); }
  [[nodiscard]] const Block& block(int b) const { return blocks_[static_cast<std::size_t>(b)]; }
  [[nodiscard]] std::int64_t global_blocks() const { return global_blocks_; }
  /// Blocks per direction at `level` over the whole domain.
  [[nodiscard]] std::array<std::int64_t, 3> blocks_per_direction(int level) const;
  /// Domain extent per direction (m).
  [[nodiscard]] Vec3 extent() const;

  [[nodiscard]] MPI_Comm comm() const { return comm_; }
  [[nodiscard]] int rank() const { return rank_; }
  [[nodiscard]] int ranks() const { return ranks_; }

  /// Fills the ghost cells of every block that face another block (within
  /// `width` <= min(ghost layers of the fields' layout, b) of the block) with copies of that
  /// block's interior, for all the given fields (same b). Boundary ghosts are left for
  /// boundary.hpp. With `faces_only` the edge and corner ghosts are left as they are (7-point
  /// stencils read face ghosts only).
  void exchange(std::span<BlockField* const> fields, int width, bool faces_only = false,
                CoarseGhosts coarse_ghosts = CoarseGhosts::Interpolated) const;
  /// Whether every block is at one level and on this process. A block's ghosts are then
  /// copies of its neighbours' interior cells alone, so a loop over the blocks may fill
  /// each block's ghosts right before it reads them (fill_same_level_ghosts) instead of
  /// exchanging them all first: the same values, read while they are in cache.
  [[nodiscard]] bool uniform_local() const;
  /// exchange(fields, width) for block blk alone (uniform_local() forests only). Reads
  /// only the neighbours' interior cells and writes only blk's ghosts, so blocks may be
  /// filled in any order and on any thread, as long as no interior of these fields
  /// changes meanwhile. stencil_only: the face ghosts `width` deep, the edge ghosts one
  /// layer deep, no corner ghosts (what the face prediction and the face average read);
  /// the others keep their values.
  void fill_same_level_ghosts(std::span<BlockField* const> fields, int blk, int width,
                              bool stencil_only = false) const;
  void exchange(BlockField& field, int width, bool faces_only = false,
                CoarseGhosts coarse_ghosts = CoarseGhosts::Interpolated) const {
    BlockField* one[] = {&field};
    exchange(one, width, faces_only, coarse_ghosts);
  }

  /// Only the ghost layer (width 1) beyond face `face` (2 d + side) of the
  /// blocks whose neighbour there is finer: the 8-cell means of the finer
  /// blocks' cells, exactly as exchange() fills it, and nothing else. For
  /// data that only coarse-fine faces read (Multigrid::match_fluxes), at a
  /// fraction of a full exchange's cost. Collective like exchange().
  void exchange_from_finer(BlockField& field, int face) const;
  /// exchange(field, 1, true) without the faces copy_face_ghosts() fills: the
  /// faces towards blocks of another level or on another rank. Collective.
  void exchange_face_ghosts_but_local_same_level(
      BlockField& field, CoarseGhosts coarse_ghosts = CoarseGhosts::Interpolated) const;

  /// Whether every face neighbour of every block is a block of the same level
  /// on this rank (or the domain boundary): one rank, a uniform forest. Then
  /// copy_face_ghosts() fills every face ghost there is to fill.
  [[nodiscard]] bool faces_local_same_level() const { return ranks_ == 1 && uniform(); }
  /// The face ghosts (width 1) of block `blk` towards its neighbours of the
  /// same level on this rank, from their interiors: the values
  /// exchange(field, 1, true) puts there, one block at a time, right before a
  /// kernel reads them (the multigrid smoother). With `colour` 0 or 1 only the
  /// ghosts of that cell colour, (i + j + k + b (coord sum)) & 1 (red-black
  /// sweeps read one colour and may write the other meanwhile). Other faces
  /// (boundary, other level, other rank) are left alone.
  void copy_face_ghosts(BlockField& field, int blk, int colour = -1) const;

  /// body(b) for the listed local blocks, on the forest's OpenMP threads.
  template <typename Body>
  void for_each_listed(const std::vector<std::int32_t>& list, Body&& body) const;
  /// Local blocks with a finer / a coarser neighbour across at least one face.
  [[nodiscard]] const std::vector<std::int32_t>& blocks_beside_finer() const {
    return beside_finer_blocks_;
  }
  [[nodiscard]] const std::vector<std::int32_t>& blocks_beside_coarser() const {
    return beside_coarser_blocks_;
  }

  /// Runs body(b) for every local block, on the forest's OpenMP threads.
  template <typename Body>
  void for_each_block(Body&& body) const;
  /// for_each_block() with each thread's share of the blocks (the same
  /// shares) taken in reverse order: for passes whose block order is free,
  /// so that a pass starts where the pass before it ended, in cache.
  template <typename Body>
  void for_each_block_backward(Body&& body) const;

  /// Sum and maximum over all ranks.
  [[nodiscard]] double sum(double local) const;
  [[nodiscard]] double max(double local) const;

  /// Coarsest and finest level of any block (over all ranks).
  [[nodiscard]] int min_level() const { return min_level_; }
  [[nodiscard]] int max_level() const { return max_level_; }
  [[nodiscard]] bool uniform() const { return min_level_ == max_level_; }
  /// Whether local blocks first..first+7 are the 8 children of one parent, in
  /// p4est's child order (x fastest): the families adapt() may merge.
  [[nodiscard]] bool is_family(int first) const;
  /// Global number (p8est order over all ranks) of this rank's first block.
  [[nodiscard]] std::int64_t first_global_block() const { return first_global_block_; }

  /// Repartitions the blocks evenly over the ranks, keeping families of 8
  /// on one rank (so the split may differ from the even one of a forest
  /// just built), and moves `fields` (BlockFields of any layout, one entry
  /// per local block, e.g. also FaceField components) with them by
  /// p8est_transfer_fixed: each block's whole storage, ghosts included (so a
  /// face field keeps its slot b; cell ghosts are stale until the next
  /// exchange). Returns whether any block changed rank (the same on all ranks).
  bool partition(std::span<BlockField* const> fields = {});

  /// Refines and coarsens blocks by `flags` (one per local block), restores
  /// the 2:1 balance across faces, edges and corners (which may refine more
  /// blocks, and undoes coarsenings that would break it), repartitions, and
  /// carries the cell-centred `fields` along (see adapt.cpp): a new parent
  /// gets the volume average of its children's cells, a new child the
  /// parent's cell plus minmod-limited slopes (second order, exact for linear
  /// fields). The fields' ghosts are filled by an exchange (and, for cells on
  /// the domain boundary, one-sided slopes are used) before refining, and are
  /// left unfilled after. `face_fields` (faces 0..b of every block valid,
  /// slot b included) are carried so that fluxes and divergence are kept: a
  /// parent face is the mean of its 4 child faces, a child face on a parent
  /// face takes that face's value and a child face inside a parent cell the
  /// mean of the parent's two faces along its normal (exact for components
  /// linear along their own direction; constant across). Refinement beyond
  /// `max_level` is ignored. Returns whether any block changed or moved to
  /// another rank (the same on all ranks): the local block list is new.
  bool adapt(std::span<const AdaptFlag> flags, std::span<BlockField* const> fields,
             std::span<FaceField* const> face_fields = {}, int max_level = kForestMaxLevel);
  /// The same with the flag of every block given by a callback.
  bool adapt(const std::function<AdaptFlag(const Block&)>& decide,
             std::span<BlockField* const> fields, std::span<FaceField* const> face_fields = {},
             int max_level = kForestMaxLevel);
  /// Makes this forest's leaves those of `fine` with every family of its finest level
  /// merged into the parent (the multigrid's level-by-level hierarchy,
  /// coarsened_blocks.hpp), split over the ranks as partition() splits them. `fine` must
  /// have this forest's spec and blocks below its trees' level. Each rank works on its own
  /// blocks (a copy of `fine`'s p8est, coarsened; the families are whole on one rank as
  /// adapt() and partition() leave them, and a copy of a forest split evenly is split so
  /// first), and only the repartitions talk to the others. Fields are not carried.
  void assign_coarsened_finest_level(const Forest& fine);
  /// The rank that holds the leaf at (level, coord) of this forest (p8est's partition
  /// markers; no communication).
  [[nodiscard]] int owner_of(int level, const std::array<std::int64_t, 3>& coord) const;

 private:
  /// exchange(); with finer_face >= 0 only that face of blocks beside finer
  /// ones; with skip_local_same_level not the faces copy_face_ghosts() fills.
  void exchange_scoped(std::span<BlockField* const> fields, int width, bool faces_only,
                       int finer_face, bool skip_local_same_level = false,
                       CoarseGhosts coarse_ghosts = CoarseGhosts::Interpolated) const;
  /// What exchange_scoped() writes into block blk (its ghost cells, from the neighbours'
  /// interior cells; `remote`: the interiors of the ghost layer's blocks, packed).
  /// Which of a block's ghosts a fill writes: all (faces, edges and corners, `width`
  /// deep), the faces only, or the stencil's (faces `width` deep, edges one deep).
  enum class GhostExtent { All, Faces, Stencil };
  void fill_block_ghosts(std::span<BlockField* const> fields, int blk, int width,
                         GhostExtent extent, int finer_face, bool skip_local_same_level,
                         CoarseGhosts coarse_ghosts, const double* remote) const;
  void build_blocks();
  void build_ghost_tables();
  void build_neighbours();
  /// faces_apart_blocks_ and finer_face_blocks_ from the neighbours.
  void list_face_exchanges();

  void rebuild_tables();  ///< ghost layer, block list, mirrors, neighbours
  void migrate_fields(const std::vector<std::int64_t>& before, std::span<BlockField* const> fields);
  /// Key of the block at (level, coord) for the neighbour and matching maps.
  [[nodiscard]] std::uint64_t block_key(int level, const std::array<std::int64_t, 3>& c) const;

  struct P4estObjects;  ///< connectivity, forest and ghost layer (forest.cpp)

  ForestSpec spec_;
  MPI_Comm comm_;
  int rank_ = 0;
  int ranks_ = 1;
  std::unique_ptr<P4estObjects> p4est_;
  std::vector<Block> blocks_;
  std::vector<std::int32_t> mirror_blocks_;  ///< local block number of each mirror
  std::int64_t global_blocks_ = 0;
  std::int64_t remote_blocks_ = 0;  ///< blocks in the ghost layer
  std::int64_t first_global_block_ = 0;
  int min_level_ = 0;
  int max_level_ = 0;
  /// Whether the blocks are split over the ranks as partition() and adapt()
  /// split them (families of 8 on one rank); a forest just built is split
  /// evenly instead, unless it has one rank.
  bool families_partitioned_ = false;
  /// Blocks with a face towards another level or rank (what
  /// exchange_face_ghosts_but_local_same_level fills), and per face (2 d +
  /// side) the blocks whose neighbour there is finer (exchange_from_finer).
  std::vector<std::int32_t> faces_apart_blocks_;
  std::array<std::vector<std::int32_t>, 6> finer_face_blocks_;
  std::vector<std::int32_t> beside_finer_blocks_, beside_coarser_blocks_;

  /// body(b) over each thread's block_share(), forwards or backwards.
  template <bool kBackward, typename Body>
  void for_each_block_share(Body&& body) const;
};

/// The blocks [first, first + count) that thread t of `threads` takes: equal
/// contiguous shares, the first n % threads threads one block more (what
/// GCC's schedule(static) does; spelled out so that both loops below agree
/// on any OpenMP runtime).
struct BlockShare {
  int first = 0, count = 0;
};
inline BlockShare block_share(int n, int threads, int t) {
  const int share = n / threads, extra = n % threads;
  return {t * share + std::min(t, extra), share + (t < extra ? 1 : 0)};
}

template <bool kBackward, typename Body>
void Forest::for_each_block_share(Body&& body) const {
  const auto run = [&](BlockShare mine) {
    if constexpr (kBackward) {
      for (int b = mine.first + mine.count - 1; b >= mine.first; --b) body(b);
    } else {
      for (int b = mine.first; b < mine.first + mine.count; ++b) body(b);
    }
  };
  const int n = local_blocks();
  if (spec_.threads > 1) {
#pragma omp parallel num_threads(spec_.threads)
    run(block_share(n, omp_get_num_threads(), omp_get_thread_num()));
  } else {
    run({0, n});
  }
}

template <typename Body>
void Forest::for_each_block(Body&& body) const {
  for_each_block_share<false>(body);
}

template <typename Body>
void Forest::for_each_block_backward(Body&& body) const {
  for_each_block_share<true>(body);
}

template <typename Body>
void Forest::for_each_listed(const std::vector<std::int32_t>& list, Body&& body) const {
  const auto n = static_cast<std::ptrdiff_t>(list.size());
  if (spec_.threads > 1) {
#pragma omp parallel for schedule(static) num_threads(spec_.threads)
    for (std::ptrdiff_t k = 0; k < n; ++k) body(list[static_cast<std::size_t>(k)]);
  } else {
    for (std::ptrdiff_t k = 0; k < n; ++k) body(list[static_cast<std::size_t>(k)]);
  }
}

}  // namespace sanguis::flow
