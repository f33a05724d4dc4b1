#pragma once
// Measures of a granular collapse (dam break) over time: centre of mass
// (app. B.1), mean translational velocity (Fig. 3.9-3.10) and the flow regime
// of the final state (§3.3.1, Fig. 3.6).
#include <string>

#include "core/vec3.hpp"
#include "dem/analysis/run_output.hpp"

namespace sanguis::dem::analysis {

// Mass-weighted centre of mass; equal weights when the frame has no masses.
Vec3 centre_of_mass(const ParticleFrame& particles);
// Mean of |v| over the particles.
double mean_speed(const ParticleFrame& particles);

// Collapsed: the avalanche involves the whole column, the final height drops
// below the initial one. Fractured: particles behind a fracture line stay in
// place, the final height is the initial height, yet the front ran out.
// Stable: the column stands (it neither ran out nor lost height).
enum class FlowRegime { kStable, kFractured, kCollapsed };
std::string to_string(FlowRegime regime);

struct RegimeThresholds {
  double height_loss = 0.05;  // H_inf < (1 - this) H0: the height dropped
  double runout_gain = 0.10;  // (L_inf - L0) / L0 above this: the front moved
};
FlowRegime classify_regime(double initial_height, double final_height, double initial_length,
                           double final_length, const RegimeThresholds& thresholds = {});

}  // namespace sanguis::dem::analysis
