#pragma once
// A small non-spherical case shared by the determinism tests: 36 crosses (Table 3.1
// size and stiffness) in four layers, spinning, falling onto a floor: element contacts
// by GJK between crosses and with the floor.
#include <cstdint>

#include "dem/simulation.hpp"
#include "geometry/mass_properties.hpp"

namespace sanguis::dem::testing {

// Cross n (0..35) gets the id id_of(n).
template <typename IdOf>
DemSetup falling_crosses(int threads, IdOf id_of) {
  DemSetup s;
  s.shapes.push_back(
      make_particle_shape("cross", geometry::cross_particle(0.027, 0.002, 0.003), 1e-4));
  const ParticleShape& cross = s.shapes.back();
  s.domain = {{0.0, 0.0, 0.0}, {0.09, 0.09, 0.1}, {false, false, false}};
  s.gravity = {0.0, 0.0, -9.81};
  s.time_step = 2.5e-6;
  s.threads = threads;
  s.particles_per_thread = 1;  // threads on this small system
  ContactParameters p;
  p.normal_stiffness = 4.5e5;
  p.normal_damping = 0.05;
  p.tangential_stiffness = 3e2;
  p.tangential_damping = 0.02;
  p.friction = 0.5;
  s.contacts = ContactTable(2);
  s.contacts.set(0, 0, p);
  s.contacts.set(0, 1, p);
  Obstacle floor;
  floor.material = 1;
  floor.shape = PlaneShape{{0, 0, 0}, {0, 0, 1}};
  s.obstacles.push_back(floor);
  const Quaternion axes =
      geometry::composite_mass_properties(geometry::cross_particle(0.027, 0.002, 0.003))
          .principal_axes;
  for (int n = 0; n < 36; ++n) {
    const Vec3 x{0.015 + 0.03 * (n % 3), 0.015 + 0.03 * ((n / 3) % 3), 0.002 + 0.0035 * (n / 9)};
    const Quaternion q = Quaternion::from_axis_angle({0.0, 0.0, 1.0}, 0.7 * n) * axes;
    s.particles.add_body(static_cast<std::int64_t>(id_of(n)), 0, 0, cross.bounding_radius,
                         770.0 * cross.volume, 770.0 * cross.inertia_per_density, normalized(q), x,
                         {0.0, 0.0, -0.3}, {0.0, 0.0, 0.5 * (n % 5)});
  }
  return s;
}

}  // namespace sanguis::dem::testing
