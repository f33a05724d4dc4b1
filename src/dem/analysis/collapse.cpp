#include "dem/analysis/collapse.hpp"

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

}  // namespace sanguis::dem::analysis
