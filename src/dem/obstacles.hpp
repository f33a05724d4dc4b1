#pragma once
// Obstacles for spheres: infinite planes and finite boxes (a closed container is
// a set of them), fixed or moving with prescribed kinematics (obstacle_motion.hpp),
// each removable at a given time (the dam-break gate of §3.2.1 lifted instantly).
// Narrow phase against a sphere is analytic, in the obstacle's initial frame.
#include <cstdint>
#include <limits>
#include <string>
#include <variant>
#include <vector>

#include "core/vec3.hpp"
#include "dem/obstacle_motion.hpp"
#include "geometry/gjk.hpp"
#include "geometry/shapes.hpp"

namespace sanguis::dem {

struct PlaneShape {
  Vec3 point;   // any point of the plane [m]
  Vec3 normal;  // unit normal, pointing to the side where particles live
};

struct AxisAlignedBoxShape {
  Vec3 min, max;  // corners [m]
};

// Any convex shapes placed in space (a cylinder, a polyhedron, the pieces of a funnel,
// the triangles of an STL surface), each its own element with its own contacts.
struct ObstacleElement {
  geometry::ConvexShape shape;  // in its own frame
  Vec3 position;                // of the element frame, space frame at t = 0 [m]
  Quaternion orientation;       // element frame -> space at t = 0
};

struct ShapeObstacle {
  std::vector<ObstacleElement> elements;
};

struct Obstacle {
  std::string name;
  std::int32_t material = 0;
  std::variant<PlaneShape, AxisAlignedBoxShape, ShapeObstacle> shape;
  double remove_at = std::numeric_limits<double>::infinity();  // [s]
  ObstacleMotion motion;  // shape given at t = 0; static unless a speed law is set

  bool active(double time) const { return time < remove_at; }
};

// Contact of a sphere with an obstacle: overlap (> 0 in contact) and unit normal
// from the sphere towards the obstacle.
struct SphereObstacleGap {
  double overlap = 0.0;
  Vec3 normal;
};

inline SphereObstacleGap sphere_gap(const PlaneShape& plane, const Vec3& centre, double radius) {
  const double height = dot(centre - plane.point, plane.normal);
  return {radius - height, -plane.normal};
}

inline SphereObstacleGap sphere_gap(const AxisAlignedBoxShape& box, const Vec3& centre,
                                    double radius) {
  Vec3 closest;
  bool inside = true;
  for (int k = 0; k < 3; ++k) {
    double c = centre[k];
    if (c < box.min[k]) {
      c = box.min[k];
      inside = false;
    } else if (c > box.max[k]) {
      c = box.max[k];
      inside = false;
    }
    closest[k] = c;
  }
  if (!inside) {
    const Vec3 d = closest - centre;
    const double dist = norm(d);
    return {radius - dist, d / dist};
  }
  // Centre inside the box: push out through the nearest face.
  double best = std::numeric_limits<double>::infinity();
  SphereObstacleGap gap;
  for (int k = 0; k < 3; ++k) {
    const double to_min = centre[k] - box.min[k];
    const double to_max = box.max[k] - centre[k];
    if (to_min < best) {
      best = to_min;
      gap.normal = Vec3{};
      gap.normal[k] = 1.0;  // obstacle lies on the +k side of the outward -k face
    }
    if (to_max < best) {
      best = to_max;
      gap.normal = Vec3{};
      gap.normal[k] = -1.0;
    }
  }
  gap.overlap = radius + best;
  return gap;
}

// Nearest element of a shape obstacle (GJK from the centre point).
inline SphereObstacleGap sphere_gap(const ShapeObstacle& o, const Vec3& centre, double radius) {
  SphereObstacleGap best{-std::numeric_limits<double>::infinity(), {0.0, 0.0, -1.0}};
  const geometry::ConvexShape point = geometry::Sphere{0.0};
  for (const ObstacleElement& e : o.elements) {
    const geometry::DistanceResult d =
        geometry::gjk_distance(point, {centre, {}}, e.shape, {e.position, e.orientation});
    const double overlap = radius - d.distance;
    if (overlap > best.overlap) {
      best.overlap = overlap;
      if (d.distance > 0.0) best.normal = (d.point_b - centre) / d.distance;
    }
  }
  return best;
}

// Gap of a sphere with an obstacle at its pose at time t.
inline SphereObstacleGap sphere_gap(const Obstacle& o, double t, const Vec3& centre,
                                    double radius) {
  if (o.motion.is_static()) {
    return std::visit([&](const auto& shape) { return sphere_gap(shape, centre, radius); },
                      o.shape);
  }
  const Vec3 local = o.motion.to_initial_frame(t, centre);
  SphereObstacleGap gap =
      std::visit([&](const auto& shape) { return sphere_gap(shape, local, radius); }, o.shape);
  gap.normal = o.motion.direction_to_space(t, gap.normal);
  return gap;
}

}  // namespace sanguis::dem
