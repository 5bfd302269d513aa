// Shear-band diagnostics: the nonlocal second-order work (paper eq 42) and the band measurement
// of the CSV (band_angle, band_width).
//
// Second-order work over a window of steps, per point (N/m^2 = J/m^3):
//   d2E_i = sum_j (dT_ij . dU^_ij + dM_ij . dOmega_ij) V_j                     (eq 42)
// with d the change over the window and T_ij = sigma-bar_i K_i^-1 xi, M_ij = m_i K_i^-1 xi the
// effective force and moment states of the correspondence model (eqs 64-65 without the
// stabilization). With the bond set unchanged over the window the bond sum closes in point data:
//   sum_j (d sigma K^-1 xi) . dU^ V_j = d sigma : [sum_j dU^ (x) xi V_j] K^-1 = d sigma : d eps
// (eq 50; K symmetric), and likewise for M with d kappa (eq 51), so
//   d2E_i = d sigma-bar_i : d eps_i + d m_i : d kappa_i                          (eq 40)
// exactly, as the paper notes below eq 42: the window's starting sigma-bar, m, eps, kappa per
// point are all it needs (no per-bond history). The test (tests/solvers/test_plasticity_solver.cpp)
// evaluates the bond sum of eq 42 itself and compares. Bonds that break inside a window change
// K; the point formula then uses each end's own K of the window's end.
//
// Band measurement (Example 3): the localized points are those with an equivalent plastic
// strain of at least half the largest one (and above zero). They are split into the two
// branches of a conjugate pair through their own centroid c (the crossing of an X, wherever it
// nucleated): branch + where (x - c_x)(y - c_y) > 0 (a band rising to the right), branch -
// where < 0. Each branch gets the
// principal axis of its points' second moments (a total least-squares line through their
// centroid): its angle from the horizontal, in [0, 90] degrees, and its width sqrt(12) times the
// standard deviation across the axis (the width of a uniform band with that spread). band_angle
// and band_width are the means over the branches with at least 3 points; both are 0 while no
// point has yielded or while the localized points fill more than half of the body's volume
// (diffuse yielding, no band yet).
#ifndef MUPM_SHEAR_BANDS_HPP
#define MUPM_SHEAR_BANDS_HPP

#include <cmath>

#include "mupm/core/types.hpp"
#include "mupm/data/points.hpp"

