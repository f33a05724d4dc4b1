// CapsuleSet: placement of several capsules, forces independent of the thread
// count, and overdamped relaxation (dx/dt = F/zeta, forward Euler) of a
// capsule stretched along x at constant volume and released:
//  - elastic only, stretch 1.1: back to the sphere, Taylor deformation
//    1e-1 -> below 1e-6 (measured 2e-8), area to 1e-6;
//  - with bending (Eb = 0.05 Es R^2), stretch 1.25: inertia-ellipsoid
//    deformation below 1e-6 (measured 6e-10); node radii within 1e-3
//    (measured 1.3e-4: the discretisation error of Delta_s kappa leaves a
//    small residual bending force on the sphere).
// Without bending a larger stretch (1.25) does NOT come back: compressed
// nodes pop through their one-ring, an isometry of the triangles, so the
// elastic energy still falls to 1e-11 of its start while the shape stays
// dimpled (D = 0.03). That is the physics of a bending-free membrane
// (buckling, thesis Fig. 4.6), not a solver failure.
#include "membrane/capsules.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "membrane/measures.hpp"

using namespace sanguis;
using namespace sanguis::membrane;

namespace {

TriangleMesh unit_sphere(int k) {
  TriangleMesh m = icosphere(k);
  map_to_sphere(m, {1.0});
  return m;
}

}  // namespace

TEST(CapsuleSet, PlacesPreInflatedCapsules) {
  const std::vector<CapsulePlacement> placements{
      {{0, 0, 0}, {}}, {{5, 0, 0}, normalized(Quaternion::from_axis_angle({0, 1, 0}, 1.0))}};
  CapsuleSet set(unit_sphere(2), 1.05, placements);
  ASSERT_EQ(set.capsule_count(), 2u);
  for (const auto& x : set.positions(1)) EXPECT_NEAR(norm(x - Vec3{5, 0, 0}), 1.05, 1e-14);
  // Pre-inflation stretches every triangle by 1.05: an outward-pulling tension.
  set.compute_forces(NeoHookeanLaw{}, std::nullopt, 1);
  const auto x = set.positions(0);
  const auto f = set.forces(0);
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_LT(dot(f[i], x[i]), 0.0);
  EXPECT_THROW(CapsuleSet(unit_sphere(1), 0.0, placements), std::invalid_argument);
  EXPECT_THROW(set.compute_forces(SkalakLaw{-1.0, 10.0}, std::nullopt, 1), std::invalid_argument);
}

TEST(CapsuleSet, ForcesDoNotDependOnTheThreadCount) {
  std::vector<CapsulePlacement> placements;
  for (int c = 0; c < 3; ++c)
    placements.push_back(
        {{3.0 * c, 0, 0}, normalized(Quaternion::from_axis_angle({1.0, 1.0, double(c)}, c))});
  TriangleMesh shape = icosphere(3);
  map_to_biconcave(shape, {});
  CapsuleSet set(shape, 1.02, placements);
  const HelfrichParameters bending{0.1, 0.3, 4};
  set.compute_forces(SkalakLaw{1.0, 10.0}, bending, 1);
  const auto serial = set.all_forces();
  for (const int threads : {2, 4}) {  // 2: capsules shared; 4: threads inside each capsule
    set.compute_forces(SkalakLaw{1.0, 10.0}, bending, threads);
    for (std::size_t i = 0; i < serial.size(); ++i) ASSERT_EQ(serial[i], set.all_forces()[i]);
  }
}

namespace {

// Stretches the capsule along x (volume kept), then integrates dx/dt = F/zeta.
struct Relaxation {
  double initial_deformation = 0.0, final_deformation = 0.0, final_radii_deformation = 0.0;
  double area_error = 0.0;
};

Relaxation relax(const std::optional<HelfrichParameters>& bending, double s, double dt, int steps) {
  CapsuleSet set(unit_sphere(2), 1.0, {{{0, 0, 0}, {}}});
  const auto& tri = set.shape().triangles;
  const double reference_area = surface_area(tri, set.shape().positions);
  auto x = set.positions(0);
  for (auto& p : x) p = {s * p.x, p.y / std::sqrt(s), p.z / std::sqrt(s)};
  Relaxation r;
  r.initial_deformation = taylor_deformation(inertia_ellipsoid(tri, x));
  const double zeta = 1.0;
  for (int n = 0; n < steps; ++n) {
    set.compute_forces(NeoHookeanLaw{1.0}, bending, 1);
    const auto f = set.forces(0);
    for (std::size_t i = 0; i < x.size(); ++i) x[i] += (dt / zeta) * f[i];
  }
  const InertiaEllipsoid e = inertia_ellipsoid(tri, x);
  r.final_deformation = taylor_deformation(e);
  r.final_radii_deformation = taylor_deformation_from_radii(x, e.centroid);
  r.area_error = std::fabs(surface_area(tri, x) / reference_area - 1.0);
  return r;
}

}  // namespace

TEST(CapsuleSet, OverdampedCapsuleRelaxesToItsReferenceShape) {
  const Relaxation elastic = relax(std::nullopt, 1.1, 0.1, 4000);
  EXPECT_GT(elastic.initial_deformation, 0.05);
  EXPECT_LT(elastic.final_deformation, 1e-6);
  EXPECT_LT(elastic.final_radii_deformation, 1e-6);
  EXPECT_LT(elastic.area_error, 1e-6);

  const Relaxation with_bending = relax(HelfrichParameters{0.05, 0.0, 4}, 1.25, 0.05, 4000);
  EXPECT_GT(with_bending.initial_deformation, 0.1);
  EXPECT_LT(with_bending.final_deformation, 1e-6);
  EXPECT_LT(with_bending.final_radii_deformation, 1e-3);
  EXPECT_LT(with_bending.area_error, 1e-4);
}
