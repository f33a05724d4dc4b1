#include "dem/particle_store.hpp"

#include <algorithm>
#include <numbers>
#include <numeric>

namespace sanguis::dem {

std::size_t ParticleStore::add_sphere(std::int64_t particle_id, std::int32_t material_index,
                                      double r, double density, const Vec3& x, const Vec3& v,
                                      const Vec3& w, std::int32_t species_index) {
  const double m = 4.0 / 3.0 * std::numbers::pi * r * r * r * density;
  const double inertia = 0.4 * m * r * r;
  const std::size_t i = add_body(particle_id, material_index, species_index, r, m,
                                 {inertia, inertia, inertia}, {}, x, v, w);
  spherical[i] = 1;
  return i;
}

std::size_t ParticleStore::add_body(std::int64_t particle_id, std::int32_t material_index,
                                    std::int32_t species_index, double bounding_radius, double m,
                                    const Vec3& inertia, const Quaternion& q, const Vec3& x,
                                    const Vec3& v, const Vec3& w) {
  id.push_back(particle_id);
  sort_key.push_back(0);
  material.push_back(material_index);
  radius.push_back(bounding_radius);
  mass.push_back(m);
  inverse_mass.push_back(1.0 / m);
  species.push_back(species_index);
  spherical.push_back(0);
  inertia_body.push_back(inertia);
  inverse_inertia_body.push_back({1.0 / inertia.x, 1.0 / inertia.y, 1.0 / inertia.z});
  orientation.push_back(q);
  position.push_back(x);
  velocity.push_back(v);
  angular_velocity.push_back(w);
  force.push_back({});
  torque.push_back({});
  coordination.push_back(0);
  return position.size() - 1;
}

void ParticleStore::fix(std::size_t i) {
  inverse_mass[i] = 0.0;
  inverse_inertia_body[i] = {};
  velocity[i] = {};
  angular_velocity[i] = {};
}

void ParticleStore::append_from(const ParticleStore& o, std::size_t i) {
  id.push_back(o.id[i]);
  sort_key.push_back(o.sort_key[i]);
  material.push_back(o.material[i]);
  radius.push_back(o.radius[i]);
  mass.push_back(o.mass[i]);
  inverse_mass.push_back(o.inverse_mass[i]);
  species.push_back(o.species[i]);
  spherical.push_back(o.spherical[i]);
  inertia_body.push_back(o.inertia_body[i]);
  inverse_inertia_body.push_back(o.inverse_inertia_body[i]);
  orientation.push_back(o.orientation[i]);
  position.push_back(o.position[i]);
  velocity.push_back(o.velocity[i]);
  angular_velocity.push_back(o.angular_velocity[i]);
  force.push_back(o.force[i]);
  torque.push_back(o.torque[i]);
  coordination.push_back(o.coordination[i]);
}

void ParticleStore::permute(std::span<const std::uint32_t> order) {
  apply_order(id, order);
  apply_order(sort_key, order);
  apply_order(material, order);
  apply_order(radius, order);
  apply_order(mass, order);
  apply_order(inverse_mass, order);
  apply_order(species, order);
  apply_order(spherical, order);
  apply_order(inertia_body, order);
  apply_order(inverse_inertia_body, order);
  apply_order(orientation, order);
  apply_order(position, order);
  apply_order(velocity, order);
  apply_order(angular_velocity, order);
  apply_order(force, order);
  apply_order(torque, order);
  apply_order(coordination, order);
}

std::vector<std::uint32_t> id_order(const std::vector<std::int64_t>& id) {
  std::vector<std::uint32_t> order(id.size());
  std::iota(order.begin(), order.end(), 0u);
  if (!std::is_sorted(id.begin(), id.end())) {
    std::sort(order.begin(), order.end(),
              [&](std::uint32_t a, std::uint32_t b) { return id[a] < id[b]; });
  }
  return order;
}

}  // namespace sanguis::dem
