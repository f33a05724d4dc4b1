#include "dem/analysis/run_output.hpp"

#include <unordered_set>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

#include "core/error.hpp"
#include "core/io/vtk_reader.hpp"

namespace sanguis::dem::analysis {
namespace {

// The frames of a .pvd index: a decomposed run writes one part per process at each time.
std::vector<std::pair<double, std::vector<std::string>>> frames_of(
    const std::filesystem::path& pvd) {
  std::vector<std::pair<double, std::vector<std::string>>> frames;
  if (!std::filesystem::exists(pvd)) return frames;
  for (const auto& e : io::read_pvd(pvd)) {
    if (e.part > 0 && !frames.empty() && frames.back().first == e.time) {
      frames.back().second.push_back(e.dataset);
    } else {
      frames.push_back({e.time, {e.dataset}});
    }
  }
  return frames;
}

std::vector<std::vector<std::string>> dataset_files(const std::filesystem::path& pvd) {
  std::vector<std::vector<std::string>> files;
  for (auto& frame : frames_of(pvd)) files.push_back(std::move(frame.second));
  return files;
}

// Pieces of one frame written by the same writer: the same arrays in the same order.
template <typename Array>
void append_arrays(std::vector<Array>& to, const std::vector<Array>& from) {
  if (to.empty()) {
    to = from;
    return;
  }
  for (std::size_t k = 0; k < to.size() && k < from.size(); ++k) {
    to[k].values.insert(to[k].values.end(), from[k].values.begin(), from[k].values.end());
  }
}

io::PointCloud read_clouds(const std::vector<std::string>& files) {
  io::PointCloud all;
  for (const std::string& file : files) {
    const io::PointCloud piece = io::read_point_cloud_vtu(file);
    all.points.insert(all.points.end(), piece.points.begin(), piece.points.end());
    append_arrays(all.point_data, piece.point_data);
    append_arrays(all.int_point_data, piece.int_point_data);
  }
  return all;
}

io::PolyMesh read_meshes(const std::vector<std::string>& files) {
  io::PolyMesh all;
  for (const std::string& file : files) {
    const io::PolyMesh piece = io::read_polymesh_vtp(file);
    const auto offset = static_cast<std::int64_t>(all.points.size());
    all.points.insert(all.points.end(), piece.points.begin(), piece.points.end());
    for (auto cell : piece.lines) {
      for (auto& v : cell) v += offset;
      all.lines.push_back(std::move(cell));
    }
    for (auto cell : piece.polygons) {
      for (auto& v : cell) v += offset;
      all.polygons.push_back(std::move(cell));
    }
    // Cell data: lines then polygons per piece; pieces here hold only one of the two.
    append_arrays(all.cell_data, piece.cell_data);
    append_arrays(all.int_cell_data, piece.int_cell_data);
  }
  return all;
}

std::vector<Vec3> as_vectors(const std::vector<double>& xyz) {
  std::vector<Vec3> v(xyz.size() / 3);
  for (std::size_t k = 0; k < v.size(); ++k) v[k] = {xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]};
  return v;
}

const std::vector<std::string>& file_of(const std::vector<std::vector<std::string>>& files,
                                        std::size_t frame, const std::string& what) {
  if (frame >= files.size()) {
    throw std::runtime_error("frame " + std::to_string(frame) + " has no " + what + " file");
  }
  return files[frame];
}

// Keeps the entries k with keep[k] of each array (all of one frame's length), in order.
template <typename... Arrays>
void keep_entries(const std::vector<bool>& keep, Arrays&... arrays) {
  const auto compact = [&](auto& a) {
    if (a.empty()) return;  // an optional array the run did not write
    std::size_t kept = 0;
    for (std::size_t k = 0; k < keep.size(); ++k) {
      if (keep[k]) a[kept++] = a[k];
    }
    a.resize(kept);
  };
  (compact(arrays), ...);
}

// Glued particles (a rough floor) are part of the walls, not of the granular mass: the
// run-out, heights, velocities and coordination are measured on the mobile particles.
void drop_fixed(ParticleFrame& f, const std::vector<std::int64_t>& fixed) {
  if (fixed.size() != f.size())
    throw std::runtime_error("particle frame: 'fixed' has a wrong length");
  std::vector<bool> keep(fixed.size());
  for (std::size_t k = 0; k < fixed.size(); ++k) keep[k] = fixed[k] == 0;
  keep_entries(keep, f.id, f.position, f.velocity, f.radius, f.mass, f.spherical);
}

}  // namespace

RunOutput::RunOutput(std::filesystem::path dir) : dir_(std::move(dir)) {
  const auto pvd = dir_ / "particles.pvd";
  if (!std::filesystem::exists(pvd)) {
    throw InputError(dir_.string(), "", "not a sanguis DEM output folder (no particles.pvd)");
  }
  for (auto& frame : frames_of(pvd)) {
    times_.push_back(frame.first);
    particle_files_.push_back(std::move(frame.second));
  }
  contact_files_ = dataset_files(dir_ / "contacts.pvd");
  branch_files_ = dataset_files(dir_ / "branches.pvd");
  body_files_ = frames_of(dir_ / "bodies.pvd");

  // obstacles.csv: index,type,remove_at_s,name (the name last: it may hold commas).
  std::ifstream table(dir_ / "obstacles.csv");
  std::string line;
  std::getline(table, line);  // header
  while (std::getline(table, line)) {
    const std::size_t type = line.find(',');
    const std::size_t removal = type == std::string::npos ? type : line.find(',', type + 1);
    const std::size_t name = removal == std::string::npos ? removal : line.find(',', removal + 1);
    if (name == std::string::npos) continue;
    obstacle_names_.push_back(line.substr(name + 1));
    const double t = std::strtod(line.c_str() + removal + 1, nullptr);  // "inf": never removed
    if (std::isfinite(t) && (!first_removal_ || t < *first_removal_)) first_removal_ = t;
  }
}

