#include "dem/analysis/collapse.hpp"

#include <algorithm>
#include <cmath>

namespace sanguis::dem::analysis {

Vec3 centre_of_mass(const ParticleFrame& particles) {
  const bool weighted = particles.mass.size() == particles.size();
  Vec3 sum;
  double total = 0.0;
  for (std::size_t k = 0; k < particles.size(); ++k) {
    const double m = weighted ? particles.mass[k] : 1.0;
    sum += m * particles.position[k];
    total += m;
  }
  return total > 0 ? (1.0 / total) * sum : Vec3{};
}

double mean_speed(const ParticleFrame& particles) {
  if (particles.size() == 0) return 0.0;
  double sum = 0.0;
  for (const Vec3& v : particles.velocity) sum += norm(v);
  return sum / static_cast<double>(particles.size());
}

std::string to_string(FlowRegime regime) {
  switch (regime) {
    case FlowRegime::kStable:
      return "stable";
    case FlowRegime::kFractured:
      return "fractured";
    case FlowRegime::kCollapsed:
      return "collapsed";
  }
  return "unknown";
}

FlowRegime classify_regime(double initial_height, double final_height, double initial_length,
                           double final_length, const RegimeThresholds& t) {
  const bool height_dropped = final_height < (1.0 - t.height_loss) * initial_height;
  if (height_dropped) return FlowRegime::kCollapsed;
  const bool ran_out = final_length - initial_length > t.runout_gain * initial_length;
  return ran_out ? FlowRegime::kFractured : FlowRegime::kStable;
}

Halts find_halts(std::span<const double> time, std::span<const double> speed,
                 const HaltThresholds& t) {
  Halts halts;
  bool started = false, below = false;
  double below_since = 0.0;  // start of the current stretch under the line, when `below`
  for (std::size_t k = 0; k < std::min(time.size(), speed.size()); ++k) {
    if (speed[k] >= t.speed) {
      if (below && time[k] - below_since >= t.min_duration) {
        ++halts.count;
        halts.longest = std::max(halts.longest, time[k] - below_since);
      }
      below = false;
      started = true;
    } else if (started && !below) {
      below = true;
      below_since = time[k];
    }
  }
  return halts;
}

}  // namespace sanguis::dem::analysis
