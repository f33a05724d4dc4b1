#include "membrane/biconcave_profile.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace sanguis::membrane {

namespace {

struct Meridian {
  double r, dr, ddr, z, dz, ddz;
};

Meridian meridian(const BiconcaveShape& s, double phi) {
  const double c = std::cos(phi), sn = std::sin(phi), y = c * c;
  const double p = s.alpha1 + s.alpha2 * y + s.alpha3 * y * y;
  const double dp_dy = s.alpha2 + 2.0 * s.alpha3 * y;
  const double d2p_dy2 = 2.0 * s.alpha3;
  // y = cos^2 phi: y' = -2 c s, y'' = -2 cos(2 phi).
  const double dy = -2.0 * c * sn, ddy = -2.0 * std::cos(2.0 * phi);
  const double q = p, dq = dp_dy * dy, ddq = d2p_dy2 * dy * dy + dp_dy * ddy;
  const double half = 0.5 * s.radius;
  return {s.radius * c,  -s.radius * sn,           -s.radius * c,
          half * sn * q, half * (c * q + sn * dq), half * (-sn * q + 2.0 * c * dq + sn * ddq)};
}

double mean_curvature_at(const BiconcaveShape& s, double phi) {
  const Meridian m = meridian(s, phi);
  const double l = std::sqrt(m.dr * m.dr + m.dz * m.dz);
  const double k_m = (m.dr * m.ddz - m.ddr * m.dz) / (l * l * l);
  const double k_p = m.dz / (m.r * l);
  return 0.5 * (k_m + k_p);
}

}  // namespace

AxisymmetricCurvatures biconcave_curvatures(const BiconcaveShape& s, double phi) {
  constexpr double kAxisGap = 1e-3, kStep = 1e-4;
  phi = std::min(std::fabs(phi), 0.5 * std::numbers::pi - kAxisGap);
  const Meridian m = meridian(s, phi);
  const double l = std::sqrt(m.dr * m.dr + m.dz * m.dz);
  const double k_m = (m.dr * m.ddz - m.ddr * m.dz) / (l * l * l);
  const double k_p = m.dz / (m.r * l);
  // (r/L) dkappa/dphi at phi +- h, each by a central difference.
  const auto flux = [&](double p) {
    const Meridian mp = meridian(s, p);
    const double lp = std::sqrt(mp.dr * mp.dr + mp.dz * mp.dz);
    const double dk =
        (mean_curvature_at(s, p + kStep) - mean_curvature_at(s, p - kStep)) / (2 * kStep);
    return mp.r / lp * dk;
  };
  const double laplacian = (flux(phi + kStep) - flux(phi - kStep)) / (2.0 * kStep) / (m.r * l);
  return {0.5 * (k_m + k_p), k_m * k_p, laplacian};
}

double biconcave_latitude(const BiconcaveShape& s, const Vec3& x) {
  const double c = std::min(std::sqrt(x.x * x.x + x.y * x.y) / s.radius, 1.0);
  const double y = c * c;
  const double p = s.alpha1 + s.alpha2 * y + s.alpha3 * y * y;
  return std::atan2(2.0 * x.z / (s.radius * p), c);
}

double polar_angle(const Vec3& x) {
  return std::atan2(std::sqrt(x.x * x.x + x.y * x.y), std::fabs(x.z));
}

}  // namespace sanguis::membrane
