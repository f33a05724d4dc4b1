#pragma once
// Narrow phase for non-spherical bodies (thesis app. A.2.3, Grains3D): the
// distance d between two element cores is computed by GJK; the elements touch
// when d < crust_a + crust_b, with overlap crust_a + crust_b - d, normal along
// the line of the closest core points, and contact point the midpoint of the
// two crust surfaces (Fig. A.5). If the cores themselves intersect (overlap
// larger than the crusts), EPA gives the penetration depth and normal.
// Planes use the support function directly (exact, no iteration).
#include <array>
#include <limits>

#include "dem/contact_law.hpp"
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

namespace detail {

// Centre of the supporting feature of a core along -n (a face, an edge or a vertex), as
// the mean of the core's vertices weighted by how deep each one is in the contact: with
// `band` the overlap of the deepest vertex, weight 1 - (height above it) / band, i.e. the
// vertex's own overlap over the deepest one (vertices out of contact weigh nothing). This
// is the resultant of a bed of normal springs sampled at the vertices (Winkler): a face
// lying flat pushes at its centre rather than at one corner, and the point moves
// continuously towards the lower edge as the face tilts, giving the restoring torque of a
// flat contact; the single contact point of §2.3 is kept.
// Curved cores have a unique support point. Body-frame points; `down` is the body-frame
// direction towards the plane.
template <typename Vertices>
inline Vec3 weighted_support(const Vertices& vertices, const Vec3& down, double band) {
  double lowest = -std::numeric_limits<double>::infinity();
  for (const Vec3& v : vertices) lowest = std::max(lowest, dot(v, down));
  Vec3 sum;
  double weights = 0.0;
  for (const Vec3& v : vertices) {
    const double w = 1.0 - (lowest - dot(v, down)) / band;
    if (w > 0.0) {
      sum += w * v;
      weights += w;
    }
  }
  return sum / weights;
}

inline Vec3 feature_centre(const geometry::ConvexShape& core, const Vec3& down, double band) {
  if (const auto* box = std::get_if<geometry::Box>(&core)) {
    const Vec3 h = box->half_extents;
    const std::array<Vec3, 8> corners{
        Vec3{-h.x, -h.y, -h.z}, Vec3{h.x, -h.y, -h.z}, Vec3{-h.x, h.y, -h.z}, Vec3{h.x, h.y, -h.z},
        Vec3{-h.x, -h.y, h.z},  Vec3{h.x, -h.y, h.z},  Vec3{-h.x, h.y, h.z},  Vec3{h.x, h.y, h.z}};
    return weighted_support(corners, down, band);
  }
  if (const auto* poly = std::get_if<geometry::ConvexPolyhedron>(&core)) {
    return weighted_support(poly->vertices(), down, band);
  }
  return geometry::support(core, down);
}

}  // namespace detail

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
// particles. The overlap is that of the deepest core point (exact, by support); the
// contact point is the overlap-weighted centre of the supporting feature
// (detail::feature_centre).
inline ElementContact element_plane_contact(const geometry::ConvexShape& core,
                                            const geometry::Pose& pose, double crust,
                                            const Vec3& plane_point, const Vec3& plane_normal) {
  ElementContact c;
  const Vec3 down = rotate_inverse(pose.orientation, -plane_normal);
  const Vec3 deepest = pose.position + rotate(pose.orientation, geometry::support(core, down));
  const double height = dot(deepest - plane_point, plane_normal);
  if (height >= crust) return c;
  c.touching = true;
  c.deep = height < 0.0;
  c.overlap = crust - height;
  c.normal = -plane_normal;
  const Vec3 centre =
      pose.position + rotate(pose.orientation, detail::feature_centre(core, down, c.overlap));
  // On the plane of the deepest point, half-way into the overlap.
  c.point = centre - dot(centre - deepest, plane_normal) * plane_normal -
            (crust - 0.5 * c.overlap) * plane_normal;
  return c;
}

// Kinematics of a sphere touching an obstacle (gap.overlap >= 0) at time t; `arm` gets
// the lever arm from the centre to the contact point (midway in the overlap). Shared by
// the force loop and the contact output.
inline ContactKinematics sphere_wall_kinematics(const Obstacle& obstacle, double t, const Vec3& x,
                                                const Vec3& v, const Vec3& w, double radius,
                                                const SphereObstacleGap& gap, Vec3& arm) {
  ContactKinematics c;
  c.normal = gap.normal;
  c.overlap = gap.overlap;
  arm = (radius - 0.5 * c.overlap) * gap.normal;
  c.relative_velocity = v + cross(w, arm);
  if (!obstacle.motion.is_static()) c.relative_velocity -= obstacle.motion.velocity_at(t, x + arm);
  c.relative_angular_velocity = w;
  if (obstacle.motion.rotation.moving()) {
    c.relative_angular_velocity -= obstacle.motion.rotation.speed_at(t) * obstacle.motion.axis;
  }
  c.reduced_radius = radius;
  return c;
}

// An element core against element `element` of an obstacle at time t (plane: exact by
// support; box and shape obstacles: GJK with no crust on the obstacle side). Shared by the
// force loop and the contact output.
inline ElementContact element_obstacle_contact(const Obstacle& obstacle, std::size_t element,
                                               double t, const geometry::ConvexShape& core,
                                               const geometry::Pose& pose, double crust,
                                               geometry::GjkWarmStart* warm) {
  const ObstacleMotion& m = obstacle.motion;
  if (const auto* plane = std::get_if<PlaneShape>(&obstacle.shape)) {
    return element_plane_contact(core, pose, crust, m.point_at(t, plane->point),
                                 m.direction_to_space(t, plane->normal));
  }
  if (const auto* box = std::get_if<AxisAlignedBoxShape>(&obstacle.shape)) {
    const geometry::ConvexShape box_core = geometry::Box{0.5 * (box->max - box->min)};
    const geometry::Pose box_pose{m.point_at(t, 0.5 * (box->min + box->max)), m.rotation_at(t)};
    return element_pair_contact(core, pose, crust, box_core, box_pose, 0.0, warm);
  }
  const ObstacleElement& e = std::get<ShapeObstacle>(obstacle.shape).elements[element];
  const geometry::Pose element_pose{m.point_at(t, e.position), m.rotation_at(t) * e.orientation};
  return element_pair_contact(core, pose, crust, e.shape, element_pose, 0.0, warm);
}

}  // namespace sanguis::dem
