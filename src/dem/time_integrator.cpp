#include "dem/time_integrator.hpp"

#include "core/parallel.hpp"

#include <algorithm>
#include <stdexcept>
#include <type_traits>

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

// Component-wise product (diagonal inertia tensors in the body frame).
constexpr Vec3 scale(const Vec3& a, const Vec3& b) {
  return {a.x * b.x, a.y * b.y, a.z * b.z};
}

// dq/dt = 1/2 (0, omega) q with omega in the space frame, one explicit step, renormalised.
inline Quaternion advance_orientation(const Quaternion& q, const Vec3& omega, double dt) {
  const Quaternion dq = Quaternion{0.0, omega.x, omega.y, omega.z} * q;
  const double h = 0.5 * dt;
  return normalized({q.w + h * dq.w, q.x + h * dq.x, q.y + h * dq.y, q.z + h * dq.z});
}

// Thesis §2.5.2, first order: eq. 2.34 in the body frame, then the orientation with the
// new angular velocity.
inline void rotate_first_order(Quaternion& q, Vec3& omega, const Vec3& torque, const Vec3& inertia,
                               const Vec3& inverse_inertia, double dt) {
  const Vec3 wb = rotate_inverse(q, omega);
  const Vec3 tb = rotate_inverse(q, torque);
  const Vec3 alpha = scale(inverse_inertia, tb - cross(wb, scale(inertia, wb)));  // eq. 2.34
  omega = rotate(q, wb + dt * alpha);
  q = advance_orientation(q, omega, dt);
}

// Rotation of a free rigid body about its principal axis k for time h: the body turns by
// phi = h L_k / J_k, and the body components of the (space-fixed) angular momentum turn
// the other way. The angle is taken through the Cayley map, tan(phi'/2) = phi/2
// (phi' = phi - phi^3/12 + ...): exactly orthogonal, so |L| is kept to round-off, and
// its O(h^3) error per substep keeps the splitting second order, without a sin/cos.
inline void free_rotation_about_axis(Quaternion& q, Vec3& body_momentum, int k, double h,
                                     const Vec3& inverse_inertia) {
  const double half_tan = 0.5 * h * body_momentum[k] * inverse_inertia[k];
  const double scale = 1.0 / std::sqrt(1.0 + half_tan * half_tan);
  Quaternion r{scale, 0.0, 0.0, 0.0};
  (k == 0 ? r.x : (k == 1 ? r.y : r.z)) = half_tan * scale;
  q = q * r;
  body_momentum = rotate_inverse(r, body_momentum);
}

// Symmetric splitting of the free rotor (Dullweber, Leimkuhler & McLachlan, J. Chem. Phys.
// 107, 5840, 1997): x(h/2) y(h/2) z(h) y(h/2) x(h/2). Second order, keeps |L| exactly.
inline void free_rotation(Quaternion& q, Vec3& body_momentum, double h,
                          const Vec3& inverse_inertia) {
  free_rotation_about_axis(q, body_momentum, 0, 0.5 * h, inverse_inertia);
  free_rotation_about_axis(q, body_momentum, 1, 0.5 * h, inverse_inertia);
  free_rotation_about_axis(q, body_momentum, 2, h, inverse_inertia);
  free_rotation_about_axis(q, body_momentum, 1, 0.5 * h, inverse_inertia);
  free_rotation_about_axis(q, body_momentum, 0, 0.5 * h, inverse_inertia);
  q = normalized(q);
}

void resize_history(MultistepHistory& h, std::size_t n) {
  for (int k = 0; k < 2; ++k) {
    h.velocity[k].resize(n);
    h.acceleration[k].resize(n);
    h.angular_velocity[k].resize(n);
    h.angular_acceleration[k].resize(n);
  }
}

