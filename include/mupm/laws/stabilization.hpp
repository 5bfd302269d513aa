// Stabilization constants (paper eqs 66-71 for the solid, 76-78 for the flow): functions of the
// law's moduli and the family geometry only.
#ifndef MUPM_STABILIZATION_HPP
#define MUPM_STABILIZATION_HPP

#include <cmath>

#include "mupm/core/types.hpp"
#include "mupm/laws/micropolar_elastic.hpp"

namespace mupm {

// Stabilization modulus D of eqs 69-71.
// 3D, eq 71: D = E (1 - 4 nu) / (4 pi delta^2 (1 - nu - 2 nu^2)) = (mu - lambda) / (2 pi delta^2),
//   zero at nu = 1/4 and negative above: a negative stiffness would feed the zero-energy modes.
// Bulk matching (2D and 3D): choose D so that the stabilization energy density of a uniform
//   expansion eps = e 1 applied as R = eps xi equals the elastic one:
//   3D: 1/2 int_0^delta (12 D / r^3) e^2 r^2 4 pi r^2 dr = 12 pi D delta^2 e^2 = (9K/2) e^2
//       => D = 3K / (8 pi delta^2),
//   2D (thickness h, dV = h 2 pi r dr, K2 = lambda + mu the in-plane bulk modulus; plane stress:
//   lambda* of MicropolarElastic::plane_stress in place of lambda):
//       1/2 int_0^delta (12 D / r^3) e^2 r^2 h 2 pi r dr = 12 pi D h delta e^2 = 2 K2 e^2
//       => D = K2 / (6 pi h delta).
//   The same D enters C2 = D/|xi| (eq 70), as in the paper.
enum class StabilizationModulus { Automatic, Eq71, BulkMatching };

template <int Dim>
double stabilization_modulus(const MicropolarElastic& law, double delta, double thickness,
                             StabilizationModulus choice) {
  const double eq71 = (law.mu - law.lambda) / (2 * kPi * delta * delta);
  const double bulk = Dim == 3 ? 3 * (law.lambda + 2 * law.mu / 3) / (8 * kPi * delta * delta)
                               : (law.lambda + law.mu) / (6 * kPi * thickness * delta);
  if (choice == StabilizationModulus::Eq71)
    return eq71;
  if (choice == StabilizationModulus::BulkMatching)
    return bulk;
  return (Dim == 3 && eq71 > 0) ? eq71 : bulk;
}

// k2 = int_H |xi|^2 / Dim dV of a full continuous family: the micro-conductivity of the flow
// stabilization is c = 2 lambda / k2 (derivation in include/mupm/kernels/fluid.hpp).
template <int Dim>
double family_second_moment(double delta, double thickness) {
  return Dim == 3 ? 4 * kPi * std::pow(delta, 5) / 15 : kPi * thickness * std::pow(delta, 4) / 4;
}

}  // namespace mupm

#endif
