#pragma once
// Separating-axis test for two oriented boxes with a margin: a cheap, conservative
// rejection of element pairs for the box elements of composite particles (the crosses
// of thesis §3.2), used when the element lists are rebuilt. Fifteen candidate axes
// (three face normals of each box and the nine cross products of their edges,
// Gottschalk et al. 1996); along a unit axis L the boxes' projections are at least
// |T.L| - rA(L) - rB(L) apart, and so are the boxes. When that gap exceeds `margin`
// (crusts plus skin) the pair cannot touch before the next rebuild. A pair it keeps may
// still be farther apart than the margin: it never drops one that is closer.
#include <algorithm>
#include <cmath>

#include "core/quaternion.hpp"
#include "core/vec3.hpp"
#include "geometry/gjk.hpp"
#include "geometry/shapes.hpp"

namespace sanguis::geometry {

inline bool boxes_apart_beyond(const Box& a, const Pose& pose_a, const Box& b, const Pose& pose_b,
                               double margin) {
  margin *= 1.0 + 1e-9;  // round-off never turns a touching pair into a rejected one
  // The boxes' axes in space: the columns of their rotation matrices.
  const Mat3 rot_a = rotation_matrix(pose_a.orientation);
  const Mat3 rot_b = rotation_matrix(pose_b.orientation);
  Vec3 ax[3], bx[3];
  for (int k = 0; k < 3; ++k) {
    ax[k] = {rot_a.m[0][k], rot_a.m[1][k], rot_a.m[2][k]};
    bx[k] = {rot_b.m[0][k], rot_b.m[1][k], rot_b.m[2][k]};
  }
  const double ea[3] = {a.half_extents.x, a.half_extents.y, a.half_extents.z};
  const double eb[3] = {b.half_extents.x, b.half_extents.y, b.half_extents.z};
  const Vec3 d = pose_b.position - pose_a.position;
  double r[3][3], abs_r[3][3], t[3];
  for (int i = 0; i < 3; ++i) {
    t[i] = dot(d, ax[i]);
    for (int j = 0; j < 3; ++j) {
      r[i][j] = dot(ax[i], bx[j]);  // b's axis j in a's frame
      abs_r[i][j] = std::abs(r[i][j]);
    }
  }
  for (int i = 0; i < 3; ++i) {  // face normals of a
    const double rb = eb[0] * abs_r[i][0] + eb[1] * abs_r[i][1] + eb[2] * abs_r[i][2];
    if (std::abs(t[i]) > ea[i] + rb + margin) return true;
  }
  for (int j = 0; j < 3; ++j) {  // face normals of b
    const double ra = ea[0] * abs_r[0][j] + ea[1] * abs_r[1][j] + ea[2] * abs_r[2][j];
    const double tj = t[0] * r[0][j] + t[1] * r[1][j] + t[2] * r[2][j];
    if (std::abs(tj) > ra + eb[j] + margin) return true;
  }
  for (int i = 0; i < 3; ++i) {  // L = a_i x b_j, of length sin(angle) (unscaled test)
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      const double length = std::sqrt(std::max(0.0, 1.0 - r[i][j] * r[i][j]));
      if (length < 1e-6) continue;  // parallel edges: the face normals decide
      const double projection = std::abs(t[i2] * r[i1][j] - t[i1] * r[i2][j]);
      const double ra = ea[i1] * abs_r[i2][j] + ea[i2] * abs_r[i1][j];
      const double rb = eb[j1] * abs_r[i][j2] + eb[j2] * abs_r[i][j1];
      if (projection > ra + rb + margin * length) return true;
    }
  }
  return false;
}

}  // namespace sanguis::geometry
