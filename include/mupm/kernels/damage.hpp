// Damage of a point from its bonds (paper eq 37):
// D_i = 1 - sum_j rho_ij omega V_j / sum_j omega V_j over the family, rho_ij = 1 for an intact
// bond and 0 for a broken one, omega = 1; and the fracture points (eq 104): D_i >= D_cr, or next
// to a pre-crack or to an increment of the J criterion with fracture flow (kFlagCut). Kernels
// only.
#ifndef MUPM_DAMAGE_HPP
#define MUPM_DAMAGE_HPP

#include <cmath>

#include "mupm/core/geometry.hpp"
#include "mupm/data/bonds.hpp"
#include "mupm/data/points.hpp"

namespace mupm {

// Unit normal of point i's crack: the sum of its broken bonds' vectors (they all cross the
// crack), normalized. False (n = 0) without broken bonds.
template <int Dim, class Offsets, class Neighbors, class Intact, class X>
KOKKOS_INLINE_FUNCTION bool crack_normal(const Offsets& offsets, const Neighbors& neighbor,
                                         const Intact& intact, const X& x, std::size_t i,
                                         double n[Dim]) {
  double len = 0;
  for (int d = 0; d < Dim; ++d)
    n[d] = 0;
  for (BondIndex b = offsets(i); b < offsets(i + 1); ++b)
    if (!intact(b))
      for (int d = 0; d < Dim; ++d)
        n[d] += x(neighbor(b), d) - x(i, d);
  for (int d = 0; d < Dim; ++d)
    len += n[d] * n[d];
  if (!(len > 0))
    return false;
  len = std::sqrt(len);
  for (int d = 0; d < Dim; ++d)
    n[d] /= len;
  return true;
}

// D_i and the fracture flags on the owned points.
template <int Dim>
void compute_damage(const Bonds& bonds, const Points<Dim>& p, double critical_damage) {
  auto offsets = bonds.offsets;
  auto neighbor = bonds.neighbor;
  auto intact = bonds.intact;
  auto volume = p.volume;
  auto damage = p.damage;
  auto fracture = p.fracture;
  auto flags = p.flags;
  Kokkos::parallel_for(
      "mupm::Fracture::damage", range(0, p.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        double all = 0, kept = 0;
        for (BondIndex b = offsets(i); b < offsets(i + 1); ++b) {
          const double vj = volume(neighbor(b));
          all += vj;
          kept += intact(b) * vj;
        }
        const double d = all > 0 ? 1.0 - kept / all : 0.0;
        damage(i) = d;
        fracture(i) = (flags(i) & (kFlagPreCrack | kFlagCut)) || d >= critical_damage ? 1 : 0;
      });
}

// Flags the points within dx of `seg` (a 2D segment: the pre-crack's rule, mesh/grid.hpp) with
// kFlagCut, owned and ghosts.
template <int Dim>
void mark_cut(const Points<Dim>& p, const Crack& seg, double dx) {
  auto x = p.x;
  auto flags = p.flags;
  Kokkos::parallel_for(
      "mupm::Fracture::mark_cut", range(0, p.size()), KOKKOS_LAMBDA(const std::size_t i) {
        double xi[3] = {0, 0, 0};
        for (int d = 0; d < Dim; ++d)
          xi[d] = x(i, d);
        if (distance2_to_crack<Dim>(seg, xi) < dx * dx)
          flags(i) |= kFlagCut;
      });
}

// Crack aperture of the points with broken bonds (eqs 38-39).
// Eq 38, c = y~ cos(beta) - x, is the opening of a broken bond across the crack: with beta the
// angle between the deformed bond y = xi + U and the crack normal n, and x the reference bond's
// normal component xi.n (the paper's Figure 3), c = (xi + U).n - xi.n = U.n, U = u_j - u_i. The
// paper gives no n; a point's broken bonds all cross the crack, so their sum points across it:
// n_i = sum_broken xi / |sum_broken xi| (for a point on a straight crack's face, exactly the
// normal by symmetry). Eq 39 averages c over the broken bonds with omega = 1:
// mean_opening = sum_broken c V_j / sum_broken V_j (negative when the faces are pressed
// together; 0 without broken bonds), and the aperture a_i is its positive part. Needs u
// current on the ghosts.
template <int Dim, class Offsets, class Neighbors, class Intact, class X, class U, class Vol>
KOKKOS_INLINE_FUNCTION double mean_opening(const Offsets& offsets, const Neighbors& neighbor,
                                           const Intact& intact, const X& x, const U& u,
                                           const Vol& volume, std::size_t i) {
  double n[Dim];
  if (!crack_normal<Dim>(offsets, neighbor, intact, x, i, n))
    return 0.0;
  double sum = 0, vsum = 0;
  for (BondIndex b = offsets(i); b < offsets(i + 1); ++b) {
    if (intact(b))
      continue;
    const int j = neighbor(b);
    double c = 0;
    for (int d = 0; d < Dim; ++d)
      c += (u(j, d) - u(i, d)) * n[d];  // eq 38
    sum += c * volume(j);
    vsum += volume(j);
  }
  return sum / vsum;  // eq 39
}

template <int Dim>
void compute_aperture(const Bonds& bonds, const Points<Dim>& p) {
  auto offsets = bonds.offsets;
  auto neighbor = bonds.neighbor;
  auto intact = bonds.intact;
  auto x = p.x, u = p.u;
  auto volume = p.volume;
  auto damage = p.damage;
  auto aperture = p.aperture;
  Kokkos::parallel_for(
      "mupm::Fracture::aperture", range(0, p.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        const double c =
            damage(i) > 0 ? mean_opening<Dim>(offsets, neighbor, intact, x, u, volume, i) : 0.0;
        aperture(i) = c > 0 ? c : 0.0;
      });
}

}  // namespace mupm

#endif
