#pragma once
// Narrow phase for non-spherical bodies (thesis app. A.2.3, Grains3D): the
// distance d between two element cores is computed by GJK; the elements touch
// when d < crust_a + crust_b, with overlap crust_a + crust_b - d, normal along
// the line of the closest core points, and contact point the midpoint of the
// two crust surfaces (Fig. A.5). If the cores themselves intersect (overlap
// larger than the crusts), EPA gives the penetration depth and normal.
// Planes use the support function directly (exact, no iteration).
#include "dem/obstacles.hpp"
#include "dem/particle_shape.hpp"
#include "geometry/gjk.hpp"

namespace sanguis::dem {

struct ElementContact {
  bool touching = false;
  bool deep = false;  // cores intersect: overlap beyond the crusts (EPA used)
  double overlap = 0.0;
  Vec3 normal;  // unit, from the first element towards the second
  Vec3 point;   // contact point (space frame)
};

inline geometry::Pose element_pose(const ShapeElement& e, const Vec3& body_position,
                                   const Quaternion& body_orientation) {
  return {body_position + rotate(body_orientation, e.position), body_orientation * e.orientation};
}

// Two elements (of two particles, or a particle and an obstacle element with crust 0).
inline ElementContact element_pair_contact(const geometry::ConvexShape& core_a,
                                           const geometry::Pose& pose_a, double crust_a,
                                           const geometry::ConvexShape& core_b,
                                           const geometry::Pose& pose_b, double crust_b,
                                           geometry::GjkWarmStart* warm) {
  ElementContact c;
  const double reach = crust_a + crust_b;
  geometry::GjkSettings settings;
  settings.stop_beyond = reach;
  settings.relative_tolerance = 1e-10;
  const geometry::DistanceResult d =
      geometry::gjk_distance(core_a, pose_a, core_b, pose_b, warm, settings);
  if (!d.intersecting && d.distance >= reach) return c;
  c.touching = true;
  if (!d.intersecting && d.distance > 1e-12 * reach) {
    c.normal = (d.point_b - d.point_a) / d.distance;
    c.overlap = reach - d.distance;
    // midpoint of the crust surfaces: point_a + crust_a n and point_b - crust_b n
    c.point = 0.5 * (d.point_a + d.point_b) + (0.5 * (crust_a - crust_b)) * c.normal;
    return c;
  }
  // Cores intersect (or touch): the overlap exceeds the crusts. Fall back to EPA.
  const geometry::PenetrationResult p = geometry::epa_penetration(core_a, pose_a, core_b, pose_b);
  c.deep = true;
  c.normal = p.normal;
  c.overlap = reach + std::max(p.depth, 0.0);
  c.point = 0.5 * (p.point_a + p.point_b) + (0.5 * (crust_a - crust_b)) * c.normal;
  return c;
}

// An element core (with its crust) against a plane whose normal points towards the
// particles: exact, from the support point along -normal.
inline ElementContact element_plane_contact(const geometry::ConvexShape& core,
                                            const geometry::Pose& pose, double crust,
                                            const Vec3& plane_point, const Vec3& plane_normal) {
  ElementContact c;
  const Vec3 local = geometry::support(core, rotate_inverse(pose.orientation, -plane_normal));
  const Vec3 p = pose.position + rotate(pose.orientation, local);
  const double height = dot(p - plane_point, plane_normal);
  if (height >= crust) return c;
  c.touching = true;
  c.deep = height < 0.0;
  c.overlap = crust - height;
  c.normal = -plane_normal;
  c.point = p - (crust - 0.5 * c.overlap) * plane_normal;
  return c;
}

}  // namespace sanguis::dem
