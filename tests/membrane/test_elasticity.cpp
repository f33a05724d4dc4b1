// FEM elastic forces (eq. 4.17-4.19): minus the gradient of the discrete
// energy (central finite differences, agreement to 1e-6 of the largest force,
// the FD truncation/round-off level at step 1e-6 R), zero for rigid motions
// (1e-12 of the force scale Es R), zero net force and torque for an arbitrary
// deformation (1e-12 of the summed force magnitudes), and bitwise the same
// forces for 1 and 2 threads.
#include "membrane/elasticity.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace sanguis;
using namespace sanguis::membrane;

namespace {

struct Sphere {
  TriangleMesh mesh;
  MeshTopology topology;
  std::vector<ReferenceTriangle> reference;
  explicit Sphere(int k, double radius = 1.0)
      : mesh([&] {
          TriangleMesh m = icosphere(k);
          map_to_sphere(m, {radius});
          return m;
        }()),
        topology(mesh.node_count(), mesh.triangles),
        reference(make_reference(mesh)) {}
};

std::vector<Vec3> randomly_deformed(const std::vector<Vec3>& x, double amplitude, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  std::vector<Vec3> y = x;
  for (auto& p : y) p = Vec3{1.3 * p.x, 0.9 * p.y, p.z} + Vec3{u(rng), u(rng), u(rng)};
  return y;
}

std::vector<Vec3> forces(const ElasticLaw& law, const Sphere& s, const std::vector<Vec3>& x,
                         int threads = 1) {
  std::vector<Vec3> f(x.size());
  std::vector<std::array<Vec3, 3>> scratch;
  add_elastic_forces(law, s.reference, s.mesh.triangles, s.topology, x, f, threads, scratch);
  return f;
}

const ElasticLaw kLaws[] = {NeoHookeanLaw{2.0, NeoHookeanConvention::kChapter4},
                            NeoHookeanLaw{2.0, NeoHookeanConvention::kChapter5},
                            SkalakLaw{2.0, 10.0}};

}  // namespace

TEST(MembraneElasticity, ForcesAreMinusTheEnergyGradient) {
  const Sphere s(1);
  const auto x = randomly_deformed(s.mesh.positions, 0.05, 7);
  for (const auto& law : kLaws) {
    const auto f = forces(law, s, x);
    double f_max = 0.0;
    for (const auto& v : f) f_max = std::max(f_max, norm(v));
    ASSERT_GT(f_max, 0.1);
    const double h = 1e-6;
    auto y = x;
    for (std::size_t i = 0; i < x.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        y[i][k] = x[i][k] + h;
        const double e_plus = elastic_energy(law, s.reference, s.mesh.triangles, y);
        y[i][k] = x[i][k] - h;
        const double e_minus = elastic_energy(law, s.reference, s.mesh.triangles, y);
        y[i][k] = x[i][k];
        EXPECT_NEAR(f[i][k], -(e_plus - e_minus) / (2 * h), 1e-6 * f_max)
            << "node " << i << " component " << k << " law " << law.index();
      }
  }
}

TEST(MembraneElasticity, RigidMotionsGiveNoForce) {
  const Sphere s(3, 2.0);
  auto x = s.mesh.positions;
  place(x, normalized(Quaternion::from_axis_angle({1, 2, 3}, 0.7)), {5, -3, 1});
  for (const auto& law : kLaws) {
    const auto f = forces(law, s, x);
    for (const auto& v : f) ASSERT_LT(norm(v), 1e-12 * 2.0 * 2.0);
    EXPECT_NEAR(elastic_energy(law, s.reference, s.mesh.triangles, x), 0.0, 1e-12);
  }
}

TEST(MembraneElasticity, NetForceAndTorqueVanishForAnyDeformation) {
  const Sphere s(3);
  const auto x = randomly_deformed(s.mesh.positions, 0.02, 11);
  for (const auto& law : kLaws) {
    const auto f = forces(law, s, x);
    Vec3 total, torque;
    double magnitude = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      total += f[i];
      torque += cross(x[i], f[i]);
      magnitude += norm(f[i]);
    }
    ASSERT_GT(magnitude, 1.0);
    EXPECT_LT(norm(total), 1e-12 * magnitude);
    EXPECT_LT(norm(torque), 1e-12 * magnitude);
  }
}

TEST(MembraneElasticity, SameForcesForAnyThreadCount) {
  const Sphere s(3);
  const auto x = randomly_deformed(s.mesh.positions, 0.02, 3);
  for (const auto& law : kLaws) {
    const auto f1 = forces(law, s, x, 1), f2 = forces(law, s, x, 2);
    for (std::size_t i = 0; i < x.size(); ++i) ASSERT_EQ(f1[i], f2[i]);
  }
}

TEST(MembraneElasticity, PrincipalStretchesOfAStretchedTriangle) {
  TriangleMesh tri;
  tri.positions = {{0, 0, 0}, {1, 0, 0}, {0.3, 0.8, 0}};
  tri.triangles = {{0, 1, 2}};
  const auto ref = make_reference(tri).front();
  EXPECT_NEAR(ref.area, 0.4, 1e-15);
  // Stretch by 1.5 along x and 0.8 along y, then rotate out of plane: the
  // stretches do not see the rotation.
  const Quaternion q = normalized(Quaternion::from_axis_angle({1, 1, 0}, 1.1));
  const auto map = [&](const Vec3& p) { return rotate(q, Vec3{1.5 * p.x, 0.8 * p.y, 0.0}); };
  const auto s =
      triangle_strain(ref, map(tri.positions[0]), map(tri.positions[1]), map(tri.positions[2]));
  const auto [l1, l2] = principal_stretches(s);
  EXPECT_NEAR(l1, 0.8, 1e-14);
  EXPECT_NEAR(l2, 1.5, 1e-14);
  TriangleMesh degenerate;
  degenerate.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  degenerate.triangles = {{0, 1, 2}};
  EXPECT_THROW(make_reference(degenerate), std::invalid_argument);
}
