#pragma once
// Prescribed kinematics of an obstacle: a translation along a fixed direction and
// a rotation about a fixed axis through a centre that travels with the
// translation, each with a speed law (none, constant, ramp to a speed with a
// given acceleration, or piecewise linear in time). The dam-break gate of §3.2.1
// is a ramp: 0 -> 3 m/s upwards at 43 m/s^2.
#include <cmath>
#include <utility>
#include <vector>

#include "core/quaternion.hpp"
#include "core/vec3.hpp"

namespace sanguis::dem {

struct SpeedLaw {
  enum class Kind { kNone, kConstant, kRamp, kPiecewise };
  Kind kind = Kind::kNone;
  double start = 0.0;         // [s] the law acts from this time on (constant, ramp)
  double speed = 0.0;         // constant speed, or the ramp's final speed [m/s or rad/s]
  double acceleration = 0.0;  // ramp [m/s^2 or rad/s^2]
  std::vector<std::pair<double, double>> points;  // piecewise: (time, speed), times increasing

  bool moving() const { return kind != Kind::kNone; }

  double speed_at(double t) const {
    switch (kind) {
      case Kind::kNone:
        return 0.0;
      case Kind::kConstant:
        return t < start ? 0.0 : speed;
      case Kind::kRamp:
        return t < start ? 0.0 : std::min(speed, acceleration * (t - start));
      case Kind::kPiecewise: {
        if (points.empty() || t <= points.front().first)
          return points.empty() ? 0.0 : points.front().second;
        for (std::size_t k = 1; k < points.size(); ++k) {
          if (t <= points[k].first) {
            const auto [t0, s0] = points[k - 1];
            const auto [t1, s1] = points[k];
            return s0 + (s1 - s0) * (t - t0) / (t1 - t0);
          }
        }
        return points.back().second;
      }
    }
    return 0.0;
  }

  // Integral of the speed from 0 to t (exact for each law).
  double distance_at(double t) const {
    switch (kind) {
      case Kind::kNone:
        return 0.0;
      case Kind::kConstant:
        return t < start ? 0.0 : speed * (t - start);
      case Kind::kRamp: {
        if (t < start) return 0.0;
        const double t_ramp = speed / acceleration;  // time to reach the final speed
        const double s = t - start;
        return s <= t_ramp ? 0.5 * acceleration * s * s
                           : 0.5 * acceleration * t_ramp * t_ramp + speed * (s - t_ramp);
      }
      case Kind::kPiecewise: {
        if (points.empty()) return 0.0;
        // Before the first point the speed is held at its first value (from t = 0).
        double d = points.front().second * std::min(t, points.front().first);
        for (std::size_t k = 1; k < points.size() && t > points[k - 1].first; ++k) {
          const double t0 = points[k - 1].first;
          const double t1 = std::min(t, points[k].first);
          d += 0.5 * (speed_at(t0) + speed_at(t1)) * (t1 - t0);
        }
        if (t > points.back().first) d += points.back().second * (t - points.back().first);
        return d;
      }
    }
    return 0.0;
  }
};

struct ObstacleMotion {
  Vec3 direction{0.0, 0.0, 1.0};  // unit translation direction
  SpeedLaw translation;
  Vec3 axis{0.0, 0.0, 1.0};  // unit rotation axis
  Vec3 centre;               // a point of the axis at t = 0 [m]
  SpeedLaw rotation;         // angular speed [rad/s]

  bool is_static() const { return !translation.moving() && !rotation.moving(); }

  Vec3 offset_at(double t) const { return translation.distance_at(t) * direction; }
  Quaternion rotation_at(double t) const {
    return rotation.moving() ? Quaternion::from_axis_angle(axis, rotation.distance_at(t))
                             : Quaternion{};
  }
  // Velocity of the obstacle's material point that is at `point` at time t.
  Vec3 velocity_at(double t, const Vec3& point) const {
    Vec3 v = translation.speed_at(t) * direction;
    if (rotation.moving()) v += cross(rotation.speed_at(t) * axis, point - (centre + offset_at(t)));
    return v;
  }
  // Maps a space point at time t to the obstacle's frame at t = 0, and a direction back.
  Vec3 to_initial_frame(double t, const Vec3& point) const {
    const Vec3 c = centre + offset_at(t);
    return centre + rotate_inverse(rotation_at(t), point - c);
  }
  Vec3 direction_to_space(double t, const Vec3& d) const { return rotate(rotation_at(t), d); }
  // Where the obstacle's material point that was at `point` at t = 0 is at time t.
  Vec3 point_at(double t, const Vec3& point) const {
    return centre + offset_at(t) + rotate(rotation_at(t), point - centre);
  }
};

}  // namespace sanguis::dem