namespace mupm {

// d2E of the window ending now (eq 40 = eq 42, header) into out (none if out is empty: the first
// window's start), and the window's start <- now.
// start: [n][2 (Dim*Dim + RotDim*Dim)]: sigma-bar, eps, m, kappa.
template <int Dim>
void second_order_work(const Points<Dim>& pts, const Vectors& eps, const Vectors& kappa,
                       const Vectors& start, const Scalars& out) {
  constexpr int R = kRotDim<Dim>, S = Dim * Dim, C = R * Dim;
  auto sig = pts.stress, m = pts.couple_stress;
  const bool write = out.extent(0) > 0;
  Kokkos::parallel_for(
      "mupm::ShearBands::second_order_work", range(0, pts.n_owned),
      KOKKOS_LAMBDA(const std::size_t i) {
        double w = 0;
        for (int k = 0; k < S; ++k) {
          w += (sig(i, k) - start(i, k)) * (eps(i, k) - start(i, S + k));
          start(i, k) = sig(i, k);
          start(i, S + k) = eps(i, k);
        }
        for (int k = 0; k < C; ++k) {
          w += (m(i, k) - start(i, 2 * S + k)) * (kappa(i, k) - start(i, 2 * S + C + k));
          start(i, 2 * S + k) = m(i, k);
          start(i, 2 * S + C + k) = kappa(i, k);
        }
        if (write)
          out(i) = w;
      });
}

// Volume of the body's points (boundary layers excluded) and of those with d2E < 0, this rank.
template <int Dim>
void negative_volume(const Points<Dim>& pts, const Scalars& d2, double& total, double& negative) {
  auto vol = pts.volume;
  auto flags = pts.flags;
  total = negative = 0;
  Kokkos::parallel_reduce(
      "mupm::ShearBands::negative_volume", range(0, pts.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, double& t, double& n) {
        if (flags(i) & kFlagBoundaryLayer)
          return;
        t += vol(i);
        if (d2(i) < 0)
          n += vol(i);
      },
      total, negative);
}

// Sums of the band measurement, this rank: per branch (+, -) the count, sum x, y, xx, xy, yy of
// the localized points (coordinates relative to c), and the body's and the localized volume.
struct BandMoments {
  double b[2][6] = {};
  double all[6] = {};  // the same over all localized points
  double body_volume = 0, localized_volume = 0;
};

// The largest equivalent plastic strain of this rank's body points.
template <int Dim>
double max_equivalent_plastic_strain(const Points<Dim>& pts) {
  auto e = pts.equivalent_plastic_strain;
  auto flags = pts.flags;
  double mx = 0;
  Kokkos::parallel_reduce(
      "mupm::ShearBands::max_eq", range(0, pts.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, double& acc) {
        if (!(flags(i) & kFlagBoundaryLayer) && e(i) > acc)
          acc = e(i);
      },
      Kokkos::Max<double>(mx));
  return mx;
}

template <int Dim>
BandMoments band_moments(const Points<Dim>& pts, double threshold, double cx, double cy) {
  auto e = pts.equivalent_plastic_strain;
  auto x = pts.x;
  auto vol = pts.volume;
  auto flags = pts.flags;
  BandMoments out;
  for (int br = 0; br < 3; ++br) {  // 2: all localized points (c = 0: their centroid)
    const double sign = br == 0 ? 1.0 : -1.0;
    double s[6] = {};
    Kokkos::parallel_reduce(
        "mupm::ShearBands::moments", range(0, pts.n_owned),
        KOKKOS_LAMBDA(const std::size_t i, double& n, double& sx, double& sy, double& sxx,
                      double& sxy, double& syy) {
          if ((flags(i) & kFlagBoundaryLayer) || !(e(i) >= threshold))
            return;
          const double dx = x(i, 0) - cx, dy = x(i, 1) - cy;
          if (br < 2 && !(sign * dx * dy > 0))
            return;
          n += 1;
          sx += dx;
          sy += dy;
          sxx += dx * dx;
          sxy += dx * dy;
          syy += dy * dy;
        },
        s[0], s[1], s[2], s[3], s[4], s[5]);
    for (int k = 0; k < 6; ++k)
      (br < 2 ? out.b[br][k] : out.all[k]) = s[k];
  }
  double t = 0, l = 0;
  Kokkos::parallel_reduce(
      "mupm::ShearBands::localized_volume", range(0, pts.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, double& tv, double& lv) {
        if (flags(i) & kFlagBoundaryLayer)
          return;
        tv += vol(i);
        if (e(i) >= threshold)
          lv += vol(i);
      },
      t, l);
  out.body_volume = t;
  out.localized_volume = l;
  return out;
}

// band_angle [degrees] and band_width [m] from the summed moments (header).
inline void band_measure(const BandMoments& bm, double& angle, double& width) {
  angle = width = 0;
  if (!(bm.localized_volume > 0) || bm.localized_volume > 0.5 * bm.body_volume)
    return;
  int used = 0;
  for (int br = 0; br < 2; ++br) {
    const double* s = bm.b[br];
    const double n = s[0];
    if (n < 3)
      continue;
    const double mx = s[1] / n, my = s[2] / n;
    const double cxx = s[3] / n - mx * mx, cxy = s[4] / n - mx * my, cyy = s[5] / n - my * my;
    const double phi = 0.5 * std::atan2(2 * cxy, cxx - cyy);  // major axis
    const double tr = cxx + cyy, det = cxx * cyy - cxy * cxy;
    const double disc = std::sqrt(std::fmax(0.25 * tr * tr - det, 0.0));
    const double minor = std::fmax(0.5 * tr - disc, 0.0);
    double a = std::fabs(phi) * 180 / kPi;
    if (a > 90)
      a = 180 - a;
    angle += a;
    width += std::sqrt(12 * minor);
    ++used;
  }
  if (used > 0) {
    angle /= used;
    width /= used;
  }
}

// The whole measurement over the ranks: sum(data, n) and max(data, n) reduce in place over
// them (the caller's MPI; identity on one rank). cx, cy: the body's centre.
template <int Dim, class Sum, class Max>
void measure_bands(const Points<Dim>& pts, double cx, double cy, const Sum& sum, const Max& max,
                   double& angle, double& width) {
  double mx = max_equivalent_plastic_strain(pts);
  max(&mx, 1);
  BandMoments bm;
  if (mx > 0) {
    // The localized points' centroid first, then the branches through it.
    bm = band_moments(pts, 0.5 * mx, cx, cy);
    sum(bm.all, 6);
    const double n = bm.all[0] > 0 ? bm.all[0] : 1;
    bm = band_moments(pts, 0.5 * mx, cx + bm.all[1] / n, cy + bm.all[2] / n);
    sum(&bm.b[0][0], 12);
    sum(&bm.body_volume, 1);
    sum(&bm.localized_volume, 1);
  }
  band_measure(bm, angle, width);
}

}  // namespace mupm

#endif
