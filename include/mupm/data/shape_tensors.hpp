// What pass 1 of the solid and of the fluid need of each owned point's family geometry, computed
// once from the intact bonds and kept until the bond set changes (a restart reads other intact
// flags; fracture breaks bonds): K^-1 (eq 45), whether K is singular, and the volume of the
// intact family sum_j omega V_j (for omega_0 / V_H of eq 68).
#ifndef MUPM_SHAPE_TENSORS_HPP
#define MUPM_SHAPE_TENSORS_HPP

#include "mupm/core/types.hpp"

namespace mupm {

template <int Dim>
struct ShapeTensors {
  Vectors Kinv;           // K_i^-1 [n_owned][Dim*Dim], row-major; 0 where K is singular
  Scalars family_volume;  // sum over intact bonds of V_j [n_owned]
  Bytes singular;         // 1 where K is singular (invert_shape_tensor) [n_owned]

  void allocate(std::size_t n_owned) {
    Kinv = Vectors("mupm::shape_tensor_inverse", n_owned, Dim * Dim);
    family_volume = Scalars("mupm::family_volume", n_owned);
    singular = Bytes("mupm::shape_tensor_singular", n_owned);
  }
};

}  // namespace mupm

#endif
