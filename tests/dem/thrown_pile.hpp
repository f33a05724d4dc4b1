#pragma once
// A small sphere case shared by the DEM tests that step a busy system: 500 beads of
// 0.4-0.6 mm thrown about (0.4 m/s of noise) in a box with walls, a periodic axis and
// rolling resistance, so that contacts open and close and lists are rebuilt every few
// dozen steps (test_thread_determinism.cpp, dem_allocation_check.cpp).

namespace sanguis::dem::testing {

inline constexpr const char* kThrownPile = R"(
[simulation]
end_time_s = 1.0
seed = 9
threads = 1
[domain]
min_m = [0.0, 0.0, 0.0]
max_m = [0.012, 0.012, 0.03]
periodic = [true, false, false]
[[material]]
name = "glass"
density_kg_m3 = 2500.0
[[material]]
name = "wall"
[[interaction]]
materials = ["glass", "glass"]
normal_restitution = 0.4
tangential_restitution = 0.3
max_overlap_ratio = 0.01
max_impact_velocity_m_s = 0.5
rolling_friction = 0.1
[[interaction]]
materials = ["glass", "wall"]
normal_restitution = 0.4
tangential_restitution = 0.3
max_overlap_ratio = 0.01
max_impact_velocity_m_s = 0.5
rolling_friction = 0.1
[[obstacle]]
type = "plane"
material = "wall"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[obstacle]]
type = "plane"
material = "wall"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
[[obstacle]]
type = "box"
material = "wall"
min_m = [0.0, 0.011, 0.0]
max_m = [0.012, 0.02, 0.03]
[[particles]]
material = "glass"
radius_min_m = 0.4e-3
radius_max_m = 0.6e-3
arrangement = "random"
count = 500
region_min_m = [0.0, 0.0, 0.0]
region_max_m = [0.012, 0.011, 0.01]
velocity_noise_m_s = 0.4
)";

}  // namespace sanguis::dem::testing
