#include "flow/flow_output.hpp"

#include <cstring>
#include <fstream>
#include <type_traits>

#include "core/error.hpp"
#include "core/io/atomic_file.hpp"

namespace sanguis::flow {

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
  io::DataArray velocity{"velocity", 3, {}}, pressure{"pressure", 1, {}},
      vort{"vorticity_magnitude", 1, {}}, viscosity{"viscosity", 1, {}};
  io::IntDataArray level{"level", 1, {}}, rank{"rank", 1, {}}, block_id{"block", 1, {}};
  velocity.values.reserve(3 * cells);
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
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          mesh.cells.push_back({point(i, j, k), point(i + 1, j, k), point(i + 1, j + 1, k),
                                point(i, j + 1, k), point(i, j, k + 1), point(i + 1, j, k + 1),
                                point(i + 1, j + 1, k + 1), point(i, j + 1, k + 1)});
          for (int c = 0; c < 3; ++c)
            velocity.values.push_back(ns.velocity()[static_cast<std::size_t>(c)](blk, i, j, k));
          pressure.values.push_back(ns.pressure()(blk, i, j, k));
          vort.values.push_back(vorticity(blk, i, j, k));
          viscosity.values.push_back(ns.viscosity()(blk, i, j, k));
          level.values.push_back(block.level);
          rank.values.push_back(forest.rank());
          block_id.values.push_back(blk);
        }
  }
  mesh.cell_data = {std::move(velocity), std::move(pressure), std::move(vort),
                    std::move(viscosity)};
  mesh.int_cell_data = {std::move(level), std::move(rank), std::move(block_id)};
  return mesh;
}

namespace {

constexpr char kMagic[16] = "sanguis-flow-1";

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
  return fields;
}

struct Header {
  char magic[16];
  std::int64_t global_blocks, local_blocks, block_cells, ranks, rank, steps, frames;
  double time;
};

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
  io::write_file_atomically(path, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(&header), sizeof header);
    for (const BlockField* f : state_fields(ns)) {
      out.write(reinterpret_cast<const char*>(f->raw().data()),
                static_cast<std::streamsize>(f->raw().size() * sizeof(double)));
    }
  });
}

CheckpointCounters load_flow_checkpoint(const std::filesystem::path& path, NavierStokes& ns) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "", "cannot read the checkpoint");
  Header header{};
  in.read(reinterpret_cast<char*>(&header), sizeof header);
  const Forest& forest = ns.forest();
  if (!in || std::memcmp(header.magic, kMagic, sizeof kMagic) != 0) {
    throw InputError(path.string(), "", "not a sanguis flow checkpoint");
  }
  if (header.global_blocks != forest.global_blocks() ||
      header.local_blocks != forest.local_blocks() || header.block_cells != forest.block_cells() ||
      header.ranks != forest.ranks() || header.rank != forest.rank()) {
    throw InputError(path.string(), "",
                     "written for another grid or number of ranks (the case's grid and the "
                     "mpirun -np must be those of the run that wrote it)");
  }
  for (BlockField* f : state_fields(ns)) {
    auto& data = f->raw();
    in.read(reinterpret_cast<char*>(data.data()),
            static_cast<std::streamsize>(data.size() * sizeof(double)));
  }
  if (!in) throw InputError(path.string(), "", "checkpoint is truncated");
  ns.set_time(header.time);
  return {header.steps, header.frames};
}

}  // namespace sanguis::flow
