#pragma once
// Unit quaternion q = (w, x, y, z) for orientations: a body-frame vector v_b maps
// to the space frame as v_s = q v_b q^-1 (rotate), and back with rotate_inverse.
#include <cmath>

#include "core/mat3.hpp"
#include "core/vec3.hpp"

namespace sanguis {

struct Quaternion {
  double w = 1.0, x = 0.0, y = 0.0, z = 0.0;

  static Quaternion from_axis_angle(const Vec3& axis, double angle) {
    const double n = norm(axis);
    if (n == 0.0) return {};
    const double s = std::sin(0.5 * angle) / n;
    return {std::cos(0.5 * angle), s * axis.x, s * axis.y, s * axis.z};
  }
  Vec3 vector() const { return {x, y, z}; }
};

constexpr Quaternion operator*(const Quaternion& a, const Quaternion& b) {
  return {
      a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
      a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

constexpr Quaternion conjugate(const Quaternion& q) {
  return {q.w, -q.x, -q.y, -q.z};
}

inline Quaternion normalized(const Quaternion& q) {
  const double n = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  return {q.w / n, q.x / n, q.y / n, q.z / n};
}

// q v q^-1 for a unit quaternion, without forming the product twice.
constexpr Vec3 rotate(const Quaternion& q, const Vec3& v) {
  const Vec3 u{q.x, q.y, q.z};
  const Vec3 t = 2.0 * cross(u, v);
  return v + q.w * t + cross(u, t);
}

constexpr Vec3 rotate_inverse(const Quaternion& q, const Vec3& v) {
  return rotate(conjugate(q), v);
}

// Rotation matrix R with R v = rotate(q, v).
constexpr Mat3 rotation_matrix(const Quaternion& q) {
  Mat3 r;
  const double xx = q.x * q.x, yy = q.y * q.y, zz = q.z * q.z;
  const double xy = q.x * q.y, xz = q.x * q.z, yz = q.y * q.z;
  const double wx = q.w * q.x, wy = q.w * q.y, wz = q.w * q.z;
  r.m[0][0] = 1 - 2 * (yy + zz);
  r.m[0][1] = 2 * (xy - wz);
  r.m[0][2] = 2 * (xz + wy);
  r.m[1][0] = 2 * (xy + wz);
  r.m[1][1] = 1 - 2 * (xx + zz);
  r.m[1][2] = 2 * (yz - wx);
  r.m[2][0] = 2 * (xz - wy);
  r.m[2][1] = 2 * (yz + wx);
  r.m[2][2] = 1 - 2 * (xx + yy);
  return r;
}

}  // namespace sanguis
