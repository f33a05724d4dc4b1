#pragma once
// Exact orientation test for the hull and EPA: the sign of
// det[b - a, c - a, p - a] = (b - a) x (c - a) . (p - a), i.e. whether p lies
// above (+1), on (0) or below (-1) the plane of the counter-clockwise
// triangle abc. A floating-point evaluation decides when its error bound
// allows; otherwise the determinant is evaluated exactly with floating-point
// expansions (Shewchuk, "Adaptive precision floating-point arithmetic and
// fast robust geometric predicates", Discrete Comput. Geom. 18 (1997) 305).
// Exact signs make every visibility decision of the incremental hull mutually
// consistent, whatever the rounding of sliver faces' planes.
#include <cmath>

#include "core/vec3.hpp"

namespace sanguis::geometry::detail {

int orientation_exact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p);

inline int orientation(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double xy = ab.x * ac.y, yx = ab.y * ac.x;
  const double yz = ab.y * ac.z, zy = ab.z * ac.y;
  const double zx = ab.z * ac.x, xz = ab.x * ac.z;
  const double det = ap.x * (yz - zy) + ap.y * (zx - xz) + ap.z * (xy - yx);
  const double permanent = std::abs(ap.x) * (std::abs(yz) + std::abs(zy)) +
                           std::abs(ap.y) * (std::abs(zx) + std::abs(xz)) +
                           std::abs(ap.z) * (std::abs(xy) + std::abs(yx));
  // Shewchuk's bound for this evaluation (differences included) is
  // (7 + 56 eps) eps * permanent, eps = 2^-53; 1e-15 covers it.
  const double bound = 1e-15 * permanent;
  if (det > bound) return 1;
  if (det < -bound) return -1;
  return orientation_exact(a, b, c, p);
}

}  // namespace sanguis::geometry::detail
