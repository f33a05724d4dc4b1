#pragma once
// What a flow run writes: the block grid as hexahedra with the flow fields
// (ParaView), and the full state for a restart.

#include <filesystem>

#include "core/io/vtk.hpp"
#include "flow/navier_stokes.hpp"

namespace sanguis::flow {

/// The local blocks of the forest as hexahedral cells ((b+1)^3 points per
/// block), with cell data velocity, pressure, vorticity_magnitude, viscosity
/// and the integers level, rank, block.
io::HexMesh flow_mesh(NavierStokes& ns);

/// Writes the solver state of this rank (fields with their ghost layers,
/// time) atomically; `steps` and `frames` are the run's counters.
void save_flow_checkpoint(const std::filesystem::path& path, const NavierStokes& ns,
                          std::int64_t steps, std::int64_t frames);

struct CheckpointCounters {
  std::int64_t steps = 0;
  std::int64_t frames = 0;
};

/// Restores a state written by save_flow_checkpoint on the same grid and
/// number of ranks; throws InputError naming the file when it does not fit.
CheckpointCounters load_flow_checkpoint(const std::filesystem::path& path, NavierStokes& ns);

}  // namespace sanguis::flow
