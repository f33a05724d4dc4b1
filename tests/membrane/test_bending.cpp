// Helfrich bending by paraboloid fits (eq. 4.9-4.10, §4.3.4).
//  - Sphere: kappa = 1/R and kappa_g = 1/R^2 converge at second order (observed
//    orders >= 1.8 required from 320 to 20480 triangles); Delta_s kappa = 0
//    converges slowly in RMS (order >= 0.4 required; its maximum stays near
//    0.15/R^3 at the twelve valence-5 nodes, where five neighbours make the
//    second fit an interpolation of the O(h^2) curvature error, a known
//    weakness of one-ring fits: Guckenberger et al. 2016).
//  - Sphere, kappa0 = 0: the force density is zero up to that same error
//    (RMS < 0.06 Eb/R^3 at 5120 triangles and decreasing); kappa0 != 0: the
//    total normal force matches the exact 4 Eb kappa0 (1 - kappa0 R)/R^2 times
//    the area to 1 % at 5120 triangles (the noise averages out).
//  - Biconcave cell (eq. 4.21) of 5120 triangles against the exact geometry
//    (biconcave_profile.hpp): bounds set about 25 % above the values measured
//    when this was written (the thesis quotes no numbers, only "a few
//    outliers ... by a few percents"); see docs/validation/membrane.md.
#include "membrane/bending.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "../../validation/membrane/bending_errors.hpp"
#include "membrane/measures.hpp"

using namespace sanguis;
using namespace sanguis::membrane;

namespace {
double order(double coarse, double fine) {
  return std::log2(coarse / fine) / 2.0;
}
// log2(error ratio) per subdivision (h halves): divided by 1, not 2.
double order_per_level(double coarse, double fine) {
  return std::log2(coarse / fine);
}
}  // namespace

TEST(MembraneBending, SphereCurvaturesConvergeAtSecondOrder) {
  const double radius = 2.0;
  std::vector<validation::BendingErrors> e;
  for (int k = 2; k <= 5; ++k)
    e.push_back(validation::errors(validation::compare_sphere(k, radius, 0.0), 1.0 / radius,
                                   1.0 / (radius * radius * radius), 1.0));
  for (std::size_t l = 1; l < e.size(); ++l) {
    EXPECT_GE(order_per_level(e[l - 1].kappa.linf, e[l].kappa.linf), 1.8) << l;
    EXPECT_GE(order_per_level(e[l - 1].kappa_g.linf, e[l].kappa_g.linf), 1.8) << l;
    EXPECT_GE(order_per_level(e[l - 1].laplace.l2, e[l].laplace.l2), 0.4) << l;
  }
  EXPECT_LT(e.back().kappa.linf, 1e-3);
  EXPECT_LT(e.back().laplace.linf, 0.2);
}

TEST(MembraneBending, SphereWithoutReferenceCurvatureHasNoBendingForce) {
  double previous = INFINITY;
  for (int k = 2; k <= 5; ++k) {
    const auto nodes = validation::compare_sphere(k, 1.0, 0.0);
    double sum = 0.0;
    for (const auto& c : nodes) {
      EXPECT_EQ(c.force_exact, 0.0);
      sum += c.force * c.force;
    }
    const double rms = std::sqrt(sum / static_cast<double>(nodes.size()));  // [Eb / R^3]
    EXPECT_LT(rms, previous);
    if (k == 4) {
      EXPECT_LT(rms, 0.06);
    }
    previous = rms;
  }
}

TEST(MembraneBending, SphereWithReferenceCurvatureGetsTheExactForce) {
  // R = 1, Eb = 1. kappa0 = 0.5: the sphere wants radius 2 and is pushed
  // outward; kappa0 = -1 (or 2): inward.
  for (const double kappa0 : {0.5, -1.0, 2.0}) {
    TriangleMesh m = icosphere(4);
    map_to_sphere(m, {1.0});
    const MeshTopology topo(m.node_count(), m.triangles);
    std::vector<Vec3> f(m.node_count());
    SurfaceGeometry g;
    add_bending_forces({1.0, kappa0, 4}, m.triangles, topo, m.positions, f, g, 1);
    double radial = 0.0;
    Vec3 net;
    for (std::size_t i = 0; i < f.size(); ++i) {
      radial += dot(f[i], m.positions[i]);
      net += f[i];
    }
    const double exact_density = 4.0 * kappa0 * (1.0 - kappa0);  // -dE/dR / (4 pi R^2)
    const double area = surface_area(m.triangles, m.positions);
    EXPECT_NEAR(radial, exact_density * area, 0.01 * std::fabs(exact_density) * area) << kappa0;
    EXPECT_LT(norm(net), 1e-10 * std::fabs(exact_density) * area);
  }
}

