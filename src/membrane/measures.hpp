#pragma once
// Global measures of a closed membrane (thesis §4.4.2, §5.4.2, app. C eq. C.2):
// surface area, enclosed volume, centroid of the enclosed volume, inertia
// ellipsoid, Taylor deformation parameter D and the largest principal tension
// statistics.
//
// Volume, centroid and inertia are those of the enclosed solid (unit density),
// from the divergence theorem on the tetrahedra joining the origin to each
// triangle (outward triangles give a positive volume). The inertia ellipsoid
// is the solid ellipsoid with the same principal moments: for semi-axes
// a, b, c, I_a = V (b^2 + c^2)/5, so a^2 = 5 (I_b + I_c - I_a) / (2 V).
// Taylor deformation D = (L - B)/(L + B) with either
//  - L, B the largest and smallest semi-axes of the inertia ellipsoid, or
//  - L, B the largest and smallest distances of a node from the centroid
//    (r_max, r_min of §4.4.2 and eq. C.2).
#include <array>
#include <span>
#include <vector>

#include "core/mat3.hpp"
#include "core/vec3.hpp"
#include "membrane/elasticity.hpp"
#include "membrane/triangle_mesh.hpp"

namespace sanguis::membrane {

double surface_area(const std::vector<Triangle>& triangles, std::span<const Vec3> positions);
double enclosed_volume(const std::vector<Triangle>& triangles, std::span<const Vec3> positions);

struct InertiaEllipsoid {
  double volume = 0.0;
  Vec3 centroid;                      // of the enclosed volume
  Mat3 inertia;                       // about the centroid, per unit density
  std::array<double, 3> semi_axes{};  // ascending
  std::array<Vec3, 3> axes{};         // unit axis of each semi-axis
};

// Throws std::invalid_argument if the enclosed volume is not positive
// (inverted or open surface).
InertiaEllipsoid inertia_ellipsoid(const std::vector<Triangle>& triangles,
                                   std::span<const Vec3> positions);

// D from the inertia ellipsoid's largest and smallest semi-axes.
double taylor_deformation(const InertiaEllipsoid& e);
// D from the largest and smallest node distances to `centre`.
double taylor_deformation_from_radii(std::span<const Vec3> positions, const Vec3& centre);

// Largest principal tension sigma2 of §5.4.2 (the larger eigenvalue of the
// tension per triangle): maximum over the triangles and mean weighted by
// current triangle area.
struct TensionStatistics {
  double max_largest = 0.0;
  double mean_largest = 0.0;
};
TensionStatistics largest_tension_statistics(const ElasticLaw& law,
                                             std::span<const ReferenceTriangle> reference,
                                             const std::vector<Triangle>& triangles,
                                             std::span<const Vec3> positions);

}  // namespace sanguis::membrane
