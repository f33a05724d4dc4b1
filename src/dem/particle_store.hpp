#pragma once
// Particle state as a structure of arrays: each field is one contiguous array
// indexed by the particle's local index, so that kernels stream through memory.
// Spheres only for now: mass and moment of inertia are scalars.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/vec3.hpp"

namespace sanguis::dem {

struct ParticleStore {
  std::vector<std::int64_t> id;            // stable identifier (output, checkpoints)
  std::vector<std::int32_t> material;      // index into the material table
  std::vector<double> radius;              // [m]
  std::vector<double> mass;                // [kg]
  std::vector<double> inverse_mass;        // [1/kg]
  std::vector<double> inverse_inertia;     // 1 / (2/5 m R^2) [1/(kg m^2)]
  std::vector<Vec3> position;              // centre of mass [m]
  std::vector<Vec3> velocity;              // [m/s]
  std::vector<Vec3> angular_velocity;      // [rad/s]
  std::vector<Vec3> force;                 // sum of contact forces [N] (gravity excluded)
  std::vector<Vec3> torque;                // sum of contact torques [N m]
  std::vector<std::int32_t> coordination;  // contacts touching this particle at the last step

  std::size_t size() const { return position.size(); }

  // Appends a sphere of the given radius and density; returns its index.
  std::size_t add_sphere(std::int64_t particle_id, std::int32_t material_index, double r,
                         double density, const Vec3& x, const Vec3& v, const Vec3& w);
};

}  // namespace sanguis::dem
