// Energy-based bond breakage (paper eqs 34-37, Algorithm 4). Kernels only.
//
// The bond energy W (eq 34) is accumulated per pair of unit volumes by solid pass 2
// (include/mupm/kernels/solid.hpp); a bond breaks (rho = 0, eq 35) once W >= W_cr.
//
// Critical energy W_cr from the critical energy release rate G_cr (eq 36 in 3D; derived here in
// 2D). A crack surface of unit area separates the pairs (x, x') whose bond crosses it; when the
// crack opens, each of them releases W_cr, so G_cr = W_cr * (measure of those pairs per unit
// area).
//   3D: the pairs crossing a unit area of a plane, at distance z below and z' = r cos(phi) - z
//   above it, measure int_0^delta int_z^delta int_0^arccos(z/r) 2 pi r^2 sin(phi) dphi dr dz
//   = int_0^delta int_z^delta 2 pi r (r - z) dr dz = pi delta^4 / 4, so W_cr = 4 G_cr/(pi delta^4)
//   (eq 36).
//   2D (plane strain or stress: W_cr holds no modulus), thickness h: a point at distance z from
//   a crack line of length L (area L h) has volume h dA; its bonds crossing the line are those
//   of length r in (z, delta) within the angle 2 arccos(z/r): measure per unit line length
//   h^2 int_0^delta int_z^delta 2 r arccos(z/r) dr dz = h^2 (2 delta^3 / 3), i.e.
//   h (2 delta^3 / 3) per unit crack area, so
//   W_cr = 3 G_cr / (2 h delta^3).
// W is counted once per pair (both directed copies of a bond hold the same W, each releases half
// of W V_i V_j). tests/kernels/test_fracture.cpp opens a straight crack through a uniform grid
// and checks the released energy against G_cr per unit area, in 2D and 3D.
#ifndef MUPM_FRACTURE_HPP
#define MUPM_FRACTURE_HPP

#include <cmath>

#include "mupm/core/geometry.hpp"
#include "mupm/data/bonds.hpp"
#include "mupm/data/points.hpp"

namespace mupm {

// None: bonds never break; Energy: eqs 34-36 (below); JIntegral: the J criterion (Algorithm 3,
// include/mupm/solvers/j_integral.hpp).
enum class BondBreaking { None, Energy, JIntegral };

struct FractureParams {
  BondBreaking criterion = BondBreaking::None;
  double critical_energy = 0;    // W_cr per pair of unit volumes [J/m^6]
  double critical_damage = 0.3;  // D_cr: fracture point at D >= D_cr (eq 104)
  bool effective_state = true;   // bond energy of the effective (true) or total force state
  // Fracture flow (include/mupm/kernels/fracture_flow.hpp).
  bool flow = false;             // p_f on the fracture network, exchange, crack pressure on faces
  double viscosity = 1e-3;       // mu_w [Pa s] of the cubic law
  double min_aperture = 1e-6;    // lower bound of the aperture in conductance and storage [m]
  double water_modulus = 2.2e9;  // K_w [Pa] (Fluid->Fluid Bulk Modulus): the crack water's
                                 // stiffness in the solid's stable-step estimate
  bool face_pressure = true;     // p_f on the crack's faces (true) or on fracture bonds (eq 17)
  // J criterion: the time [s] over which an increment's bond forces fall to zero
  // (J-Integral->Release Time; 0: at once; include/mupm/solvers/solid_solver.hpp).
  double release_time = 0;
};

// W_cr of eq 36 (3D) and its plane-strain analogue (header), per pair of unit volumes.
template <int Dim>
double critical_bond_energy(double g_cr, double horizon, double thickness) {
  if constexpr (Dim == 3)
    return 4.0 * g_cr / (M_PI * std::pow(horizon, 4));
  else
    return 3.0 * g_cr / (2.0 * thickness * std::pow(horizon, 3));
}

struct Breakage {
  long long bonds = 0;  // directed bonds broken on this rank (each pair twice over the ranks)
  double energy = 0;    // energy they released [J]: half of W V_i V_j per directed bond
};

// Breaks the intact bonds of the owned points whose W reached w_cr (eq 35) and adds the energy
// they release to released(i) [J]. Both copies of a bond hold the same W (solid pass 2), so
// both break in the same call, whichever ranks own the two ends. max_energy(i): the largest W
// of point i's intact bonds (solid pass 2): points below w_cr are skipped without a bond loop.
template <int Dim>
Breakage break_bonds(const Points<Dim>& pts, const Bonds& bonds, double w_cr,
                     const Scalars& max_energy, const Scalars& released) {
  auto offsets = bonds.offsets;
  auto neighbor = bonds.neighbor;
  auto intact = bonds.intact;
  auto W = bonds.energy;
  auto vol = pts.volume;
  auto wmax = max_energy;
  Breakage out;
  Kokkos::parallel_reduce(
      "mupm::Fracture::break_bonds", range(0, pts.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, long long& n, double& e) {
        if (!(wmax(i) >= w_cr))
          return;
        double ei = 0;
        for (BondIndex b = offsets(i); b < offsets(i + 1); ++b) {
          if (!intact(b) || !(W(b) >= w_cr))
            continue;
          intact(b) = 0;
          ++n;
          ei += 0.5 * W(b) * vol(i) * vol(neighbor(b));
        }
        if (ei != 0) {
          released(i) += ei;
          e += ei;
        }
      },
      out.bonds, out.energy);
  return out;
}

// Breaks the intact bonds of the owned points that cross `seg` (reference positions: both
// copies of a bond break, whichever ranks own its ends). Returns the directed bonds broken.
template <int Dim>
long long break_crossing(const Points<Dim>& pts, const Bonds& bonds, const Crack& seg) {
  auto offsets = bonds.offsets;
  auto neighbor = bonds.neighbor;
  auto intact = bonds.intact;
  auto x = pts.x;
  long long n = 0;
  Kokkos::parallel_reduce(
      "mupm::Fracture::break_crossing", range(0, pts.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, long long& acc) {
        double xi[Dim], xj[Dim];
        for (int d = 0; d < Dim; ++d)
          xi[d] = x(i, d);
        for (BondIndex b = offsets(i); b < offsets(i + 1); ++b) {
          if (!intact(b))
            continue;
          const int j = neighbor(b);
          for (int d = 0; d < Dim; ++d)
            xj[d] = x(j, d);
          if (bond_crosses<Dim>(seg, xi, xj)) {
            intact(b) = 0;
            ++acc;
          }
        }
      },
      n);
  return n;
}

}  // namespace mupm

#endif
