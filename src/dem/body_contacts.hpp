#pragma once
// Narrow phase for non-spherical bodies (thesis app. A.2.3, Grains3D): the
// distance d between two element cores is computed by GJK; the elements touch
// when d < crust_a + crust_b, with overlap crust_a + crust_b - d, normal along
// the line of the closest core points, and contact point the midpoint of the
// two crust surfaces (Fig. A.5). If the cores themselves intersect (overlap
// larger than the crusts), EPA gives the penetration depth and normal.
// Planes use the support function directly (exact, no iteration).
//
// Flat-faced cores (boxes, polyhedra, obstacle facets) also get a contact patch
// (geometry/contact_patch.hpp): the part of the facing faces within the crusts'
// reach, a polygon whose corners carry their own overlaps. The normal force is then
// a bed of spring-dashpots at the corners (element_contact_response), which gives a
// face resting on a face its resultant at the centre of pressure and a restoring,
// damped torque when it tilts, and reduces to the single point of §2.3 at a vertex or
// an edge.
#include <algorithm>
#include <array>
#include <limits>
#include <optional>

#include "dem/contact_law.hpp"
#include "dem/obstacles.hpp"
#include "dem/particle_shape.hpp"
#include "geometry/contact_patch.hpp"
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

namespace detail {

// The patch's deepest corner should be the closest points' overlap: no part of two
// separated convex cores is nearer than their distance, and the closest points lie on
// the facing faces. They may not on a polyhedron whose best-facing face at the support
// vertex misses the support edge; the single point is kept then.
inline bool patch_holds_the_contact(const geometry::ContactPatch& patch, const ElementContact& ec) {
  double deepest = 0.0;
  for (int k = 0; k < patch.count; ++k) deepest = std::max(deepest, patch.overlap[k]);
  return deepest >= 0.99 * ec.overlap;
}

}  // namespace detail

// The contact patch of two touching elements (ec from element_pair_contact), or none,
// leaving the single point: curved cores, deep contacts, degenerate faces.
inline std::optional<geometry::ContactPatch> element_pair_patch(
    const geometry::ConvexShape& core_a, const geometry::Pose& pose_a, double crust_a,
    const geometry::ConvexShape& core_b, const geometry::Pose& pose_b, double crust_b,
    const ElementContact& ec) {
  std::optional<geometry::ContactPatch> patch;
  if (!ec.touching || ec.deep) return patch;
  geometry::SpaceFace face_a, face_b;
  if (!geometry::facing_face(core_a, pose_a, ec.normal, face_a) ||
      !geometry::facing_face(core_b, pose_b, -ec.normal, face_b) ||
      !geometry::face_pair_patch(face_a, face_b, ec.normal, crust_a, crust_b, patch.emplace()) ||
      !detail::patch_holds_the_contact(*patch, ec)) {
    patch.reset();
  }
  return patch;
}

// The contact patch of an element and obstacle element `element` at time t (ec from
// element_obstacle_contact with the same arguments), or none.
inline std::optional<geometry::ContactPatch> element_obstacle_patch(
    const Obstacle& obstacle, std::size_t element, double t, const geometry::ConvexShape& core,
    const geometry::Pose& pose, double crust, const ElementContact& ec) {
  std::optional<geometry::ContactPatch> patch;
  geometry::SpaceFace face, other;
  if (!ec.touching || ec.deep || !geometry::facing_face(core, pose, ec.normal, face)) {
    return patch;
  }
  const ObstacleMotion& m = obstacle.motion;
  bool formed = false;
  if (const auto* plane = std::get_if<PlaneShape>(&obstacle.shape)) {
    formed =
        geometry::face_plane_patch(face, m.point_at(t, plane->point),
                                   m.direction_to_space(t, plane->normal), crust, patch.emplace());
  } else {
    bool faced = false;
    if (const auto* box = std::get_if<AxisAlignedBoxShape>(&obstacle.shape)) {
      const geometry::ConvexShape box_core = geometry::Box{0.5 * (box->max - box->min)};
      const geometry::Pose box_pose{m.point_at(t, 0.5 * (box->min + box->max)), m.rotation_at(t)};
      faced = geometry::facing_face(box_core, box_pose, -ec.normal, other);
    } else {
      const ObstacleElement& e = std::get<ShapeObstacle>(obstacle.shape).elements[element];
      const geometry::Pose element_pose{m.point_at(t, e.position),
                                        m.rotation_at(t) * e.orientation};
      faced = geometry::facing_face(e.shape, element_pose, -ec.normal, other);
    }
    formed =
        faced && geometry::face_pair_patch(face, other, ec.normal, crust, 0.0, patch.emplace());
  }
  if (!formed || !detail::patch_holds_the_contact(*patch, ec)) patch.reset();
  return patch;
}

// What one element contact does to its first body.
struct ElementResponse {
  ContactResponse response;    // force and rolling torque on the first body
  Vec3 point;                  // where the force acts: the contact point or the patch's
                               // centre of pressure
  double overlap = 0.0;        // the point's, or the patch's weighted mean
  Vec3 arm_first, arm_second;  // from the bodies' centres to `point`
  Vec3 twist_torque;           // the patch's torsional resistance, on the first body [N m]
};

