#include "membrane/bending.hpp"

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/parallel.hpp"

namespace sanguis::membrane {

namespace {

// A right-handed orthonormal frame (t1, t2, n).
struct LocalFrame {
  Vec3 t1, t2, n;
};

LocalFrame frame_around(const Vec3& n) {
  // Start from the coordinate axis least aligned with n.
  const Vec3 axis = std::fabs(n.x) < std::fabs(n.y)
                        ? (std::fabs(n.x) < std::fabs(n.z) ? Vec3{1, 0, 0} : Vec3{0, 0, 1})
                        : (std::fabs(n.y) < std::fabs(n.z) ? Vec3{0, 1, 0} : Vec3{0, 0, 1});
  const Vec3 c = cross(n, axis);
  const Vec3 t1 = c / norm(c);
  return {t1, cross(n, t1), n};
}

// Least-squares fit of f(u, v) = A u^2 + B u v + C v^2 + D u + E v through the
// origin, by the normal equations (symmetric positive definite: Cholesky) in
// coordinates scaled by the neighbours' RMS distance, which keeps them well
// conditioned. With fewer than five neighbours the linear terms are dropped
// (D = E = 0).
struct QuadraticFit {
  double a = 0.0, b = 0.0, c = 0.0, d = 0.0, e = 0.0;
};

// Largest one-ring handled (fixed-size local buffers, no allocation per node).
constexpr std::size_t kMaxValence = 32;

struct Sample {
  double u = 0.0, v = 0.0, f = 0.0;
};

// Solves M c = r for symmetric positive definite M (lower triangle used) by
// an L D L^T factorisation: one division per column and no square root, the
// latency that dominates these tiny systems.
template <std::size_t N>
bool cholesky_solve(std::array<std::array<double, N>, N>& m, std::array<double, N>& r) {
  std::array<double, N> inv_d{};
  for (std::size_t j = 0; j < N; ++j) {
    double d = m[j][j];
    for (std::size_t k = 0; k < j; ++k) d -= m[j][k] * m[j][k] * m[k][k];
    if (!(d > 0.0)) return false;
    m[j][j] = d;
    inv_d[j] = 1.0 / d;
    for (std::size_t i = j + 1; i < N; ++i) {
      double s = m[i][j];
      for (std::size_t k = 0; k < j; ++k) s -= m[i][k] * m[j][k] * m[k][k];
      m[i][j] = s * inv_d[j];
    }
  }
  for (std::size_t i = 0; i < N; ++i)  // L y = r
    for (std::size_t k = 0; k < i; ++k) r[i] -= m[i][k] * r[k];
  for (std::size_t i = 0; i < N; ++i) r[i] *= inv_d[i];  // D z = y
  for (std::size_t i = N; i-- > 0;)                      // L^T c = z
    for (std::size_t k = i + 1; k < N; ++k) r[i] -= m[k][i] * r[k];
  return true;
}

// The normal matrix of the rows (u^2, u v, v^2, u, v) holds only the twelve
// moments sum u^i v^j with 2 <= i + j <= 4: accumulate those, then fill it.
template <std::size_t N>
std::array<double, N> least_squares(const Sample* samples, std::size_t count, double s,
                                    double value_scale) {
  double u4 = 0, u3v = 0, u2v2 = 0, uv3 = 0, v4 = 0, u3 = 0, u2v = 0, uv2 = 0, v3 = 0, u2 = 0,
         uv = 0, v2 = 0;
  double fu2 = 0, fuv = 0, fv2 = 0, fu = 0, fv = 0;
  for (std::size_t k = 0; k < count; ++k) {
    const double u = samples[k].u * s, v = samples[k].v * s, f = samples[k].f * value_scale;
    const double uu = u * u, uvk = u * v, vv = v * v;
    u4 += uu * uu;
    u3v += uu * uvk;
    u2v2 += uu * vv;
    uv3 += uvk * vv;
    v4 += vv * vv;
    u3 += uu * u;
    u2v += uu * v;
    uv2 += u * vv;
    v3 += vv * v;
    u2 += uu;
    uv += uvk;
    v2 += vv;
    fu2 += uu * f;
    fuv += uvk * f;
    fv2 += vv * f;
    fu += u * f;
    fv += v * f;
  }
  std::array<std::array<double, N>, N> m{};
  std::array<double, N> r{};
  // Lower triangle only (cholesky_solve reads no more).
  m[0][0] = u4;
  m[1][0] = u3v;
  m[1][1] = u2v2;
  m[2][0] = u2v2;
  m[2][1] = uv3;
  m[2][2] = v4;
  r[0] = fu2;
  r[1] = fuv;
  r[2] = fv2;
  if constexpr (N == 5) {
    m[3][0] = u3;
    m[3][1] = u2v;
    m[3][2] = uv2;
    m[3][3] = u2;
    m[4][0] = u2v;
    m[4][1] = uv2;
    m[4][2] = v3;
    m[4][3] = uv;
    m[4][4] = v2;
    r[3] = fu;
    r[4] = fv;
  }
  if (!cholesky_solve<N>(m, r)) throw std::runtime_error("paraboloid fit: singular one-ring");
  return r;
}

// `value_length_power`: 1 when the values are lengths (heights), 0 otherwise.
QuadraticFit fit_quadratic(const Sample* samples, std::size_t count, int value_length_power) {
  double h2 = 0.0;
  for (std::size_t k = 0; k < count; ++k)
    h2 += samples[k].u * samples[k].u + samples[k].v * samples[k].v;
  const double s = std::sqrt(static_cast<double>(count) / h2);  // 1 / RMS distance
  const double value_scale = value_length_power == 1 ? s : 1.0;
  QuadraticFit q;
  if (count >= 5) {
    const auto c = least_squares<5>(samples, count, s, value_scale);
    q = {c[0], c[1], c[2], c[3], c[4]};
  } else {
    const auto c = least_squares<3>(samples, count, s, value_scale);
    q = {c[0], c[1], c[2], 0.0, 0.0};
  }
  // Back to unscaled coordinates: f = (1/value_scale) (A^ s^2 u^2 + ... + D^ s u + ...).
  const double k2 = s * s / value_scale, k1 = s / value_scale;
  return {q.a * k2, q.b * k2, q.c * k2, q.d * k1, q.e * k1};
}

// Initial normal: the area-weighted mean of the incident triangle normals.
Vec3 area_weighted_normal(std::size_t i, const MeshTopology& topology,
                          std::span<const SurfaceGeometry::TriangleShare> share) {
  Vec3 n;
  for (const auto& c : topology.corners(i)) n += share[c.triangle].twice_area_normal;
  return n / norm(n);
}

struct NodeCurvature {
  LocalFrame frame;  // final frame (normal = corrected normal of the last fit)
  QuadraticFit height;
  double kappa = 0.0, kappa_g = 0.0;
};

NodeCurvature fit_curvature(std::size_t i, const MeshTopology& topology, std::span<const Vec3> x,
                            std::span<const SurfaceGeometry::TriangleShare> share,
                            int normal_iterations) {
  const auto ring = topology.ring(i);
  const Vec3 xi = x[i];
  std::array<Vec3, kMaxValence> offset;
  for (std::size_t k = 0; k < ring.size(); ++k) offset[k] = x[ring[k]] - xi;
  std::array<Sample, kMaxValence> samples;
  NodeCurvature r;
  Vec3 n = area_weighted_normal(i, topology, share);
  for (int iteration = 0;; ++iteration) {
    r.frame = frame_around(n);
    for (std::size_t k = 0; k < ring.size(); ++k)
      samples[k] = {dot(offset[k], r.frame.t1), dot(offset[k], r.frame.t2),
                    dot(offset[k], r.frame.n)};
    r.height = fit_quadratic(samples.data(), ring.size(), 1);
    // Normal of the fitted surface at the node: (-D, -E, 1) in the frame.
    const Vec3 corrected = r.frame.n - r.height.d * r.frame.t1 - r.height.e * r.frame.t2;
    n = corrected / norm(corrected);
    if (iteration >= normal_iterations) break;
  }
  const auto& h = r.height;
  const double w2 = 1.0 + h.d * h.d + h.e * h.e;
  const double w = std::sqrt(w2);
  // Monge patch: h_uu = 2A, h_uv = B, h_vv = 2C; minus sign: kappa > 0 on a sphere.
  r.kappa =
      -((1.0 + h.e * h.e) * 2.0 * h.a - 2.0 * h.d * h.e * h.b + (1.0 + h.d * h.d) * 2.0 * h.c) /
      (2.0 * w2 * w);
  r.kappa_g = (4.0 * h.a * h.c - h.b * h.b) / (w2 * w2);
  return r;
}

// Surface Laplacian at the node of the function sampled on the one-ring, in
// the Monge patch of the height fit (formula in bending.hpp).
double fit_laplace_beltrami(std::size_t i, const MeshTopology& topology, std::span<const Vec3> x,
                            const NodeCurvature& c, std::span<const double> values) {
  const auto ring = topology.ring(i);
  const Vec3 xi = x[i];
  std::array<Sample, kMaxValence> samples;
  for (std::size_t k = 0; k < ring.size(); ++k) {
    const Vec3 d = x[ring[k]] - xi;
    samples[k] = {dot(d, c.frame.t1), dot(d, c.frame.t2), values[ring[k]] - values[i]};
  }
  const QuadraticFit f = fit_quadratic(samples.data(), ring.size(), 0);
  const auto& h = c.height;
  const double w2 = 1.0 + h.d * h.d + h.e * h.e;
  // Inverse metric g^ab = delta_ab - h_a h_b / W^2.
  const double g00 = 1.0 - h.d * h.d / w2, g01 = -h.d * h.e / w2, g11 = 1.0 - h.e * h.e / w2;
  const double f_uu = 2.0 * f.a, f_uv = f.b, f_vv = 2.0 * f.c;
  const double h_uu = 2.0 * h.a, h_uv = h.b, h_vv = 2.0 * h.c;
  const double grad_dot = (h.d * f.d + h.e * f.e) / w2;
  return g00 * (f_uu - h_uu * grad_dot) + 2.0 * g01 * (f_uv - h_uv * grad_dot) +
         g11 * (f_vv - h_vv * grad_dot);
}

// Mixed Voronoi share (Meyer et al. 2003) of corner p of triangle (p, q, r).
double corner_mixed_area(const Vec3& p, const Vec3& q, const Vec3& r) {
  const double twice = norm(cross(q - p, r - p));
  const double dot_p = dot(q - p, r - p), dot_q = dot(p - q, r - q), dot_r = dot(p - r, q - r);
  if (dot_p < 0.0) return 0.25 * twice;                  // obtuse at p: A/2
  if (dot_q < 0.0 || dot_r < 0.0) return 0.125 * twice;  // obtuse elsewhere: A/4
  // Voronoi share: (|pr|^2 cot q + |pq|^2 cot r) / 8, cot = dot / |cross|.
  return (norm2(r - p) * dot_q + norm2(q - p) * dot_r) / (8.0 * twice);
}

SurfaceGeometry::TriangleShare triangle_share(const Triangle& t, std::span<const Vec3> x) {
  const Vec3 a = x[t[0]], b = x[t[1]], c = x[t[2]];
  return {cross(b - a, c - a),
          {corner_mixed_area(a, b, c), corner_mixed_area(b, c, a), corner_mixed_area(c, a, b)}};
}

}  // namespace

void validate(const HelfrichParameters& p) {
  if (!(p.bending_modulus >= 0.0))
    throw std::invalid_argument("bending modulus Eb must be >= 0, got " +
                                std::to_string(p.bending_modulus));
  if (!std::isfinite(p.reference_curvature))
    throw std::invalid_argument("reference curvature must be finite");
  if (p.normal_iterations < 0 || p.normal_iterations > 20)
    throw std::invalid_argument("normal iterations must be in [0, 20], got " +
                                std::to_string(p.normal_iterations));
}

std::vector<double> mixed_voronoi_areas(const std::vector<Triangle>& triangles,
                                        const MeshTopology& topology,
                                        std::span<const Vec3> positions) {
  std::vector<SurfaceGeometry::TriangleShare> share(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t)
    share[t] = triangle_share(triangles[t], positions);
  std::vector<double> a(positions.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    for (const auto& c : topology.corners(i)) a[i] += share[c.triangle].corner_area[c.corner];
  return a;
}

void compute_surface_geometry(const std::vector<Triangle>& triangles, const MeshTopology& topology,
                              std::span<const Vec3> positions, int normal_iterations,
                              SurfaceGeometry& g, int threads) {
  const std::size_t n = positions.size();
  if (topology.node_count() != n)
    throw std::invalid_argument("compute_surface_geometry: topology and positions differ in size");
  if (topology.max_valence() > kMaxValence)
    throw std::invalid_argument("compute_surface_geometry: a node has " +
                                std::to_string(topology.max_valence()) + " neighbours (at most " +
                                std::to_string(kMaxValence) + ")");
  g.normal.resize(n);
  g.mean_curvature.resize(n);
  g.gaussian_curvature.resize(n);
  g.laplace_beltrami.resize(n);
  g.area.resize(n);
  g.fit.resize(n);
  g.triangle_share.resize(triangles.size());
  // Pass 0: per-triangle normals and corner areas, gathered below in corner order.
  parallel_for(triangles.size(), threads, [&](std::size_t t) {
    g.triangle_share[t] = triangle_share(triangles[t], positions);
  });
  // Pass 1: fits of the height (kappa needed at all neighbours before pass 2).
  parallel_for(n, threads, [&](std::size_t i) {
    const NodeCurvature c =
        fit_curvature(i, topology, positions, g.triangle_share, normal_iterations);
    const Vec3 corrected = c.frame.n - c.height.d * c.frame.t1 - c.height.e * c.frame.t2;
    g.normal[i] = corrected / norm(corrected);
    g.mean_curvature[i] = c.kappa;
    g.gaussian_curvature[i] = c.kappa_g;
    double area = 0.0;
    for (const auto& corner : topology.corners(i))
      area += g.triangle_share[corner.triangle].corner_area[corner.corner];
    g.area[i] = area;
    g.fit[i] = {c.frame.t1, c.frame.t2, c.frame.n,  c.height.a,
                c.height.b, c.height.c, c.height.d, c.height.e};
  });
  // Pass 2: second fit, on the curvature values, in the frame of the last
  // height fit.
  parallel_for(n, threads, [&](std::size_t i) {
    const ParaboloidFit& f = g.fit[i];
    NodeCurvature c;
    c.frame = {f.t1, f.t2, f.n};
    c.height = {f.a, f.b, f.c, f.d, f.e};
    g.laplace_beltrami[i] = fit_laplace_beltrami(i, topology, positions, c, g.mean_curvature);
  });
}

void add_bending_forces(const HelfrichParameters& p, const std::vector<Triangle>& triangles,
                        const MeshTopology& topology, std::span<const Vec3> positions,
                        std::span<Vec3> forces, SurfaceGeometry& g, int threads) {
  compute_surface_geometry(triangles, topology, positions, p.normal_iterations, g, threads);
  parallel_for(positions.size(), threads, [&](std::size_t i) {
    const double f = helfrich_force_density(p, g.mean_curvature[i], g.gaussian_curvature[i],
                                            g.laplace_beltrami[i]);
    forces[i] += (f * g.area[i]) * g.normal[i];
  });
}

}  // namespace sanguis::membrane
