#include "dem/particle_store.hpp"

#include <numbers>

namespace sanguis::dem {

std::size_t ParticleStore::add_sphere(std::int64_t particle_id, std::int32_t material_index,
                                      double r, double density, const Vec3& x, const Vec3& v,
                                      const Vec3& w) {
  const double m = 4.0 / 3.0 * std::numbers::pi * r * r * r * density;
  const double inertia = 0.4 * m * r * r;
  id.push_back(particle_id);
  material.push_back(material_index);
  radius.push_back(r);
  mass.push_back(m);
  inverse_mass.push_back(1.0 / m);
  inverse_inertia.push_back(1.0 / inertia);
  position.push_back(x);
  velocity.push_back(v);
  angular_velocity.push_back(w);
  force.push_back({});
  torque.push_back({});
  coordination.push_back(0);
  return position.size() - 1;
}

}  // namespace sanguis::dem
