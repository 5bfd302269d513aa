// Fracture flow: the crack's normal, its cubic-law conductances and storage, and the force of
// the crack's water on its faces (paper eqs 17-19, 38-39, 58, 114, 118-120, 144, 146). Kernels
// and plain functions only: no MPI. The network solve that uses them is
// include/mupm/solvers/fracture_flow.hpp.
//
// The fracture space of a point. A crack of opening a between two faces is seen by the fracture
// points (D >= D_cr) around it: for a straight crack along a lattice plane with delta = 3 dx and
// D_cr = 0.3, one row on each side (the next rows lose 20 % of their bonds). Each of them gets
// the crack's full opening as its aperture (eqs 38-39, include/mupm/kernels/damage.hpp), so the
// crack is represented n_i times across its thickness, n_i the number of fracture points on the
// line through x_i along the crack normal: the fracture points j of i's family with
// |xi_par| < dx/2 (xi_par the part of xi = x_j - x_i in the crack plane), plus i itself. Point i
// then carries the share A_i = V_i / (n_i dx) of the crack's face area and the share
// phi_f,i = a_i / (n_i dx) of the crack's volume per unit volume.
//
// Conductance (deviation from eqs 58, 120, 123-124; say why): the paper writes the fracture flow
// with the correspondence gradient of the fracture family and k_f = a^2/12. The fracture family
// of a crack one or two rows thick is nearly a line (a plane in 3D): its shape tensor is
// singular across the crack, and k_f = a^2/12 smeared over a point of width dx passes dx/a times
// the cubic law. We use bond-based flow over the fracture bonds (both ends fracture points,
// eq 104, broken or not), volume rate from j to i
//   F_ij = Lambda_ij (p_f,j - p_f,i),   Lambda_ij = (kappa_i + kappa_j) / 2,
// with kappa_i calibrated to the cubic law: a crack of aperture a passes a^3/(12 mu_w) dp/ds per
// unit width. Under a uniform gradient g along the crack (tangent t), the rate across a
// section is the sum over the pairs that straddle it of Lambda (xi.t) g; a pair of offset xi
// straddles (xi.t)/dx of the sections per lattice column, so per unit width of crack
//   Q = 1/2 sum_{i per unit face area} sum_j Lambda_ij (xi.t)^2 g = kappa m / (2 A_i) g
// for a uniform band, m_i = sum_j |xi_par|^2 / (Dim - 1) (the in-plane mean of (xi.t)^2). Hence
//   kappa_i = a_i^3 A_i / (6 mu_w m_i).
// The test FractureFlow.CubicLawSlot checks the rate of a pressurized slot against a^3 dp/(12 mu
// L). The calibration counts the crack's rows along the lattice: a crack inclined to the lattice
// gets n_i and A_i approximately.
//
// Storage: the paper sets phi = 0 in the fracture space (eq 19) and eq 144 divides by
// phi dS_rf/dp_f, zero when saturated. We give the water in the crack's volume its
// compressibility: C_f,i = phi_f,i (dS_rf/dp_f + S_rf / K_w), with the storage aperture
// c_i + a_min in phi_f,i, c_i the signed mean opening (kernels/damage.hpp; Fracture->Minimum
// Aperture: a closed crack keeps a film of water, so a storage). The conductance takes
// max(a_i, a_min) (a closed crack keeps a conductance). Unlike eq 19 ("the volume coupling term
// vanishes") the crack's opening is booked: an opening dc_i makes room for S_rf dc_i / (n_i dx)
// of water per unit volume (solvers/fracture_flow.hpp says why: without it injected water can
// only compress).
//
// Exchange (eq 19; eq 118 has the order flipped): from the bulk into the fracture, per unit
// volume of the point, Q_s = (k_r k / mu_w) (p_w - p_f) / l_x * A / V with l_x = dx/2 and
// A / V = 1/dx (a point's face on the crack): Q_s = G_i (p_w - p_f), G_i = 2 k_r k / (mu_w dx^2).
//
// Force of the crack's water on its faces (deviation from eq 17; say why). Eq 17 replaces
// S_r T_w by S_rf T_f on the fracture bonds. Those bonds join fracture points on the same side
// of the crack (the bonds across it are broken and carry no force), so they lie along the faces
// and T_f = -p_f K^-1 xi pushes along the faces, not across: a pressurized crack would not
// open. What the crack's water does is push on its faces with p_f. We apply the force that is
// conjugate to the crack volume the network stores water in, so that the work the solid
// receives is the work the crack water gives (solvers/fracture_flow.hpp books
// sum V_i p_f,i S_rf,i dphi_f,i): point i's share of the crack volume is A_i c_i (A_i =
// V_i / (n_i dx), Points::pf_area, written by the network step; c_i its mean opening, eq 39,
// kernels/damage.hpp, c_i = sum_b w_ib (u_j - u_i).n_i over its broken bonds b = (i, j),
// w_ib = V_j / sum_b V_j, n_i its crack normal, a function of the reference positions), and the
// crack water's virtual work p_f,i S_rf,i A_i dc_i gives the forces
//   on j (each broken bond of i):  + P_i w_ib n_i,     on i:  - P_i n_i,    P_i = p_f,i S_rf,i A_i,
// equal and opposite, along n_i. With g_i = P_i n_i / sum_b V_j (a vector per network point,
// 0 elsewhere, refreshed onto the ghosts) the force density on point k is
//   f_k = sum over k's broken bonds (k, j) of [g_j - g_k V_j / V_k],
// which needs no bond list of a ghost (broken bonds are symmetric). On a straight crack this is
// p_f per unit face area on each face, exactly (sum_b w_ib = 1). The previous force (central
// pairs over the broken bonds, scaled by the continuum's crossing measure) gave 0.97458 of it at
// delta = 3 dx, and the solid 0.97423 of the crack water's work in a pressurized slot: the
// coupled pair lost energy. What remains with injection is the staggered step's lag (the solid
// steps with the pressure before the step's injection, solvers/fracture_flow.hpp): the solid
// receives 0.57, 0.74, 0.85 of the crack water's work at dt = 2, 1, 0.5 us early in an injection
// into a short notch (tests/cli/fracture_small.xml with water, 1e-2 m^2/s), first order in dt;
// the previous force gave 0.56 there. Momentum is conserved; the pair forces are along n_i rather
// than xi, so a pair exerts a couple, which cancels between the mirror-image pairs of a straight
// crack. The test FractureFlow.FacePressure measures the total force on a face against p_f times
// its area, FractureFlow.CrackForceWorkMatchesTheCrackWaterWork the two works.
#ifndef MUPM_FRACTURE_FLOW_HPP
#define MUPM_FRACTURE_FLOW_HPP

