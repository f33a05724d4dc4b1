#pragma once
// A flow case file: the [flow] section (grid, fluid, boundaries, initial
// state, body force, solver), [simulation] (name, end time, threads) and
// [output], read strictly (unknown keys are errors). See docs/case-file.md,
// section "Flow cases".

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/config.hpp"
#include "flow/navier_stokes.hpp"

namespace sanguis::flow {

/// A box where the grid stays at least `refine_levels` finer than [flow.grid]
/// and, with `max_refine_levels`, at most that many finer.
struct RefinementRegion {
  Vec3 min{}, max{};                     ///< (m)
  int refine_levels = 0;                 ///< levels above the grid's (a floor)
  std::optional<int> max_refine_levels;  ///< levels above the grid's (a cap)
};

/// [flow.adapt]: the grid follows the flow (wavelet criterion, eq. 4.11) on
/// the fields given a threshold zeta (0: not estimated; at least one > 0).
struct FlowAdaptivity {
  bool enabled = false;
  double velocity_threshold = 0.0;   ///< zeta for each velocity component (m/s)
  double vorticity_threshold = 0.0;  ///< zeta for the vorticity magnitude (1/s)
  double pressure_threshold = 0.0;   ///< zeta for the pressure (Pa)
  int min_level = 0;                 ///< p4est levels of the blocks (absolute)
  int max_level = 0;
  int every_steps = 1;  ///< regrid every this many steps
  std::vector<RefinementRegion> regions;
};

struct FlowCase {
  std::string name;                    ///< [simulation].name, default the file's stem
  std::filesystem::path source;        ///< the case file
  double end_time = 0.0;               ///< (s)
  ForestSpec forest;                   ///< brick, block size, periodicity
  bool block_cells_automatic = false;  ///< block_cells not given: automatic_block_cells() chose it
  std::array<int, 3> cells{};          ///< cells per direction
  std::array<FlowBoundary, 6> boundaries{};  ///< by face_index
  std::array<std::string, 6> boundary_text;  ///< as read, for the log
  Fluid fluid;
  NavierStokesOptions options;
  Vec3 initial_velocity{};  ///< uniform initial velocity (m/s)
  Vec3 body_force{};        ///< uniform body force density (N/m^3)
  /// Solid boxes [min, max] (m): cells whose centre lies inside are solid.
  std::vector<std::array<Vec3, 2>> solid_boxes;
  /// A box [min, max] (m) of another fluid viscosity.
  struct ViscosityRegion {
    Vec3 min, max;
    double viscosity = 0.0;  ///< (Pa s)
  };
  /// Cells whose centre lies inside a region take its viscosity (the last
  /// region holding it wins), the others the fluid's.
  std::vector<ViscosityRegion> viscosity_regions;
  double output_interval = 0.0;      ///< (s)
  bool vtk = true;                   ///< write ParaView files
  bool vtk_blocks = false;           ///< as blocks of ImageData (.vtm + .vti), not one .vtu
  double checkpoint_interval = 0.0;  ///< (s), 0: only at the end
  FlowAdaptivity adapt;              ///< off unless [flow.adapt] is given
};

/// True when the case file has a [flow] section (the run is a flow run).
bool is_flow_case(const ConfigTable& cfg);

/// Reads and checks a flow case; throws InputError naming file and key.
FlowCase load_flow_case(const ConfigTable& cfg, const std::filesystem::path& source);

/// The viscosity at x: the last region holding x, else the fluid's.
double viscosity_at(const FlowCase& c, const Vec3& x);

/// The block size of a grid whose case does not set `block_cells`: 16 where
/// the grid does not adapt, every cell count is a multiple of 16 and at least
/// 32, and the grid holds at least 64 such blocks (64^3 cells or more), else
/// 8. Adaptive grids refine and coarsen whole blocks, and 8 keeps refined
/// regions tight; a large grid that never adapts gains nothing from small
/// blocks, and 16^3 ones run it about 1.4x faster per cell; a small one keeps
/// 8^3 blocks so that threads and ranks have blocks to share (64 blocks of
/// 16^3 give 16 workers 4 each). The rule does not look at the number of
/// threads or ranks (docs/performance.md, "Block size", "Automatic block size").
int automatic_block_cells(const std::array<int, 3>& cells, bool adaptive);

/// Why automatic_block_cells() gives what it gives, for run.log.
std::string automatic_block_cells_reason(const std::array<int, 3>& cells, bool adaptive);

/// A line suggesting 16^3 blocks where the case sets smaller ones and
/// automatic_block_cells() would have made them 16; empty otherwise.
/// describe() includes it.
std::string block_size_hint(const FlowCase& c);

/// The resolved parameters, one per line (for run.log).
std::string describe(const FlowCase& c);

}  // namespace sanguis::flow
