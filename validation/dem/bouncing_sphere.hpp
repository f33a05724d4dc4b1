#pragma once
// Single sphere bouncing on a plane without gravity (thesis §2.6.1, Fig. 2.5),
// shared by the unit test (tests/dem/test_bouncing_sphere.cpp) and the
// validation driver (validation/dem/bouncing_sphere_main.cpp).
//
// Exact solution of the clamped law Fn = max(kn d + eta_n d', 0) for an impact at
// speed v0 starting at t1:  d(t) = v0 (t - t1) before contact, eq. 2.37 during the
// contact until the force vanishes at t1 + t*, omega t* = pi - 2 atan(gamma/omega).
// The error is measured on [0, t1 + t*], where eq. 2.37 holds; after t* the
// exact motion is free flight.
#include <cmath>
#include <numbers>
#include <vector>

#include "dem/simulation.hpp"

namespace sanguis::validation {

struct BounceSetup {
  double radius = 1e-3;       // [m]
  double density = 2500.0;    // [kg/m^3]
  double impact_speed = 1.0;  // v0 [m/s]
  dem::ContactParameters contact;
  dem::IntegratorKind integrator = dem::IntegratorKind::kLeapfrog;
  double time_step = 0.0;        // [s]
  bool contact_at_start = true;  // case (i) of §2.6.1; else case (ii)
  double approach_time = 0.0;    // t1 for case (ii) [s]
};

struct BounceResult {
  double relative_l2_error = 0.0;  // of the overlap on [0, t1 + t*]; NaN if overdamped
  double restitution = 0.0;        // |v_out| / v0 once the sphere has left the plane
};

class BounceSolution {
 public:
  BounceSolution(double mass, double kn, double eta_n, double v0, double t1) : v0_(v0), t1_(t1) {
    const double omega0 = std::sqrt(kn / mass);
    gamma_ = eta_n / (2.0 * mass);
    underdamped_ = gamma_ < omega0;
    if (underdamped_) {
      omega_ = std::sqrt(omega0 * omega0 - gamma_ * gamma_);
      t_star_ = (std::numbers::pi - 2.0 * std::atan(gamma_ / omega_)) / omega_;
    } else {  // overdamped (clamped en < e^-2): only the end of the loading phase is needed
      const double s = std::sqrt(gamma_ * gamma_ - omega0 * omega0);
      t_star_ = std::log((gamma_ + s) / (gamma_ - s)) / s;
    }
  }
  // eq. 2.37 (and so the error) is defined for underdamped contacts only.
  bool underdamped() const { return underdamped_; }
  // Overlap (negative: gap) at time t, valid for t <= t1 + t*; extends eq. 2.37 before t1
  // when `oscillator_before_contact` (the history of case (i)).
  double overlap(double t, bool oscillator_before_contact = false) const {
    const double s = t - t1_;
    if (s < 0.0 && !oscillator_before_contact) return v0_ * s;
    return v0_ / omega_ * std::exp(-gamma_ * s) * std::sin(omega_ * s);
  }
  double overlap_rate(double t) const {
    const double s = t - t1_;
    return v0_ * std::exp(-gamma_ * s) *
           (std::cos(omega_ * s) - gamma_ / omega_ * std::sin(omega_ * s));
  }
  double overlap_acceleration(double t) const {
    const double s = t - t1_;
    const double e = std::exp(-gamma_ * s);
    return v0_ * e *
           (-2.0 * gamma_ * std::cos(omega_ * s) +
            (gamma_ * gamma_ - omega_ * omega_) / omega_ * std::sin(omega_ * s));
  }
  double end_of_window() const { return t1_ + t_star_; }

 private:
  double v0_, t1_, gamma_ = 0.0, omega_ = 0.0, t_star_ = 0.0;
  bool underdamped_ = true;
};

inline BounceResult simulate_bounce(const BounceSetup& b) {
  using namespace dem;
  DemSetup s;
  s.domain.min = {-0.01, -0.01, -0.01};
  s.domain.max = {0.01, 0.01, 0.01};
  s.gravity = {};
  s.time_step = b.time_step;
  s.integrator = b.integrator;
  s.material_names = {"sphere", "plane"};
  s.contacts = ContactTable(2);
  s.contacts.set(0, 1, b.contact);
  s.contacts.set(0, 0, b.contact);
  Obstacle plane;
  plane.material = 1;
  plane.shape = PlaneShape{{0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}};
  s.obstacles.push_back(plane);
  const double t1 = b.contact_at_start ? 0.0 : b.approach_time;
  const double z0 = b.radius + b.impact_speed * t1;
  s.particles.add_sphere(0, 0, b.radius, b.density, {0.0, 0.0, z0}, {0.0, 0.0, -b.impact_speed},
                         {});
  const double mass = s.particles.mass[0];
  const BounceSolution exact(mass, b.contact.normal_stiffness, b.contact.normal_damping,
                             b.impact_speed, t1);
  DemSimulation sim(std::move(s));

  if (b.contact_at_start) {
    // A multistep scheme of order p needs p-th order starting values: take the past rates
    // from the exact solution continued before t = 0 (the contact "already exists").
    MultistepHistory& h = sim.integrator().history();
    h.depth = 2;
    for (int k = 0; k < 2; ++k) {
      const double t = -(k + 1) * b.time_step;
      h.velocity[k] = {Vec3{0.0, 0.0, -exact.overlap_rate(t)}};
      h.acceleration[k] = {Vec3{0.0, 0.0, -exact.overlap_acceleration(t)}};
      h.angular_velocity[k] = {Vec3{}};
      h.angular_acceleration[k] = {Vec3{}};
    }
  }

  double err2 = 0.0, ref2 = 0.0;
  const auto accumulate = [&]() {
    const double t = sim.time();
    if (t > exact.end_of_window()) return;
    const double numeric = b.radius - sim.particles().position[0].z;
    const double reference = exact.overlap(t);
    err2 += (numeric - reference) * (numeric - reference);
    ref2 += reference * reference;
  };
  if (exact.underdamped()) accumulate();
  while (sim.time() <= exact.end_of_window()) {
    sim.step();
    if (exact.underdamped()) accumulate();
  }
  // Run on until the sphere has clearly left the plane, then read its speed.
  while (sim.particles().position[0].z < b.radius * 1.01 || sim.wall_contacts().size() > 0) {
    sim.step();
    if (sim.time() > 100.0 * exact.end_of_window()) break;
    if (sim.particles().position[0].z > b.radius * 1.01) break;
  }
  BounceResult r;
  r.relative_l2_error = exact.underdamped() ? std::sqrt(err2 / ref2) : std::nan("");
  r.restitution = std::abs(sim.particles().velocity[0].z) / b.impact_speed;
  return r;
}

}  // namespace sanguis::validation
