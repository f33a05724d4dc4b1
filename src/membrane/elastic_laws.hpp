#pragma once
// Surface strain-energy functions W_s(lambda1, lambda2) of the membrane, per
// unit *reference* area (thesis §4.2.2):
//
//   neo-Hookean, eq. 4.6:  W = Es/6 (l1^2 + l2^2 + 1/(l1^2 l2^2) - 3)
//   neo-Hookean, eq. 5.4:  W = Es~/2 (l1^2 + l2^2 + 1/(l1^2 l2^2) - 3)
//        (chapter 5 convention, Es~ = Es/3: the same law, its modulus three
//         times smaller; it is the shear modulus Gs of Barthès-Biesel et al.)
//   Skalak, eq. 4.7:       W = Es/4 (I1^2 + 2 I1 - 2 I2 + C I2^2),
//        I1 = l1^2 + l2^2 - 2, I2 = l1^2 l2^2 - 1, C the area dilatation modulus.
//
// References: Barthès-Biesel, Diaz & Dhenin, J. Fluid Mech. 460 (2002) 211;
// Skalak, Tozeren, Zarda & Chien, Biophys. J. 13 (1973) 245.
//
// Every law here depends on the stretches only through the invariants of the
// 2x2 right Cauchy-Green tensor C (eq. 4.17): trace = l1^2 + l2^2 and
// det = l1^2 l2^2. A law provides W(trace, det) and its two partial
// derivatives; the FEM kernel (elasticity.hpp) turns them into dW/dC without
// diagonalising C, and the principal tensions of eq. 4.5 follow as
//   sigma_i = (1/l_j) dW/dl_i = 2 (l_i/l_j) (W_trace + W_det l_j^2).
//
// Laws are plain structs; ElasticLaw is a std::variant visited once per
// membrane, outside the loop over triangles (no virtual call per triangle).
#include <stdexcept>
#include <string>
#include <variant>

namespace sanguis::membrane {

// Partial derivatives of W with respect to trace(C) and det(C).
struct InvariantDerivatives {
  double d_trace = 0.0;
  double d_det = 0.0;
};

// Which definition of Es the neo-Hookean modulus follows (see the file header).
enum class NeoHookeanConvention {
  kChapter4,  // eq. 4.6: W = Es/6 (...); case-file value "chapter4"
  kChapter5,  // eq. 5.4: W = Es/2 (...), Es three times smaller; value "chapter5"
};

struct NeoHookeanLaw {
  double shear_modulus = 1.0;  // Es (eq. 4.6) or Es~ (eq. 5.4) [N/m]
  NeoHookeanConvention convention = NeoHookeanConvention::kChapter4;

  double prefactor() const {
    return convention == NeoHookeanConvention::kChapter4 ? shear_modulus / 6.0   // eq. 4.6
                                                         : shear_modulus / 2.0;  // eq. 5.4
  }
  double energy(double trace, double det) const { return prefactor() * (trace + 1.0 / det - 3.0); }
  InvariantDerivatives derivatives(double /*trace*/, double det) const {
    const double k = prefactor();
    return {k, -k / (det * det)};
  }
};

struct SkalakLaw {
  double shear_modulus = 1.0;        // Es [N/m]
  double area_modulus_ratio = 10.0;  // C (dimensionless; thesis default 10)

  // eq. 4.7
  double energy(double trace, double det) const {
    const double i1 = trace - 2.0, i2 = det - 1.0;
    return 0.25 * shear_modulus * (i1 * i1 + 2.0 * i1 - 2.0 * i2 + area_modulus_ratio * i2 * i2);
  }
  InvariantDerivatives derivatives(double trace, double det) const {
    const double i1 = trace - 2.0, i2 = det - 1.0;
    return {0.5 * shear_modulus * (i1 + 1.0),
            0.5 * shear_modulus * (area_modulus_ratio * i2 - 1.0)};
  }
};

using ElasticLaw = std::variant<NeoHookeanLaw, SkalakLaw>;

// Parses "chapter4" / "chapter5"; std::invalid_argument naming the value otherwise.
inline NeoHookeanConvention neo_hookean_convention_from_string(const std::string& name) {
  if (name == "chapter4") return NeoHookeanConvention::kChapter4;
  if (name == "chapter5") return NeoHookeanConvention::kChapter5;
  throw std::invalid_argument(
      "neo-Hookean convention must be \"chapter4\" (eq. 4.6, Es/6) or "
      "\"chapter5\" (eq. 5.4, Es/2), got \"" +
      name + "\"");
}

// Checks the moduli (> 0, C >= 0); std::invalid_argument naming the value.
inline void validate(const ElasticLaw& law) {
  std::visit(
      [](const auto& l) {
        if (!(l.shear_modulus > 0.0))
          throw std::invalid_argument("elastic shear modulus must be > 0, got " +
                                      std::to_string(l.shear_modulus));
        if constexpr (std::is_same_v<std::decay_t<decltype(l)>, SkalakLaw>)
          if (!(l.area_modulus_ratio >= 0.0))
            throw std::invalid_argument("Skalak area dilatation modulus C must be >= 0, got " +
                                        std::to_string(l.area_modulus_ratio));
      },
      law);
}

}  // namespace sanguis::membrane
