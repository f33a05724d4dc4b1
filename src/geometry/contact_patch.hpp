#pragma once
// Contact patch of two flat-faced cores (or a flat-faced core and a plane): the part
// of their facing faces that lies within the crusts' reach, as a convex polygon whose
// corners each carry their own overlap. The DEM turns it into a bed of normal springs
// and dashpots at the corners (dem/body_contacts.hpp), so that a face resting on a
// face has a resultant at its centre and a restoring, damped torque when it tilts,
// where one contact point per pair (thesis §2.3, app. A.2.3) jumps between corners.
//
// Construction, for two cores A and B with unit normal n from A to B (GJK's):
//  1. each core's face that best faces the other (largest dot(face normal, +-n)
//     among the faces holding the core's support point along +-n);
//  2. both faces projected along n onto a plane normal to n, A's polygon clipped by
//     B's (convex polygons, Sutherland-Hodgman);
//  3. the result clipped where the gap between the two face planes, measured along n,
//     is below the crusts' sum, so the overlap reach - gap is >= 0 on the patch and
//     0 on the cut.
// For a vertex or an edge touching a face, or two crossing edges, the patch shrinks
// to a sliver whose deepest corners are the GJK contact; its other corners have zero
// overlap. Only boxes, convex polyhedra and triangles have faces; curved cores do not
// make patches.
#include <array>

#include "core/vec3.hpp"
#include "geometry/gjk.hpp"
#include "geometry/shapes.hpp"

namespace sanguis::geometry {

// A face of a core placed in space: its outward unit normal, its plane offset
// (dot(normal, x) = offset on the face) and its corners in order around it.
struct SpaceFace {
  static constexpr int kCapacity = 16;
  Vec3 normal;
  double offset = 0.0;
  int count = 0;
  std::array<Vec3, kCapacity> corner;
};

// The face of `shape` (at `pose`) whose outward normal best follows the space
// direction `d` among the faces holding the support point along d. False for curved
// shapes, for faces with more than SpaceFace::kCapacity corners, and when no face
// holding the support point leans towards d.
bool facing_face(const ConvexShape& shape, const Pose& pose, const Vec3& d, SpaceFace& out);

struct ContactPatch {
  static constexpr int kCapacity = 2 * SpaceFace::kCapacity + 2;
  int count = 0;
  std::array<Vec3, kCapacity> point;      // on the middle of the two crusts, space frame
  std::array<double, kCapacity> overlap;  // reach - gap at the corner, >= 0 [m]
  // Half the lengths of the two patch edges that meet at the corner [m]: the corner's
  // share of the perimeter, which is continuous as corners split or merge while the
  // faces slide (the overlap-weighted corners then give a resultant without jumps).
  std::array<double, kCapacity> perimeter_share;
};

// The patch between face `a` of the first core (facing +n) and face `b` of the second
// (facing -n), n a unit vector from the first core to the second; `crust_a`, `crust_b`
// the crusts. False when the faces' projections do not overlap, when no part is
// within reach, or when a face is too steep to n to be measured along it.
bool face_pair_patch(const SpaceFace& a, const SpaceFace& b, const Vec3& n, double crust_a,
                     double crust_b, ContactPatch& out);

// The patch between face `a` (facing the plane) and the plane through `plane_point`
// with unit normal `plane_normal` (pointing away from the solid behind it, towards
// `a`); `crust` is the core's.
bool face_plane_patch(const SpaceFace& a, const Vec3& plane_point, const Vec3& plane_normal,
                      double crust, ContactPatch& out);

// The pressure over a patch about `centre`, measured in the plane normal to `normal`: the
// overlap, which is linear over the patch (the faces are planes), and its moments <r^2>
// and <|r|>. They are what a tangential spring spread over the patch with that pressure
// would give against twisting (dem/body_contacts.hpp): an evenly pressed square of side
// a gives a^2/6 and 0.383 a, a strip of length L L^2/12 and L/4. Integrated over the
// triangles between each edge and the centre in polar form, <r^2> exactly in the
// constructor, <|r|> (square roots) on demand, within 1 %; a patch of no area (corners on
// a line) along its edges. <|r|> >= <r^2> / farthest() bounds it from below.
class PatchPressure {
 public:
  PatchPressure(const ContactPatch& patch, const Vec3& centre, const Vec3& normal);
  double second_moment() const { return second_moment_; }  // <r^2> [m^2]
  double farthest() const { return farthest_; }            // the largest corner distance [m]
  double mean_arm() const;                                 // <|r|> [m]

 private:
  int next(int k) const { return k + 1 == n_ ? 0 : k + 1; }  // no modulo: a division
  void line_integrals();

  int n_ = 0;
  std::array<Vec3, ContactPatch::kCapacity> r_;  // corners from the centre, in the plane
  std::array<double, ContactPatch::kCapacity> overlap_;
  Vec3 normal_;
  bool flat_ = false;  // an area; else corners on a line
  double centre_overlap_ = 0.0, second_moment_ = 0.0, farthest_ = 0.0, line_mean_arm_ = 0.0;
};

struct PatchArms {
  double second_moment = 0.0;  // <r^2> [m^2]
  double mean_arm = 0.0;       // <|r|> [m]
};
// Both moments at once (PatchPressure).
PatchArms pressure_arms(const ContactPatch& patch, const Vec3& centre, const Vec3& normal);

}  // namespace sanguis::geometry
