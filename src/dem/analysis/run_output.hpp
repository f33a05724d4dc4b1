#pragma once
// Read access to the output folder of a finished (or running) DEM run:
// the frames of particles.pvd, contacts.pvd, branches.pvd and bodies.pvd,
// and the obstacle names of obstacles.csv. The analysis tools work on these
// files only, so they apply to any run, including one on another machine.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <unordered_set>
#include <vector>

#include "core/vec3.hpp"

namespace sanguis::dem::analysis {

struct ParticleFrame {
  double time = 0.0;
  std::vector<std::int64_t> id;
  std::vector<Vec3> position;  // centres of mass [m]
  std::vector<Vec3> velocity;  // [m/s]
  std::vector<double> radius;  // bounding radius [m]
  std::vector<double> mass;    // [kg]; empty for runs written before it was output
  std::vector<std::int64_t> spherical;
  std::size_t size() const { return position.size(); }
};

// Contact points (one per sphere contact or element contact), as in contacts.pvd.
struct ContactPointFrame {
  std::vector<Vec3> point;
  std::vector<Vec3> force;  // on the first particle [N]
  std::vector<std::int64_t>
      kind;  // ContactKind: 0 sphere pair, 1 sphere-wall, 2 body pair, 3 body-wall
  std::vector<std::int64_t> first;   // particle id
  std::vector<std::int64_t> second;  // particle id, or obstacle index for wall contacts
  std::size_t size() const { return point.size(); }
  static bool is_wall(std::int64_t kind) { return kind == 1 || kind == 3; }
};

// Branch vectors of touching particle pairs (walls excluded), as in branches.pvd.
struct BranchFrame {
  std::vector<Vec3> from, to;           // centres of mass of the pair
  std::vector<double> force_magnitude;  // |total contact force of the pair| [N]
  std::vector<std::int64_t> first, second;
  std::size_t size() const { return from.size(); }
};

// The surfaces of the non-spherical particles (bodies.pvd), as triangles.
struct BodySurfaceFrame {
  std::vector<Vec3> a, b, c;
  std::size_t size() const { return a.size(); }
};

class RunOutput {
 public:
  // Throws std::runtime_error when `dir` has no particles.pvd.
  explicit RunOutput(std::filesystem::path dir);

  const std::filesystem::path& dir() const { return dir_; }
  std::size_t frame_count() const { return times_.size(); }
  const std::vector<double>& times() const { return times_; }
  // Index of the last frame with time <= t (the first frame if none); t < 0: last frame.
  std::size_t frame_at(double t) const;

  ParticleFrame particles(std::size_t frame) const;
  ContactPointFrame contacts(std::size_t frame) const;
  BranchFrame branches(std::size_t frame) const;
  bool has_bodies() const { return !body_files_.empty(); }
  // The body surfaces written at the time of `frame`; throws when the run has
  // bodies but none at that time (a body frame missing: the top view would be wrong).
  BodySurfaceFrame bodies(std::size_t frame) const;
  // Obstacle names by index (obstacles.csv); "obstacle K" when the file is absent.
  std::string obstacle_name(std::int64_t index) const;
  std::size_t obstacle_count() const { return obstacle_names_.size(); }
  // When the first obstacle removed during the run (the gate) went; none if none was.
  std::optional<double> first_removal_time() const { return first_removal_; }

 private:
  // Ids of the glued particles of a frame (empty for runs without any).
  std::unordered_set<std::int64_t> fixed_ids(std::size_t frame) const;
  std::filesystem::path dir_;
  std::vector<double> times_;
  // Per frame, its files: one, or one piece per process of a decomposed run.
  std::vector<std::vector<std::string>> particle_files_, contact_files_, branch_files_;
  std::vector<std::pair<double, std::vector<std::string>>> body_files_;  // by time: may start later
  std::vector<std::string> obstacle_names_;
  std::optional<double> first_removal_;
};

}  // namespace sanguis::dem::analysis
