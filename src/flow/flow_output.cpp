#include "flow/flow_output.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <set>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/io/atomic_file.hpp"

namespace sanguis::flow {

namespace {

/// The cell arrays of a frame, block after block: velocity, pressure,
/// vorticity_magnitude, viscosity and the integers level, rank, block.
struct FrameCellData {
  io::DataArray velocity{"velocity", 3, {}}, pressure{"pressure", 1, {}},
      vorticity{"vorticity_magnitude", 1, {}}, viscosity{"viscosity", 1, {}};
  io::IntDataArray level{"level", 1, {}}, rank{"rank", 1, {}}, block{"block", 1, {}};

  /// Appends the cells of local block blk, i fastest.
  void append(const NavierStokes& ns, const BlockField& vorticity_magnitude, int blk) {
    const Forest& forest = ns.forest();
    for_each_cell(forest.block_cells(), [&](int i, int j, int k) {
      for (const BlockField& u : ns.velocity()) velocity.values.push_back(u(blk, i, j, k));
      pressure.values.push_back(ns.pressure()(blk, i, j, k));
      vorticity.values.push_back(vorticity_magnitude(blk, i, j, k));
      viscosity.values.push_back(ns.viscosity()(blk, i, j, k));
      level.values.push_back(forest.block(blk).level);
      rank.values.push_back(forest.rank());
      block.values.push_back(blk);
    });
  }

  /// Moves the arrays into a mesh's (or image's) cell data.
  template <typename Mesh>
  void move_into(Mesh& mesh) {
    mesh.cell_data = {std::move(velocity), std::move(pressure), std::move(vorticity),
                      std::move(viscosity)};
    mesh.int_cell_data = {std::move(level), std::move(rank), std::move(block)};
  }
};

/// Level and coordinates of every local block, 4 numbers each.
std::vector<std::int64_t> leaf_records(const Forest& forest) {
  std::vector<std::int64_t> records;
  records.reserve(static_cast<std::size_t>(forest.local_blocks()) * 4);
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const Block& block = forest.block(blk);
    records.push_back(block.level);
    records.insert(records.end(), block.coord.begin(), block.coord.end());
  }
  return records;
}

/// Every rank's records, rank after rank, with where each rank's start: on
/// every rank (`everyone`) or on rank 0 only (the others get none).
struct GatheredRecords {
  std::vector<std::int64_t> all;
  std::vector<int> counts, offsets;
};

GatheredRecords gather_records(const Forest& forest, const std::vector<std::int64_t>& mine,
                               bool everyone) {
  GatheredRecords g;
  const int count = static_cast<int>(mine.size());
  g.counts.resize(static_cast<std::size_t>(forest.ranks()));
  g.offsets.resize(g.counts.size());
  if (everyone) {
    MPI_Allgather(&count, 1, MPI_INT, g.counts.data(), 1, MPI_INT, forest.comm());
  } else {
    MPI_Gather(&count, 1, MPI_INT, g.counts.data(), 1, MPI_INT, 0, forest.comm());
  }
  int total = 0;
  for (std::size_t r = 0; r < g.counts.size(); ++r) {
    g.offsets[r] = total;
    total += g.counts[r];
  }
  if (everyone) {
    g.all.resize(static_cast<std::size_t>(total));
    MPI_Allgatherv(mine.data(), count, MPI_INT64_T, g.all.data(), g.counts.data(), g.offsets.data(),
                   MPI_INT64_T, forest.comm());
  } else {
    g.all.resize(static_cast<std::size_t>(forest.rank() == 0 ? total : 0));
    MPI_Gatherv(mine.data(), count, MPI_INT64_T, g.all.data(), g.counts.data(), g.offsets.data(),
                MPI_INT64_T, 0, forest.comm());
  }
  return g;
}

}  // namespace

