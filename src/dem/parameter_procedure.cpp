#include "dem/parameter_procedure.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace sanguis::dem {

namespace {

constexpr double kPi = std::numbers::pi;
// Below this distance from critical damping the critical closed form is used
// (the under/overdamped forms lose precision there).
constexpr double kCriticalBand = 1e-6;

void require_in(const char* what, double v, double lo, double hi, bool lo_open) {
  const bool ok = std::isfinite(v) && (lo_open ? v > lo : v >= lo) && v <= hi;
  if (!ok) {
    throw std::invalid_argument(std::string(what) + " must be in " + (lo_open ? "(" : "[") +
                                std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                                std::to_string(v));
  }
}

void require_positive(const char* what, double v) {
  if (!(std::isfinite(v) && v > 0.0)) {
    throw std::invalid_argument(std::string(what) + " must be > 0, got " + std::to_string(v));
  }
}

// Overdamped roots lambda_{1,2} = -d -+ sqrt(d^2 - 1), in units of omega_0.
struct OverdampedRoots {
  double s, l1, l2;
};
OverdampedRoots overdamped_roots(double d) {
  const double s = std::sqrt(d * d - 1.0);
  // -d + s computed without cancellation: (s - d) = -1 / (d + s).
  return {s, -1.0 / (d + s), -d - s};
}

}  // namespace

NormalDampingModel parse_normal_damping_model(const std::string& name) {
  if (name == "thesis") return NormalDampingModel::kThesis;
  if (name == "exact_restitution") return NormalDampingModel::kExactRestitution;
  throw std::invalid_argument(
      "normal damping model must be 'thesis' or 'exact_restitution', got '" + name + "'");
}

const char* to_string(NormalDampingModel model) {
  return model == NormalDampingModel::kThesis ? "thesis" : "exact_restitution";
}

double clamped_restitution(double d) {
  if (d <= 0.0) return 1.0;
  if (std::abs(d - 1.0) < kCriticalBand) return std::exp(-2.0);  // critical: t* = 2/omega_0
  if (d < 1.0) {
    // Underdamped: the clamped force vanishes at omega t* = pi - 2 atan(r), r = gamma/omega,
    // where the overlap rate is exactly -v0 exp(-r omega t*).
    const double r = d / std::sqrt(1.0 - d * d);
    return std::exp(-r * (kPi - 2.0 * std::atan(r)));
  }
  // Overdamped: force zero when exp(2 s t) = (l2/l1)^2, rebound speed exp(l1 t*) l1/l2.
  const auto [s, l1, l2] = overdamped_roots(d);
  const double t_star = std::log(l2 / l1) / s;
  return std::exp(l1 * t_star) * l1 / l2;
}

