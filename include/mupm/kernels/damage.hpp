// Damage of a point from its bonds (paper eq 37; FORMULATION "Fracture"):
// D_i = 1 - sum_j rho_ij omega V_j / sum_j omega V_j over the family, rho_ij = 1 for an intact
// bond and 0 for a broken one, omega = 1; and the fracture points (eq 104): D_i >= D_cr, or next
// to a pre-crack. Kernels only.
#ifndef MUPM_DAMAGE_HPP
#define MUPM_DAMAGE_HPP

#include "mupm/data/bonds.hpp"
#include "mupm/data/points.hpp"

namespace mupm {

// D_i and the fracture flags on the owned points.
template <int Dim>
void compute_damage(const Bonds& bonds, const Points<Dim>& p, double critical_damage) {
  auto offsets = bonds.offsets;
  auto neighbor = bonds.neighbor;
  auto intact = bonds.intact;
  auto volume = p.volume;
  auto damage = p.damage;
  auto fracture = p.fracture;
  auto flags = p.flags;
  Kokkos::parallel_for(
      "mupm::Fracture::damage", range(0, p.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        double all = 0, kept = 0;
        for (BondIndex b = offsets(i); b < offsets(i + 1); ++b) {
          const double vj = volume(neighbor(b));
          all += vj;
          kept += intact(b) * vj;
        }
        const double d = all > 0 ? 1.0 - kept / all : 0.0;
        damage(i) = d;
        fracture(i) = (flags(i) & kFlagPreCrack) || d >= critical_damage ? 1 : 0;
      });
}

}  // namespace mupm

#endif
