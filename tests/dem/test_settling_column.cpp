// A small settling column reaches a true static state only with the memory terms
// of the contact model (thesis §2.6.2, Fig. 2.6): 60 spheres poured into a box.
#include <gtest/gtest.h>

#include <string>

#include "core/config.hpp"
#include "dem/dem_case.hpp"

namespace sanguis::dem {
namespace {

const char* kColumn = R"(
[simulation]
end_time_s = 1.0
seed = 3
[domain]
min_m = [0.0, 0.0, 0.0]
max_m = [0.008, 0.008, 0.04]
[[material]]
name = "glass"
density_kg_m3 = 2500.0
[[material]]
name = "wall"
[[interaction]]
materials = ["glass", "glass"]
normal_restitution = 0.45
tangential_restitution = 0.3
max_overlap_ratio = 0.01
max_impact_velocity_m_s = 0.5
friction = 0.5
rolling_friction = 0.1
memory = @MEMORY@
[[interaction]]
materials = ["glass", "wall"]
normal_restitution = 0.45
tangential_restitution = 0.3
max_overlap_ratio = 0.01
max_impact_velocity_m_s = 0.5
friction = 0.5
rolling_friction = 0.1
memory = @MEMORY@
[[obstacle]]
type = "box"
material = "wall"
min_m = [-0.01, -0.01, -0.01]
max_m = [0.018, 0.018, 0.0]
[[obstacle]]
type = "plane"
material = "wall"
point_m = [0.0, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]
[[obstacle]]
type = "plane"
material = "wall"
point_m = [0.008, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
[[obstacle]]
type = "plane"
material = "wall"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
[[obstacle]]
type = "plane"
material = "wall"
point_m = [0.0, 0.008, 0.0]
normal = [0.0, -1.0, 0.0]
[[particles]]
material = "glass"
radius_min_m = 0.9e-3
radius_max_m = 1.1e-3
arrangement = "random"
count = 60
region_min_m = [0.0, 0.0, 0.0]
region_max_m = [0.008, 0.008, 0.04]
[output]
interval_s = 0.05
vtk = false
)";

DemDiagnostics settle(bool memory) {
  std::string text = kColumn;
  for (std::size_t at; (at = text.find("@MEMORY@")) != std::string::npos;) {
    text.replace(at, 8, memory ? "true" : "false");
  }
  DemCase c = load_dem_case(ConfigTable::parse_string(text, "settling-column.toml"),
                            "settling-column.toml");
  DemSimulation sim(c.setup);
  sim.run_until(c.stop.end_time);
  return sim.diagnostics();
}

TEST(SettlingColumn, ReachesAStaticStateWithMemory) {
  const DemDiagnostics d = settle(true);
  EXPECT_LT(d.mean_velocity, 1e-10);
  EXPECT_LT(d.mean_angular_velocity, 1e-8);
  EXPECT_GT(d.particle_contacts, 60);  // a packed column, not a gas
}

TEST(SettlingColumn, KeepsMovingWithoutMemory) {
  const DemDiagnostics d = settle(false);
  EXPECT_GT(d.mean_velocity, 1e-6);
  EXPECT_GT(d.mean_angular_velocity, 1e-3);
}

}  // namespace
}  // namespace sanguis::dem
