// Fig. 2.5 of the thesis: L2 error of the penetration depth of a sphere bouncing on
// a plane (no gravity) versus the time step, for each integrator, with the contact
// existing at t = 0 (case i) or starting between two steps (case ii).
// Writes CSV to stdout: integrator,case,steps_per_contact,dt_s,relative_l2_error,restitution
#include <cmath>
#include <cstdio>
#include <numbers>

#include "bouncing_sphere.hpp"
#include "dem/parameter_procedure.hpp"

int main() {
  using namespace sanguis;
  const double radius = 1e-3, density = 2500.0;
  const double mass = 4.0 / 3.0 * std::numbers::pi * radius * radius * radius * density;
  dem::ProcedureInput in;
  in.reduced_mass = mass;  // sphere on a wall
  in.reduced_radius = radius;
  in.normal_restitution = 0.45;
  in.tangential_restitution = 0.3;
  in.max_overlap = 0.005 * radius;
  in.max_impact_velocity = 1.0;
  const dem::ProcedureResult p = dem::derive_contact_parameters(in);
  const double tc = p.contact_time;

  std::printf("integrator,case,steps_per_contact,dt_s,relative_l2_error,restitution\n");
  for (auto kind : {dem::IntegratorKind::kForwardEuler, dem::IntegratorKind::kLeapfrog,
                    dem::IntegratorKind::kAdamsBashforth2, dem::IntegratorKind::kAdamsBashforth3}) {
    for (int contact_case = 1; contact_case <= 2; ++contact_case) {
      for (int n = 20; n <= 5120; n *= 2) {
        validation::BounceSetup b;
        b.radius = radius;
        b.density = density;
        b.impact_speed = 1.0;
        b.contact = p.parameters;
        b.integrator = kind;
        b.time_step = tc / n;
        b.contact_at_start = contact_case == 1;
        // contact starts at 30% of a step, whatever the step
        b.approach_time = (std::floor(0.1 * n) + 0.3) * b.time_step;
        const validation::BounceResult r = validation::simulate_bounce(b);
        std::printf("%s,%s,%d,%.9g,%.9g,%.9g\n", dem::to_string(kind),
                    contact_case == 1 ? "i" : "ii", n, b.time_step, r.relative_l2_error,
                    r.restitution);
      }
    }
  }
  return 0;
}