double damping_ratio_for_clamped_restitution(double restitution) {
  require_in("normal restitution en", restitution, 0.0, 1.0, true);
  if (restitution == 1.0) return 0.0;
  // clamped_restitution decreases monotonically from 1 (d = 0) to 0 (d -> inf).
  double lo = 0.0, hi = 1.0;
  while (clamped_restitution(hi) > restitution) hi *= 2.0;
  for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (clamped_restitution(mid) > restitution ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double scaled_max_overlap(double d) {
  if (d <= 0.0) return 1.0;
  if (std::abs(d - 1.0) < kCriticalBand) return std::exp(-1.0);
  if (d < 1.0) {
    // eq. 2.18-2.20: omega T_max = atan(zeta), zeta = omega / gamma_n.
    const double w = std::sqrt(1.0 - d * d);
    const double zeta = w / d;
    const double phase = std::atan(zeta);
    return std::exp(-phase / zeta) * std::sin(phase) / w;
  }
  const auto [s, l1, l2] = overdamped_roots(d);
  const double t_max = std::log(l2 / l1) / (2.0 * s);
  return (std::exp(l1 * t_max) - std::exp(l2 * t_max)) / (2.0 * s);
}

double scaled_clamped_duration(double d) {
  if (d <= 0.0) return kPi;
  if (std::abs(d - 1.0) < kCriticalBand) {
    // delta = t e^{-t}; force zero at t = 2, then free flight of delta(2) / e^{-2} = 2.
    return 4.0;
  }
  if (d < 1.0) {
    const double w = std::sqrt(1.0 - d * d);
    const double r = d / w;
    const double phase = kPi - 2.0 * std::atan(r);  // omega t*
    // free flight from overlap (v0/omega) e^{-r phase} sin(phase) at speed v0 e^{-r phase}
    return (phase + std::sin(phase)) / w;
  }
  const auto [s, l1, l2] = overdamped_roots(d);
  const double t_star = std::log(l2 / l1) / s;
  const double overlap = (std::exp(l1 * t_star) - std::exp(l2 * t_star)) / (2.0 * s);
  return t_star + overlap / clamped_restitution(d);
}

ProcedureResult derive_contact_parameters(const ProcedureInput& in) {
  require_positive("reduced mass", in.reduced_mass);
  require_positive("reduced radius", in.reduced_radius);
  require_positive("maximum overlap", in.max_overlap);
  require_positive("maximum impact velocity", in.max_impact_velocity);
  require_in("normal restitution en", in.normal_restitution, 0.0, 1.0, true);
  require_in("tangential restitution et", in.tangential_restitution, 0.0, 1.0, true);
  if (!(in.inertia_factor >= 0.0)) throw std::invalid_argument("inertia factor must be >= 0");
  if (!(in.friction >= 0.0)) throw std::invalid_argument("friction must be >= 0");
  if (!(in.rolling_friction >= 0.0)) throw std::invalid_argument("rolling friction must be >= 0");

  const double m = in.reduced_mass;
  const double log_en = std::log(in.normal_restitution);
  const double log_et = std::log(in.tangential_restitution);

  // Step 1-2 (eq. 2.20-2.21): the damping ratio d = gamma_n/omega_0 follows from en alone,
  // then omega_0 from delta_max = (v_max/omega_0) * scaled_max_overlap(d).
  const double d = in.damping_model == NormalDampingModel::kThesis
                       ? -log_en / std::sqrt(kPi * kPi + log_en * log_en)
                       : damping_ratio_for_clamped_restitution(in.normal_restitution);
  const double omega0 = in.max_impact_velocity * scaled_max_overlap(d) / in.max_overlap;

  ProcedureResult out;
  ContactParameters& p = out.parameters;
  p.normal_stiffness = m * omega0 * omega0;  // omega_0^2 = kn / m_ij
  p.normal_damping = 2.0 * m * d * omega0;   // eq. 2.22 (gamma_n = eta_n / 2 m_ij)

  // Step 4 (eq. 2.23-2.24, Pournin).
  const double inertia = 1.0 + in.inertia_factor;
  p.tangential_stiffness =
      p.normal_stiffness / inertia * (kPi * kPi + log_et * log_et) / (kPi * kPi + log_en * log_en);
  if (in.normal_restitution < 1.0) {
    p.tangential_damping = p.normal_damping / inertia * log_et / log_en;
  } else {
    // en = 1: eta_n = 0 and ln(en) = 0; eq. 2.24 reduces to its limit with eq. 2.22.
    p.tangential_damping = 2.0 * m * omega0 * (-log_et) / kPi / inertia;
  }
  p.friction = in.friction;

  // eq. 2.28 (Jiang et al.) with R = R_ij, consistent with M_max = mu_r R_ij |Fn| (eq. 2.13).
  const double r2 = in.reduced_radius * in.reduced_radius;
  p.rolling_friction = in.rolling_friction;
  p.rolling_stiffness = 3.0 * p.normal_stiffness * in.rolling_friction * in.rolling_friction * r2;
  p.rolling_damping = 3.0 * p.normal_damping * in.rolling_friction * in.rolling_friction * r2;

  out.damping_ratio = d;
  out.contact_time = d < 1.0 ? kPi / (omega0 * std::sqrt(1.0 - d * d))  // eq. 2.17
                             : std::numeric_limits<double>::infinity();
  out.clamped_contact_duration = scaled_clamped_duration(d) / omega0;
  out.effective_restitution = clamped_restitution(d);
  out.tangential_damping_rate = p.tangential_damping / (2.0 * m);
  // 20 steps per contact (Kruggel-Emden); the clamped duration when overdamped (no Tc).
  out.recommended_time_step = (d < 1.0 ? out.contact_time : out.clamped_contact_duration) / 20.0;
  return out;
}

}  // namespace sanguis::dem