io::HexMesh flow_mesh(NavierStokes& ns) {
  const Forest& forest = ns.forest();
  const int b = forest.block_cells();
  const int np = b + 1;
  const BlockField vorticity = ns.vorticity_magnitude();
  io::HexMesh mesh;
  const auto blocks = static_cast<std::size_t>(forest.local_blocks());
  const std::size_t cells = blocks * static_cast<std::size_t>(b * b * b);
  mesh.points.reserve(blocks * static_cast<std::size_t>(np * np * np));
  mesh.cells.reserve(cells);
  FrameCellData data;
  data.velocity.values.reserve(3 * cells);
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const Block& block = forest.block(blk);
    const double h = block.length / b;
    const auto first = static_cast<std::int64_t>(mesh.points.size());
    for (int k = 0; k < np; ++k)
      for (int j = 0; j < np; ++j)
        for (int i = 0; i < np; ++i)
          mesh.points.push_back(
              {block.lower.x + i * h, block.lower.y + j * h, block.lower.z + k * h});
    auto point = [&](int i, int j, int k) {
      return first + (static_cast<std::int64_t>(k) * np + j) * np + i;
    };
    for_each_cell(b, [&](int i, int j, int k) {
      mesh.cells.push_back({point(i, j, k), point(i + 1, j, k), point(i + 1, j + 1, k),
                            point(i, j + 1, k), point(i, j, k + 1), point(i + 1, j, k + 1),
                            point(i + 1, j + 1, k + 1), point(i, j + 1, k + 1)});
    });
    data.append(ns, vorticity, blk);
  }
  data.move_into(mesh);
  return mesh;
}

void write_flow_block_frame(NavierStokes& ns, const std::filesystem::path& dir,
                            const std::string& stem) {
  const Forest& forest = ns.forest();
  const int b = forest.block_cells();
  const BlockField vorticity = ns.vorticity_magnitude();  // collective: before any early exit
  const std::filesystem::path folder = dir / stem;
  // A frame written again (a restart from an earlier checkpoint, a run into an
  // old output folder) replaces the whole folder: blocks of the earlier grid
  // that the new index would not list do not linger.
  if (forest.rank() == 0) std::filesystem::remove_all(folder);
  MPI_Barrier(forest.comm());
  std::filesystem::create_directories(folder);
  const auto block_name = [](int rank, std::int64_t blk) {
    return "r" + std::to_string(rank) + "_b" + std::to_string(blk);
  };
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const Block& block = forest.block(blk);
    io::ImageBlock image;
    image.origin = block.lower;
    image.spacing = block.length / b;
    image.cells = {b, b, b};
    FrameCellData data;
    data.append(ns, vorticity, blk);
    data.move_into(image);
    io::write_image_block_vti(folder / (block_name(forest.rank(), blk) + ".vti"), image);
  }
  // Rank 0 lists every rank's blocks (their records in local block order).
  const GatheredRecords leaves = gather_records(forest, leaf_records(forest), false);
  if (forest.rank() != 0) return;
  // One group per level, coarsest first; within a level, by rank and block.
  const int coarsest = forest.min_level();
  std::vector<io::MultiblockGroup> levels(
      static_cast<std::size_t>(forest.max_level() - coarsest + 1));
  for (std::size_t l = 0; l < levels.size(); ++l) {
    const int level = coarsest + static_cast<int>(l);
    char name[96];
    std::snprintf(name, sizeof name, "level %d (h = %.6g m)", level,
                  forest.spec().tree_length / std::ldexp(1.0, level) / b);
    levels[l].name = name;
  }
  const std::string leaf = std::filesystem::path(stem).filename().string();
  for (int r = 0; r < forest.ranks(); ++r) {
    const auto first = static_cast<std::size_t>(leaves.offsets[static_cast<std::size_t>(r)]);
    const auto end = first + static_cast<std::size_t>(leaves.counts[static_cast<std::size_t>(r)]);
    for (std::size_t n = first; n + 4 <= end; n += 4) {
      const std::string block = block_name(r, static_cast<std::int64_t>((n - first) / 4));
      const std::int64_t* record = &leaves.all[n];
      char name[128];
      std::snprintf(name, sizeof name, "%s (cells from %lld %lld %lld)", block.c_str(),
                    static_cast<long long>(record[1] * b), static_cast<long long>(record[2] * b),
                    static_cast<long long>(record[3] * b));
      levels[static_cast<std::size_t>(record[0] - coarsest)].members.emplace_back(
          name, leaf + "/" + block + ".vti");
    }
  }
  io::write_multiblock_vtm(dir / (stem + ".vtm"), levels);
}

