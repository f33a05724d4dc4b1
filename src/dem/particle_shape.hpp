#pragma once
// The shape of a particle species (thesis §2.2, app. A): a sphere, or a rigid
// union of convex elements (one element for a convex particle; several for a
// non-convex composite such as the cross of §3.2.2). The body frame is the
// principal frame: origin at the centre of mass of the union, axes along the
// principal axes of inertia. Each element is stored as its "core" (the convex
// shape shrunk by the crust, app. A.2.3): two elements touch when the distance
// between their cores is below the sum of their crusts.
#include <string>
#include <vector>

#include "core/quaternion.hpp"
#include "core/vec3.hpp"
#include "geometry/mass_properties.hpp"
#include "geometry/shapes.hpp"

namespace sanguis::dem {

struct ShapeElement {
  geometry::ConvexShape core;  // shrunk by `crust`, in the element's own frame
  Vec3 position;               // element frame origin, in the body frame [m]
  Quaternion orientation;      // element frame -> body frame
  double crust = 0.0;          // [m]
  double reach = 0.0;          // radius of a ball about `position` holding the element [m]
};

struct ParticleShape {
  std::string name;
  std::vector<ShapeElement> elements;  // empty for a sphere
  double volume = 0.0;                 // of the union [m^3]
  Vec3 inertia_per_density;            // principal moments / density [m^5]
  double bounding_radius = 0.0;        // about the centre of mass [m]
  double equivalent_radius = 0.0;      // radius of the sphere of equal volume [m]
  double smallest_crust = 0.0;         // [m]
  geometry::TriangleMesh mesh;         // surface in the body frame, for output

  bool is_sphere() const { return elements.empty(); }
};

// A sphere species of the given radius.
ParticleShape make_sphere_shape(const std::string& name, double radius);

// A convex or composite species from elements placed in any frame: computes the
// union's mass properties, moves the elements into the principal frame and shrinks
// each by `crust` (throws std::invalid_argument if the crust does not fit).
ParticleShape make_particle_shape(const std::string& name, const geometry::Composite& elements,
                                  double crust);

}  // namespace sanguis::dem
