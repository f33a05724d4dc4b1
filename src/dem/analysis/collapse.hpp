#pragma once
// Measures of a granular collapse (dam break) over time: centre of mass
// (app. B.1), mean translational velocity (Fig. 3.9-3.10) and the flow regime
// of the final state (§3.3.1, Fig. 3.6).
#include <span>
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

// A staggered collapse (thesis §3.3.2, Fig. 3.10): the avalanche "comes to nearly a halt
// for a few tau_c before continuing". A halt here: after the mean speed has first reached
// `speed` (the collapse has started), it stays below `speed` for at least `min_duration`
// and then rises to `speed` again. Times in tau_c, speeds in sqrt(g H0); the default line
// is the 5 % by which the thesis calls a collapse over (Fig. 3.9a).
struct HaltThresholds {
  double speed = 0.05;
  double min_duration = 1.0;
};
struct Halts {
  int count = 0;
  double longest = 0.0;  // the longest halt's duration, 0 without one
};
// `time` and `speed` are one series (same length, increasing times). A halt is timed from
// its first sample below the line to the first sample back at it.
Halts find_halts(std::span<const double> time, std::span<const double> speed,
                 const HaltThresholds& thresholds = {});

}  // namespace sanguis::dem::analysis