namespace {

// Version 2: the header is followed by the level and coordinates of every
// local block (4 int64 each), so that an adaptive run restarts on its grid.
// Version 3: the predictor's correction pressure follows the viscosity.
// Version 4: then the last viscous increment's three components.
constexpr char kMagic[16] = "sanguis-flow-4";

/// The fields a checkpoint holds, in file order.
template <typename Solver>
auto state_fields(Solver& ns) {
  using Field = std::conditional_t<std::is_const_v<Solver>, const BlockField, BlockField>;
  std::vector<Field*> fields;
  for (auto& f : ns.velocity()) fields.push_back(&f);
  for (auto& f : ns.pressure_gradient()) fields.push_back(&f);
  for (auto& f : ns.face_velocity()) fields.push_back(&f);
  fields.push_back(&ns.pressure());
  fields.push_back(&ns.viscosity());
  fields.push_back(&ns.predictor_pressure());
  for (auto& f : ns.viscous_increment()) fields.push_back(&f);
  return fields;
}

struct Header {
  char magic[16];
  std::int64_t global_blocks, local_blocks, block_cells, ranks, rank, steps, frames;
  double time;
  std::int64_t trees[3], level;  ///< the case's grid: brick and initial level
  double tree_length, origin[3];
};

/// Whether the header describes the grid and ranks of `forest`'s case.
bool same_case_grid(const Header& h, const Forest& forest) {
  const ForestSpec& spec = forest.spec();
  bool same = h.block_cells == forest.block_cells() && h.ranks == forest.ranks() &&
              h.rank == forest.rank() && h.level == spec.level &&
              h.tree_length == spec.tree_length && h.local_blocks >= 0 &&
              h.local_blocks <= (std::int64_t{1} << 28);
  for (int d = 0; d < 3; ++d) {
    same = same && h.trees[d] == spec.trees[static_cast<std::size_t>(d)] &&
           h.origin[d] == spec.origin[d];
  }
  return same;
}

using LeafKey = std::array<std::int64_t, 4>;  // level, x, y, z

/// Refines and coarsens `forest` until its blocks are the leaves of all
/// ranks' checkpoints (`mine` on this rank); false if it does not get there.
bool rebuild_grid(Forest& forest, NavierStokes& ns, const std::vector<std::int64_t>& mine) {
  // Every rank needs the whole leaf set to decide its own blocks' flags.
  const std::vector<std::int64_t> all = gather_records(forest, mine, true).all;
  std::set<LeafKey> target;
  int finest = 0;
  for (std::size_t i = 0; i + 3 < all.size(); i += 4) {
    target.insert({all[i], all[i + 1], all[i + 2], all[i + 3]});
    finest = std::max(finest, static_cast<int>(all[i]));
  }
  auto has_ancestor = [&](const Block& block) {
    for (int up = 1; up <= block.level; ++up) {
      if (target.count({block.level - up, block.coord[0] >> up, block.coord[1] >> up,
                        block.coord[2] >> up}) != 0) {
        return true;
      }
    }
    return false;
  };
  for (int round = 0; round < 2 * (finest + 1); ++round) {
    std::vector<AdaptFlag> flags(static_cast<std::size_t>(forest.local_blocks()));
    double differ = 0.0;
    for (int blk = 0; blk < forest.local_blocks(); ++blk) {
      const Block& block = forest.block(blk);
      AdaptFlag& flag = flags[static_cast<std::size_t>(blk)];
      if (target.count({block.level, block.coord[0], block.coord[1], block.coord[2]}) != 0) {
        flag = AdaptFlag::Keep;
        continue;
      }
      flag = has_ancestor(block) ? AdaptFlag::Coarsen : AdaptFlag::Refine;
      differ += 1.0;
    }
    if (forest.sum(differ) == 0.0) {
      // The same blocks; split over the ranks as adapt() splits them (the
      // writer's forest went through it), unless they already are.
      if (forest.sum(leaf_records(forest) == mine ? 0.0 : 1.0) != 0.0) {
        ns.regrid(forest, std::vector<AdaptFlag>(flags.size(), AdaptFlag::Keep), {}, finest);
      }
      return true;
    }
    ns.regrid(forest, flags, {}, finest);
  }
  return false;
}

}  // namespace

