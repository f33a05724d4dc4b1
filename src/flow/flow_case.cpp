#include "flow/flow_case.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

namespace sanguis::flow {

namespace {

constexpr const char* kFaceNames[6] = {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"};

std::array<int, 3> read_cells(const ConfigTable& grid) {
  const Vec3 raw = grid.get_vec3("cells");
  std::array<int, 3> cells{};
  for (int d = 0; d < 3; ++d) {
    const double v = raw[d];
    if (v != std::floor(v) || v < 1 || v > 1 << 20) {
      grid.fail("cells", "must be three positive integers");
    }
    cells[static_cast<std::size_t>(d)] = static_cast<int>(v);
  }
  return cells;
}

/// Brick and level: as few trees as possible (the largest common level).
void choose_forest(const ConfigTable& grid, FlowCase& c, const Vec3& size) {
  const int b = c.forest.block_cells;
  for (int d = 0; d < 3; ++d) {
    if (c.cells[static_cast<std::size_t>(d)] % b != 0) {
      grid.fail("cells", "every count must be a multiple of block_cells = " + std::to_string(b));
    }
  }
  const double h = size.x / c.cells[0];
  for (int d = 1; d < 3; ++d) {
    const double hd = size[d] / c.cells[static_cast<std::size_t>(d)];
    if (std::abs(hd - h) > 1e-9 * h) {
      grid.fail("cells", "cells must be cubes: size_m / cells must be the same in x, y and z");
    }
  }
  int level = 0;
  auto divisible = [&](int l) {
    for (const int n : c.cells)
      if ((n / b) % (1 << l) != 0) return false;
    return true;
  };
  while (level < 10 && divisible(level + 1)) ++level;
  c.forest.level = level;
  for (std::size_t d = 0; d < 3; ++d) c.forest.trees[d] = c.cells[d] / b / (1 << level);
  c.forest.tree_length = h * b * (1 << level);
}

FlowBoundary read_boundary(const ConfigTable& t, std::string& text) {
  FlowBoundary bc;
  const std::string type = t.get_choice("type", {"periodic", "wall", "inflow", "outflow"});
  text = type;
  if (type == "periodic") {
    bc.kind = FlowBoundaryKind::Periodic;
  } else if (type == "wall") {
    bc.kind = FlowBoundaryKind::Wall;
    bc.wall_velocity = t.get_vec3("velocity_m_s", {});
    std::ostringstream s;
    s << "wall, velocity (" << bc.wall_velocity.x << ", " << bc.wall_velocity.y << ", "
      << bc.wall_velocity.z << ") m/s";
    text = s.str();
  } else if (type == "inflow") {
    bc.kind = FlowBoundaryKind::Inflow;
    const Vec3 u = t.get_vec3("velocity_m_s");
    const std::string profile = t.get_choice("profile", {"uniform", "parabolic"}, "uniform");
    std::ostringstream s;
    s << "inflow, " << profile << ", mean velocity (" << u.x << ", " << u.y << ", " << u.z
      << ") m/s";
    text = s.str();
    bc.inflow = [u](const Vec3&, double) { return u; };
    if (profile == "parabolic") bc.inflow = nullptr;  // set once the domain is known
    bc.wall_velocity = u;                             // the mean, for the parabolic profile
  } else {
    bc.kind = FlowBoundaryKind::Outflow;
  }
  return bc;
}

/// Parabolic inflow: 6 s (1 - s) along each non-periodic tangential direction
/// (mean 1 per direction), times the mean velocity.
VelocityProfile parabolic_profile(const FlowCase& c, int face) {
  const int d = face / 2;
  const Vec3 mean = c.boundaries[static_cast<std::size_t>(face)].wall_velocity;
  const Vec3 lower = c.forest.origin;
  const Vec3 extent{c.forest.trees[0] * c.forest.tree_length,
                    c.forest.trees[1] * c.forest.tree_length,
                    c.forest.trees[2] * c.forest.tree_length};
  const std::array<bool, 3> periodic = c.forest.periodic;
  return [=](const Vec3& x, double) {
    double shape = 1.0;
    for (int e = 0; e < 3; ++e) {
      if (e == d || periodic[static_cast<std::size_t>(e)]) continue;
      const double s = (x[e] - lower[e]) / extent[e];
      shape *= 6.0 * s * (1.0 - s);
    }
    return shape * mean;
  };
}

/// [flow.adapt]: levels relative to the grid's (the case's cells), the
/// wavelet thresholds of the fields the criterion reads, refinement regions.
void read_adaptivity(const ConfigTable& flow, const ConfigTable& t, FlowCase& c) {
  FlowAdaptivity& a = c.adapt;
  a.enabled = true;
  // 0: that field is not estimated.
  a.velocity_threshold = t.get_positive("velocity_threshold_m_s", 0.0);
  a.vorticity_threshold = t.get_positive("vorticity_threshold_1_s", 0.0);
  a.pressure_threshold = t.get_positive("pressure_threshold_Pa", 0.0);
  if (a.velocity_threshold == 0.0 && a.vorticity_threshold == 0.0 && a.pressure_threshold == 0.0) {
    t.fail("velocity_threshold_m_s",
           "missing: the wavelet criterion needs the threshold of at least one field "
           "(velocity_threshold_m_s, vorticity_threshold_1_s or pressure_threshold_Pa)");
  }
  const int base = c.forest.level;
  const std::int64_t refine = t.get_int("refine_levels", 1);
  if (refine < 0 || refine > 8) t.fail("refine_levels", "must be in 0..8");
  const std::int64_t coarsen = t.get_int("coarsen_levels", 0);
  if (coarsen < 0 || coarsen > base) {
    t.fail("coarsen_levels", "must be in 0.." + std::to_string(base) +
                                 ": the grid's blocks can be merged " + std::to_string(base) +
                                 " time(s) before they fill a p4est tree (more needs " +
                                 "cells divisible by larger powers of two)");
  }
  a.min_level = base - static_cast<int>(coarsen);
  a.max_level = base + static_cast<int>(refine);
  const std::int64_t every = t.get_int("every_steps", 1);
  if (every < 1 || every > 1000000) t.fail("every_steps", "must be in 1..1000000");
  a.every_steps = static_cast<int>(every);
  c.options.level_matched_advection = t.get_bool("level_matched_advection", false);
  // The estimate (4.11) restricts and prolongs inside a block: 4 cells at least.
  if (c.forest.block_cells < 4) {
    flow.table("grid").fail("block_cells",
                            "must be >= 4 with [flow.adapt] (the wavelet "
                            "estimate restricts and prolongs inside a block)");
  }
  for (const ConfigTable& r : t.table_array("region")) {
    RefinementRegion region;
    region.min = r.get_vec3("min_m");
    region.max = r.get_vec3("max_m");
    for (int d = 0; d < 3; ++d) {
      if (!(region.max[d] > region.min[d])) r.fail("max_m", "must be above min_m in x, y and z");
    }
    // Both keys count levels above the grid's, within [flow.adapt]'s range.
    const auto check_range = [&](const char* key, std::int64_t value) {
      if (value < -static_cast<std::int64_t>(coarsen) || value > refine) {
        r.fail(key, "must be in -coarsen_levels..refine_levels of [flow.adapt] (" +
                        std::to_string(-coarsen) + ".." + std::to_string(refine) + ")");
      }
    };
    const bool capped = r.has("max_refine_levels");
    if (!capped && !r.has("refine_levels")) {
      r.fail("refine_levels", "a region needs refine_levels, max_refine_levels or both");
    }
    // A region gives a floor, a cap or both; with a cap alone it has no floor.
    const std::int64_t levels =
        capped ? r.get_int("refine_levels", -static_cast<std::int64_t>(coarsen))
               : r.get_int("refine_levels");
    check_range("refine_levels", levels);
    region.refine_levels = static_cast<int>(levels);
    if (capped) {
      const std::int64_t cap = r.get_int("max_refine_levels");
      check_range("max_refine_levels", cap);
      if (cap < levels) r.fail("max_refine_levels", "must be >= the region's refine_levels");
      region.max_refine_levels = static_cast<int>(cap);
    }
    a.regions.push_back(region);
  }
}

/// On an adaptive grid every face of a solid box that lies inside the domain
/// must be a face of the [flow.grid] cells: the blocks kept at the finest
/// level next to solids are found by sampling the boxes at that grid's
/// resolution (NavierStokes::regrid), which sees a box between cell faces
/// only where it covers a cell centre of that grid.
void check_solids_on_grid_faces(const ConfigTable& flow, const FlowCase& c, const Vec3& size) {
  const auto boxes = flow.table_array("solid");
  for (std::size_t n = 0; n < boxes.size(); ++n) {
    const Vec3 lo = boxes[n].get_vec3("min_m"), hi = boxes[n].get_vec3("max_m");
    bool overlaps = true;  // a box outside the domain masks no cell
    for (int d = 0; d < 3; ++d) {
      overlaps = overlaps && hi[d] > c.forest.origin[d] && lo[d] < c.forest.origin[d] + size[d];
    }
    if (!overlaps) continue;
    for (const auto& [key, corner] : {std::pair{"min_m", lo}, std::pair{"max_m", hi}}) {
      for (int d = 0; d < 3; ++d) {
        const double h = size[d] / c.cells[static_cast<std::size_t>(d)];
        const double at = (corner[d] - c.forest.origin[d]) / h;  // in cells from the origin
        if (at <= 0.0 || at >= c.cells[static_cast<std::size_t>(d)]) continue;  // outside
        if (std::abs(at - std::round(at)) > 1e-6) {
          std::ostringstream why;
          why << "with [flow.adapt], solid boxes must lie on the [flow.grid] cell faces; "
              << "coordinate "
              << "xyz"[d] << " = " << corner[d] << " m is " << at - std::floor(at)
              << " of a cell past the face at " << c.forest.origin[d] + std::floor(at) * h
              << " m (cells of " << h << " m)";
          boxes[n].fail(key, why.str());
        }
      }
    }
  }
}

}  // namespace

bool is_flow_case(const ConfigTable& cfg) {
  return cfg.has("flow");
}

FlowCase load_flow_case(const ConfigTable& cfg, const std::filesystem::path& source) {
  FlowCase c;
  c.source = source;
  const ConfigTable sim = cfg.table("simulation");
  c.name = sim.get_string("name", source.stem().string());
  c.end_time = sim.get_positive("end_time_s");
  const std::int64_t threads = sim.get_int("threads", 0);
  if (threads < 0 || threads > 1024) sim.fail("threads", "must be 0 (all cores) or 1..1024");
  c.forest.threads = threads == 0 ? std::max(1, omp_get_num_procs()) : static_cast<int>(threads);

  const ConfigTable flow = cfg.table("flow");
  const ConfigTable grid = flow.table("grid");
  c.forest.origin = grid.get_vec3("origin_m", {});
  const Vec3 size = grid.get_vec3("size_m");
  for (int d = 0; d < 3; ++d) {
    if (!(size[d] > 0.0)) grid.fail("size_m", "every extent must be > 0");
  }
  c.cells = read_cells(grid);
  c.block_cells_automatic = !grid.has("block_cells");
  const std::int64_t b = c.block_cells_automatic ? automatic_block_cells(c.cells, flow.has("adapt"))
                                                 : grid.get_int("block_cells");
  if (b < 2 || b > 64 || (b & (b - 1)) != 0)
    grid.fail("block_cells", "must be a power of two in 2..64");
  c.forest.block_cells = static_cast<int>(b);
  choose_forest(grid, c, size);

  const ConfigTable fluid = flow.table("fluid");
  c.fluid.density = fluid.get_positive("density_kg_m3");
  c.fluid.viscosity = fluid.get_double("viscosity_Pa_s");
  if (!(c.fluid.viscosity >= 0.0)) fluid.fail("viscosity_Pa_s", "must be >= 0");

  const ConfigTable bounds = flow.table("boundary");
  for (int f = 0; f < 6; ++f) {
    const auto fi = static_cast<std::size_t>(f);
    c.boundaries[fi] = read_boundary(bounds.table(kFaceNames[f]), c.boundary_text[fi]);
  }
  for (int d = 0; d < 3; ++d) {
    const auto lo = static_cast<std::size_t>(2 * d), hi = lo + 1;
    const bool plo = c.boundaries[lo].kind == FlowBoundaryKind::Periodic;
    const bool phi = c.boundaries[hi].kind == FlowBoundaryKind::Periodic;
    if (plo != phi) {
      bounds.fail(
          kFaceNames[hi],
          std::string("periodic on one side needs periodic on the other (") + kFaceNames[lo] + ")");
    }
    c.forest.periodic[static_cast<std::size_t>(d)] = plo;
    for (const std::size_t f : {lo, hi}) {
      if (c.boundaries[f].kind == FlowBoundaryKind::Wall &&
          c.boundaries[f].wall_velocity[d] != 0.0) {
        bounds.fail(std::string(kFaceNames[f]) + ".velocity_m_s",
                    "a wall can only move tangentially");
      }
    }
  }
  // After the loop: the profile depends on the periodicity of all three directions.
  for (int f = 0; f < 6; ++f) {
    auto& bc = c.boundaries[static_cast<std::size_t>(f)];
    if (bc.kind == FlowBoundaryKind::Inflow && !bc.inflow) bc.inflow = parabolic_profile(c, f);
  }

  c.initial_velocity = flow.get_vec3("initial_velocity_m_s", {});
  c.body_force = flow.get_vec3("body_force_N_m3", {});
  for (const ConfigTable& box : flow.table_array("solid")) {
    const Vec3 lo = box.get_vec3("min_m"), hi = box.get_vec3("max_m");
    for (int d = 0; d < 3; ++d) {
      if (!(hi[d] > lo[d])) box.fail("max_m", "must be above min_m in x, y and z");
    }
    c.solid_boxes.push_back({lo, hi});
  }
  for (const ConfigTable& region : flow.table_array("viscosity_region")) {
    FlowCase::ViscosityRegion r;
    r.min = region.get_vec3("min_m");
    r.max = region.get_vec3("max_m");
    for (int d = 0; d < 3; ++d) {
      if (!(r.max[d] > r.min[d])) region.fail("max_m", "must be above min_m in x, y and z");
    }
    r.viscosity = region.get_double("viscosity_Pa_s");
    if (!(r.viscosity > 0.0)) region.fail("viscosity_Pa_s", "must be > 0");
    c.viscosity_regions.push_back(r);
  }

  const auto time = flow.find_table("time");
  if (time) {
    c.options.cfl = time->get_positive("cfl", 0.8);
    if (c.options.cfl > 1.0) time->fail("cfl", "must be <= 1 (BCG stability)");
    c.options.dt_max = time->get_positive("max_time_step_s", c.end_time);
    const std::string scheme =
        time->get_choice("viscous_scheme", {"backward_euler", "crank_nicolson"}, "backward_euler");
    c.options.viscous_theta = scheme == "crank_nicolson" ? 0.5 : 1.0;
  } else {
    c.options.dt_max = c.end_time;
  }
  const auto solver = flow.find_table("solver");
  if (solver) {
    const double tol = solver->get_positive("tolerance", 1e-6);
    if (tol >= 1.0) solver->fail("tolerance", "must be < 1");
    c.options.pressure.tolerance = tol;
    c.options.viscous.tolerance = tol;
    const std::int64_t cycles = solver->get_int("max_cycles", 50);
    if (cycles < 1 || cycles > 10000) solver->fail("max_cycles", "must be in 1..10000");
    c.options.pressure.max_cycles = c.options.viscous.max_cycles = static_cast<int>(cycles);
  }

  if (const auto adapt = flow.find_table("adapt")) {
    read_adaptivity(flow, *adapt, c);
    check_solids_on_grid_faces(flow, c, size);
  }

  const auto output = cfg.find_table("output");
  c.output_interval = c.end_time / 100.0;
  if (output) {
    c.output_interval = output->get_positive("interval_s", c.end_time / 100.0);
    c.vtk = output->get_bool("vtk", true);
    c.vtk_blocks = output->get_choice("vtk_format", {"vtu", "vtm"}, "vtu") == "vtm";
    c.checkpoint_interval = output->get_non_negative("checkpoint_interval_s", 0.0);
  }
  cfg.check_no_unknown_keys();
  return c;
}

double viscosity_at(const FlowCase& c, const Vec3& x) {
  double mu = c.fluid.viscosity;
  for (const auto& r : c.viscosity_regions) {
    if (x.x > r.min.x && x.x < r.max.x && x.y > r.min.y && x.y < r.max.y && x.z > r.min.z &&
        x.z < r.max.z) {
      mu = r.viscosity;
    }
  }
  return mu;
}

namespace {

/// Whether the cell counts make 64 blocks of b^3 or more, two or more per direction.
bool blocks_fit(const std::array<int, 3>& cells, int b) {
  const bool fit =
      std::all_of(cells.begin(), cells.end(), [b](int n) { return n % b == 0 && n >= 2 * b; });
  std::int64_t blocks = 1;
  for (const int n : cells) blocks *= n / b;
  return fit && blocks >= 64;
}

}  // namespace

// 32^3 blocks where they fit: out of cache a 16^3 block's two ghost layers
// make its stored 20^3 values 1.95x its cells, a 32^3 block's 36^3 1.42x, and
// the smoother streams them (docs/performance.md, "32³ blocks on large grids").
int automatic_block_cells(const std::array<int, 3>& cells, bool adaptive) {
  if (adaptive) return 8;
  if (blocks_fit(cells, 32)) return 32;
  return blocks_fit(cells, 16) ? 16 : 8;
}

std::string automatic_block_cells_reason(const std::array<int, 3>& cells, bool adaptive) {
  if (adaptive) return "8, as the grid adapts";
  if (blocks_fit(cells, 32)) return "32, as the grid does not adapt and makes 64 blocks of 32^3";
  if (!blocks_fit(cells, 16))
    return "8, as the cell counts do not make 64 blocks of 16^3 or more, two or more per "
           "direction";
  return "16, as the grid does not adapt and is large enough";
}

std::string block_size_hint(const FlowCase& c) {
  const int b = c.forest.block_cells;
  const int automatic = automatic_block_cells(c.cells, c.adapt.enabled);
  if (c.block_cells_automatic || automatic < 16 || b >= automatic) return {};
  const std::string size = std::to_string(automatic);
  return "hint: this grid does not adapt, and its cell counts make 64 blocks of " + size +
         "^3 or more: block_cells = " + size +
         ", or no block_cells at all, runs it faster per cell than " + std::to_string(b) +
         " (about 1.4x from 8 to 16 on the 64^3 cavity, 1.5x from 16 to 32 on the 128^3 one; "
         "docs/case-file.md, [flow.grid]; docs/performance.md, \"Block size\")";
}

std::string describe(const FlowCase& c) {
  std::ostringstream s;
  s.precision(10);
  const double h = c.forest.tree_length / (c.forest.block_cells << c.forest.level);
  s << "case " << c.name << " (" << c.source.string() << "): flow\n"
    << "grid: " << c.cells[0] << " x " << c.cells[1] << " x " << c.cells[2] << " cells of " << h
    << " m; blocks of " << c.forest.block_cells << "^3 cells"
    << (c.block_cells_automatic ? " (block_cells not given: " +
                                      automatic_block_cells_reason(c.cells, c.adapt.enabled) + ")"
                                : std::string())
    << "; p4est brick " << c.forest.trees[0] << " x " << c.forest.trees[1] << " x "
    << c.forest.trees[2] << " trees at level " << c.forest.level << "; origin ("
    << c.forest.origin.x << ", " << c.forest.origin.y << ", " << c.forest.origin.z << ") m\n"
    << "fluid: density " << c.fluid.density << " kg/m3, viscosity " << c.fluid.viscosity
    << " Pa s\n";
  for (int f = 0; f < 6; ++f)
    s << "boundary " << kFaceNames[f] << ": " << c.boundary_text[static_cast<std::size_t>(f)]
      << "\n";
  s << "initial velocity (" << c.initial_velocity.x << ", " << c.initial_velocity.y << ", "
    << c.initial_velocity.z << ") m/s; body force (" << c.body_force.x << ", " << c.body_force.y
    << ", " << c.body_force.z << ") N/m3\n";
  for (const auto& box : c.solid_boxes) {
    s << "solid box (" << box[0].x << ", " << box[0].y << ", " << box[0].z << ") - (" << box[1].x
      << ", " << box[1].y << ", " << box[1].z << ") m\n";
  }
  for (const auto& r : c.viscosity_regions) {
    s << "viscosity " << r.viscosity << " Pa s in (" << r.min.x << ", " << r.min.y << ", "
      << r.min.z << ") - (" << r.max.x << ", " << r.max.y << ", " << r.max.z << ") m\n";
  }
  s << "time: end " << c.end_time << " s, cfl " << c.options.cfl << ", max step "
    << c.options.dt_max << " s, viscous theta " << c.options.viscous_theta << "\n"
    << "multigrid: tolerance " << c.options.pressure.tolerance << " (relative to the rhs), at most "
    << c.options.pressure.max_cycles << " V(" << c.options.pressure.pre_sweeps << ","
    << c.options.pressure.post_sweeps << ") cycles\n"
    << "threads " << c.forest.threads << "\n";
  if (const auto hint = block_size_hint(c); !hint.empty()) s << hint << "\n";
  if (c.adapt.enabled) {
    const int base = c.forest.level;
    s << "adaptive grid: wavelet criterion (eq. 4.11) on";
    const char* sep = " ";
    const auto field = [&](double zeta, const char* name, const char* unit) {
      if (zeta == 0.0) return;
      s << sep << name << " (threshold " << zeta << " " << unit << ")";
      sep = ", ";
    };
    field(c.adapt.velocity_threshold, "the velocity", "m/s");
    field(c.adapt.vorticity_threshold, "the vorticity magnitude", "1/s");
    field(c.adapt.pressure_threshold, "the pressure", "Pa");
    s << ", every " << c.adapt.every_steps << " step(s); cells from "
      << (1 << (base - c.adapt.min_level)) << "x coarser to " << (1 << (c.adapt.max_level - base))
      << "x finer than the grid (p4est levels " << c.adapt.min_level << ".." << c.adapt.max_level
      << ")" << (c.options.level_matched_advection ? "; level-matched advection" : "") << "\n";
    for (const auto& r : c.adapt.regions) {
      s << "refinement region (" << r.min.x << ", " << r.min.y << ", " << r.min.z << ") - ("
        << r.max.x << ", " << r.max.y << ", " << r.max.z << ") m: at least " << r.refine_levels;
      if (r.max_refine_levels) s << ", at most " << *r.max_refine_levels;
      s << " level(s) above the grid\n";
    }
  }
  return s.str();
}

}  // namespace sanguis::flow
