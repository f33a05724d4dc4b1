#include "flow/flow_run.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <limits>
#include <optional>
#include <ostream>
#include <sstream>

#include "core/error.hpp"
#include "core/io/csv.hpp"
#include "core/io/vtk.hpp"
#include "core/progress.hpp"
#include "flow/adapt_criterion.hpp"
#include "flow/flow_output.hpp"

namespace sanguis::flow {

namespace {

namespace fs = std::filesystem;

const std::vector<std::string> kColumns = {"time_s",
                                           "step",
                                           "dt_s",
                                           "kinetic_energy_J",
                                           "max_velocity_m_s",
                                           "max_divergence_1_s",
                                           "pressure_vcycles",
                                           "pressure_reduction_per_cycle",
                                           "cells",
                                           "solid_force_x_N",
                                           "solid_force_y_N",
                                           "solid_force_z_N"};

struct Diagnostics {
  double kinetic_energy = 0.0;
  double max_velocity = 0.0;
};

Diagnostics diagnostics(const NavierStokes& ns) {
  const Forest& forest = ns.forest();
  const int b = forest.block_cells();
  double energy = 0.0, vmax = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const double h = forest.block(blk).length / b;
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          double v2 = 0.0;
          for (const auto& u : ns.velocity()) v2 += u(blk, i, j, k) * u(blk, i, j, k);
          energy += 0.5 * ns.fluid().density * v2 * h * h * h;
          vmax = std::max(vmax, std::sqrt(v2));
        }
  }
  if (!std::isfinite(energy)) vmax = std::numeric_limits<double>::infinity();
  return {forest.sum(energy), forest.max(vmax)};
}

/// "flow/flow_NNNNNNNN": a frame's name without its rank or extension.
std::string frame_stem(std::int64_t frame) {
  char name[64];
  std::snprintf(name, sizeof name, "flow/flow_%08lld", static_cast<long long>(frame));
  return name;
}

/// The .vtu of rank `rank` (of `ranks`) for a frame, relative to the output folder.
std::string frame_file(std::int64_t frame, int rank, int ranks) {
  return frame_stem(frame) + (ranks == 1 ? "" : "_r" + std::to_string(rank)) + ".vtu";
}

fs::path checkpoint_path(const fs::path& dir, const Forest& forest) {
  return forest.ranks() == 1 ? dir / "checkpoint.bin"
                             : dir / ("checkpoint_r" + std::to_string(forest.rank()) + ".bin");
}

/// Cells over all ranks.
double leaf_cells(const Forest& forest) {
  const double b = forest.block_cells();
  return static_cast<double>(forest.global_blocks()) * b * b * b;
}

/// [flow.adapt]: the wavelet criterion (eq. 4.11) on the fields with a
/// threshold (the three velocity components, the vorticity magnitude, the
/// pressure) within the case's levels, at least the regions' floors and at
/// most their caps (a block overlapping a region takes both).
std::vector<AdaptFlag> adapt_flags(const FlowAdaptivity& a, const Forest& forest,
                                   NavierStokes& ns) {
  // The estimate fills the fields' ghosts: the derived fields are copies, so
  // the solver's own pressure is left as the step made it.
  std::vector<BlockField*> fields;
  WaveletCriterion criterion{{}, a.min_level, a.max_level};
  if (a.velocity_threshold > 0.0) {
    for (BlockField& component : ns.velocity()) {
      fields.push_back(&component);
      criterion.thresholds.push_back(a.velocity_threshold);
    }
  }
  BlockField vorticity, pressure;
  if (a.vorticity_threshold > 0.0) {
    vorticity = ns.vorticity_magnitude();
    fields.push_back(&vorticity);
    criterion.thresholds.push_back(a.vorticity_threshold);
  }
  if (a.pressure_threshold > 0.0) {
    pressure = ns.pressure();
    fields.push_back(&pressure);
    criterion.thresholds.push_back(a.pressure_threshold);
  }
  const int base = forest.spec().level;
  const auto blocks = static_cast<std::size_t>(forest.local_blocks());
  criterion.block_min_level.assign(blocks, a.min_level);
  const bool capped = std::any_of(a.regions.begin(), a.regions.end(),
                                  [](const RefinementRegion& r) { return r.max_refine_levels; });
  if (capped) criterion.block_max_level.assign(blocks, a.max_level);
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const Block& block = forest.block(blk);
    const auto at = static_cast<std::size_t>(blk);
    for (const RefinementRegion& r : a.regions) {
      bool overlaps = true;
      for (int d = 0; d < 3; ++d) {
        overlaps =
            overlaps && block.lower[d] < r.max[d] && block.lower[d] + block.length > r.min[d];
      }
      if (!overlaps) continue;
      criterion.block_min_level[at] =
          std::max(criterion.block_min_level[at], base + r.refine_levels);
      if (r.max_refine_levels) {
        criterion.block_max_level[at] =
            std::min(criterion.block_max_level[at], base + *r.max_refine_levels);
      }
    }
  }
  return wavelet_flags(forest, fields, criterion);
}

}  // namespace

