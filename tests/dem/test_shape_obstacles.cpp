// Obstacles of any convex shape or triangulated surface (issue #3): contacts by GJK
// with each obstacle element, from case files.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/config.hpp"
#include "dem/dem_case.hpp"

namespace sanguis::dem {
namespace {

std::string sphere_case(const std::string& obstacle) {
  return R"(
[simulation]
end_time_s = 0.15
[domain]
min_m = [-0.02, -0.02, -0.02]
max_m = [0.02, 0.02, 0.02]
[[shape]]
name = "roller"
type = "cylinder"
radius_m = 0.004
height_m = 0.02
[[material]]
name = "glass"
density_kg_m3 = 2500.0
[[material]]
name = "steel"
[[interaction]]
materials = ["glass", "glass"]
normal_restitution = 0.3
tangential_restitution = 0.3
max_overlap_ratio = 0.005
max_impact_velocity_m_s = 0.5
rolling_friction = 0.2
[[interaction]]
materials = ["glass", "steel"]
normal_restitution = 0.3
tangential_restitution = 0.3
max_overlap_ratio = 0.005
max_impact_velocity_m_s = 0.5
rolling_friction = 0.2
)" + obstacle +
         R"(
[[particles]]
material = "glass"
radius_m = 1e-3
arrangement = "list"
positions_m = [[0.0003, 0.0, 0.0052]]
)";
}

TEST(ShapeObstacles, SphereRestsOnTopOfACylinderObstacle) {
  // A cylinder of radius 4 mm lying along y (axis z turned 90 deg about x), crest at
  // z = 4 mm. The sphere (R = 1 mm) lands 0.3 mm off the crest: the slope there (0.06) is
  // below mu_r = 0.2, so the rolling resistance holds it (with 1.1 mm it rolls off).
  const std::string text = sphere_case(R"(
[[obstacle]]
name = "roller"
type = "shape"
shape = "roller"
material = "steel"
rotation_axis = [1.0, 0.0, 0.0]
rotation_angle_deg = 90.0
)");
  DemCase c = load_dem_case(ConfigTable::parse_string(text, "roller.toml"), "roller.toml");
  DemSimulation sim(c.setup);
  sim.run_until(c.stop.end_time);
  const Vec3 x = sim.particles().position[0];
  // On the cylinder surface: distance from the axis (the y axis) = 4 mm + R, less a tiny overlap.
  EXPECT_NEAR(std::hypot(x.x, x.z), 0.005, 2e-6);
  EXPECT_LT(norm(sim.particles().velocity[0]), 1e-6);
  EXPECT_EQ(sim.diagnostics().wall_contacts, 1);
}

TEST(ShapeObstacles, SphereRestsOnAnStlSurface) {
  // A 2 x 2 cm square at z = 4 mm made of two triangles, read from an ASCII STL file.
  const auto dir = std::filesystem::temp_directory_path() / "sanguis_test_stl_floor";
  std::filesystem::create_directories(dir);
  {
    std::ofstream stl(dir / "floor.stl");
    stl << "solid floor\n"
           "facet normal 0 0 1\nouter loop\nvertex -10 -10 4\nvertex 10 -10 4\nvertex 10 10 4\n"
           "endloop\nendfacet\n"
           "facet normal 0 0 1\nouter loop\nvertex -10 -10 4\nvertex 10 10 4\nvertex -10 10 4\n"
           "endloop\nendfacet\nendsolid floor\n";
  }
  const std::string text = sphere_case(R"(
[[obstacle]]
name = "floor"
type = "mesh"
file = "floor.stl"
scale = 0.001
material = "steel"
)");
  DemCase c = load_dem_case(ConfigTable::parse_string(text, (dir / "case.toml").string()),
                            dir / "case.toml");
  DemSimulation sim(c.setup);
  sim.run_until(c.stop.end_time);
  const Vec3 x = sim.particles().position[0];
  EXPECT_NEAR(x.z, 0.005, 2e-6);  // on the surface, 1 mm above z = 4 mm
  EXPECT_LT(norm(sim.particles().velocity[0]), 1e-6);
  EXPECT_EQ(sim.diagnostics().wall_contacts, 1);  // one triangle under it
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sanguis::dem
