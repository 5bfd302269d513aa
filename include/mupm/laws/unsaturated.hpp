// Unsaturated pore water: van Genuchten retention (paper eq 12) and Mualem relative
// permeability (eq 56), as a small value type usable inside kernels.
//
// Pore pressure p is positive in compression, negative (suction s = -p) when unsaturated;
// passive pore air (p_a = 0):
//   S_r(p) = [1 + (-p / s_a)^n]^(-m)   for p < 0,     S_r = 1 for p >= 0      (eq 12)
//   k_r(S_r) = S_r^(1/2) [1 - (1 - S_r^(1/m))^m]^2                           (eq 56)
// The paper does not tie m to n; the input default is Mualem's m = 1 - 1/n.
#ifndef MUPM_UNSATURATED_HPP
#define MUPM_UNSATURATED_HPP

#include <cmath>

#include "mupm/core/types.hpp"

namespace mupm {

struct VanGenuchten {
  bool enabled = false;    // false: saturated everywhere (S_r = 1, k_r = 1, dS_r/dp = 0)
  double air_entry = 1e4;  // s_a [Pa]
  double n = 2;
  double m = 0.5;

  // Mualem's m = 1 - 1/n.
  static VanGenuchten mualem(double air_entry, double n) { return {true, air_entry, n, 1 - 1 / n}; }

  KOKKOS_INLINE_FUNCTION double saturation(double p) const {
    if (!enabled || p >= 0)
      return 1.0;
    return saturation_from(std::pow(-p / air_entry, n));
  }
  // S_r and dS_r/dp from x = s/s_a and x^n (p < 0): for callers that have x^n already
  // (include/mupm/kernels/fluid.hpp, RetentionEnergy).
  KOKKOS_INLINE_FUNCTION double saturation_from(double xn) const { return std::pow(1 + xn, -m); }
  KOKKOS_INLINE_FUNCTION double slope_from(double x, double xn, double s_r) const {
    return m * n * (xn / x) * (s_r / (1 + xn)) / air_entry;
  }
  // dS_r/dp = m n (s/s_a)^(n-1) [1 + (s/s_a)^n]^(-m-1) / s_a with s = -p (>= 0: drying lowers
  // S_r as p falls), written m n (x^n / x) (S_r / (1 + x^n)) / s_a with x = s/s_a: the two powers
  // of S_r itself instead of three more.
  KOKKOS_INLINE_FUNCTION double dsaturation_dp(double p) const {
    double s_r, ds;
    saturation_and_slope(p, s_r, ds);
    return ds;
  }
  // S_r (the same bits as saturation()) and dS_r/dp together, from two powers.
  KOKKOS_INLINE_FUNCTION void saturation_and_slope(double p, double& s_r, double& ds) const {
    if (!enabled || p >= 0) {
      s_r = 1.0;
      ds = 0.0;
      return;
    }
    const double x = -p / air_entry;
    const double xn = std::pow(x, n);
    s_r = saturation_from(xn);
    ds = slope_from(x, xn, s_r);
  }
  KOKKOS_INLINE_FUNCTION double relative_permeability(double sr) const {
    if (!enabled || sr >= 1)
      return 1.0;
    if (!(sr > 0))
      return 0.0;
    const double a = 1 - std::pow(1 - std::pow(sr, 1 / m), m);
    return std::sqrt(sr) * a * a;
  }
};

}  // namespace mupm

#endif