#include <cmath>

#include "mupm/kernels/damage.hpp"

namespace mupm {

// The crack water's pressure the solid applies, undrained (the fracture's analogue of the bulk's
// p* = p - (S_r/C) d(tr eps), eq 141's split): on a network point
//   p_f* = p_f - M_f (c - c_ref),   M_f = S_rf / (C_f n_i dx)   [Pa/m],
// c the point's mean opening now (kernels/damage.hpp), c_ref and p_f those of the last fracture-
// flow step (Points::pf_aperture, pf), M_f its undrained modulus (Points::pf_modulus, written by
// the fracture-flow step; 0 where p_f is prescribed). This is the p_f the next fracture-flow step
// starts from before any flow (solvers/fracture_flow.hpp), so the solid sees the crack water's
// stiffness at the displacement it is at. Without it the force used the p_f of one step earlier:
// a lagged spring of stiffness K_w/a_min, which grew without bound in Example 1 unless dt was
// below ~5e-8 s (measured). Off the network p_f* = p_f. Owned points; u current on the ghosts.
template <int Dim>
void undrained_fracture_pressure(const Bonds& bonds, const Points<Dim>& pts, const Scalars& out) {
  auto offsets = bonds.offsets;
  auto neighbor = bonds.neighbor;
  auto intact = bonds.intact;
  auto x = pts.x, u = pts.u, vol = pts.volume;
  auto pf = pts.pf, sat = pts.pf_saturation, ref = pts.pf_aperture, mod = pts.pf_modulus;
  Kokkos::parallel_for(
      "mupm::Fracture::undrained_pressure", range(0, pts.n_owned),
      KOKKOS_LAMBDA(const std::size_t i) {
        double p = pf(i);
        if (sat(i) > 0 && mod(i) != 0)
          p -= mod(i) * (mean_opening<Dim>(offsets, neighbor, intact, x, u, vol, i) - ref(i));
        out(i) = p;
      });
}

// g_i of the crack water's force (header) on the owned points, from the pressure `pf` (p_f*):
// P_i n_i / sum_b V_j on a network point (fracture_saturation > 0) with a crack normal and a
// face-area share, 0 elsewhere. Refresh it onto the ghosts before crack_pressure_force.
template <int Dim>
void crack_face_load(const Bonds& bonds, const Points<Dim>& pts, const Scalars& pf,
                     const Vectors& g) {
  auto offsets = bonds.offsets;
  auto neighbor = bonds.neighbor;
  auto intact = bonds.intact;
  auto x = pts.x, vol = pts.volume;
  auto sat = pts.pf_saturation, area = pts.pf_area;
  Kokkos::parallel_for(
      "mupm::Fracture::crack_face_load", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        double n[Dim] = {};
        double vsum = 0;
        if (sat(i) > 0 && area(i) > 0 && crack_normal<Dim>(offsets, neighbor, intact, x, i, n))
          for (BondIndex b = offsets(i); b < offsets(i + 1); ++b)
            if (!intact(b))
              vsum += vol(neighbor(b));
        const double s = vsum > 0 ? pf(i) * sat(i) * area(i) / vsum : 0.0;
        for (int d = 0; d < Dim; ++d)
          g(i, d) = s * n[d];
      });
}

// Adds the crack water's force density f_k = sum over broken bonds (k, j) of g_j - g_k V_j/V_k
// (header) to `body` (owned points); g from crack_face_load, current on the ghosts.
template <int Dim>
void crack_pressure_force(const Bonds& bonds, const Points<Dim>& pts, const Vectors& g,
                          const Vectors& body) {
  auto offsets = bonds.offsets;
  auto neighbor = bonds.neighbor;
  auto intact = bonds.intact;
  auto vol = pts.volume;
  Kokkos::parallel_for(
      "mupm::Fracture::crack_pressure", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t k) {
        double f[Dim] = {};
        const double inv_v = 1.0 / vol(k);
        for (BondIndex b = offsets(k); b < offsets(k + 1); ++b) {
          if (intact(b))
            continue;
          const int j = neighbor(b);
          const double w = vol(j) * inv_v;
          for (int d = 0; d < Dim; ++d)
            f[d] += g(j, d) - g(k, d) * w;
        }
        for (int d = 0; d < Dim; ++d)
          body(k, d) += f[d];
      });
}

}  // namespace mupm

#endif
