#include "dem/dem_run.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>

#include "core/error.hpp"
#include "core/io/csv.hpp"
#include "core/io/vtk.hpp"
#include "core/progress.hpp"
#include "core/version.hpp"

namespace sanguis::dem {

namespace {

const std::vector<std::string> kDiagnosticColumns = {"time_s",
                                                     "kinetic_energy_translational_J",
                                                     "kinetic_energy_rotational_J",
                                                     "mean_velocity_m_s",
                                                     "max_velocity_m_s",
                                                     "mean_angular_velocity_rad_s",
                                                     "particle_contacts",
                                                     "wall_contacts",
                                                     "max_overlap_over_radius"};

std::vector<double> diagnostic_row(const DemDiagnostics& d) {
  return {d.time,
          d.kinetic_energy_translational,
          d.kinetic_energy_rotational,
          d.mean_velocity,
          d.max_velocity,
          d.mean_angular_velocity,
          static_cast<double>(d.particle_contacts),
          static_cast<double>(d.wall_contacts),
          d.max_overlap_ratio};
}

io::PointCloud particle_cloud(const ParticleStore& p) {
  io::PointCloud cloud;
  cloud.points = p.position;
  const auto vec_field = [&](const char* name, const std::vector<Vec3>& values) {
    io::DataArray a{name, 3, {}};
    a.values.reserve(3 * values.size());
    for (const Vec3& v : values) a.values.insert(a.values.end(), {v.x, v.y, v.z});
    cloud.point_data.push_back(std::move(a));
  };
  cloud.point_data.push_back({"radius", 1, p.radius});
  vec_field("velocity", p.velocity);
  vec_field("angular_velocity", p.angular_velocity);
  vec_field("force", p.force);
  io::IntDataArray ids{"id", 1, {p.id.begin(), p.id.end()}};
  io::IntDataArray coordination{"coordination", 1, {p.coordination.begin(), p.coordination.end()}};
  io::IntDataArray material{"material", 1, {p.material.begin(), p.material.end()}};
  cloud.int_point_data = {ids, coordination, material};
  return cloud;
}

// Obstacles as polygons: boxes as their 6 faces, planes as a square patch covering the
// domain, so that ParaView shows the container and the gate disappearing.
io::PolyMesh obstacle_mesh(const DemSetup& s, double time) {
  io::PolyMesh mesh;
  std::vector<std::int64_t> ids;
  const auto add_quad = [&](const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
                            std::int64_t id) {
    const auto base = static_cast<std::int64_t>(mesh.points.size());
    mesh.points.insert(mesh.points.end(), {a, b, c, d});
    mesh.polygons.push_back({base, base + 1, base + 2, base + 3});
    ids.push_back(id);
  };
  const Vec3 centre = 0.5 * (s.domain.min + s.domain.max);
  const double half = 0.5 * norm(s.domain.max - s.domain.min);
  for (std::size_t o = 0; o < s.obstacles.size(); ++o) {
    const Obstacle& ob = s.obstacles[o];
    if (!ob.active(time)) continue;
    const auto id = static_cast<std::int64_t>(o);
    if (const auto* plane = std::get_if<PlaneShape>(&ob.shape)) {
      const Vec3 n = plane->normal;
      const Vec3 helper = std::abs(n.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
      const Vec3 u = cross(n, helper) / norm(cross(n, helper));
      const Vec3 v = cross(n, u);
      const Vec3 c = centre - dot(centre - plane->point, n) * n;
      add_quad(c - half * u - half * v, c + half * u - half * v, c + half * u + half * v,
               c - half * u + half * v, id);
    } else {
      const auto& b = std::get<AxisAlignedBoxShape>(ob.shape);
      const Vec3 p[8] = {{b.min.x, b.min.y, b.min.z}, {b.max.x, b.min.y, b.min.z},
                         {b.max.x, b.max.y, b.min.z}, {b.min.x, b.max.y, b.min.z},
                         {b.min.x, b.min.y, b.max.z}, {b.max.x, b.min.y, b.max.z},
                         {b.max.x, b.max.y, b.max.z}, {b.min.x, b.max.y, b.max.z}};
      const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                               {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}};
      for (const auto& f : faces) add_quad(p[f[0]], p[f[1]], p[f[2]], p[f[3]], id);
    }
  }
  mesh.int_cell_data.push_back({"obstacle", 1, ids});
  return mesh;
}

class SnapshotWriter {
 public:
  SnapshotWriter(const std::filesystem::path& dir, bool enabled, bool restart, double t)
      : dir_(dir),
        enabled_(enabled),
        particles_(dir / "particles.pvd"),
        obstacles_(dir / "obstacles.pvd") {
    if (!enabled_) return;
    std::filesystem::create_directories(dir / "particles");
    std::filesystem::create_directories(dir / "obstacles");
    if (restart) {
      particles_.load_existing(t);
      obstacles_.load_existing(t);
      next_frame_ = static_cast<std::int64_t>(particles_.entries().size());
    }
  }

  // Frames are numbered in the order they are written (not by time), so an extra
  // snapshot (end time off the output grid, a blow-up) never overwrites another.
  void write(const DemSimulation& sim) {
    if (!enabled_) return;
    char name[64];
    std::snprintf(name, sizeof name, "%08lld", static_cast<long long>(next_frame_++));
    const std::string p = std::string("particles/particles_") + name + ".vtu";
    const std::string o = std::string("obstacles/obstacles_") + name + ".vtp";
    io::write_point_cloud_vtu(dir_ / p, particle_cloud(sim.particles()));
    io::write_polymesh_vtp(dir_ / o, obstacle_mesh(sim.setup(), sim.time()));
    particles_.add(sim.time(), p);
    obstacles_.add(sim.time(), o);
    particles_.write();
    obstacles_.write();
  }