FlowRunSummary run_flow_case(const FlowCase& c, const FlowRunOptions& options,
                             std::ostream& console) {
  const fs::path dir = options.output_dir;
  Forest forest(c.forest);
  const bool root = forest.rank() == 0;
  const fs::path checkpoint = checkpoint_path(dir, forest);
  const fs::path csv_path = dir / "diagnostics.csv";
  if (options.restart && !fs::exists(checkpoint)) {
    const bool other_ranks =
        fs::exists(dir / "checkpoint_r0.bin") || fs::exists(dir / "checkpoint.bin");
    throw InputError(checkpoint.string(), "",
                     other_ranks
                         ? "no checkpoint for this number of ranks (restart with the mpirun -np "
                           "of the run that wrote the checkpoint)"
                         : "no checkpoint to restart from");
  }
  NavierStokes ns(forest, c.boundaries, c.fluid, c.options);
  if (!c.solid_boxes.empty()) {
    ns.set_solid([&](const Vec3& x) {
      for (const auto& box : c.solid_boxes) {
        if (x.x > box[0].x && x.x < box[1].x && x.y > box[0].y && x.y < box[1].y &&
            x.z > box[0].z && x.z < box[1].z) {
          return true;
        }
      }
      return false;
    });
  }
  ns.set_body_force([&](const Vec3&) { return c.body_force; });
  // Sampled at cell centres, again after each regrid (a checkpoint's values replace it on restart).
  if (!c.viscosity_regions.empty())
    ns.set_viscosity([&](const Vec3& x) { return viscosity_at(c, x); });
  std::int64_t steps = 0, frames = 0;
  double regrid_seconds = 0.0;
  const auto regrid = [&]() {
    const auto start = std::chrono::steady_clock::now();
    ns.regrid(forest, adapt_flags(c.adapt, forest, ns), {}, c.adapt.max_level);
    regrid_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  if (options.restart) {
    const auto counters = load_flow_checkpoint(checkpoint, ns, c.adapt.enabled ? &forest : nullptr);
    steps = counters.steps;
    frames = counters.frames;
    if (root && fs::exists(csv_path)) io::CsvWriter::truncate_after(csv_path, ns.time());
  } else {
    ns.set_velocity([&](const Vec3&) { return c.initial_velocity; });
    if (c.adapt.enabled) {
      // The initial grid: one level per pass, then the initial field on it.
      for (int pass = 0; pass <= c.adapt.max_level - c.adapt.min_level; ++pass) {
        regrid();
        ns.set_velocity([&](const Vec3&) { return c.initial_velocity; });
      }
      regrid_seconds = 0.0;  // the share reported is that of the time loop
    }
  }
  fs::create_directories(dir / "flow");

  std::ofstream log;
  if (root) {
    log = open_run_log(dir, options.restart, ns.time());
    log << describe(c) << "ranks " << forest.ranks() << "\n"
        << "multigrid blocks " << ns.solver_block_cells() << "^3"
        << (ns.solver_block_cells() != forest.block_cells()
                ? " (the grid's blocks merged by families of 8: docs/theory/flow.md)"
                : "")
        << "\n"
        << std::flush;
  }
  io::PvdIndex pvd(dir / "flow.pvd");
  if (options.restart && root) pvd.load_existing(ns.time());
  std::optional<io::CsvWriter> csv;
  if (root) csv.emplace(csv_path, kColumns, options.restart && fs::exists(csv_path));

  StepReport last;
  const auto record = [&]() {
    if (c.vtk && c.vtk_blocks) {
      write_flow_block_frame(ns, dir, frame_stem(frames));
      if (root) {
        pvd.add(ns.time(), frame_stem(frames) + ".vtm");
        pvd.write();
      }
      ++frames;
    } else if (c.vtk) {
      io::write_hex_mesh_vtu(dir / frame_file(frames, forest.rank(), forest.ranks()),
                             flow_mesh(ns));
      if (root) {
        for (int r = 0; r < forest.ranks(); ++r) {
          pvd.add(ns.time(), frame_file(frames, r, forest.ranks()), r);
        }
        pvd.write();
      }
      ++frames;
    }
    const Diagnostics d = diagnostics(ns);
    const double divergence = ns.max_divergence();
    const Vec3 force = ns.solid_force();
    if (csv) {
      csv->row({ns.time(), static_cast<double>(steps), last.dt, d.kinetic_energy, d.max_velocity,
                divergence, static_cast<double>(last.pressure_cycles), last.pressure_reduction,
                leaf_cells(forest), force.x, force.y, force.z});
    }
    if (!std::isfinite(d.max_velocity))
      throw SimulationError("non-finite velocity at t = " + std::to_string(ns.time()));
  };
  if (!options.restart) record();

  const double end = options.stop_at >= 0.0 ? std::min(options.stop_at, c.end_time) : c.end_time;
  const double eps = 1e-12 * c.end_time;
  double next_output = c.output_interval * (std::floor(ns.time() / c.output_interval + 1e-9) + 1.0);
  double next_checkpoint =
      c.checkpoint_interval > 0.0
          ? c.checkpoint_interval * (std::floor(ns.time() / c.checkpoint_interval + 1e-9) + 1.0)
          : std::numeric_limits<double>::infinity();
  if (root) {
    console << "sanguis run: " << c.name << ": flow, " << static_cast<long long>(leaf_cells(forest))
            << " cells in " << forest.global_blocks() << " blocks"
            << (c.adapt.enabled ? " (adaptive)" : "") << " on " << forest.ranks()
            << " rank(s), to t = " << end << " s, output to " << dir.string() << "\n";
  }
  ProgressReporter progress(std::cerr, root && !options.quiet && isatty(STDERR_FILENO) != 0);
  const std::int64_t first_step = steps;
  double cell_updates = 0.0;
  std::int64_t pressure_cycles = 0;
  try {
    while (ns.time() < end - eps &&
           (options.max_steps < 0 || steps - first_step < options.max_steps)) {
      // Every k steps counted from the start (a restart keeps the schedule).
      if (c.adapt.enabled && steps > 0 && steps % c.adapt.every_steps == 0) regrid();
      double dt = ns.stable_dt();
      dt = std::min({dt, next_output - ns.time(), end - ns.time()});
      last = ns.step(dt);
      ++steps;
      pressure_cycles += last.pressure_cycles;
      cell_updates += leaf_cells(forest);
      if (ns.time() >= next_output - eps) {
        record();
        next_output += c.output_interval;
      }
      if (ns.time() >= next_checkpoint - eps) {
        save_flow_checkpoint(checkpoint, ns, steps, frames);
        next_checkpoint += c.checkpoint_interval;
      }
      if (root && !options.quiet && (steps & 15) == 0) {
        char status[128];
        std::snprintf(status, sizeof status, "t = %.4g / %.4g s, dt %.3g s", ns.time(), end, dt);
        progress.update(ns.time() / end, status, cell_updates);
      }
    }
  } catch (const SimulationError& e) {
    if (root) {
      log << "ERROR: " << e.what() << "\nended by this error, "
          << ProgressReporter::wall_clock_stamp() << "\n";
    }
    throw;
  }
  const double since_output = ns.time() - (next_output - c.output_interval);
  if (since_output > eps && ns.time() >= c.end_time - eps) record();
  save_flow_checkpoint(checkpoint, ns, steps, frames);

  FlowRunSummary summary;
  summary.steps = steps - first_step;
  summary.simulated_time = ns.time();
  summary.wall_seconds = progress.elapsed_seconds();
  summary.regrid_seconds = regrid_seconds;
  summary.cells = leaf_cells(forest);
  summary.pressure_cycles = pressure_cycles;
  summary.ranks = forest.ranks();
  std::ostringstream done;
  done.precision(4);
  // The time to 10 digits: scripts read it to tell a finished run from a stopped one
  // (validation/*/), and 4 digits could round an end time down.
  done << "done: t = " << std::setprecision(10) << ns.time() << std::setprecision(4) << " s, "
       << summary.steps << " steps in " << ProgressReporter::format_duration(summary.wall_seconds)
       << " (" << (summary.wall_seconds > 0 ? cell_updates / summary.wall_seconds : 0.0)
       << " cell-updates/s), ended " << ProgressReporter::wall_clock_stamp();
  if (c.adapt.enabled && summary.wall_seconds > 0) {
    done << "; " << static_cast<long long>(leaf_cells(forest)) << " cells at the end, regridding "
         << 100.0 * regrid_seconds / summary.wall_seconds << " % of the time";
  }
  if (root) progress.finish(done.str());
  if (root) {
    log << done.str() << "\n";
    console << "outputs:\n"
            << "  ParaView    " << (dir / "flow.pvd").string() << "\n"
            << "  diagnostics " << csv_path.string() << "\n"
            << "  log         " << (dir / "run.log").string() << "\n"
            << "  checkpoint  " << checkpoint.string() << "\n";
  }
  return summary;
}

}  // namespace sanguis::flow
