#pragma once
// What a flow run writes: the block grid as hexahedra with the flow fields
// (ParaView), and the full state for a restart.

#include <filesystem>
#include <string>

#include "core/io/vtk.hpp"
#include "flow/navier_stokes.hpp"

namespace sanguis::flow {

/// The local blocks of the forest as hexahedral cells ((b+1)^3 points per
/// block), with cell data velocity, pressure, vorticity_magnitude, viscosity
/// and the integers level, rank, block.
io::HexMesh flow_mesh(NavierStokes& ns);

/// Writes a frame as a block-structured data set: every local block as an
/// ImageData file `dir/stem/rR_bN.vti` (rank R, local block N; the cell
/// arrays of flow_mesh), and on rank 0 the multiblock index `dir/stem.vtm`
/// listing every rank's blocks, grouped by level (coarsest first).
/// Collective over the ranks.
void write_flow_block_frame(NavierStokes& ns, const std::filesystem::path& dir,
                            const std::string& stem);

/// Writes the solver state of this rank (fields with their ghost layers,
/// time) atomically; `steps` and `frames` are the run's counters.
void save_flow_checkpoint(const std::filesystem::path& path, const NavierStokes& ns,
                          std::int64_t steps, std::int64_t frames);

struct CheckpointCounters {
  std::int64_t steps = 0;
  std::int64_t frames = 0;
};

/// Restores a state written by save_flow_checkpoint with the same number of
/// ranks. The checkpoint lists its blocks: when they differ from the
/// solver's forest (an adaptive run) and `forest` is given (the solver's
/// forest, mutable), the forest is first refined and coarsened to the
/// checkpoint's blocks; otherwise, or when the grids cannot match, throws
/// InputError naming the file.
CheckpointCounters load_flow_checkpoint(const std::filesystem::path& path, NavierStokes& ns,
                                        Forest* forest = nullptr);

}  // namespace sanguis::flow
