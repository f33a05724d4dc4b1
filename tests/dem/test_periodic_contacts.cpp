// A contact across a periodic boundary behaves exactly like the same contact in
// the middle of the box, history included, while the pair drifts across the
// boundary and the lists are rebuilt with wrapped positions.
#include <gtest/gtest.h>

#include "dem/simulation.hpp"

namespace sanguis::dem {
namespace {

DemSetup sliding_pair(double shift_x) {
  DemSetup s;
  s.domain = {{0.0, 0.0, 0.0}, {0.02, 0.02, 0.02}, {true, true, true}};
  s.gravity = {};
  s.time_step = 1e-6;
  s.skin = 0.1e-3;
  s.material_names = {"glass"};
  ContactParameters p;
  // Soft contact (Tc ~ 2 ms) so that the collision lasts while the pair crosses x = L.
  p.normal_stiffness = 10.0;
  p.normal_damping = 1e-5;
  p.tangential_stiffness = 3.0;
  p.tangential_damping = 1e-5;
  p.friction = 0.3;
  p.rolling_stiffness = 1e-9;
  p.rolling_damping = 1e-12;
  p.rolling_friction = 0.1;
  s.contacts = ContactTable(1);
  s.contacts.set(0, 0, p);
  // Two spheres touching along x, colliding at 0.05 m/s while sliding past each other
  // along y and spinning, and drifting in +x at 0.5 m/s so that they cross x = L.
  const double r = 1e-3;
  const auto wrap = [&](double x) { return x >= 0.02 ? x - 0.02 : x; };
  s.particles.add_sphere(0, 0, r, 2500.0, {wrap(shift_x), 0.01, 0.01}, {0.525, 0.02, 0.0},
                         {0.0, 0.0, 3.0});
  s.particles.add_sphere(1, 0, r, 2500.0, {wrap(shift_x + 2e-3), 0.01, 0.01}, {0.475, -0.02, 0.0},
                         {0.0, 0.0, -3.0});
  return s;
}

TEST(PeriodicContacts, ContactAcrossTheBoundaryMatchesTheInteriorOne) {
  DemSimulation inside(sliding_pair(0.005));
  DemSimulation across(sliding_pair(0.0195));  // straddles x = L; sphere 0 wraps at 1 ms
  std::int64_t rebuilds_before = across.neighbor_search().rebuild_count();
  for (int n = 0; n < 1500; ++n) {  // 1.5 ms within the contact; 0.75 mm drift in x
    inside.step();
    across.step();
    // Storage may be re-sorted along space (sphere 0 wraps to the far side): match by id.
    const std::vector<std::uint32_t> a = id_order(across.particles().id),
                                     b = id_order(inside.particles().id);
    for (int k = 0; k < 2; ++k) {
      const std::size_t i = a[static_cast<std::size_t>(k)], j = b[static_cast<std::size_t>(k)];
      ASSERT_NEAR(across.particles().force[i].x, inside.particles().force[j].x, 1e-9) << n;
      ASSERT_NEAR(across.particles().force[i].y, inside.particles().force[j].y, 1e-9) << n;
      ASSERT_NEAR(across.particles().torque[i].z, inside.particles().torque[j].z, 1e-12) << n;
    }
  }
  EXPECT_GT(across.neighbor_search().rebuild_count(), rebuilds_before);  // wrapped at least once
  EXPECT_EQ(across.diagnostics().particle_contacts, 1);
  // The tangential spring was loaded (memory in use), identically in both.
  const auto& h_in = inside.particle_contacts().history[0].tangential_displacement;
  const auto& h_ac = across.particle_contacts().history[0].tangential_displacement;
  EXPECT_GT(norm(h_in), 0.0);
  EXPECT_NEAR(norm(h_ac), norm(h_in), 1e-15);
}

}  // namespace
}  // namespace sanguis::dem
