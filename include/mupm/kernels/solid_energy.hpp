// The solid's energies and powers over one rank's points, for its energy ledger (eqs 137-140;
// include/mupm/solvers/solid_ledger.hpp). Each returns this rank's sum: the caller reduces
// over the ranks.
#ifndef MUPM_KERNELS_SOLID_ENERGY_HPP
#define MUPM_KERNELS_SOLID_ENERGY_HPP

#include <cstdint>

#include "mupm/data/points.hpp"

namespace mupm {

// acc += s m V |w|^2 over point i's free components: m = rho for the Dim translational ones
// (w of `trans`), J for the rotational ones (w of `rot`). The kinetic energy is s = 1/2 with
// v, omega; the acceleration sum s = 1 with a, alpha.
template <int Dim, class VT, class VR>
KOKKOS_INLINE_FUNCTION void add_free_squares(double& acc, double s, std::uint32_t fx, double rho,
                                             double J, double vol, const VT& trans, const VR& rot,
                                             std::size_t i) {
  for (int k = 0; k < Dim; ++k)
    if (!(fx & (1u << k)))
      acc += s * rho * vol * trans(i, k) * trans(i, k);
  for (int r = 0; r < kRotDim<Dim>; ++r)
    if (!(fx & (1u << (Dim + r))))
      acc += s * J * vol * rot(i, r) * rot(i, r);
}

// sum V (rho |a|^2 + J |alpha|^2) over the free components.
template <int Dim>
double acceleration_sum(const Points<Dim>& p, const Scalars& rho, const Scalars& J) {
  auto a = p.a, al = p.alpha, vol = p.volume;
  auto fixed = p.fixed;
  double e = 0;
  Kokkos::parallel_reduce(
      "mupm::Solid::acceleration_sum", range(0, p.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, double& acc) {
        add_free_squares<Dim>(acc, 1.0, fixed(i), rho(i), J(i), vol(i), a, al, i);
      },
      e);
  return e;
}

// sum of the points' strain energies `energy` (elastic and stabilization) [J].
inline double stored_energy(const Scalars& energy, std::size_t n_owned) {
  double e = 0;
  Kokkos::parallel_reduce(
      "mupm::Solid::stored_energy", range(0, n_owned),
      KOKKOS_LAMBDA(const std::size_t i, double& acc) { acc += energy(i); }, e);
  return e;
}

// In one pass over the points: e[0] the strain energy, e[1] the kinetic energy, e[2]
// acceleration_sum.
template <int Dim>
void point_energies(const Points<Dim>& p, const Scalars& energy, const Scalars& rho,
                    const Scalars& J, double e[3]) {
  auto v = p.v, om = p.omega, a = p.a, al = p.alpha;
  auto vol = p.volume;
  auto fixed = p.fixed;
  e[0] = e[1] = e[2] = 0;
  Kokkos::parallel_reduce(
      "mupm::Solid::energy", range(0, p.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, double& ei, double& ek, double& ea) {
        ei += energy(i);
        add_free_squares<Dim>(ek, 0.5, fixed(i), rho(i), J(i), vol(i), v, om, i);
        add_free_squares<Dim>(ea, 1.0, fixed(i), rho(i), J(i), vol(i), a, al, i);
      },
      e[0], e[1], e[2]);
}

// Power of the external agents on the step's increment du [owned][Dim + R], out[0]: on
// prescribed components the boundary holds the point against the body's force density f (it
// applies -f V); on free components gravity and the body/traction forces (body, couple) act.
// out[1]: the crack water's face forces' share of it (crack, part of body; free components;
// none where crack is empty).
template <int Dim>
void external_power(const Points<Dim>& p, const Vectors& f, const Vectors& l, const Vectors& b,
                    const Vectors& bc, const Vectors& du, const Scalars& rho,
                    const Kokkos::Array<double, 3>& g, const Vectors& fc, double out[2]) {
  constexpr int R = kRotDim<Dim>;
  auto vol = p.volume;
  auto fixed = p.fixed;
  const bool crack = fc.extent(0) > 0;
  out[0] = out[1] = 0;
  Kokkos::parallel_reduce(
      "mupm::Solid::external_work", range(0, p.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, double& acc, double& acc_crack) {
        const std::uint32_t fx = fixed(i);
        for (int k = 0; k < Dim; ++k) {
          const bool held = (fx & (1u << k)) != 0;
          acc += (held ? -f(i, k) : b(i, k) + rho(i) * g[k]) * du(i, k) * vol(i);
          if (crack && !held)
            acc_crack += fc(i, k) * du(i, k) * vol(i);
        }
        for (int r = 0; r < R; ++r)
          acc += ((fx & (1u << (Dim + r))) ? -l(i, r) : bc(i, r)) * du(i, Dim + r) * vol(i);
      },
      out[0], out[1]);
}

// sum V (F . du + L . dtheta) over the free components, F and L the J criterion's release force
// and couple densities (Points::release_force, include/mupm/solvers/solid_solver.hpp) at full
// strength: times the mean of the step's two release factors, the release force's work.
template <int Dim>
double release_work(const Points<Dim>& p, const Vectors& du) {
  constexpr int N = Dim + kRotDim<Dim>;
  auto rel = p.release_force, vol = p.volume;
  auto fixed = p.fixed;
  double w = 0;
  Kokkos::parallel_reduce(
      "mupm::Solid::release_work", range(0, p.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, double& acc) {
        const std::uint32_t fx = fixed(i);
        for (int k = 0; k < N; ++k)
          if (!(fx & (1u << k)))
            acc += rel(i, k) * du(i, k) * vol(i);
      },
      w);
  return w;
}

// Damping power c (rho v.v + J omega.omega) V at the half step.
template <int Dim>
double damping_power(const Points<Dim>& p, const Scalars& rho, const Scalars& J, double c) {
  constexpr int R = kRotDim<Dim>;
  auto v = p.v, om = p.omega, vol = p.volume;
  auto fixed = p.fixed;
  double w = 0;
  Kokkos::parallel_reduce(
      "mupm::Solid::damping_power", range(0, p.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, double& acc) {
        const std::uint32_t fx = fixed(i);
        for (int k = 0; k < Dim; ++k)
          if (!(fx & (1u << k)))
            acc += c * rho(i) * v(i, k) * v(i, k) * vol(i);
        for (int r = 0; r < R; ++r)
          if (!(fx & (1u << (Dim + r))))
            acc += c * J(i) * om(i, r) * om(i, r) * vol(i);
      },
      w);
  return w;
}

// sum_i V_i biot S_r (p*_old + p*_new)/2 (tr eps_new - tr eps_old) of a step, with the p* the
// forces were evaluated with (pstar the new; p.solid_pressure the old, from before any fluid
// update in between, as the first half of the velocity update used it: the trapezoid rule on
// the applied forces, like the external work); vs_old: tr eps at the step's start.
template <int Dim>
double pore_power(const Points<Dim>& p, const Scalars& pstar, const Scalars& vs_old, double biot) {
  auto vs = p.vol_strain, sr = p.saturation, vol = p.volume;
  auto ps_old = p.solid_pressure;
  double w = 0;
  Kokkos::parallel_reduce(
      "mupm::Solid::pore_work", range(0, p.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, double& acc) {
        acc += vol(i) * biot * sr(i) * 0.5 * (pstar(i) + ps_old(i)) * (vs(i) - vs_old(i));
      },
      w);
  return w;
}

// Power of eq 17's crack-water forces fw on the step's increment du, with the forces at the
// step's end (rectangle rule: first order, and nothing to keep for a restart): the work the
// crack's water does on the skeleton, booked with the pore work (eq 140).
template <int Dim>
double eq17_power(const Points<Dim>& p, const Vectors& fw, const Vectors& du) {
  constexpr int R = kRotDim<Dim>;
  auto vol = p.volume;
  auto fixed = p.fixed;
  double w = 0;
  Kokkos::parallel_reduce(
      "mupm::Solid::eq17_work", range(0, p.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, double& acc) {
        for (int c = 0; c < Dim + R; ++c)
          if (!(fixed(i) & (1u << c)))
            acc += fw(i, c) * du(i, c) * vol(i);
      },
      w);
  return w;
}

// Plastic dissipation of the step (the law's dissipation of the current stress).
template <int Dim, class Law>
double plastic_power(const Points<Dim>& p, const Law& law) {
  auto sig = p.stress, m = p.couple_stress, vol = p.volume;
  double d = 0;
  Kokkos::parallel_reduce(
      "mupm::Solid::plastic_dissipation", range(0, p.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, double& acc) {
        acc += vol(i) * law.dissipation(i, sig, m);
      },
      d);
  return d;
}

}  // namespace mupm

#endif
