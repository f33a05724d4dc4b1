#include "membrane/elasticity.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "core/parallel.hpp"

namespace sanguis::membrane {

std::vector<ReferenceTriangle> make_reference(const TriangleMesh& stress_free) {
  std::vector<ReferenceTriangle> out(stress_free.triangle_count());
  for (std::size_t t = 0; t < out.size(); ++t) {
    const auto& tri = stress_free.triangles[t];
    const Vec3 x0 = stress_free.positions[tri[0]], x1 = stress_free.positions[tri[1]],
               x2 = stress_free.positions[tri[2]];
    const Vec3 normal = cross(x1 - x0, x2 - x0);
    const double twice_area = norm(normal);
    const double edge = norm(x1 - x0);
    if (!(twice_area > 1e-14 * edge * edge) || !(edge > 0.0))
      throw std::invalid_argument("membrane reference triangle " + std::to_string(t) +
                                  " is degenerate");
    // In-plane orthonormal frame (e1 along edge 0-1) and 2D corner coordinates.
    const Vec3 e1 = (x1 - x0) / edge;
    const Vec3 e2 = cross(normal / twice_area, e1);
    const double a1 = edge, b2x = dot(x2 - x0, e1), b2y = dot(x2 - x0, e2);
    // Linear shape functions on (0,0), (a1,0), (b2x,b2y): N_k(p) = alpha + g_k . p,
    // with g_k = (perpendicular of the opposite edge) / (2 A).
    const double two_a = a1 * b2y;  // twice the area in the plane
    ReferenceTriangle r;
    r.area = 0.5 * two_a;
    r.gradient[1] = {b2y / two_a, -b2x / two_a};
    r.gradient[2] = {0.0, a1 / two_a};
    r.gradient[0] = {-r.gradient[1][0] - r.gradient[2][0], -r.gradient[1][1] - r.gradient[2][1]};
    out[t] = r;
  }
  return out;
}

std::array<double, 2> principal_stretches(const TriangleStrain& s) {
  const double mean = 0.5 * (s.c00 + s.c11);
  const double half_diff = 0.5 * (s.c00 - s.c11);
  const double radius = std::sqrt(half_diff * half_diff + s.c01 * s.c01);
  // The smaller eigenvalue from det / larger avoids cancellation.
  const double larger = mean + radius;
  return {std::sqrt(s.det() / larger), std::sqrt(larger)};
}

namespace {

template <typename Law>
void add_forces_with(const Law& law, std::span<const ReferenceTriangle> reference,
                     const std::vector<Triangle>& triangles, const MeshTopology& topology,
                     std::span<const Vec3> x, std::span<Vec3> forces, int threads,
                     std::vector<std::array<Vec3, 3>>& scratch) {
  const std::size_t nt = triangles.size();
  if (threads <= 1) {
    for (std::size_t t = 0; t < nt; ++t) {
      const auto& tri = triangles[t];
      const auto f = triangle_forces(law, reference[t], x[tri[0]], x[tri[1]], x[tri[2]]);
      forces[tri[0]] += f[0];
      forces[tri[1]] += f[1];
      forces[tri[2]] += f[2];
    }
    return;
  }
  scratch.resize(nt);
  parallel_for(nt, threads, [&](std::size_t t) {
    const auto& tri = triangles[t];
    scratch[t] = triangle_forces(law, reference[t], x[tri[0]], x[tri[1]], x[tri[2]]);
  });
  parallel_for(x.size(), threads, [&](std::size_t i) {
    Vec3 sum = forces[i];
    for (const auto& c : topology.corners(i)) sum += scratch[c.triangle][c.corner];
    forces[i] = sum;
  });
}

}  // namespace

void add_elastic_forces(const ElasticLaw& law, std::span<const ReferenceTriangle> reference,
                        const std::vector<Triangle>& triangles, const MeshTopology& topology,
                        std::span<const Vec3> positions, std::span<Vec3> forces, int threads,
                        std::vector<std::array<Vec3, 3>>& scratch) {
  if (reference.size() != triangles.size() || forces.size() != positions.size() ||
      topology.node_count() != positions.size())
    throw std::invalid_argument("add_elastic_forces: sizes of mesh, reference and forces differ");
  std::visit(
      [&](const auto& l) {
        add_forces_with(l, reference, triangles, topology, positions, forces, threads, scratch);
      },
      law);
}

double elastic_energy(const ElasticLaw& law, std::span<const ReferenceTriangle> reference,
                      const std::vector<Triangle>& triangles, std::span<const Vec3> positions) {
  return std::visit(
      [&](const auto& l) {
        double energy = 0.0;
        for (std::size_t t = 0; t < triangles.size(); ++t) {
          const auto& tri = triangles[t];
          const TriangleStrain s = triangle_strain(reference[t], positions[tri[0]],
                                                   positions[tri[1]], positions[tri[2]]);
          energy += reference[t].area * l.energy(s.trace(), s.det());
        }
        return energy;
      },
      law);
}

PrincipalTensions principal_tensions(const ElasticLaw& law, const ReferenceTriangle& ref,
                                     const Vec3& x0, const Vec3& x1, const Vec3& x2) {
  const TriangleStrain s = triangle_strain(ref, x0, x1, x2);
  const auto d = std::visit([&](const auto& l) { return l.derivatives(s.trace(), s.det()); }, law);
  const auto [l1, l2] = principal_stretches(s);
  PrincipalTensions p;
  p.lambda1 = l1;
  p.lambda2 = l2;
  // eq. 4.5: sigma_i = (1/l_j) dW/dl_i, dW/dl_i = 2 l_i (W_trace + W_det l_j^2).
  p.sigma1 = 2.0 * l1 / l2 * (d.d_trace + d.d_det * l2 * l2);
  p.sigma2 = 2.0 * l2 / l1 * (d.d_trace + d.d_det * l1 * l1);
  return p;
}

std::vector<PrincipalTensions> principal_tensions(const ElasticLaw& law,
                                                  std::span<const ReferenceTriangle> reference,
                                                  const std::vector<Triangle>& triangles,
                                                  std::span<const Vec3> positions) {
  std::vector<PrincipalTensions> out(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    out[t] = principal_tensions(law, reference[t], positions[tri[0]], positions[tri[1]],
                                positions[tri[2]]);
  }
  return out;
}

}  // namespace sanguis::membrane
