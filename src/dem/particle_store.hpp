#pragma once
// Particle state as a structure of arrays: each field is one contiguous array
// indexed by the particle's local index, so that kernels stream through memory.
// Spheres and rigid bodies of any shape: a body carries an orientation and its
// principal moments of inertia (body frame = principal axes, origin = centroid).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <vector>

#include "core/permutation.hpp"
#include "core/quaternion.hpp"
#include "core/vec3.hpp"

namespace sanguis::dem {

struct ParticleStore {
  std::vector<std::int64_t> id;  // stable identifier (output, checkpoints)
  // Place along space at the last storage sort (NeighborSearch::space_keys); particles
  // are stored in (sort_key, id) order, the order in which contacts are listed and
  // summed, so that every process of a decomposed run orders them as one process does.
  // 0 until sorted; a particle poured since the last sort has the largest key.
  std::vector<std::uint64_t> sort_key;
  std::vector<std::int32_t> material;      // index into the material table
  std::vector<double> radius;              // bounding radius about the centroid [m]
  std::vector<double> mass;                // [kg]
  std::vector<double> inverse_mass;        // [1/kg]; 0 for a fixed particle (see fix())
  std::vector<std::int32_t> species;       // index into the species (shape) table
  std::vector<std::uint8_t> spherical;     // 1: a sphere (isotropic: no orientation dynamics)
  std::vector<Vec3> inertia_body;          // principal moments of inertia [kg m^2]
  std::vector<Vec3> inverse_inertia_body;  // their inverses [1/(kg m^2)]
  std::vector<Quaternion> orientation;     // body frame -> space frame
  std::vector<Vec3> position;              // centre of mass [m]
  std::vector<Vec3> velocity;              // [m/s]
  std::vector<Vec3> angular_velocity;      // [rad/s]
  std::vector<Vec3> force;                 // sum of contact forces [N] (gravity excluded)
  std::vector<Vec3> torque;                // sum of contact torques [N m]
  std::vector<std::int32_t> coordination;  // contacts touching this particle at the last step

  std::size_t size() const { return position.size(); }

  // A fixed particle (a bead glued to a wall: a rough floor) takes part in contacts but
  // never moves: infinite mass and inertia, encoded as zero inverses so that the flag
  // travels with every copy, sort, migration and checkpoint of the inverse mass.
  void fix(std::size_t i);
  bool is_fixed(std::size_t i) const { return inverse_mass[i] == 0.0; }

  // Reorders the particles: the new particle k is the old particle order[k] (`order` is a
  // permutation of 0..size()-1).
  void permute(std::span<const std::uint32_t> order);

  // Appends particle i of `other`, every field as it is.
  void append_from(const ParticleStore& other, std::size_t i);

  // Appends a sphere of the given radius and density; returns its index.
  std::size_t add_sphere(std::int64_t particle_id, std::int32_t material_index, double r,
                         double density, const Vec3& x, const Vec3& v, const Vec3& w,
                         std::int32_t species_index = 0);

  // Appends a rigid body: `bounding_radius` encloses it about its centroid, `inertia`
  // are the principal moments [kg m^2] in the body frame, `q` maps body to space.
  std::size_t add_body(std::int64_t particle_id, std::int32_t material_index,
                       std::int32_t species_index, double bounding_radius, double m,
                       const Vec3& inertia, const Quaternion& q, const Vec3& x, const Vec3& v,
                       const Vec3& w);
};

// values[k] = old values[order[k]] for a per-particle array, in place; an empty array
// (a history not started, no ghosts) is left as it is.
template <typename T>
void apply_order(std::vector<T>& values, std::span<const std::uint32_t> order) {
  if (values.empty()) return;
  if (values.size() != order.size()) {
    throw std::logic_error("apply_order: a per-particle array has the wrong length");
  }
  std::vector<std::uint8_t> visited;
  permute_in_place(values, order, visited);
}

// True when some particle is not a sphere (a rigid body of elements).
inline bool has_non_spherical(const ParticleStore& p) {
  return std::find(p.spherical.begin(), p.spherical.end(), std::uint8_t{0}) != p.spherical.end();
}

// The storage order of particles: by sort key, then by id. One process sorts into it
// (DemSimulation::rebuild_sorted); the processes of a decomposed run keep it.
inline bool stored_before(std::uint64_t key_a, std::int64_t id_a, std::uint64_t key_b,
                          std::int64_t id_b) {
  return key_a != key_b ? key_a < key_b : id_a < id_b;
}

// Storage indices in increasing id order: 0, 1, 2, ... when the ids increase with the
// index, else sorted by id (outputs list particles by id whatever the storage order).
std::vector<std::uint32_t> id_order(const std::vector<std::int64_t>& id);

// A per-particle array listed in increasing id order (two runs whose storage orders
// differ, e.g. sorted at different steps, compare value by value).
template <typename T>
std::vector<T> in_id_order(const std::vector<T>& values, const std::vector<std::int64_t>& id) {
  std::vector<T> out;
  out.reserve(values.size());
  for (const std::uint32_t i : id_order(id)) out.push_back(values[i]);
  return out;
}

}  // namespace sanguis::dem