 private:
  std::filesystem::path dir_;
  bool enabled_;
  io::PvdIndex particles_, obstacles_;
  std::int64_t next_frame_ = 0;
};

std::int64_t steps_for(double duration, double dt) {
  return std::max<std::int64_t>(1, std::llround(duration / dt));
}

}  // namespace

RunSummary run_dem_case(const DemCase& c, const RunOptions& options, std::ostream& console) {
  namespace fs = std::filesystem;
  const fs::path dir = options.output_dir;
  const fs::path checkpoint = dir / "checkpoint.bin";
  const fs::path csv_path = dir / "diagnostics.csv";
  if (options.restart && !fs::exists(checkpoint)) {
    throw InputError(checkpoint.string(), "", "no checkpoint to restart from");
  }

  DemSimulation sim(c.setup);
  const double dt = sim.time_step();
  if (options.restart) {
    sim.load_checkpoint(checkpoint);
    if (fs::exists(csv_path)) io::CsvWriter::truncate_after(csv_path, sim.time());
  }
  fs::create_directories(dir);

  // run.log: resolved parameters first, then events.
  std::ofstream log(dir / "run.log", options.restart ? std::ios::app : std::ios::trunc);
  if (!log) throw InputError((dir / "run.log").string(), "", "cannot write the run log");
  log << (options.restart ? "\n--- restart from checkpoint at t = " : "sanguis ")
      << (options.restart ? std::to_string(sim.time()) + " s" : std::string(kVersion)) << "\n"
      << describe(c) << std::flush;

  const std::int64_t total_steps = steps_for(c.stop.end_time, dt);
  const std::int64_t stop_step =
      options.stop_at >= 0 ? std::min(total_steps, steps_for(options.stop_at, dt)) : total_steps;
  const std::int64_t output_every = steps_for(c.output.interval, dt);
  const std::int64_t checkpoint_every =
      c.output.checkpoint_interval > 0 ? steps_for(c.output.checkpoint_interval, dt) : 0;
  const std::int64_t settle_after = std::llround(c.stop.settle_check_after / dt);

  SnapshotWriter snapshots(dir, c.output.vtk, options.restart, sim.time());
  io::CsvWriter csv(csv_path, kDiagnosticColumns, options.restart && fs::exists(csv_path));
  const auto record = [&]() {
    snapshots.write(sim);
    csv.row(diagnostic_row(sim.diagnostics()));
  };
  if (!options.restart) record();

  console << "sanguis run: " << c.name << ": " << sim.particles().size() << " particles, "
          << total_steps << " steps of " << dt << " s, output to " << dir.string() << "\n";
  ProgressReporter progress(std::cerr, !options.quiet && isatty(STDERR_FILENO) != 0);
  const std::int64_t first_step = sim.step_index();
  const double n = static_cast<double>(sim.particles().size());

  RunSummary summary;
  try {
    while (sim.step_index() < stop_step) {
      sim.step();
      const std::int64_t s = sim.step_index();
      const bool output_now = s % output_every == 0;
      if (output_now) record();
      if (checkpoint_every > 0 && s % checkpoint_every == 0) sim.save_checkpoint(checkpoint);
      if (output_now && c.stop.mean_velocity_below && s >= settle_after &&
          sim.diagnostics().mean_velocity < *c.stop.mean_velocity_below) {
        summary.settled = true;
        log << "settled at t = " << sim.time() << " s: mean velocity below "
            << *c.stop.mean_velocity_below << " m/s\n";
        break;
      }
      if (!options.quiet && (s & 255) == 0) {
        char status[128];
        std::snprintf(status, sizeof status, "t = %.4g / %.4g s", sim.time(), c.stop.end_time);
        progress.update(static_cast<double>(s) / static_cast<double>(total_steps), status,
                        n * static_cast<double>(s - first_step));
      }
    }
  } catch (const SimulationError& e) {
    // Keep what the run had: a last snapshot to look at, and the reason in the log.
    record();
    log << "ERROR: " << e.what() << "\n";
    throw;
  }
  // A last record at the end time if it is off the output grid; not when stopping early
  // for a later restart, so that a split run writes exactly the rows of a whole one.
  const bool stopped_early = sim.step_index() < total_steps && !summary.settled;
  if (sim.step_index() % output_every != 0 && !stopped_early) record();
  sim.save_checkpoint(checkpoint);

  summary.steps = sim.step_index() - first_step;
  summary.simulated_time = sim.time();
  summary.wall_seconds = progress.elapsed_seconds();
  summary.last = sim.diagnostics();
  std::ostringstream done;
  done.precision(4);
  done << "done: t = " << sim.time() << " s, " << summary.steps << " steps in "
       << ProgressReporter::format_duration(summary.wall_seconds) << " ("
       << (summary.wall_seconds > 0 ? n * static_cast<double>(summary.steps) / summary.wall_seconds
                                    : 0.0)
       << " particle-steps/s)" << (summary.settled ? ", settled" : "");
  progress.finish(done.str());
  log << done.str() << "\n";
  console << "outputs:\n"
          << "  ParaView    " << (dir / "particles.pvd").string() << "  (and obstacles.pvd)\n"
          << "  diagnostics " << csv_path.string() << "\n"
          << "  log         " << (dir / "run.log").string() << "\n"
          << "  checkpoint  " << checkpoint.string() << "\n";
  return summary;
}

}  // namespace sanguis::dem
