#pragma once
// Explicit time integration of eq. 2.1-2.4 for spheres (thesis §2.5.1):
//   forward Euler                 eq. 2.30   (order 1)
//   leapfrog                      eq. 2.31   (order 2, symplectic; default)
//   Adams-Bashforth 2 and 3       eq. 2.32   (orders 2 and 3; multi-step)
// Spheres (isotropic inertia) advance their angular velocity with the same
// scheme, eq. 2.3 reducing to d(omega)/dt = T / I. Other bodies integrate eq. 2.34
// in the body frame with a unit quaternion: with Euler and Adams-Bashforth, the
// first-order scheme of §2.5.2 (explicit Euler on eq. 2.34, then dq/dt =
// 1/2 omega q); with leapfrog, a second-order symplectic splitting (half kicks of
// the angular momentum around the free-rotor splitting of Dullweber, Leimkuhler
// and McLachlan 1997), which conserves |L| exactly and energy to O(dt^2).
//
// One step is split around the force evaluation:
//   advance(): uses the accelerations a_n (forces at x_n) to produce x_{n+1}
//   finish():  called after the forces at x_{n+1} are known.
// Leapfrog is written in its kick-drift-kick form: v_{n+1/2} = v_n + dt/2 a_n,
// x_{n+1} = x_n + dt v_{n+1/2}, v_{n+1} = v_{n+1/2} + dt/2 a_{n+1}. Its positions are
// those of eq. 2.31 (with the Euler half-step start the thesis describes) and its
// velocities are synchronised with the positions, so outputs need no interpolation.
// Forces at x_{n+1} see the predicted velocity v_n + dt a_n, not v_{n+1/2}: with
// damping forces the half-step velocity would make the scheme first order.
#include <array>
#include <span>
#include <string>
#include <vector>

#include "core/vec3.hpp"
#include "dem/particle_store.hpp"

namespace sanguis::dem {

enum class IntegratorKind { kForwardEuler, kLeapfrog, kAdamsBashforth2, kAdamsBashforth3 };

IntegratorKind parse_integrator(const std::string& name);  // throws std::invalid_argument
const char* to_string(IntegratorKind kind);
int order_of(IntegratorKind kind);

// Past rates for the Adams-Bashforth schemes: index 0 is step n-1, index 1 step n-2.
struct MultistepHistory {
  int depth = 0;  // how many past steps are stored (the scheme starts with lower orders)
  std::array<std::vector<Vec3>, 2> velocity, acceleration;
  std::array<std::vector<Vec3>, 2> angular_velocity, angular_acceleration;
};

class TimeIntegrator {
 public:
  explicit TimeIntegrator(IntegratorKind kind = IntegratorKind::kLeapfrog) : kind_(kind) {}

  IntegratorKind kind() const { return kind_; }
  // Particles are independent: the loops run on `threads` OpenMP threads.
  void set_threads(int threads) { threads_ = threads < 1 ? 1 : threads; }
  void advance(ParticleStore& p, const Vec3& gravity, double dt);
  void finish(ParticleStore& p, const Vec3& gravity, double dt);
  // Particles were appended (pouring): their multistep history is that of free flight
  // (past velocity = current, past acceleration = gravity), the others keep theirs.
  void extend_history(const ParticleStore& p, const Vec3& gravity);
  // The particles were reordered (ParticleStore::permute with the same `order`).
  void permute(std::span<const std::uint32_t> order);

  MultistepHistory& history() { return history_; }
  const MultistepHistory& history() const { return history_; }
  // Leapfrog's mid-step velocities between advance() and finish(), per particle: they move
  // with the particles when a domain decomposition renumbers them within a step.
  std::vector<Vec3>& half_velocity() { return half_velocity_; }
  std::vector<Vec3>& half_angular_velocity() { return half_angular_velocity_; }

 private:
  IntegratorKind kind_;
  int threads_ = 1;
  MultistepHistory history_;
  // Leapfrog: v_{n+1/2} and, for spheres, omega_{n+1/2} (for other bodies the body-frame
  // angular momentum L_{n+1/2}) between advance() and finish(); not state: rebuilt every step.
  std::vector<Vec3> half_velocity_, half_angular_velocity_;
};

}  // namespace sanguis::dem
