#pragma once
// Elastic nodal forces of a triangulated membrane by linear-triangle finite
// elements and virtual work (thesis §4.3.4, eq. 4.17-4.19, Algorithm 4.1;
// Charrier, Shrivastava & Wu, J. Strain Anal. 24 (1989) 55; Doddi & Bagchi,
// Phys. Rev. E 79 (2009) 046318).
//
// Each triangle stores its stress-free (reference) shape once: its area A0 and
// the gradients g_k of its three linear shape functions in an orthonormal
// frame of its own plane. In the current configuration the in-plane
// deformation gradient is the 3x2 matrix F = sum_k x_k g_k^T (eq. 4.17: the
// rotation R of Algorithm 4.1 is folded in, since F^T F does not depend on it)
// and C = F^T F is the 2x2 right Cauchy-Green tensor; its eigenvalues are
// lambda1^2, lambda2^2. The triangle's energy is A0 W(trace C, det C), and the
// force on node j is minus its gradient (virtual work, eq. 4.18-4.19):
//
//   F_j = -A0 dW/dx_j = -2 A0 F S g_j,  S = dW/dC = W_trace I + W_det adj(C),
//
// which equals A0 (dW/dl1 dl1/dv_j + dW/dl2 dl2/dv_j) of eq. 4.18 but stays
// defined where lambda1 = lambda2 (there dl/dv of the eigen form is singular).
// The forces are those the membrane exerts on its nodes (restoring: they
// point back towards the reference shape), so an overdamped node moves as
// dx/dt = F/zeta. Their sum and their moment vanish for any deformation, and
// they vanish for rigid motions of the reference shape.
#include <array>
#include <span>
#include <vector>

#include "core/vec3.hpp"
#include "membrane/elastic_laws.hpp"
#include "membrane/mesh_topology.hpp"
#include "membrane/triangle_mesh.hpp"

namespace sanguis::membrane {

// Stress-free state of one triangle.
struct ReferenceTriangle {
  double area = 0.0;                                // A0
  std::array<std::array<double, 2>, 3> gradient{};  // g_k, shape-function gradients
};

// Per-triangle reference state of a membrane, built from its stress-free node
// positions (e.g. the icosphere mapped to the capsule shape, before any
// pre-inflation). Rigid motions do not change it, so all capsules of one shape
// share it. Throws std::invalid_argument for a degenerate triangle.
std::vector<ReferenceTriangle> make_reference(const TriangleMesh& stress_free);

// Kinematics of one triangle (eq. 4.17): the columns of F and C's components.
struct TriangleStrain {
  Vec3 f0, f1;                             // columns of the 3x2 deformation gradient F
  double c00 = 1.0, c01 = 0.0, c11 = 1.0;  // C = F^T F
  double trace() const { return c00 + c11; }
  double det() const { return c00 * c11 - c01 * c01; }
};

inline TriangleStrain triangle_strain(const ReferenceTriangle& ref, const Vec3& x0, const Vec3& x1,
                                      const Vec3& x2) {
  TriangleStrain s;
  const auto& g = ref.gradient;
  s.f0 = g[0][0] * x0 + g[1][0] * x1 + g[2][0] * x2;
  s.f1 = g[0][1] * x0 + g[1][1] * x1 + g[2][1] * x2;
  s.c00 = dot(s.f0, s.f0);
  s.c01 = dot(s.f0, s.f1);
  s.c11 = dot(s.f1, s.f1);
  return s;
}

// Principal stretches lambda1 <= lambda2: square roots of C's eigenvalues.
std::array<double, 2> principal_stretches(const TriangleStrain& s);

// Forces on the three nodes of one triangle (eq. 4.18-4.19), for any law.
template <typename Law>
inline std::array<Vec3, 3> triangle_forces(const Law& law, const ReferenceTriangle& ref,
                                           const Vec3& x0, const Vec3& x1, const Vec3& x2) {
  const TriangleStrain s = triangle_strain(ref, x0, x1, x2);
  const InvariantDerivatives d = law.derivatives(s.trace(), s.det());
  // S = W_trace I + W_det adj(C), adj(C) = [[c11, -c01], [-c01, c00]].
  const double s00 = d.d_trace + d.d_det * s.c11;
  const double s01 = -d.d_det * s.c01;
  const double s11 = d.d_trace + d.d_det * s.c00;
  // F S: two 3-vectors, scaled by -2 A0.
  const double k = -2.0 * ref.area;
  const Vec3 fs0 = k * (s00 * s.f0 + s01 * s.f1);
  const Vec3 fs1 = k * (s01 * s.f0 + s11 * s.f1);
  const auto& g = ref.gradient;
  return {g[0][0] * fs0 + g[0][1] * fs1, g[1][0] * fs0 + g[1][1] * fs1,
          g[2][0] * fs0 + g[2][1] * fs1};
}

// Adds the elastic forces of one membrane to `forces` (same size as
// `positions`). With threads > 1 the triangles are processed in parallel into
// `scratch` (resized as needed) and gathered per node in the corner order of
// the topology; with one thread they are scattered in triangle order. Both
// sum each node's contributions in increasing triangle order, so the result is
// bitwise the same for any thread count.
void add_elastic_forces(const ElasticLaw& law, std::span<const ReferenceTriangle> reference,
                        const std::vector<Triangle>& triangles, const MeshTopology& topology,
                        std::span<const Vec3> positions, std::span<Vec3> forces, int threads,
                        std::vector<std::array<Vec3, 3>>& scratch);

// Total elastic energy sum_T A0 W (the forces are minus its gradient).
double elastic_energy(const ElasticLaw& law, std::span<const ReferenceTriangle> reference,
                      const std::vector<Triangle>& triangles, std::span<const Vec3> positions);

// Principal tensions of eq. 4.5 per triangle, sigma1 <= sigma2 ([N/m], force
// per unit current length), with their stretches.
struct PrincipalTensions {
  double lambda1 = 1.0, lambda2 = 1.0;  // lambda1 <= lambda2
  double sigma1 = 0.0, sigma2 = 0.0;    // tension along lambda1's and lambda2's direction
  double largest() const { return sigma1 > sigma2 ? sigma1 : sigma2; }
};

PrincipalTensions principal_tensions(const ElasticLaw& law, const ReferenceTriangle& ref,
                                     const Vec3& x0, const Vec3& x1, const Vec3& x2);

std::vector<PrincipalTensions> principal_tensions(const ElasticLaw& law,
                                                  std::span<const ReferenceTriangle> reference,
                                                  const std::vector<Triangle>& triangles,
                                                  std::span<const Vec3> positions);

}  // namespace sanguis::membrane
