// Central-difference (velocity Verlet) integration of u and theta (paper eqs 127-136 with
// beta1 = 1/2, beta2 = 0), with optional mass-proportional damping for dynamic relaxation.
// Prescribed components (Points::fixed) are left to the boundary conditions.
#ifndef MUPM_CENTRAL_DIFFERENCE_HPP
#define MUPM_CENTRAL_DIFFERENCE_HPP

#include "mupm/data/points.hpp"

namespace mupm {

// First half: v(n+1/2) = v(n) + dt/2 a(n), u(n+1) = u(n) + dt v(n+1/2); the same for theta.
template <int Dim>
void advance_positions(const Points<Dim>& pts, double dt) {
  constexpr int R = kRotDim<Dim>;
  auto u = pts.u, v = pts.v, a = pts.a, th = pts.theta, om = pts.omega, al = pts.alpha;
  auto fixed = pts.fixed;
  Kokkos::parallel_for(
      "mupm::Solver::advance_positions", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        const std::uint32_t fx = fixed(i);
        for (int k = 0; k < Dim; ++k) {
          if (fx & (1u << k))
            continue;
          v(i, k) += 0.5 * dt * a(i, k);
          u(i, k) += dt * v(i, k);
        }
        for (int r = 0; r < R; ++r) {
          if (fx & (1u << (Dim + r)))
            continue;
          om(i, r) += 0.5 * dt * al(i, r);
          th(i, r) += dt * om(i, r);
        }
      });
}

// Second half, with the new force density f and moment density l:
// a = f/rho + g - c v(n+1/2), v(n+1) = v(n+1/2) + dt/2 a; alpha = l/J - c omega(n+1/2), likewise.
// (eq 127: rho a = f + rho g; eq 128: J alpha = l.) body: extra body-force density [n][Dim]
// (tractions applied on the outermost real layer), couple: body-couple density [n][RotDim];
// either may be empty.
template <int Dim>
void advance_velocities(const Points<Dim>& pts, const Vectors& force, const Vectors& moment,
                        const Scalars& rho, const Scalars& inertia, const Vectors& body,
                        const Vectors& couple, Kokkos::Array<double, 3> gravity, double damping,
                        double dt) {
  constexpr int R = kRotDim<Dim>;
  auto v = pts.v, a = pts.a, om = pts.omega, al = pts.alpha;
  auto fixed = pts.fixed;
  const bool has_body = body.extent(0) > 0, has_couple = couple.extent(0) > 0;
  Kokkos::parallel_for(
      "mupm::Solver::advance_velocities", range(0, pts.n_owned),
      KOKKOS_LAMBDA(const std::size_t i) {
        const std::uint32_t fx = fixed(i);
        for (int k = 0; k < Dim; ++k) {
          if (fx & (1u << k))
            continue;
          const double b = has_body ? body(i, k) : 0.0;
          a(i, k) = (force(i, k) + b) / rho(i) + gravity[k] - damping * v(i, k);
          v(i, k) += 0.5 * dt * a(i, k);
        }
        for (int r = 0; r < R; ++r) {
          if (fx & (1u << (Dim + r)))
            continue;
          const double m = has_couple ? couple(i, r) : 0.0;
          al(i, r) = (moment(i, r) + m) / inertia(i) - damping * om(i, r);
          om(i, r) += 0.5 * dt * al(i, r);
        }
      });
}

}  // namespace mupm

#endif
