// The nonlocal shape tensor of pass 1 (paper eq 45):
// K_i = sum_j omega_ij (xi (x) xi) V_j over the intact bonds, xi = x_j - x_i, omega = 1 (unit
// influence) for an intact bond and 0 for a broken one.
#ifndef MUPM_SHAPE_TENSOR_HPP
#define MUPM_SHAPE_TENSOR_HPP

#include "mupm/core/small_matrix.hpp"
#include "mupm/data/bonds.hpp"
#include "mupm/data/points.hpp"
#include "mupm/data/shape_tensors.hpp"

namespace mupm {

// K^-1 of a point's shape tensor, or false (and K^-1 = 0) when K is singular: no intact bond
// (trace 0) or det K below 1e-6 of the determinant (tr K / Dim)^Dim of a well-conditioned K of
// the same trace. Pass 1 of the solid and of the fluid treat such a point as degenerate.
template <int Dim>
KOKKOS_INLINE_FUNCTION bool invert_shape_tensor(const double* K, double* Kinv) {
  double tr = 0;
  for (int d = 0; d < Dim; ++d)
    tr += K[d * Dim + d];
  const double det = tr > 0 ? invert<Dim>(K, Kinv) : 0.0;
  double scale = tr / Dim;
  for (int d = 1; d < Dim; ++d)
    scale *= tr / Dim;
  if (tr > 0 && det > 1e-6 * scale)
    return true;
  for (int k = 0; k < Dim * Dim; ++k)
    Kinv[k] = 0;
  return false;
}

// K_i (row-major, into k) and the intact family volume sum_j omega V_j of owned point i, summed
// over its bonds in their (global-id) order.
template <int Dim, class X, class V>
KOKKOS_INLINE_FUNCTION double shape_tensor_of(std::size_t i, const View1<BondIndex>& offsets,
                                              const View1<LocalId>& neighbor, const Bytes& intact,
                                              const X& x, const V& volume, double* k) {
  for (int m = 0; m < Dim * Dim; ++m)
    k[m] = 0;
  double wsum = 0;
  for (BondIndex b = offsets(i); b < offsets(i + 1); ++b) {
    if (!intact(b))
      continue;
    const int j = neighbor(b);
    double xi[Dim];
    for (int d = 0; d < Dim; ++d)
      xi[d] = x(j, d) - x(i, d);
    const double vj = volume(j);
    for (int r = 0; r < Dim; ++r)
      for (int c = 0; c < Dim; ++c)
        k[r * Dim + c] += xi[r] * xi[c] * vj;
    wsum += vj;
  }
  return wsum;
}

// Fills K [n_owned][Dim*Dim] (row-major) for the owned points.
template <int Dim>
void compute_shape_tensor(const Points<Dim>& p, const Bonds& bonds, const Vectors& K) {
  auto offsets = bonds.offsets;
  auto neighbor = bonds.neighbor;
  auto intact = bonds.intact;
  auto x = p.x;
  auto volume = p.volume;
  Kokkos::parallel_for(
      "mupm::Kinematics::shape_tensor", range(0, p.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        double k[Dim * Dim];
        shape_tensor_of<Dim>(i, offsets, neighbor, intact, x, volume, k);
        for (int m = 0; m < Dim * Dim; ++m)
          K(i, m) = k[m];
      });
}

// K^-1, the singular flags and the family volumes of the owned points (allocated if needed).
// Call after any change of the intact flags.
template <int Dim>
void update_shape_tensors(const Points<Dim>& p, const Bonds& bonds, ShapeTensors<Dim>& st) {
  if (st.Kinv.extent(0) != p.n_owned)
    st.allocate(p.n_owned);
  auto offsets = bonds.offsets;
  auto neighbor = bonds.neighbor;
  auto intact = bonds.intact;
  auto x = p.x;
  auto volume = p.volume;
  auto Kinv = st.Kinv;
  auto fam = st.family_volume;
  auto singular = st.singular;
  Kokkos::parallel_for(
      "mupm::Kinematics::shape_tensor_inverse", range(0, p.n_owned),
      KOKKOS_LAMBDA(const std::size_t i) {
        double k[Dim * Dim], ki[Dim * Dim] = {};
        fam(i) = shape_tensor_of<Dim>(i, offsets, neighbor, intact, x, volume, k);
        singular(i) = invert_shape_tensor<Dim>(k, ki) ? 0 : 1;
        for (int m = 0; m < Dim * Dim; ++m)
          Kinv(i, m) = ki[m];
      });
  Kokkos::fence();
}

}  // namespace mupm

#endif
