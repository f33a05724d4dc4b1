#pragma once
// Coefficients of the linear spring-dashpot contact law with memory (thesis
// §2.3, eq. 2.5-2.13) for one pair of materials.
namespace sanguis::dem {

struct ContactParameters {
  double normal_stiffness = 0.0;      // kn [N/m], eq. 2.5
  double normal_damping = 0.0;        // eta_n [N s/m], eq. 2.5
  double tangential_stiffness = 0.0;  // kt [N/m], eq. 2.6
  double tangential_damping = 0.0;    // eta_t [N s/m], eq. 2.6
  double friction = 0.0;              // mu_c, Coulomb sliding coefficient, eq. 2.6
  double rolling_stiffness = 0.0;     // kr [N m/rad], eq. 2.10
  double rolling_damping = 0.0;       // eta_r [N m s/rad], eq. 2.11
  double rolling_friction = 0.0;      // mu_r, eq. 2.13 (0 disables rolling resistance)
};

}  // namespace sanguis::dem
