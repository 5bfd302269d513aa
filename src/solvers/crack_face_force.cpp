#include "mupm/solvers/crack_face_force.hpp"

#include "mupm/kernels/fracture_flow.hpp"

namespace mupm {

template <int Dim>
CrackFaceForce<Dim>::CrackFaceForce(Discretization<Dim>& disc)
    : disc_(disc),
      force_("mupm::crack_force", disc.points.n_owned, Dim),
      pf_star_("mupm::undrained_fracture_pressure", disc.points.n_owned),
      face_load_("mupm::crack_face_load", disc.points.size(), Dim) {}

template <int Dim>
void CrackFaceForce<Dim>::evaluate() {
  Kokkos::deep_copy(force_, 0.0);
  add(disc_.points, force_);
}

template <int Dim>
void CrackFaceForce<Dim>::add(const Points<Dim>& pts, const Vectors& out) {
  undrained_fracture_pressure(disc_.bonds, pts, pf_star_);
  crack_face_load(disc_.bonds, pts, pf_star_, face_load_);
  disc_.dist.refresh({face_load_});
  crack_pressure_force(disc_.bonds, pts, face_load_, out);
}

template <int Dim>
Points<Dim> CrackFaceForce<Dim>::linear_part(Points<Dim> q, Scratch& scratch, double joins) const {
  q.pf = scratch.copy("crack_pf", q.pf);
  q.pf_saturation = scratch.copy("crack_saturation", q.pf_saturation);
  q.pf_modulus = scratch.copy("crack_modulus", q.pf_modulus);
  q.pf_aperture = scratch.copy("crack_aperture", q.pf_aperture);
  q.pf_area = scratch.copy("crack_area", q.pf_area);
  const double inv_dx = 1.0 / disc_.grid.dx;
  auto pf = q.pf, sat = q.pf_saturation, mod = q.pf_modulus, ref = q.pf_aperture;
  auto area = q.pf_area, vol = q.volume;
  auto frac = q.fracture;
  Kokkos::parallel_for(
      "mupm::Solid::crack_stiffness", range(0, q.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        if (frac(i) && !(sat(i) > 0)) {
          sat(i) = 1.0;
          mod(i) = joins;
          area(i) = vol(i) * inv_dx;
        }
        pf(i) = 0;
        ref(i) = 0;
      });
  disc_.dist.refresh({as_vectors(q.pf_saturation)});
  return q;
}

template class CrackFaceForce<2>;
template class CrackFaceForce<3>;

}  // namespace mupm