// body(i, all_spheres) for every particle; all_spheres is std::true_type when no particle
// is a body, so `if (all_spheres || sphere[i])` folds away and the loop is the plain
// sphere update (1.8x faster than with the test and the body branch beside it,
// dem-spheres 2026-11-24), else std::false_type. Same operations, so the same bits.
template <typename Body>
void for_each_particle(const ParticleStore& p, int threads, Body&& body) {
  const std::size_t n = p.size();
  if (!has_non_spherical(p)) {
    parallel_for(n, threads, [&](std::size_t i) { body(i, std::true_type{}); });
  } else {
    parallel_for(n, threads, [&](std::size_t i) { body(i, std::false_type{}); });
  }
}

// Plain pointers to the per-particle arrays the integrators use, taken once per pass.
// The loops read them as m.x[i], not through a structured binding: clang before 16
// (Debian 12 ships 14) cannot capture structured bindings in a lambda.
struct MotionArrays {
  Vec3* x;
  Vec3* v;
  Vec3* w;
  Quaternion* q;
  const Vec3* f;
  const Vec3* t;
  const double* inv_m;
  const Vec3* inv_j;
  const Vec3* j_body;
  const std::uint8_t* sphere;
};

MotionArrays motion_arrays(ParticleStore& p) {
  return {p.position.data(),
          p.velocity.data(),
          p.angular_velocity.data(),
          p.orientation.data(),
          p.force.data(),
          p.torque.data(),
          p.inverse_mass.data(),
          p.inverse_inertia_body.data(),
          p.inertia_body.data(),
          p.spherical.data()};
}

// A fixed particle (zero inverse mass) feels no gravity either: it stays where it is.
inline Vec3 gravity_on(double inverse_mass, const Vec3& gravity) {
  return inverse_mass != 0.0 ? gravity : Vec3{};
}

}  // namespace

void TimeIntegrator::advance(ParticleStore& p, const Vec3& gravity, double dt) {
  const std::size_t n = p.size();
  const MotionArrays m = motion_arrays(p);

  switch (kind_) {
    case IntegratorKind::kForwardEuler:  // eq. 2.30
      for_each_particle(p, threads_, [&](std::size_t i, auto all_spheres) {
        m.x[i] += dt * m.v[i];
        m.v[i] += dt * (m.inv_m[i] * m.f[i] + gravity_on(m.inv_m[i], gravity));
        if (all_spheres || m.sphere[i]) {
          m.w[i] += (dt * m.inv_j[i].x) * m.t[i];
        } else {
          rotate_first_order(m.q[i], m.w[i], m.t[i], m.j_body[i], m.inv_j[i], dt);
        }
      });
      break;
    case IntegratorKind::kLeapfrog: {  // eq. 2.31, kick-drift half
      half_velocity_.resize(n);
      half_angular_velocity_.resize(n);
      Vec3* half_v = half_velocity_.data();
      Vec3* half_w = half_angular_velocity_.data();
      for_each_particle(p, threads_, [&](std::size_t i, auto all_spheres) {
        const Vec3 kick = (0.5 * dt) * (m.inv_m[i] * m.f[i] + gravity_on(m.inv_m[i], gravity));
        half_v[i] = m.v[i] + kick;
        m.x[i] += dt * half_v[i];
        // The forces at x_{n+1} see the predicted v_{n+1} = v_n + dt a_n rather than
        // v_{n+1/2}: with velocity-dependent (damping) forces this keeps the scheme
        // second order (the half-step velocity makes it first order, see Fig. 2.5 report).
        m.v[i] = half_v[i] + kick;
        if (all_spheres || m.sphere[i]) {
          const Vec3 spin = (0.5 * dt * m.inv_j[i].x) * m.t[i];
          half_w[i] = m.w[i] + spin;
          m.w[i] = half_w[i] + spin;
        } else {
          // Half kick of the body-frame angular momentum, free rotation over dt (DLM), and
          // the predicted omega_{n+1} for the forces; finish() applies the second half kick.
          Vec3 lb = scale(m.j_body[i], rotate_inverse(m.q[i], m.w[i])) +
                    (0.5 * dt) * rotate_inverse(m.q[i], m.t[i]);
          free_rotation(m.q[i], lb, dt, m.inv_j[i]);
          half_w[i] = lb;  // body-frame angular momentum L_{n+1/2}
          const Vec3 lb_predicted = lb + (0.5 * dt) * rotate_inverse(m.q[i], m.t[i]);
          m.w[i] = rotate(m.q[i], scale(m.inv_j[i], lb_predicted));
        }
      });
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
      for_each_particle(p, threads_, [&](std::size_t i, auto all_spheres) {
        const Vec3 a = m.inv_m[i] * m.f[i] + gravity_on(m.inv_m[i], gravity);
        const Vec3 alpha = m.inv_j[i].x * m.t[i];  // spheres only; bodies below
        const Vec3 v_now = m.v[i];
        const Vec3 w_now = m.w[i];
        m.x[i] += ab_increment(order, dt, v_now, h.velocity[0][i], h.velocity[1][i]);
        m.v[i] += ab_increment(order, dt, a, h.acceleration[0][i], h.acceleration[1][i]);
        if (all_spheres || m.sphere[i]) {
          m.w[i] += ab_increment(order, dt, alpha, h.angular_acceleration[0][i],
                                 h.angular_acceleration[1][i]);
        } else {
          // Non-spherical bodies rotate with the first-order scheme of §2.5.2.
          rotate_first_order(m.q[i], m.w[i], m.t[i], m.j_body[i], m.inv_j[i], dt);
        }
        h.velocity[1][i] = h.velocity[0][i];
        h.acceleration[1][i] = h.acceleration[0][i];
        h.angular_velocity[1][i] = h.angular_velocity[0][i];
        h.angular_acceleration[1][i] = h.angular_acceleration[0][i];
        h.velocity[0][i] = v_now;
        h.acceleration[0][i] = a;
        h.angular_velocity[0][i] = w_now;
        h.angular_acceleration[0][i] = alpha;
      });
      h.depth = std::min(h.depth + 1, 2);
      break;
    }
  }
}

