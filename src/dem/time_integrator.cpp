#include "dem/time_integrator.hpp"

#include <stdexcept>

namespace sanguis::dem {

IntegratorKind parse_integrator(const std::string& name) {
  if (name == "euler") return IntegratorKind::kForwardEuler;
  if (name == "leapfrog") return IntegratorKind::kLeapfrog;
  if (name == "adams_bashforth_2") return IntegratorKind::kAdamsBashforth2;
  if (name == "adams_bashforth_3") return IntegratorKind::kAdamsBashforth3;
  throw std::invalid_argument("unknown integrator '" + name +
                              "' (euler, leapfrog, adams_bashforth_2, adams_bashforth_3)");
}

const char* to_string(IntegratorKind kind) {
  switch (kind) {
    case IntegratorKind::kForwardEuler:
      return "euler";
    case IntegratorKind::kLeapfrog:
      return "leapfrog";
    case IntegratorKind::kAdamsBashforth2:
      return "adams_bashforth_2";
    case IntegratorKind::kAdamsBashforth3:
      return "adams_bashforth_3";
  }
  return "?";
}

int order_of(IntegratorKind kind) {
  switch (kind) {
    case IntegratorKind::kForwardEuler:
      return 1;
    case IntegratorKind::kLeapfrog:
      return 2;
    case IntegratorKind::kAdamsBashforth2:
      return 2;
    case IntegratorKind::kAdamsBashforth3:
      return 3;
  }
  return 0;
}

namespace {

// One Adams-Bashforth update y += dt * sum_k c_k r_{n-k}, of the order the stored
// history allows (1 = Euler, 2, 3).
inline Vec3 ab_increment(int order, double dt, const Vec3& r0, const Vec3& r1, const Vec3& r2) {
  switch (order) {
    case 3:
      return (dt / 12.0) * (23.0 * r0 - 16.0 * r1 + 5.0 * r2);
    case 2:
      return (dt / 2.0) * (3.0 * r0 - r1);
    default:
      return dt * r0;
  }
}

void resize_history(MultistepHistory& h, std::size_t n) {
  for (int k = 0; k < 2; ++k) {
    h.velocity[k].resize(n);
    h.acceleration[k].resize(n);
    h.angular_velocity[k].resize(n);
    h.angular_acceleration[k].resize(n);
  }
}

}  // namespace

void TimeIntegrator::advance(ParticleStore& p, const Vec3& gravity, double dt) {
  const std::size_t n = p.size();
  Vec3* x = p.position.data();
  Vec3* v = p.velocity.data();
  Vec3* w = p.angular_velocity.data();
  const Vec3* f = p.force.data();
  const Vec3* t = p.torque.data();
  const double* inv_m = p.inverse_mass.data();
  const double* inv_i = p.inverse_inertia.data();

  switch (kind_) {
    case IntegratorKind::kForwardEuler:  // eq. 2.30
      for (std::size_t i = 0; i < n; ++i) {
        x[i] += dt * v[i];
        v[i] += dt * (inv_m[i] * f[i] + gravity);
        w[i] += (dt * inv_i[i]) * t[i];
      }
      break;
    case IntegratorKind::kLeapfrog: {  // eq. 2.31, kick-drift half
      half_velocity_.resize(n);
      half_angular_velocity_.resize(n);
      for (std::size_t i = 0; i < n; ++i) {
        const Vec3 kick = (0.5 * dt) * (inv_m[i] * f[i] + gravity);
        const Vec3 spin = (0.5 * dt * inv_i[i]) * t[i];
        half_velocity_[i] = v[i] + kick;
        half_angular_velocity_[i] = w[i] + spin;
        x[i] += dt * half_velocity_[i];
        // The forces at x_{n+1} see the predicted v_{n+1} = v_n + dt a_n rather than
        // v_{n+1/2}: with velocity-dependent (damping) forces this keeps the scheme
        // second order (the half-step velocity makes it first order, see Fig. 2.5 report).
        v[i] = half_velocity_[i] + kick;
        w[i] = half_angular_velocity_[i] + spin;
      }
      break;
    }
    case IntegratorKind::kAdamsBashforth2:
    case IntegratorKind::kAdamsBashforth3: {  // eq. 2.32 and its third-order sibling
      MultistepHistory& h = history_;
      if (h.velocity[0].size() != n) {
        resize_history(h, n);
        h.depth = 0;
      }
      const int max_order = kind_ == IntegratorKind::kAdamsBashforth2 ? 2 : 3;
      const int order = std::min(max_order, h.depth + 1);
      for (std::size_t i = 0; i < n; ++i) {
        const Vec3 a = inv_m[i] * f[i] + gravity;
        const Vec3 alpha = inv_i[i] * t[i];
        const Vec3 v_now = v[i];
        const Vec3 w_now = w[i];
        x[i] += ab_increment(order, dt, v_now, h.velocity[0][i], h.velocity[1][i]);
        v[i] += ab_increment(order, dt, a, h.acceleration[0][i], h.acceleration[1][i]);
        w[i] += ab_increment(order, dt, alpha, h.angular_acceleration[0][i],
                             h.angular_acceleration[1][i]);
        h.velocity[1][i] = h.velocity[0][i];
        h.acceleration[1][i] = h.acceleration[0][i];
        h.angular_velocity[1][i] = h.angular_velocity[0][i];
        h.angular_acceleration[1][i] = h.angular_acceleration[0][i];
        h.velocity[0][i] = v_now;
        h.acceleration[0][i] = a;
        h.angular_velocity[0][i] = w_now;
        h.angular_acceleration[0][i] = alpha;
      }
      h.depth = std::min(h.depth + 1, 2);
      break;
    }
  }
}

void TimeIntegrator::finish(ParticleStore& p, const Vec3& gravity, double dt) {
  if (kind_ != IntegratorKind::kLeapfrog) return;
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i) {  // final half kick with a_{n+1}
    p.velocity[i] = half_velocity_[i] + (0.5 * dt) * (p.inverse_mass[i] * p.force[i] + gravity);
    p.angular_velocity[i] =
        half_angular_velocity_[i] + (0.5 * dt * p.inverse_inertia[i]) * p.torque[i];
  }
}

}  // namespace sanguis::dem
