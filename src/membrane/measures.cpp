#include "membrane/measures.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "geometry/mass_properties.hpp"

namespace sanguis::membrane {

double surface_area(const std::vector<Triangle>& triangles, std::span<const Vec3> x) {
  double a = 0.0;
  for (const auto& t : triangles) a += 0.5 * norm(cross(x[t[1]] - x[t[0]], x[t[2]] - x[t[0]]));
  return a;
}

double enclosed_volume(const std::vector<Triangle>& triangles, std::span<const Vec3> x) {
  double v = 0.0;
  for (const auto& t : triangles) v += dot(x[t[0]], cross(x[t[1]], x[t[2]])) / 6.0;
  return v;
}

InertiaEllipsoid inertia_ellipsoid(const std::vector<Triangle>& triangles,
                                   std::span<const Vec3> x) {
  // Moments relative to a point near the surface's centre keep the
  // tetrahedra small for a capsule far from the origin.
  Vec3 origin;
  for (const auto& p : x) origin += p;
  origin = origin / static_cast<double>(x.size());
  double volume = 0.0;
  Vec3 first;
  Mat3 second;
  for (const auto& t : triangles) {
    const Vec3 a = x[t[0]] - origin, b = x[t[1]] - origin, c = x[t[2]] - origin;
    const double v = dot(a, cross(b, c)) / 6.0;
    const Vec3 s = a + b + c;
    volume += v;
    first += (v / 4.0) * s;
    // Tetrahedron (0, a, b, c): integral of x x^T = V/20 (a a^T + b b^T + c c^T + s s^T).
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        second(i, j) += v / 20.0 * (a[i] * a[j] + b[i] * b[j] + c[i] * c[j] + s[i] * s[j]);
  }
  if (!(volume > 0.0))
    throw std::invalid_argument("membrane encloses a non-positive volume (" +
                                std::to_string(volume) + "): inverted or open surface");
  const geometry::MassProperties mp = geometry::from_moments(volume, first, second);
  InertiaEllipsoid e;
  e.volume = volume;
  e.centroid = mp.centroid + origin;
  e.inertia = mp.inertia_about_centroid;
  const auto& m = mp.principal_moments;
  const std::array<double, 3> moments{m.x, m.y, m.z};
  std::array<std::pair<double, Vec3>, 3> axes;
  const Vec3 unit_axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int k = 0; k < 3; ++k) {
    const double a2 = 2.5 * (moments[(k + 1) % 3] + moments[(k + 2) % 3] - moments[k]) / volume;
    axes[k] = {std::sqrt(std::max(a2, 0.0)), rotate(mp.principal_axes, unit_axes[k])};
  }
  std::sort(axes.begin(), axes.end(),
            [](const auto& l, const auto& r) { return l.first < r.first; });
  for (int k = 0; k < 3; ++k) {
    e.semi_axes[k] = axes[k].first;
    e.axes[k] = axes[k].second;
  }
  return e;
}

double taylor_deformation(const InertiaEllipsoid& e) {
  return (e.semi_axes[2] - e.semi_axes[0]) / (e.semi_axes[2] + e.semi_axes[0]);
}

double taylor_deformation_from_radii(std::span<const Vec3> x, const Vec3& centre) {
  double r_min = INFINITY, r_max = 0.0;
  for (const auto& p : x) {
    const double r = norm(p - centre);
    r_min = std::min(r_min, r);
    r_max = std::max(r_max, r);
  }
  return (r_max - r_min) / (r_max + r_min);
}

TensionStatistics largest_tension_statistics(const ElasticLaw& law,
                                             std::span<const ReferenceTriangle> reference,
                                             const std::vector<Triangle>& triangles,
                                             std::span<const Vec3> x) {
  TensionStatistics s;
  s.max_largest = -INFINITY;
  double weighted = 0.0, area = 0.0;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    const double sigma =
        principal_tensions(law, reference[t], x[tri[0]], x[tri[1]], x[tri[2]]).largest();
    const double a = 0.5 * norm(cross(x[tri[1]] - x[tri[0]], x[tri[2]] - x[tri[0]]));
    s.max_largest = std::max(s.max_largest, sigma);
    weighted += a * sigma;
    area += a;
  }
  s.mean_largest = weighted / area;
  return s;
}

}  // namespace sanguis::membrane