std::size_t RunOutput::frame_at(double t) const {
  if (times_.empty()) throw std::runtime_error(dir_.string() + ": no frames");
  if (t < 0) return times_.size() - 1;
  const auto after = std::upper_bound(times_.begin(), times_.end(), t + 1e-12 * std::abs(t));
  return after == times_.begin() ? 0 : static_cast<std::size_t>(after - times_.begin()) - 1;
}

ParticleFrame RunOutput::particles(std::size_t frame) const {
  const io::PointCloud cloud = read_clouds(file_of(particle_files_, frame, "particle"));
  ParticleFrame f;
  f.time = times_.at(frame);
  f.position = cloud.points;
  f.radius = io::find_array(cloud.point_data, "radius").values;
  f.velocity = as_vectors(io::find_array(cloud.point_data, "velocity").values);
  if (io::has_array(cloud.point_data, "mass"))
    f.mass = io::find_array(cloud.point_data, "mass").values;
  f.id = io::find_array(cloud.int_point_data, "id").values;
  f.spherical = io::find_array(cloud.int_point_data, "spherical").values;
  if (io::has_array(cloud.int_point_data, "fixed")) {
    drop_fixed(f, io::find_array(cloud.int_point_data, "fixed").values);
  }
  return f;
}

std::unordered_set<std::int64_t> RunOutput::fixed_ids(std::size_t frame) const {
  std::unordered_set<std::int64_t> ids;
  const io::PointCloud cloud = read_clouds(file_of(particle_files_, frame, "particle"));
  if (!io::has_array(cloud.int_point_data, "fixed")) return ids;
  const auto& fixed = io::find_array(cloud.int_point_data, "fixed").values;
  const auto& id = io::find_array(cloud.int_point_data, "id").values;
  for (std::size_t k = 0; k < fixed.size() && k < id.size(); ++k) {
    if (fixed[k] != 0) ids.insert(id[k]);
  }
  return ids;
}

ContactPointFrame RunOutput::contacts(std::size_t frame) const {
  const io::PointCloud cloud = read_clouds(file_of(contact_files_, frame, "contact"));
  ContactPointFrame f;
  f.point = cloud.points;
  f.force = as_vectors(io::find_array(cloud.point_data, "force").values);
  f.kind = io::find_array(cloud.int_point_data, "kind").values;
  f.first = io::find_array(cloud.int_point_data, "first_id").values;
  f.second = io::find_array(cloud.int_point_data, "second_id").values;
  // Contacts of glued particles belong to the walls they make: left out with them.
  const auto fixed = fixed_ids(frame);
  if (fixed.empty()) return f;
  std::vector<bool> keep(f.size());
  for (std::size_t k = 0; k < f.size(); ++k) {
    const bool pair = !ContactPointFrame::is_wall(f.kind[k]);
    keep[k] = !fixed.count(f.first[k]) && !(pair && fixed.count(f.second[k]));
  }
  keep_entries(keep, f.point, f.force, f.kind, f.first, f.second);
  return f;
}

BranchFrame RunOutput::branches(std::size_t frame) const {
  const io::PolyMesh mesh = read_meshes(file_of(branch_files_, frame, "branch"));
  BranchFrame f;
  for (const auto& line : mesh.lines) {
    f.from.push_back(mesh.points.at(static_cast<std::size_t>(line.front())));
    f.to.push_back(mesh.points.at(static_cast<std::size_t>(line.back())));
  }
  f.force_magnitude = io::find_array(mesh.cell_data, "force_magnitude").values;
  f.first = io::find_array(mesh.int_cell_data, "first_id").values;
  f.second = io::find_array(mesh.int_cell_data, "second_id").values;
  const auto fixed = fixed_ids(frame);
  if (fixed.empty()) return f;
  std::vector<bool> keep(f.size());
  for (std::size_t k = 0; k < f.size(); ++k) {
    keep[k] = !fixed.count(f.first[k]) && !fixed.count(f.second[k]);
  }
  keep_entries(keep, f.from, f.to, f.force_magnitude, f.first, f.second);
  return f;
}

BodySurfaceFrame RunOutput::bodies(std::size_t frame) const {
  BodySurfaceFrame f;
  if (body_files_.empty()) return f;
  const double t = times_.at(frame);
  const auto match = std::find_if(body_files_.begin(), body_files_.end(), [&](const auto& entry) {
    return std::abs(entry.first - t) <= 1e-9 * std::max(1.0, std::abs(t));
  });
  if (match == body_files_.end()) {
    throw std::runtime_error(dir_.string() +
                             ": no body surfaces (bodies.pvd) at t = " + std::to_string(t) +
                             " s, the time of particle frame " + std::to_string(frame));
  }
  const io::PolyMesh mesh = read_meshes(match->second);
  for (const auto& polygon : mesh.polygons) {
    // Fan triangulation (the writer emits triangles; this keeps quads correct too).
    for (std::size_t k = 1; k + 1 < polygon.size(); ++k) {
      f.a.push_back(mesh.points.at(static_cast<std::size_t>(polygon[0])));
      f.b.push_back(mesh.points.at(static_cast<std::size_t>(polygon[k])));
      f.c.push_back(mesh.points.at(static_cast<std::size_t>(polygon[k + 1])));
    }
  }
  return f;
}

std::string RunOutput::obstacle_name(std::int64_t index) const {
  if (index >= 0 && static_cast<std::size_t>(index) < obstacle_names_.size()) {
    return obstacle_names_[static_cast<std::size_t>(index)];
  }
  return "obstacle " + std::to_string(index);
}

}  // namespace sanguis::dem::analysis