// The response of one element contact: at its single point, or (patch with two corners
// or more) as a bed of normal spring-dashpots at the patch corners plus the tangential
// spring and rolling resistance of §2.3 at their centre of pressure, with the contact's
// one memory.
//
// Corner k weighs w_k = d_k s_k / sum(d s), d its overlap and s its perimeter share:
// each corner pushes with w_k (kn d_k + eta_n vn_k), clipped at 0 (eq. 2.5 per
// corner), vn_k the normal speed at the corner. Weighting by the overlap makes the
// law the point law of §2.3 wherever the patch is a sliver at a vertex, an edge or
// two crossing edges (the corners at the far side have zero overlap), and kn d for a
// flat face pressed evenly; corners enter with zero overlap and split or merge with
// their perimeter shares, so the force has no jumps as faces tilt and slide. The
// normal damping acts at the corners, so a rocking face is damped, which a single
// point at its centre does not do.
//
// A patch also resists twisting about the normal, which the tangential spring at its
// centre does not see: a torsional spring-dashpot with memory, as if the tangential
// spring and dashpot of §2.3 were spread over the patch with its pressure. Its stiffness
// and damping are kt J and eta_t J, J = <r^2> the pressure's second moment about the
// centre (geometry::PatchPressure), and it slips at mu_c |Fn| <|r|> (an evenly pressed
// disc of radius R at 2/3 mu_c |Fn| R). The memory `twist_moment` is the spring's moment
// about n [N m], grown by -kt J dtheta each step as the rolling spring of eq. 2.10 is, so
// a patch that grows or shrinks without turning gains no torque, and one with no spread
// (a vertex on a face, J = 0) keeps none; on slipping it holds the slip moment less the
// dashpot's, kept continuous as eq. 2.8 does. The rolling resistance then acts on the
// relative rotation less its twist. A single point has no twist: `twist_moment` is zeroed.
//
// `other_velocity(x)` is the second body's velocity at the space point x;
// `other_centre` its centre, or null for an obstacle (no lever arm: the arm is zero).
template <typename OtherVelocity>
ElementResponse element_contact_response(const ContactParameters& params, const ElementContact& ec,
                                         const geometry::ContactPatch* patch, const Vec3& xi,
                                         const Vec3& vi, const Vec3& wi,
                                         OtherVelocity&& other_velocity, const Vec3& other_omega,
                                         const Vec3* other_centre, ContactHistory& h,
                                         double& twist_moment, double dt) {
  ElementResponse out;
  const auto kinematics_at = [&](const Vec3& point, double overlap) {
    out.point = point;
    out.overlap = overlap;
    out.arm_first = point - xi;
    out.arm_second = other_centre != nullptr ? point - *other_centre : Vec3{};
    ContactKinematics c;
    c.normal = ec.normal;
    c.overlap = overlap;
    c.relative_velocity = vi + cross(wi, out.arm_first) - other_velocity(point);
    c.relative_angular_velocity = wi - other_omega;
    const double li = norm(out.arm_first), lj = norm(out.arm_second);
    c.reduced_radius = lj > 0.0 ? li * lj / (li + lj) : li;
    return c;
  };
  double weights = 0.0;
  if (patch != nullptr && patch->count >= 2) {
    for (int k = 0; k < patch->count; ++k) weights += patch->overlap[k] * patch->perimeter_share[k];
  }
  if (!(weights > 0.0)) {
    out.response = evaluate_contact(params, kinematics_at(ec.point, ec.overlap), h, dt);
    twist_moment = 0.0;
    return out;
  }
  double fn = 0.0, overlap = 0.0;
  Vec3 pressed, centre;
  for (int k = 0; k < patch->count; ++k) {
    const Vec3& x = patch->point[k];
    const double w = patch->overlap[k] * patch->perimeter_share[k] / weights;
    const double vn = dot(vi + cross(wi, x - xi) - other_velocity(x), ec.normal);
    const double f = w * normal_force_magnitude(params, patch->overlap[k], vn);
    fn += f;
    pressed += f * x;
    centre += w * x;
    overlap += w * patch->overlap[k];
  }
  if (fn > 0.0) centre = pressed / fn;
  ContactKinematics c = kinematics_at(centre, overlap);
  // The twist about the normal is the torsional spring's (below): the rolling resistance
  // gets the rest of the relative rotation, so that no twist is resisted twice.
  const double spin = dot(c.relative_angular_velocity, ec.normal);
  c.relative_angular_velocity -= spin * ec.normal;
  out.response = contact_response_for_normal_force(params, c, h, dt, fn);

  const geometry::PatchPressure pressure(*patch, centre, ec.normal);
  const double stiffness = params.tangential_stiffness * pressure.second_moment();
  const double damping = params.tangential_damping * pressure.second_moment();
  twist_moment -= stiffness * dt * spin;
  double moment = twist_moment - damping * spin;
  // <|r|> >= <r^2> / (the farthest corner): a moment below 0.9 mu_c |Fn| of that (0.9 for
  // the quadrature's 1 %) holds for sure, and <|r|> is integrated only above it.
  const double held =
      pressure.farthest() > 0.0 ? 0.9 * pressure.second_moment() / pressure.farthest() : 0.0;
  if (std::abs(moment) > params.friction * fn * held) {
    const double moment_max = params.friction * fn * pressure.mean_arm();
    if (std::abs(moment) > moment_max) {
      moment = std::copysign(moment_max, moment);
      twist_moment = moment + damping * spin;
    }
  }
  out.twist_torque = moment * ec.normal;
  return out;
}

}  // namespace sanguis::dem
