// The solid's force and moment densities of a state (include/mupm/kernels/solid.hpp: pass 1,
// ghost refresh, pass 2), and the fold of slaved layers' forces onto their mirrors. Defined in
// src/solvers/solid_forces.cpp for Dim 2, 3 and the shipped laws.
#ifndef MUPM_SOLID_FORCES_HPP
#define MUPM_SOLID_FORCES_HPP

#include "mupm/kernels/boundary_conditions.hpp"
#include "mupm/kernels/solid.hpp"
#include "mupm/laws/laws.hpp"
#include "mupm/mesh/discretization.hpp"

namespace mupm {

// Pass 1, ghost refresh, pass 2: the force and moment densities of the state of `pts` (the
// discretization's points, or a copy of them with other Views for some fields: the stable-step
// estimate's iterate). u, theta (and p, S_r) must be current on the ghosts.
template <int Dim, class Law>
void solid_forces(const Points<Dim>& pts, Discretization<Dim>& disc, const SolidParams& prm,
                  const Law& law, SolidState<Dim>& st);
// The same for the discretization's points.
template <int Dim, class Law>
void solid_forces(Discretization<Dim>& disc, const SolidParams& prm, const Law& law,
                  SolidState<Dim>& st) {
  solid_forces(disc.points, disc, prm, law, st);
}
// The same with the elastic law of prm.
template <int Dim>
void solid_forces(Discretization<Dim>& disc, const SolidParams& prm, SolidState<Dim>& st) {
  solid_forces(disc.points, disc, prm, prm.law, st);
}

// The fold of the slaved layers' forces and moments onto their mirrors
// (kernels/boundary_conditions.hpp): buf ([owned + ghosts][blocks * (Dim + R)]) zeroed, packed,
// its ghost rows added into their owners across ranks, added to the owned points' force, moment.
template <int Dim>
void fold_layer_forces(Discretization<Dim>& disc, const FaceSlots& slots, const Vectors& force,
                       const Vectors& moment, const Vectors& buf);

// The force and moment densities the discrete operator makes of a uniform total stress sigma
// (kernels/solid.hpp, uniform_stress_pass1), into st.force and st.moment (st allocated for the
// discretization, st.work Off).
template <int Dim>
void uniform_stress_forces(Discretization<Dim>& disc, const SolidParams& prm,
                           const Kokkos::Array<double, 9>& sigma, SolidState<Dim>& st);

#define MUPM_SOLID_FORCES_LAW(D, LAW)                                                  \
  MUPM_EXTERN template void solid_forces<D, LAW>(const Points<D>&, Discretization<D>&, \
                                                 const SolidParams&, const LAW&, SolidState<D>&);
#define MUPM_SOLID_FORCES(D)                                                                      \
  MUPM_FOR_EACH_LAW(MUPM_SOLID_FORCES_LAW, D)                                                     \
  MUPM_EXTERN template void fold_layer_forces<D>(Discretization<D>&, const FaceSlots&,            \
                                                 const Vectors&, const Vectors&, const Vectors&); \
  MUPM_EXTERN template void uniform_stress_forces<D>(                                             \
      Discretization<D>&, const SolidParams&, const Kokkos::Array<double, 9>&, SolidState<D>&);
#define MUPM_EXTERN extern
MUPM_SOLID_FORCES(2)
MUPM_SOLID_FORCES(3)
#undef MUPM_EXTERN

}  // namespace mupm

#endif