TEST(MembraneBending, MixedVoronoiAreasSumToTheAreaAlsoWithObtuseTriangles) {
  TriangleMesh m = icosphere(3);
  map_to_ellipsoid(m, {{3.0, 1.0, 0.3}});
  const MeshTopology topo(m.node_count(), m.triangles);
  int obtuse = 0;
  for (const auto& t : m.triangles)
    for (int c = 0; c < 3; ++c) {
      const Vec3 p = m.positions[t[c]], q = m.positions[t[(c + 1) % 3]],
                 r = m.positions[t[(c + 2) % 3]];
      obtuse += dot(q - p, r - p) < 0.0;
    }
  ASSERT_GT(obtuse, 10);
  const auto a = mixed_voronoi_areas(m.triangles, topo, m.positions);
  double sum = 0.0;
  for (const double v : a) {
    EXPECT_GT(v, 0.0);
    sum += v;
  }
  const double area = surface_area(m.triangles, m.positions);
  EXPECT_NEAR(sum, area, 1e-12 * area);
}

TEST(MembraneBending, BiconcaveCellAgreesWithTheExactGeometry) {
  const BiconcaveShape rbc{1.0, 0.207, 2.003, -1.123};
  const auto e5120 = validation::errors(validation::compare_biconcave(4, rbc), 0.0, 0.0, 0.0);
  EXPECT_LT(e5120.kappa.linf, 0.018);    // measured 0.0145
  EXPECT_LT(e5120.kappa_g.linf, 0.027);  // measured 0.0212
  EXPECT_LT(e5120.laplace.l2, 0.07);     // measured 0.0557
  EXPECT_LT(e5120.laplace.linf, 0.20);   // measured 0.159 (valence-5 nodes)
  EXPECT_LT(e5120.force.l2, 0.08);       // measured 0.0635
  EXPECT_LT(e5120.force.linf, 0.23);     // measured 0.185
  // kappa and kappa_g converge under refinement (320 -> 1280 -> 5120).
  const auto e320 = validation::errors(validation::compare_biconcave(2, rbc), 0.0, 0.0, 0.0);
  EXPECT_GE(order(e320.kappa.l2, e5120.kappa.l2), 1.7);
  EXPECT_GE(order(e320.kappa_g.l2, e5120.kappa_g.l2), 1.5);
}

TEST(MembraneBending, ParametersAreChecked) {
  EXPECT_NO_THROW(validate(HelfrichParameters{2e-19, -2.09 / 3.91e-6, 4}));
  EXPECT_THROW(validate(HelfrichParameters{-1.0, 0.0, 4}), std::invalid_argument);
  EXPECT_THROW(validate(HelfrichParameters{1.0, 0.0, -1}), std::invalid_argument);
  EXPECT_THROW(validate(HelfrichParameters{1.0, NAN, 4}), std::invalid_argument);
}

TEST(MembraneBending, GeometryIsFrameInvariantAndThreadIndependent) {
  TriangleMesh m = icosphere(3);
  map_to_biconcave(m, {});
  const MeshTopology topo(m.node_count(), m.triangles);
  SurfaceGeometry g1, g2, g3;
  compute_surface_geometry(m.triangles, topo, m.positions, 4, g1, 1);
  compute_surface_geometry(m.triangles, topo, m.positions, 4, g2, 2);
  auto moved = m.positions;
  place(moved, normalized(Quaternion::from_axis_angle({0.3, -1, 2}, 2.1)), {4, 5, 6});
  compute_surface_geometry(m.triangles, topo, moved, 4, g3, 1);
  for (std::size_t i = 0; i < m.node_count(); ++i) {
    ASSERT_EQ(g1.mean_curvature[i], g2.mean_curvature[i]);
    ASSERT_EQ(g1.laplace_beltrami[i], g2.laplace_beltrami[i]);
    EXPECT_NEAR(g3.mean_curvature[i], g1.mean_curvature[i], 1e-9);
    EXPECT_NEAR(g3.gaussian_curvature[i], g1.gaussian_curvature[i], 1e-9);
    // Delta_s kappa reaches ~100 / R^3 here: 1e-6 relative.
    EXPECT_NEAR(g3.laplace_beltrami[i], g1.laplace_beltrami[i], 1e-4);
    EXPECT_NEAR(g3.area[i], g1.area[i], 1e-13);
  }
}
