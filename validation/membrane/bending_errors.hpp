#pragma once
// Bending validation shared by the driver (validation/membrane/bending_main.cpp)
// and the unit tests: numerical curvatures, Laplace-Beltrami and Helfrich
// force density of a triangulated sphere or biconcave cell against the exact
// ones (thesis §4.4.1, Fig. 4.3-4.4; Guckenberger et al. 2016).
//
// Error norms over the nodes, relative to the largest exact magnitude:
//   L2 = sqrt(mean (num - exact)^2) / max|exact|,  Linf = max|num - exact| / max|exact|
// (on a sphere, where Delta_s kappa = 0, relative to 1/R^3).
#include <cmath>
#include <vector>

#include "membrane/bending.hpp"
#include "membrane/biconcave_profile.hpp"
#include "membrane/mesh_topology.hpp"
#include "membrane/triangle_mesh.hpp"

namespace sanguis::validation {

struct NodeComparison {
  double theta = 0.0;  // polar angle from the symmetry axis
  double kappa = 0.0, kappa_exact = 0.0;
  double kappa_g = 0.0, kappa_g_exact = 0.0;
  double laplace = 0.0, laplace_exact = 0.0;
  double force = 0.0, force_exact = 0.0;  // Helfrich force per unit area along n
};

struct ErrorNorm {
  double l2 = 0.0, linf = 0.0;
};

struct BendingErrors {
  ErrorNorm kappa, kappa_g, laplace, force;
};

// One comparison per node of an icosphere with `subdivisions` mapped to the
// biconcave shape (kappa0 = 0, Eb = 1).
inline std::vector<NodeComparison> compare_biconcave(int subdivisions,
                                                     const membrane::BiconcaveShape& shape,
                                                     int normal_iterations = 4) {
  using namespace membrane;
  TriangleMesh m = icosphere(subdivisions);
  map_to_biconcave(m, shape);
  const MeshTopology topo(m.node_count(), m.triangles);
  SurfaceGeometry g;
  compute_surface_geometry(m.triangles, topo, m.positions, normal_iterations, g, 1);
  const HelfrichParameters p{1.0, 0.0, normal_iterations};
  std::vector<NodeComparison> out(m.node_count());
  for (std::size_t i = 0; i < m.node_count(); ++i) {
    const auto exact = biconcave_curvatures(shape, biconcave_latitude(shape, m.positions[i]));
    auto& c = out[i];
    c.theta = polar_angle(m.positions[i]);
    c.kappa = g.mean_curvature[i];
    c.kappa_g = g.gaussian_curvature[i];
    c.laplace = g.laplace_beltrami[i];
    c.force = helfrich_force_density(p, c.kappa, c.kappa_g, c.laplace);
    c.kappa_exact = exact.mean;
    c.kappa_g_exact = exact.gaussian;
    c.laplace_exact = exact.laplace_beltrami;
    c.force_exact = helfrich_force_density(p, exact.mean, exact.gaussian, exact.laplace_beltrami);
  }
  return out;
}

// Same on a sphere of radius R (exact: 1/R, 1/R^2, 0; force density for kappa0).
inline std::vector<NodeComparison> compare_sphere(int subdivisions, double radius, double kappa0,
                                                  int normal_iterations = 4) {
  using namespace membrane;
  TriangleMesh m = icosphere(subdivisions);
  map_to_sphere(m, {radius});
  const MeshTopology topo(m.node_count(), m.triangles);
  SurfaceGeometry g;
  compute_surface_geometry(m.triangles, topo, m.positions, normal_iterations, g, 1);
  const HelfrichParameters p{1.0, kappa0, normal_iterations};
  std::vector<NodeComparison> out(m.node_count());
  for (std::size_t i = 0; i < m.node_count(); ++i) {
    auto& c = out[i];
    c.theta = polar_angle(m.positions[i]);
    c.kappa = g.mean_curvature[i];
    c.kappa_g = g.gaussian_curvature[i];
    c.laplace = g.laplace_beltrami[i];
    c.force = helfrich_force_density(p, c.kappa, c.kappa_g, c.laplace);
    c.kappa_exact = 1.0 / radius;
    c.kappa_g_exact = 1.0 / (radius * radius);
    c.laplace_exact = 0.0;
    c.force_exact = helfrich_force_density(p, 1.0 / radius, 1.0 / (radius * radius), 0.0);
  }
  return out;
}

template <typename Num, typename Exact>
ErrorNorm error_norm(const std::vector<NodeComparison>& nodes, Num num, Exact exact, double scale) {
  double sum = 0.0, worst = 0.0, largest = scale;
  for (const auto& c : nodes) largest = std::max(largest, std::fabs(exact(c)));
  for (const auto& c : nodes) {
    const double e = std::fabs(num(c) - exact(c));
    sum += e * e;
    worst = std::max(worst, e);
  }
  return {std::sqrt(sum / static_cast<double>(nodes.size())) / largest, worst / largest};
}

// `scale`: a floor for max|exact| (used where the exact value is 0).
inline BendingErrors errors(const std::vector<NodeComparison>& n, double scale_kappa,
                            double scale_laplace, double scale_force) {
  return {
      error_norm(
          n, [](auto& c) { return c.kappa; }, [](auto& c) { return c.kappa_exact; }, scale_kappa),
      error_norm(
          n, [](auto& c) { return c.kappa_g; }, [](auto& c) { return c.kappa_g_exact; },
          scale_kappa * scale_kappa),
      error_norm(
          n, [](auto& c) { return c.laplace; }, [](auto& c) { return c.laplace_exact; },
          scale_laplace),
      error_norm(
          n, [](auto& c) { return c.force; }, [](auto& c) { return c.force_exact; }, scale_force),
  };
}

}  // namespace sanguis::validation
