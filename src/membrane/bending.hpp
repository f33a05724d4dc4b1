#pragma once
// Helfrich bending of a triangulated membrane (thesis §4.2.2 eq. 4.9-4.10 and
// §4.3.4; Helfrich, Z. Naturforsch. 28c (1973) 693; method E of Guckenberger,
// Schraml, Chen, Leonetti & Gekle, Comput. Phys. Commun. 207 (2016) 1).
//
// Curvatures (Farutin, Biben & Misbah, J. Comput. Phys. 275 (2014) 539;
// Yazdani & Bagchi, Phys. Rev. E 84 (2011) 026314): at node i, in a local
// frame (t1, t2, n) with n the current normal estimate, the one-ring
// neighbours at (u, v, w) are fitted by least squares with the paraboloid
//   w = A u^2 + B u v + C v^2 + D u + E v       (through node i itself).
// The normal is then corrected to the fitted surface's normal
// (n - D t1 - E t2, normalised) and the fit repeated (normal_iterations
// times; 3-5 suffice, §4.3.4). From the last fit (Monge patch h(u, v)):
//   kappa   = -((1+E^2) 2A - 2 D E B + (1+D^2) 2C) / (2 W^3),   W^2 = 1 + D^2 + E^2
//   kappa_g = (4 A C - B^2) / W^4.
// Laplace-Beltrami (§4.3.4, "second fit"): the values kappa_j - kappa_i are
// fitted with the same quadratic form in (u, v) of the final frame, and
//   Delta_s f = g^ab (f_ab - h_ab (grad h . grad f) / W^2),  g^ab = delta_ab - h_a h_b / W^2
// at the node (the metric of the Monge patch; = f_uu + f_vv once D = E = 0).
// Nodal area: mixed Voronoi area of Meyer, Desbrun, Schröder & Barr (2003):
// the Voronoi share for non-obtuse triangles, A/2 at an obtuse corner and A/4
// at the other two corners of an obtuse triangle; the areas sum to the
// surface area exactly.
//
// SIGN CONVENTIONS (see docs/theory/membrane.md):
//  - n is the outward unit normal.
//  - kappa = (kappa1 + kappa2)/2 is POSITIVE on a sphere (kappa = 1/R,
//    kappa_g = 1/R^2): kappa = div_s(n)/2.
//  - The nodal force is minus the variation of E_B = integral of
//    2 Eb (kappa - kappa0)^2 dA (eq. 4.9; the Gaussian term is a topological
//    invariant), i.e. the force the membrane exerts on its node:
//      F_i = +2 Eb [Delta_s(kappa - kappa0) + 2 (kappa - kappa0)(kappa^2 - kappa_g + kappa0 kappa)]
//      A_i n_i.
//    This is eq. 4.10 with the thesis' minus sign once the curvature sign is
//    flipped (kappa_thesis = -kappa, kappa0_thesis = -kappa0: the Helfrich /
//    Ou-Yang convention, negative on a sphere with outward normal); a
//    reference curvature quoted in that convention enters here negated.
//    Check on a sphere: E_B = 8 pi Eb (1 - kappa0 R)^2, -dE/dR / (4 pi R^2)
//    = 4 Eb kappa0 (1 - kappa0 R)/R^2, which is the formula above.
#include <array>
#include <span>
#include <vector>

#include "core/vec3.hpp"
#include "membrane/mesh_topology.hpp"
#include "membrane/triangle_mesh.hpp"

namespace sanguis::membrane {

struct HelfrichParameters {
  double bending_modulus = 1.0;      // Eb [J]
  double reference_curvature = 0.0;  // kappa0 [1/m], sign convention above
  int normal_iterations = 4;         // normal corrections of the paraboloid fit
};

// The last height fit at a node: its frame (t1, t2, n: n the normal the fit
// was made around) and the paraboloid h(u, v) = a u^2 + b u v + c v^2 + d u + e v.
struct ParaboloidFit {
  Vec3 t1, t2, n;
  double a = 0.0, b = 0.0, c = 0.0, d = 0.0, e = 0.0;
};

// Checks Eb >= 0 and 0 <= normal_iterations <= 20; std::invalid_argument
// naming the value otherwise.
void validate(const HelfrichParameters& parameters);

// Local differential geometry at every node.
struct SurfaceGeometry {
  std::vector<Vec3> normal;                // outward unit normal (from the fit)
  std::vector<double> mean_curvature;      // kappa, 1/R on a sphere
  std::vector<double> gaussian_curvature;  // kappa_g, 1/R^2 on a sphere
  std::vector<double> laplace_beltrami;    // Delta_s (kappa - kappa0) = Delta_s kappa
  std::vector<double> area;                // mixed Voronoi area A_i
  std::vector<ParaboloidFit> fit;          // the height fits (reused by the second fit)
  // Per triangle, computed once and gathered by its three nodes: twice its
  // area times its unit normal, and the mixed-area share of each corner.
  struct TriangleShare {
    Vec3 twice_area_normal;
    std::array<double, 3> corner_area{};
  };
  std::vector<TriangleShare> triangle_share;
};

// Mixed Voronoi areas (Meyer et al. 2003) of every node; they sum to the area.
std::vector<double> mixed_voronoi_areas(const std::vector<Triangle>& triangles,
                                        const MeshTopology& topology,
                                        std::span<const Vec3> positions);

// Normals, curvatures, Laplace-Beltrami of kappa and nodal areas; `geometry`
// is resized (reuse it between steps to avoid allocation). Parallel over nodes
// (each node's result depends only on its own one-ring: same for any thread
// count).
void compute_surface_geometry(const std::vector<Triangle>& triangles, const MeshTopology& topology,
                              std::span<const Vec3> positions, int normal_iterations,
                              SurfaceGeometry& geometry, int threads);

// Bending force per unit area along n (the bracket of the formula above,
// times 2 Eb), from the local geometry.
inline double helfrich_force_density(const HelfrichParameters& p, double kappa, double kappa_g,
                                     double laplace_beltrami_kappa) {
  const double dk = kappa - p.reference_curvature;
  return 2.0 * p.bending_modulus *
         (laplace_beltrami_kappa +
          2.0 * dk * (kappa * kappa - kappa_g + p.reference_curvature * kappa));
}

// Adds the Helfrich nodal forces F_i = f_i A_i n_i to `forces`, computing the
// geometry into `geometry` (left there for output).
void add_bending_forces(const HelfrichParameters& parameters,
                        const std::vector<Triangle>& triangles, const MeshTopology& topology,
                        std::span<const Vec3> positions, std::span<Vec3> forces,
                        SurfaceGeometry& geometry, int threads);

}  // namespace sanguis::membrane