void TimeIntegrator::extend_history(const ParticleStore& p, const Vec3& gravity) {
  MultistepHistory& h = history_;
  const std::size_t old = h.velocity[0].size();
  if (old == 0 || old >= p.size()) return;  // no history yet: advance() starts it
  for (int k = 0; k < 2; ++k) {
    for (std::size_t i = old; i < p.size(); ++i) {
      h.velocity[k].push_back(p.velocity[i]);
      h.acceleration[k].push_back(gravity);
      h.angular_velocity[k].push_back(p.angular_velocity[i]);
      h.angular_acceleration[k].push_back({});
    }
  }
}

void TimeIntegrator::permute(std::span<const std::uint32_t> order) {
  for (int k = 0; k < 2; ++k) {
    apply_order(history_.velocity[k], order);
    apply_order(history_.acceleration[k], order);
    apply_order(history_.angular_velocity[k], order);
    apply_order(history_.angular_acceleration[k], order);
  }
  apply_order(half_velocity_, order);
  apply_order(half_angular_velocity_, order);
}

void TimeIntegrator::finish(ParticleStore& p, const Vec3& gravity, double dt) {
  if (kind_ != IntegratorKind::kLeapfrog) return;
  const MotionArrays m = motion_arrays(p);
  const Vec3* half_v = half_velocity_.data();
  const Vec3* half_w = half_angular_velocity_.data();
  // The final half kick with a_{n+1}.
  for_each_particle(p, threads_, [&](std::size_t i, auto all_spheres) {
    m.v[i] = half_v[i] + (0.5 * dt) * (m.inv_m[i] * m.f[i] + gravity_on(m.inv_m[i], gravity));
    if (all_spheres || m.sphere[i]) {
      m.w[i] = half_w[i] + (0.5 * dt * m.inv_j[i].x) * m.t[i];
    } else {
      const Vec3 lb = half_w[i] + (0.5 * dt) * rotate_inverse(m.q[i], m.t[i]);
      m.w[i] = rotate(m.q[i], scale(m.inv_j[i], lb));
    }
  });
}

}  // namespace sanguis::dem
