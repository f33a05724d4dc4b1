#pragma once
// 3D convex hull by Quickhull (Barber, Dobkin & Huhdanpaa, ACM TOMS 22 (1996)
// 469): the factory of ConvexPolyhedron, and the convexity check of meshes
// read from STL/OBJ files.
//
// Robustness: all decisions use one distance tolerance, relative_tolerance
// times the diagonal of the points' bounding box (points are first shifted to
// the box centre so that far-off coordinates lose no digits). A point within
// the tolerance of the hull is inside; adjacent triangles whose vertices lie
// within the tolerance of a common plane are merged into one polygon face (a
// cube has 6 quadrilaterals), and vertices lying on an edge between two faces
// are dropped. Which faces a new point sees is decided with an exact
// orientation predicate, so the surface stays a closed convex 2-manifold
// however nearly coplanar the input (float32 STL coordinates, lattices).
// Duplicates, coplanar and collinear points are harmless; all input points
// lie within about twice the tolerance of the result's face planes (plus the
// rounding of sliver faces' planes when the input has features just above
// the tolerance).
#include <span>
#include <vector>

#include "core/vec3.hpp"
#include "geometry/shapes.hpp"

namespace sanguis::geometry {

inline constexpr double kHullTolerance = 1e-10;

// Convex hull of the points, in their own frame (not re-centred). Throws
// std::invalid_argument with a clear message for fewer than 4 points,
// non-finite coordinates, or points that are coincident, collinear or coplanar
// within the tolerance (no volume).
ConvexPolyhedron convex_hull(std::span<const Vec3> points,
                             double relative_tolerance = kHullTolerance);

// The particle-shape factory: the hull of the points, translated so that its
// centroid (centre of volume) is at the origin. If `centroid` is given it
// receives the centroid in the points' frame, i.e. the position at which the
// returned body must be placed to cover the input points.
ConvexPolyhedron make_convex_polyhedron(std::vector<Vec3> points, Vec3* centroid = nullptr,
                                        double relative_tolerance = kHullTolerance);

// Whether a closed triangle mesh bounds a convex solid, i.e. is its own hull,
// with distance tolerance relative_tolerance times the mesh's bounding-box
// diagonal. Checks: every edge is shared by exactly two triangles with
// opposite orientations (a closed, consistently oriented surface); every edge
// is convex (each triangle's neighbour bends away from it by no more than the
// tolerance: no dents); and the enclosed volume equals the hull's (within the
// tolerance times the hull's area: the surface does not wind around twice).
// Either orientation is accepted. False for meshes with fewer than 4 vertices.
bool is_convex_mesh(const TriangleMesh& mesh, double relative_tolerance = 1e-9);

}  // namespace sanguis::geometry
