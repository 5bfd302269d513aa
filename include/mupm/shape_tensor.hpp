// The nonlocal shape tensor of pass 1 (paper eq 45; FORMULATION "Pass 1"):
// K_i = sum_j omega_ij (xi (x) xi) V_j over the intact bonds, xi = x_j - x_i, omega = 1 (unit
// influence) for an intact bond and 0 for a broken one.
#ifndef MUPM_SHAPE_TENSOR_HPP
#define MUPM_SHAPE_TENSOR_HPP

#include "mupm/bonds.hpp"
#include "mupm/points.hpp"

namespace mupm {

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
        double k[Dim * Dim] = {};
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
        }
        for (int m = 0; m < Dim * Dim; ++m)
          K(i, m) = k[m];
      });
}

}  // namespace mupm

#endif
