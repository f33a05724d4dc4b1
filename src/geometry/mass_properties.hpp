#pragma once
// Volume, centroid and inertia of shapes and of composite particles (thesis
// app. A.1 and §3.2.2; Grains3D "composite particles": Rakotonirina, Delenne,
// Radjai & Wachs, Comput. Part. Mech. 6 (2019) 55).
//
// Inertia is per unit density: multiply by the density for kg m^2 (in SI).
// Primitives use their closed forms; a polyhedron uses the divergence theorem
// on a tetrahedral decomposition (polytope.hpp). A composite counts the space
// where its elements overlap once: its mass properties are those of the
// *union*, by inclusion-exclusion over the elements' intersections, each
// intersection computed by half-space clipping:
//   M(E1 u ... u En) = sum_i M(Ei) - sum_{i<j} M(Ei n Ej) + ... (+-) M(E1 n ... n En)
// where M is any additive moment (volume, first, second moment). Subsets whose
// intersection is empty are pruned with all their supersets.
#include <vector>

#include "core/mat3.hpp"
#include "core/quaternion.hpp"
#include "core/vec3.hpp"
#include "geometry/shapes.hpp"

namespace sanguis::geometry {

struct MassProperties {
  double volume = 0.0;
  Vec3 centroid;                // in the body (or composite) frame
  Mat3 inertia_about_centroid;  // per unit density [length^5]
  Vec3 principal_moments;       // eigenvalues of the inertia, ascending
  // Rotation from the principal frame to the body frame: rotate(principal_axes,
  // e_k) is the axis of principal_moments[k]; right-handed.
  Quaternion principal_axes;
};

// Closed forms: sphere I = 2/5 V r^2; box I_xx = V (b^2 + c^2)/3 (half
// extents a, b, c); cylinder I_zz = V r^2/2, I_xx = V (r^2/4 + h^2/12); cone
// I_zz = 3/10 V r^2, I_xx = V (3/20 r^2 + 3/80 h^2) about its centroid;
// ellipsoid I_xx = V (b^2 + c^2)/5. Throws std::invalid_argument for a
// Triangle (no volume).
MassProperties mass_properties(const ConvexShape& shape);

// From volume, first and second moments about the frame origin: centroid,
// inertia about it, principal moments and axes (Eigen's self-adjoint solver).
MassProperties from_moments(double volume, const Vec3& first, const Mat3& second);

// One convex piece of a composite, placed in the composite's frame.
struct CompositeElement {
  ConvexShape shape;
  Vec3 position;           // of the element's body origin
  Quaternion orientation;  // rotate(orientation, .) maps element body -> composite frame
};

using Composite = std::vector<CompositeElement>;

// Mass properties of the union of the elements, in the composite's frame (not
// re-centred: translate by -centroid to put the centre of mass at the origin).
// Single elements use their exact moments; intersections of two or more are
// computed on polyhedra: exact for Box and ConvexPolyhedron elements; a curved
// element is replaced there by the hull of tessellate(shape,
// curved_resolution), inscribed in it. Each intersection volume is then too
// small by at most the sum, over its curved elements, of the volume the
// inscribed polyhedron misses (composite_volume_error_bound): about 0.4 % of
// the element volume for a sphere at resolution 64, and decreasing as
// resolution^-2. Throws std::invalid_argument for an empty composite, a
// Triangle element, or a resolution < 3.
MassProperties composite_mass_properties(const std::vector<CompositeElement>& elements,
                                         int curved_resolution = 64);

// The bound stated above, summed over all non-empty intersection terms: the
// union volume from composite_mass_properties is within this of the exact one
// (0 when no curved element overlaps another).
double composite_volume_error_bound(const std::vector<CompositeElement>& elements,
                                    int curved_resolution = 64);

// The cross of thesis §3.2.2: two boxes of length x width x thickness sharing
// their centre at the origin, one along x, one along y, thickness along z
// (27 x 2 x 3 mm in the thesis: union volume 2*27*2*3 - 2*2*3 = 312 mm^3).
Composite cross_particle(double length, double width, double thickness);

}  // namespace sanguis::geometry
