// Micropolar (Cosserat) linear elasticity (paper eqs 80-81), mixture density (eq 1) and
// micro-inertia (eq 13).
#ifndef MUPM_MICROPOLAR_ELASTIC_HPP
#define MUPM_MICROPOLAR_ELASTIC_HPP

#include <Kokkos_Core.hpp>

#include "mupm/core/types.hpp"

namespace mupm {

// How the pore pressure p couples with the skeleton (Bishop's effective stress, eq 46, and the
// mass balance, eq 117): the total stress sigma-bar - biot S_r p 1 and the water balance
// C* dp/dt = -biot S_r d tr(eps)/dt - div + s, C* = C + lateral_compliance S_r d(S_r p)/dp.
// biot = 1 and lateral_compliance = 0 in 3D and in plane strain. In plane stress (sigma_zz,total
// = 0 with the pore water; derivation at MicropolarElastic::plane_stress_coupling) the thickness
// follows the pressure: biot = 2 mu / (lambda + 2 mu) and lateral_compliance = 1 / (lambda + 2 mu).
struct PoreCoupling {
  double biot = 1;                // in-plane coefficient of S_r p
  double lateral_compliance = 0;  // d eps_zz / d(S_r p) [1/Pa]
};

struct MicropolarElastic {
  static constexpr bool plastic = false;
  double lambda = 0;  // Lame constant [Pa]
  double mu = 0;      // shear modulus [Pa]
  double mu_c = 0;    // micropolar (Cosserat) shear modulus [Pa]
  double length = 0;  // micropolar length scale l [m]

  static MicropolarElastic from_bulk_shear(double K, double mu, double mu_c, double l) {
    return {K - 2.0 * mu / 3.0, mu, mu_c, l};
  }
  // 2D plane stress (Discretization->Plane = Stress): sigma_zz = 0 with eps_zz free. Eq 80's
  // sigma_zz = lambda (eps_kk + eps_zz) + 2 mu eps_zz (k in-plane; mu_c does not enter, eps_zz
  // having no antisymmetric part) vanishes for eps_zz = -lambda eps_kk / (lambda + 2 mu), so the
  // in-plane stress is eq 80 with lambda* = 2 lambda mu / (lambda + 2 mu); mu, mu_c and the
  // couple stresses m_zx, m_zy (eq 81, gradients of theta_z in the plane) are unchanged, and
  // m_xz, m_yz stay zero as in plane strain (no in-plane rotation components). Every constant
  // derived from the law follows: the P-wave speed sqrt((lambda* + 2 mu)/rho) =
  // sqrt(E / (rho (1 - nu^2))), the in-plane bulk modulus lambda* + mu of the stabilization
  // modulus, the stable step, poisson() = nu / (1 + nu) (the 2D ratio that turns the
  // plane-strain formulas into plane-stress ones), the J-integral's energy density.
  MicropolarElastic plane_stress() const {
    return {2 * lambda * mu / (lambda + 2 * mu), mu, mu_c, length};
  }
  // The pore water in plane stress (PoreCoupling), of this 3D law. With the total sigma_zz =
  // lambda (tr eps + eps_zz) + 2 mu eps_zz - S_r p = 0 (tr over the plane),
  // eps_zz = (S_r p - lambda tr eps) / (lambda + 2 mu), so
  //   in-plane total stress  = eq 80 with lambda* - (2 mu / (lambda + 2 mu)) S_r p 1,
  //   volume strain (3D)     = (2 mu / (lambda + 2 mu)) tr eps + S_r p / (lambda + 2 mu):
  // the same coefficient biot = 2 mu / (lambda + 2 mu) in the force and in the mass balance (the
  // coupling stays symmetric, so the energy balance still closes), and the water's storage gains
  // S_r d(S_r p)/dp / (lambda + 2 mu): the thickness swells with the pressure. Its energy
  // (S_r p)^2 / (2 (lambda + 2 mu)) is the eps_zz part of the skeleton's strain energy, booked
  // with the water's stored energy (include/mupm/kernels/fluid.hpp). Checks: saturated,
  // incompressible water and grains under an in-plane all-round pressure q take p = 2q/3 (not
  // q), and the one-dimensional consolidation modulus becomes lambda* + 2 mu with storage
  // phi/K_w + 1/(lambda + mu) (tests/solvers/test_fluid_solver.cpp, the plane-stress entries).
  // Drucker-Prager returns to sigma'_zz = S_r p and gives the water its plastic thickness change
  // on top of this coupling (include/mupm/laws/micropolar_drucker_prager.hpp).
  PoreCoupling plane_stress_coupling() const {
    return {2 * mu / (lambda + 2 * mu), 1 / (lambda + 2 * mu)};
  }
  double young() const { return mu * (3 * lambda + 2 * mu) / (lambda + mu); }
  double poisson() const { return lambda / (2 * (lambda + mu)); }
  // Couple-stress modulus B of m = B kappa: eq 81, m_ij = 1/2 mu l^2 kappa_ij.
  KOKKOS_INLINE_FUNCTION double couple_modulus() const { return 0.5 * mu * length * length; }

