// SolidSolver::estimate_stable_dt (include/mupm/solvers/solid_solver.hpp): the largest stable
// step of the undamped central difference, 2 / omega_max, with omega_max^2 the largest
// eigenvalue of M^-1 K of the discrete operator, by power iteration
// (include/mupm/solvers/power_iteration.hpp) on an iterate of its own: of the points' fields
// only the stress pass 1 writes changes, and the forces of the points' state, evaluated again
// at the end, write it back.
#include "mupm/core/timers.hpp"
#include "mupm/solvers/power_iteration.hpp"
#include "mupm/solvers/solid_solver.hpp"

namespace mupm {
namespace {

// M^-1 K of the power iteration: the iterate is (u, theta), K x = -(f, l) (prescribed
// components held), M = (rho, J).
template <int Dim>
struct StableStepOperator {
  Vectors u, th, f, l;
  Scalars rho, J;
  Flags fixed;
  KOKKOS_INLINE_FUNCTION double& x(std::size_t i, int c) const {
    return c < Dim ? u(i, c) : th(i, c - Dim);
  }
  KOKKOS_INLINE_FUNCTION double ax(std::size_t i, int c) const {
    return c < Dim ? -f(i, c) : -l(i, c - Dim);
  }
  KOKKOS_INLINE_FUNCTION double mass(std::size_t i, int c) const { return c < Dim ? rho(i) : J(i); }
  KOKKOS_INLINE_FUNCTION bool held(std::size_t i, int c) const {
    return (fixed(i) & (1u << c)) != 0;
  }
  KOKKOS_INLINE_FUNCTION double start(std::size_t i, int c, double s) const {
    if (held(i, c))
      return 0.0;
    return c < Dim ? std::sin(1.3 * s + 0.7 * c) + 0.1 : std::cos(0.9 * s + 0.3 * (c - Dim));
  }
};

}  // namespace

// The operator is the linear part of the step's forces, on `q`, a copy of the points whose u,
// theta are the iterate and whose pore pressure and volumetric-strain reference are zero. With a
// fluid it includes the undrained stiffness (biot S_r)^2 / C of the undrained split
// (include/mupm/kernels/solid.hpp): the fastest waves are the undrained ones. The elastic law
// throughout: the stiffest tangent, no state. The forces are computed into the solver's
// workspace (SolidState), evaluated again for the points' state at the end.
template <int Dim, class Law>
double SolidSolver<Dim, Law>::estimate_stable_dt(int iterations) {
  ScopedRegion region("mupm::Solid::stable_step");
  auto& p = disc_.points;
  Points<Dim> q = p;
  q.u = scratch_.vectors("iterate_u", p.u.extent(0), p.u.extent(1));
  q.theta = scratch_.vectors("iterate_theta", p.theta.extent(0), p.theta.extent(1));
  q.p = scratch_.scalars("zero_p", p.p.extent(0));
  q.vol_strain_ref = scratch_.scalars("zero_strain_reference", p.vol_strain_ref.extent(0));
  Kokkos::deep_copy(q.p, 0.0);
  Kokkos::deep_copy(q.vol_strain_ref, 0.0);
  const BondWork work = st_.work;
  st_.work = BondWork::Off;  // the iterates are no motion of the body
  // With the crack's water on its faces the operator includes its undrained stiffness M_f
  // (kernels/fracture_flow.hpp, CrackFaceForce::linear_part). The crack water's stiffness
  // K_w / a_min is what limits the step of a fluid-driven crack (Example 1 at 66 x 66,
  // K_w = 2.2 GPa, a_min = 0.1 mm: stable at 0.4 us, unstable at 0.95 us, the skeleton's own
  // limit being 1.9 us). Semi-implicit: p_f comes from the pressure solve (M_f = 0,
  // pressure_projection.hpp), the crack water adds no stiffness.
  const bool crack = crack_ && !set_.semi_implicit;
  if (crack)
    q = crack_->linear_part(q, scratch_, set_.fracture.water_modulus / set_.fracture.min_aperture);
  const StableStepOperator<Dim> op{q.u, q.theta, st_.force, st_.moment, rho_, inertia_, p.fixed};
  const double lambda = largest_eigenvalue(
      op, Dim + R, p.n_owned, p.gid, p.volume,
      [&] {
        disc_.dist.refresh({q.u, q.theta});
        boundary_.slave_linear(q);  // the slaving's linear part (g = 0), then its fold: P^T K P
        solid_forces(q, disc_, prm_, prm_.law, st_);
        boundary_.fold(st_.force, st_.moment);
        if (crack)
          crack_->add(q, st_.force);
      },
      comm_, iterations);
  disc_.dist.refresh({p.u, p.theta});
  solid_forces(disc_, prm_, law_, st_);
  boundary_.fold(st_.force, st_.moment);
  st_.work = work;
  // The forces the run applied last, not those of the pressure the fluid has updated since
  // (the next step's external work starts from them).
  restore_applied();
  return lambda > 0 ? 2.0 / std::sqrt(lambda) : 0.0;
}

#define MUPM_STABLE_STEP(D, LAW) template double SolidSolver<D, LAW>::estimate_stable_dt(int);
MUPM_FOR_EACH_LAW(MUPM_STABLE_STEP, 2)
MUPM_FOR_EACH_LAW(MUPM_STABLE_STEP, 3)

}  // namespace mupm
