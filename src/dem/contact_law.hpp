#pragma once
// Linear spring-dashpot contact law with memory, thesis §2.3:
//   normal      Fn = max(kn dn + eta_n d(dn)/dt, 0) un                       eq. 2.5
//   tangential  Ft = min(|-kt dt - eta_t vt|, mu_c |Fn|) ut,cumul             eq. 2.6-2.7
//               dt = rotated previous dt + vt Delta t (sticking), or the value
//               that keeps Ft continuous through desaturation (sliding)      eq. 2.8
//   rolling     Mr = Mk + Md, Mk incremental with memory, |Mk| <= mu_r R_ij |Fn|  eq. 2.9-2.13
// References: Cundall & Strack (1979); Luding (2008) for the continuous
// saturation of eq. 2.8; Ai et al., Powder Technol. 206 (2011) for rolling.
//
// The kernel works on one contact and plain data: no allocation, no virtual call.
// Sign convention: the normal points from the first body to the second; the
// relative velocity is that of the first body's material point at the contact
// minus the second's; the returned force and torque act on the first body
// (the second body gets the opposite).
#include <cmath>

#include "core/vec3.hpp"
#include "dem/contact_parameters.hpp"

namespace sanguis::dem {

// Memory carried by one contact from step to step.
struct ContactHistory {
  Vec3 tangential_displacement;  // delta_t of eq. 2.8 [m]
  Vec3 rolling_spring_torque;    // M_k of eq. 2.10 [N m]
  Vec3 normal;                   // contact normal at the previous step; zero for a new contact
};

struct ContactKinematics {
  Vec3 normal;                     // unit, first -> second
  double overlap = 0.0;            // dn > 0 in contact [m]
  Vec3 relative_velocity;          // at the contact point, first minus second [m/s]
  Vec3 relative_angular_velocity;  // omega_first - omega_second [rad/s]
  double reduced_radius = 0.0;     // R_ij [m], eq. 2.13
};

struct ContactResponse {
  Vec3 force;                 // on the first body [N]
  Vec3 rolling_torque;        // on the first body [N m], in addition to the moment of `force`
  double normal_force = 0.0;  // |Fn| [N]
};

// What one contact contributes to its two bodies (no second body for walls).
struct ContactOutcome {
  Vec3 force;          // on the first body (the second gets -force)
  Vec3 torque_first;   // total torque on the first body
  Vec3 torque_second;  // total torque on the second body
  double overlap_ratio = 0.0;
  bool touching = false;
  bool deep = false;  // element contact deeper than the crusts
};

// Rotates a vector lying in the previous tangent plane into the current one by the
// smallest rotation that takes the old normal onto the new normal (q_rot of eq. 2.8).
[[gnu::always_inline]] inline Vec3 rotate_into_new_plane(const Vec3& v, const Vec3& old_normal,
                                                         const Vec3& new_normal) {
  const double c = dot(old_normal, new_normal);
  if (c <= -0.999999) return Vec3{};  // normal flipped: no meaningful memory to carry
  const Vec3 k = cross(old_normal, new_normal);
  // Rodrigues formula for the rotation about k/|k| by acos(c), written without trigonometry.
  return c * v + cross(k, v) + (dot(k, v) / (1.0 + c)) * k;
}

// eq. 2.5: the normal force |Fn| of one contact point, viscoelastic, never attractive.
[[gnu::always_inline]] inline double normal_force_magnitude(const ContactParameters& p,
                                                            double overlap, double normal_speed) {
  const double fn_trial = p.normal_stiffness * overlap + p.normal_damping * normal_speed;
  return fn_trial > 0.0 ? fn_trial : 0.0;  // (std::fmax is a libm call here)
}

// The contact's force and rolling torque given its normal force magnitude `fn`: the
// tangential spring-dashpot and the rolling resistance, both with memory. `fn` is
// eq. 2.5 at one point (evaluate_contact) or the resultant of a patch of points
// (dem/body_contacts.hpp).
[[gnu::always_inline]] inline ContactResponse contact_response_for_normal_force(
    const ContactParameters& p, const ContactKinematics& c, ContactHistory& h, double dt,
    double fn) {
  ContactResponse out;
  const Vec3& n = c.normal;
  const double normal_speed = dot(c.relative_velocity, n);  // d(dn)/dt
  out.normal_force = fn;
  out.force = -fn * n;

  const bool continuing = h.normal.x != 0.0 || h.normal.y != 0.0 || h.normal.z != 0.0;

  // eq. 2.6-2.8: tangential spring-dashpot with cumulative displacement.
  const Vec3 vt = c.relative_velocity - normal_speed * n;
  Vec3 delta = continuing ? rotate_into_new_plane(h.tangential_displacement, h.normal, n) : Vec3{};
  delta += dt * vt;
  Vec3 ft = -p.tangential_stiffness * delta - p.tangential_damping * vt;
  const double ft_max = p.friction * fn;
  const double ft_norm2 = norm2(ft);
  if (ft_norm2 > ft_max * ft_max) {
    const double ft_norm = std::sqrt(ft_norm2);
    // Sliding: Ft = mu_c |Fn| ut,cumul, and delta_t such that -kt delta - eta_t vt = Ft, so
    // that Ft stays continuous when the contact sticks again (eq. 2.8, second line).
    ft = ft_norm > 0.0 ? (ft_max / ft_norm) * ft : Vec3{};
    delta = p.tangential_stiffness > 0.0
                ? (-1.0 / p.tangential_stiffness) * (ft + p.tangential_damping * vt)
                : Vec3{};
  }
  out.force += ft;
  h.tangential_displacement = delta;

  // eq. 2.9-2.13: rolling resistance with memory (Ai et al.), on the relative rotation.
  if (p.rolling_friction > 0.0) {
    const Vec3 dtheta = dt * c.relative_angular_velocity;
    Vec3 mk = continuing ? rotate_into_new_plane(h.rolling_spring_torque, h.normal, n) : Vec3{};
    mk -= p.rolling_stiffness * dtheta;
    const double mk_norm = norm(mk);
    const double m_max = p.rolling_friction * c.reduced_radius * fn;  // eq. 2.13
    if (mk_norm <= m_max) {
      out.rolling_torque = mk - p.rolling_damping * c.relative_angular_velocity;  // eq. 2.11
    } else {
      mk = mk_norm > 0.0 ? (m_max / mk_norm) * mk : Vec3{};  // eq. 2.10 saturated, eq. 2.12
      out.rolling_torque = mk;                               // Md = 0 while saturated (eq. 2.11)
    }
    h.rolling_spring_torque = mk;
  }
  h.normal = n;
  return out;
}

// One contact point, eq. 2.5-2.13. Forced inline: it runs once per contact per step
// inside the force loops.
[[gnu::always_inline]] inline ContactResponse evaluate_contact(const ContactParameters& p,
                                                               const ContactKinematics& c,
                                                               ContactHistory& h, double dt) {
  const double fn = normal_force_magnitude(p, c.overlap, dot(c.relative_velocity, c.normal));
  return contact_response_for_normal_force(p, c, h, dt, fn);
}

}  // namespace sanguis::dem
