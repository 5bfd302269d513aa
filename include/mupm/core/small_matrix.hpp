// Fixed-size dense matrix helpers for kernels (row-major arrays, Dim <= 3).
#ifndef MUPM_SMALL_MATRIX_HPP
#define MUPM_SMALL_MATRIX_HPP

#include <Kokkos_Core.hpp>

namespace mupm {

// Inverse of the Dim x Dim matrix a into inv; returns the determinant.
template <int Dim>
KOKKOS_INLINE_FUNCTION double invert(const double* a, double* inv) {
  if constexpr (Dim == 2) {
    const double det = a[0] * a[3] - a[1] * a[2];
    const double r = 1.0 / det;
    inv[0] = a[3] * r;
    inv[1] = -a[1] * r;
    inv[2] = -a[2] * r;
    inv[3] = a[0] * r;
    return det;
  } else {
    const double c00 = a[4] * a[8] - a[5] * a[7];
    const double c01 = a[5] * a[6] - a[3] * a[8];
    const double c02 = a[3] * a[7] - a[4] * a[6];
    const double det = a[0] * c00 + a[1] * c01 + a[2] * c02;
    const double r = 1.0 / det;
    inv[0] = c00 * r;
    inv[1] = (a[2] * a[7] - a[1] * a[8]) * r;
    inv[2] = (a[1] * a[5] - a[2] * a[4]) * r;
    inv[3] = c01 * r;
    inv[4] = (a[0] * a[8] - a[2] * a[6]) * r;
    inv[5] = (a[2] * a[3] - a[0] * a[5]) * r;
    inv[6] = c02 * r;
    inv[7] = (a[1] * a[6] - a[0] * a[7]) * r;
    inv[8] = (a[0] * a[4] - a[1] * a[3]) * r;
    return det;
  }
}

// c (R x Dim) = a (R x Dim) b (Dim x Dim)
template <int R, int Dim>
KOKKOS_INLINE_FUNCTION void mat_mul(const double* a, const double* b, double* c) {
  for (int r = 0; r < R; ++r)
    for (int k = 0; k < Dim; ++k) {
      double s = 0;
      for (int m = 0; m < Dim; ++m)
        s += a[r * Dim + m] * b[m * Dim + k];
      c[r * Dim + k] = s;
    }
}

// y (R) = a (R x Dim) x (Dim)
template <int R, int Dim>
KOKKOS_INLINE_FUNCTION void mat_vec(const double* a, const double* x, double* y) {
  for (int r = 0; r < R; ++r) {
    double s = 0;
    for (int m = 0; m < Dim; ++m)
      s += a[r * Dim + m] * x[m];
    y[r] = s;
  }
}

// Rotation vector (RotDim components) cross a Dim-vector: 2D theta e_z x xi = theta (-xi_y, xi_x).
template <int Dim>
KOKKOS_INLINE_FUNCTION void rot_cross(const double* theta, const double* xi, double* out) {
  if constexpr (Dim == 2) {
    out[0] = -theta[0] * xi[1];
    out[1] = theta[0] * xi[0];
  } else {
    out[0] = theta[1] * xi[2] - theta[2] * xi[1];
    out[1] = theta[2] * xi[0] - theta[0] * xi[2];
    out[2] = theta[0] * xi[1] - theta[1] * xi[0];
  }
}

// a x b of two Dim-vectors as a rotation vector (2D: the z component only).
template <int Dim>
KOKKOS_INLINE_FUNCTION void cross(const double* a, const double* b, double* out) {
  if constexpr (Dim == 2) {
    out[0] = a[0] * b[1] - a[1] * b[0];
  } else {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
  }
}

}  // namespace mupm

#endif
