#pragma once
// Contact parameters from measurable quantities: the procedure of thesis §2.4
// (eq. 2.16-2.28), after Yan et al. and Cleary (kn from a maximum overlap at a
// maximum impact velocity), Pournin (tangential from normal, eq. 2.23-2.24) and
// Jiang et al. (rolling, eq. 2.28).
//
// Beyond the thesis: eq. 2.16/2.22 give the restitution of a linear
// damped oscillator whose force may turn attractive at the end of the contact.
// The law of eq. 2.5 clamps the normal force with max(., 0), which ends the
// contact early and raises the measured restitution (0.45 -> 0.51,
// 0.1 -> 0.25). The model `kExactRestitution` chooses the damping so that the
// clamped law rebounds with exactly en (closed forms below, after Schwager &
// Poeschel, Phys. Rev. E 75, 051304, 2007); the default `kThesis` keeps
// eq. 2.22 so that Table 2.1 is reproduced.
#include <string>

#include "dem/contact_parameters.hpp"

namespace sanguis::dem {

enum class NormalDampingModel { kThesis, kExactRestitution };

NormalDampingModel parse_normal_damping_model(
    const std::string& name);  // "thesis"|"exact_restitution"
const char* to_string(NormalDampingModel model);

struct ProcedureInput {
  double reduced_mass = 0.0;            // m_ij = m_i m_j / (m_i + m_j); m_i for a wall [kg]
  double reduced_radius = 0.0;          // R_ij = R_i R_j / (R_i + R_j); R_i for a wall [m]
  double inertia_factor = 2.5;          // m_ij (R_i^2/I_i + R_j^2/I_j) of eq. 2.23; 2.5 for spheres
  double normal_restitution = 0.5;      // en in (0, 1]
  double tangential_restitution = 0.5;  // et in (0, 1]
  double max_overlap = 0.0;             // delta_max [m]
  double max_impact_velocity = 0.0;     // v_max [m/s]
  double friction = 0.5;                // mu_c
  double rolling_friction = 0.0;        // mu_r
  NormalDampingModel damping_model = NormalDampingModel::kThesis;
};

struct ProcedureResult {
  ContactParameters parameters;
  double damping_ratio = 0.0;             // gamma_n / omega_0
  double contact_time = 0.0;              // Tc of eq. 2.17 (pi / omega; infinite if overdamped)
  double clamped_contact_duration = 0.0;  // duration of an impact under the max(.,0) law
  double effective_restitution = 0.0;     // rebound ratio of the max(.,0) law
  double tangential_damping_rate = 0.0;   // gamma_t = eta_t / (2 m_ij) [1/s] (Table 2.1)
  double recommended_time_step = 0.0;     // contact time / 20 (Kruggel-Emden)
};

// Validates the input (throws std::invalid_argument naming the quantity) and
// runs steps 1-4 of §2.4 plus eq. 2.28.
ProcedureResult derive_contact_parameters(const ProcedureInput& input);

// Restitution of the clamped law Fn = max(kn d + eta_n d', 0) as a function of
// the damping ratio gamma_n/omega_0 (any value > 0, under- or overdamped).
double clamped_restitution(double damping_ratio);
// Inverse of clamped_restitution; en must be in (0, 1].
double damping_ratio_for_clamped_restitution(double restitution);
// omega_0 * (maximum overlap) / (impact velocity) for a given damping ratio.
double scaled_max_overlap(double damping_ratio);
// omega_0 * (duration of the clamped impact) for a given damping ratio.
double scaled_clamped_duration(double damping_ratio);

}  // namespace sanguis::dem
