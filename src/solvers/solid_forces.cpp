#include "mupm/solvers/solid_forces.hpp"

#include "mupm/core/timers.hpp"

namespace mupm {

template <int Dim, class Law>
void solid_forces(const Points<Dim>& pts, Discretization<Dim>& disc, const SolidParams& prm,
                  const Law& law, SolidState<Dim>& st) {
  ScopedRegion region("mupm::Solid::forces");
  solid_pass1(pts, disc.bonds, disc.shape, prm, law, st);
  disc.dist.refresh(st.pass2_ghosts());
  solid_pass2(pts, disc.bonds, prm, st);
}

template <int Dim>
void fold_layer_forces(Discretization<Dim>& disc, const FaceSlots& slots, const Vectors& force,
                       const Vectors& moment, const Vectors& buf) {
  Kokkos::deep_copy(buf, 0.0);
  pack_layer_forces(disc.points, disc.mirror, slots, force, moment, buf);
  disc.dist.add_to_owners(buf);
  add_folded(disc.points, buf, force, moment);
  Kokkos::fence();
}

template <int Dim>
void uniform_stress_forces(Discretization<Dim>& disc, const SolidParams& prm,
                           const Kokkos::Array<double, 9>& sigma, SolidState<Dim>& st) {
  uniform_stress_pass1(disc.points, disc.shape, sigma, st);
  disc.dist.refresh(st.pass2_ghosts());
  solid_pass2(disc.points, disc.bonds, prm, st);
}

#define MUPM_EXTERN
MUPM_SOLID_FORCES(2)
MUPM_SOLID_FORCES(3)

}  // namespace mupm