  // sigma-bar_ij = lambda eps_kk delta_ij + (mu + mu_c) eps_ij + (mu - mu_c) eps_ji (eq 80),
  // m = B kappa (eq 81). eps is Dim x Dim, kappa RotDim x Dim, both row-major. Returns the
  // strain energy density W = 1/2 (sigma : eps + m : kappa).
  template <int Dim>
  KOKKOS_INLINE_FUNCTION double stress(const double* eps, const double* kappa, double* sigma,
                                       double* m) const {
    constexpr int R = kRotDim<Dim>;
    double tr = 0;
    for (int d = 0; d < Dim; ++d)
      tr += eps[d * Dim + d];
    double w = 0;
    for (int a = 0; a < Dim; ++a)
      for (int b = 0; b < Dim; ++b) {
        const double s = (a == b ? lambda * tr : 0.0) + (mu + mu_c) * eps[a * Dim + b] +
                         (mu - mu_c) * eps[b * Dim + a];
        sigma[a * Dim + b] = s;
        w += 0.5 * s * eps[a * Dim + b];
      }
    const double B = couple_modulus();
    for (int k = 0; k < R * Dim; ++k) {
      m[k] = B * kappa[k];
      w += 0.5 * m[k] * kappa[k];
    }
    return w;
  }
  // The law of pass 1 (include/mupm/kernels/solid.hpp): the same at every point.
  // srp (S_r p*) is for the plastic law's plane stress; the elastic law's pore water is in
  // PoreCoupling.
  template <int Dim>
  KOKKOS_INLINE_FUNCTION double stress(std::size_t /*i*/, const double* eps, const double* kappa,
                                       double* sigma, double* m, double /*srp*/ = 0) const {
    return stress<Dim>(eps, kappa, sigma, m);
  }
  // The plastic law's shift of the water's volumetric strain (none here).
  KOKKOS_INLINE_FUNCTION double pore_shift(std::size_t) const { return 0.0; }
  KOKKOS_INLINE_FUNCTION double pore_shift_start(std::size_t) const { return 0.0; }
};

// Mixture density rho = (1 - phi) rho_s + S_r phi rho_w (eq 1).
KOKKOS_INLINE_FUNCTION double mixture_density(double phi, double rho_s, double sr, double rho_w) {
  return (1.0 - phi) * rho_s + sr * phi * rho_w;
}

// Micro-inertia density J = (pi/2)(1 - phi) rho_s l^2 (eq 13).
KOKKOS_INLINE_FUNCTION double micro_inertia(double phi, double rho_s, double l) {
  return 0.5 * kPi * (1.0 - phi) * rho_s * l * l;
}

}  // namespace mupm

#endif
