#pragma once
// Convex polytopes as plain vertex/face-loop data in any frame, with the two
// operations the mass properties and the crust need: clipping by a half-space
// (Sutherland & Hodgman, CACM 17 (1974) 32, applied face by face, plus the cap
// polygon on the cutting plane) and the volume moments by the divergence
// theorem on a tetrahedral decomposition (Mirtich, J. Graphics Tools 1 (1996)
// 31; Tonon, J. Math. Stat. 1 (2004) 8 for the second-moment formulas).
#include <cstdint>
#include <vector>

#include "core/mat3.hpp"
#include "core/quaternion.hpp"
#include "core/vec3.hpp"
#include "geometry/shapes.hpp"

namespace sanguis::geometry {

struct Polytope {
  std::vector<Vec3> vertices;
  std::vector<std::vector<std::uint32_t>> faces;  // loops, counter-clockwise seen from outside

  bool empty() const { return faces.size() < 4; }
};

// The polyhedron placed at `position` with orientation q.
Polytope to_polytope(const ConvexPolyhedron& p, const Vec3& position = {},
                     const Quaternion& q = {});

// Outward face planes (area-weighted normal of each loop, through its mean).
std::vector<Plane> face_planes(const Polytope& p);

// The part of p with dot(plane.normal, x) <= plane.offset. Vertices within
// `tolerance` of the plane count as on it (no sliver faces). An empty Polytope
// when nothing of volume is left.
Polytope clip(const Polytope& p, const Plane& plane, double tolerance);

// p clipped by every half-space in turn (the intersection with a convex
// polytope whose face planes these are).
Polytope clip(Polytope p, const std::vector<Plane>& halfspaces, double tolerance);

// Integrals over the solid per unit density: volume, first moment (integral
// of x) and second moment (integral of x x^T), about the frame's origin.
struct VolumeMoments {
  double volume = 0.0;
  Vec3 first;
  Mat3 second;
};

VolumeMoments volume_moments(const Polytope& p);

}  // namespace sanguis::geometry