void save_flow_checkpoint(const std::filesystem::path& path, const NavierStokes& ns,
                          std::int64_t steps, std::int64_t frames) {
  const Forest& forest = ns.forest();
  Header header{};
  std::memcpy(header.magic, kMagic, sizeof kMagic);
  header.global_blocks = forest.global_blocks();
  header.local_blocks = forest.local_blocks();
  header.block_cells = forest.block_cells();
  header.ranks = forest.ranks();
  header.rank = forest.rank();
  header.steps = steps;
  header.frames = frames;
  header.time = ns.time();
  const ForestSpec& spec = forest.spec();
  for (int d = 0; d < 3; ++d) {
    header.trees[d] = spec.trees[static_cast<std::size_t>(d)];
    header.origin[d] = spec.origin[d];
  }
  header.level = spec.level;
  header.tree_length = spec.tree_length;
  io::write_file_atomically(path, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(&header), sizeof header);
    const std::vector<std::int64_t> leaves = leaf_records(forest);
    out.write(reinterpret_cast<const char*>(leaves.data()),
              static_cast<std::streamsize>(leaves.size() * sizeof(std::int64_t)));
    for (const BlockField* f : state_fields(ns)) {
      out.write(reinterpret_cast<const char*>(f->raw().data()),
                static_cast<std::streamsize>(f->raw().size() * sizeof(double)));
    }
  });
}

CheckpointCounters load_flow_checkpoint(const std::filesystem::path& path, NavierStokes& ns,
                                        Forest* adaptable) {
  const Forest& forest = ns.forest();
  // Every rank reads its own file; a fault on one rank is made known to all
  // before anyone throws, so that none waits in a collective.
  std::string fault;
  std::ifstream in(path, std::ios::binary);
  Header header{};
  std::vector<std::int64_t> leaves;
  if (!in) {
    fault = "cannot read the checkpoint";
  } else {
    in.read(reinterpret_cast<char*>(&header), sizeof header);
    if (!in || std::memcmp(header.magic, kMagic, sizeof kMagic) != 0) {
      fault = "not a sanguis flow checkpoint (or one of an older version)";
    } else if (header.block_cells != forest.block_cells()) {
      // Since 2026-12-03 a case without block_cells may get 16^3 blocks where it got 8^3.
      fault = "written with blocks of " + std::to_string(header.block_cells) +
              "^3 cells, this run has " + std::to_string(forest.block_cells()) +
              "^3 (set [flow.grid] block_cells = " + std::to_string(header.block_cells) +
              " to restart it)";
    } else if (!same_case_grid(header, forest)) {
      fault =
          "written for another grid or number of ranks (the case's [flow.grid] and the mpirun "
          "-np must be those of the run that wrote it)";
    } else {
      leaves.resize(static_cast<std::size_t>(header.local_blocks) * 4);
      in.read(reinterpret_cast<char*>(leaves.data()),
              static_cast<std::streamsize>(leaves.size() * sizeof(std::int64_t)));
      if (!in) fault = "checkpoint is truncated";
    }
  }
  auto agree = [&](const std::string& reason) {
    if (forest.max(fault.empty() ? 0.0 : 1.0) > 0.0) {
      throw InputError(path.string(), "",
                       fault.empty() ? "the checkpoint of another rank " + reason : fault);
    }
  };
  agree("cannot be used");
  if (forest.sum(leaf_records(forest) == leaves ? 0.0 : 1.0) != 0.0) {
    // An adaptive run: rebuild its grid (the solver's state is read below).
    if (adaptable == nullptr || adaptable != &forest) {
      fault =
          "written by an adaptive run ([flow.adapt]) or on another grid: restart with the case "
          "file that wrote it";
    } else if (!rebuild_grid(*adaptable, ns, leaves) ||
               forest.sum(leaf_records(forest) == leaves ? 0.0 : 1.0) != 0.0) {
      fault = "its blocks could not be rebuilt on this case's grid";
    }
    agree("does not fit");
  }
  if (header.global_blocks != forest.global_blocks()) fault = "the block count does not match";
  agree("does not fit");
  for (BlockField* f : state_fields(ns)) {
    auto& data = f->raw();
    in.read(reinterpret_cast<char*>(data.data()),
            static_cast<std::streamsize>(data.size() * sizeof(double)));
  }
  if (!in) fault = "checkpoint is truncated";
  agree("is truncated");
  ns.set_time(header.time);
  return {header.steps, header.frames};
}

}  // namespace sanguis::flow
