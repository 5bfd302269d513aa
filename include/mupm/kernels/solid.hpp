// Stabilized micropolar correspondence kernels (paper eqs 2-9, 43-51, 62-71, 96-112).
//
// The discrete energy is
//   Psi = sum_i V_i [ W(eps_i, kappa_i) + 1/2 sum_j (alpha1_ij |R1_ij|^2 + alpha2_ij |R2_ij|^2) V_j
//   ]
// with R1_ij = U^_ij - eps_i xi (eq 62), R2_ij = Omega_ij - kappa_i xi (eq 63). The force and
// moment states are exactly dPsi/dU^ and dPsi/dOmega:
//   T_ij = omega (sigma_i - S_r p_i 1 - Q1_i) K_i^-1 xi + alpha1_ij R1_ij         (eqs 46, 64)
//   M_ij = omega (m_i - Q2_i) K_i^-1 xi + alpha2_ij R2_ij                          (eq 65)
// where Q1_i = sum_j alpha1_ij R1_ij (x) xi V_j and Q2_i likewise. The Q terms are not in the
// paper's eqs 64-65: they vanish when alpha is the same on every bond of the family (then
// sum_j omega R (x) xi V_j = 0 by the definition of eps), and for any affine field (R = 0), but
// alpha ~ 1/|xi|^3 (eq 69) varies over the family, and without them the stabilization forces
// are not the gradient of any energy: the energy of an undamped run would drift. With them,
// f_i = sum_j (T_ij - T_ji) V_j and l_i = sum_j (M_ij - M_ji) V_j + 1/2 sum_j xi x (T_ij - T_ji)
// V_j are -dPsi/du_i / V_i and -dPsi/dtheta_i / V_i, so energy, linear and angular momentum are
// conserved by the central-difference scheme.
//
// Pore pressure in the total stress (undrained split). With a fluid, pass 1 uses
//   p* = p - (biot S_r / C) (tr eps - tr eps_ref)   (biot: PoreCoupling, 1 but in plane stress),
// the pressure the point would have if no water had flowed since the last fluid update
// (tr eps_ref; Points::undrained_modulus = biot S_r / C, zero where p is prescribed or without a
// fluid). The fluid update then starts from p* and adds the flow
// (include/mupm/solvers/fluid_solver.hpp). Using p itself (held over the solid step, "drained
// split") makes the pressure force lag the deformation by a step: with K_w/phi much larger than the
// skeleton's modulus the central difference is then unconditionally unstable (the lagged stiffness
// gives a characteristic root product 1 + (omega dt)^2 > 1). With p* the pore water is an undrained
// stiffness (biot S_r)^2 / C of the current state, whose waves the stable-step estimate includes.
// (Kim, Tchelepi & Juanes 2011 analyse the same splits for implicit coupling.)
//
// Kernels only: no MPI; the solver refreshes the ghosts between the passes
// (include/mupm/solvers/solid_forces.hpp).
//
// A point whose intact bonds leave K singular (det K below 1e-6 of a well-conditioned K of the
// same trace) is "degenerate": eps = kappa = 0 there and its bonds act as the stabilization
// springs alone (T_ij = alpha1 U^, M_ij = alpha2 Omega): still the gradient of Psi, never NaN.
#ifndef MUPM_SOLID_HPP
#define MUPM_SOLID_HPP

#include <cmath>
#include <type_traits>
#include <vector>

#include "mupm/core/small_matrix.hpp"
#include "mupm/data/bonds.hpp"
#include "mupm/data/points.hpp"
#include "mupm/data/shape_tensors.hpp"
#include "mupm/laws/micropolar_elastic.hpp"
#include "mupm/laws/stabilization.hpp"

namespace mupm {

struct SolidParams {
  MicropolarElastic law;
  double stabilization = 0.5;  // G in [0, 1] (eqs 66-67)
  double stab_modulus = 0;     // D (eq 71 or the bulk-matched value), Pa/m^2
  double horizon_volume = 0;   // volume of a full continuous family (pi delta^2 h, 4/3 pi delta^3)
  PoreCoupling pore;           // the pore pressure's coefficient (plane stress: biot < 1)
};

// What pass 2 does with the bond energy W (eq 34; include/mupm/kernels/fracture.hpp):
// Off: nothing (stable-step estimates, tests of the forces); Record: keep each bond's pair force
// state as the start of the next step's trapezoid; Accumulate: W += the trapezoid of the pair
// force states over the step's increment, then record.
enum class BondWork { Off, Record, Accumulate };

template <int Dim>
struct SolidState {
  static constexpr int R = kRotDim<Dim>;
  Vectors eps, kappa;  // nonlocal strain and wryness (eqs 50-51), owned + ghosts
  Vectors P1, P2;      // (sigma - S_r p 1 - Q1) K^-1 and (m - Q2) K^-1, owned + ghosts
  Scalars winv;        // V_H / omega_0, 1 over the family's share of a full family (eq 68);
                       // 0 where the family is empty or the point carries no energy
  Bytes degenerate;    // 1 where K is singular
  Vectors force;       // force density f_i [n_owned][Dim]
  Vectors moment;      // moment density [n_owned][R]
  Scalars energy;      // V_i (W_i + stabilization energy density) [n_owned]
  Scalars pstar;       // p* of this evaluation (undrained split, below) [n_owned]
  // Bond energy (runs that break bonds): the step's increment of (u, theta) [n_all][Dim + R]
  // (ghosts refreshed by the solver with u), and S_r p* K^-1 [n_all][Dim*Dim] when the energy
  // takes the effective force state with a fluid (allocated then only; pass 1 fills it).
  BondWork work = BondWork::Off;
  Vectors increment;
  Vectors P1w;
  // Fracture flow with the paper's eq 17 (Fracture->Crack Water Force = Eq 17): on the fracture
  // network (fracture_saturation > 0) (S_r p* - S_rf p_f) K^-1 [n_all][Dim*Dim], so that a
  // bond between two network points carries -S_rf p_f K^-1 xi in place of -S_r p* K^-1 xi.
  Vectors P1f;
  Vectors water_force;  // the eq 17 part of (f, l) [n_owned][Dim + R] (with P1f)
  Scalars max_energy;   // largest W of the point's intact bonds after Accumulate [n_owned]

  void allocate(std::size_t n_all, std::size_t n_owned) {
    eps = Vectors("mupm::eps", n_all, Dim * Dim);
    kappa = Vectors("mupm::kappa", n_all, R * Dim);
    P1 = Vectors("mupm::P1", n_all, Dim * Dim);
    P2 = Vectors("mupm::P2", n_all, R * Dim);
    winv = Scalars("mupm::inverse_family_share", n_all);
    degenerate = Bytes("mupm::degenerate", n_all);
    force = Vectors("mupm::force", n_owned, Dim);
    moment = Vectors("mupm::moment", n_owned, R);
    energy = Scalars("mupm::strain_energy", n_owned);
    pstar = Scalars("mupm::solid_pore_pressure", n_owned);
  }
  // Crack Water Force = Eq 17 (fracture flow): P1f and water_force.
  void allocate_eq17(std::size_t n_all, std::size_t n_owned) {
    P1f = Vectors("mupm::fracture_part_of_P1", n_all, Dim * Dim);
    water_force = Vectors("mupm::eq17_force", n_owned, Dim + R);
  }
  // What pass 2 reads from the neighbours, besides u and theta.
  std::vector<Vectors> pass2_ghosts() const {
    std::vector<Vectors> g{eps, kappa, P1, P2, as_vectors(winv)};
    if (P1w.extent(0) > 0)
      g.push_back(P1w);
    if (P1f.extent(0) > 0)
      g.push_back(P1f);
    return g;
  }
};

// Kinematics of bond i -> j (eqs 2-9): xi = x_j - x_i, the composite relative displacement
// U^ = (u_j - u_i) - Omega-bar x xi with Omega-bar = (theta_i + theta_j)/2, and the relative
// rotation Omega = theta_j - theta_i. Returns |xi|^2.
template <int Dim, class X, class U, class T>
KOKKOS_INLINE_FUNCTION double bond_kinematics(const X& x, const U& u, const T& th, int i, int j,
                                              double* xi, double* uh, double* om) {
  constexpr int R = kRotDim<Dim>;
  double tb[R], c[Dim], len2 = 0;
  for (int d = 0; d < Dim; ++d) {
    xi[d] = x(j, d) - x(i, d);
    len2 += xi[d] * xi[d];
  }
  for (int r = 0; r < R; ++r) {
    tb[r] = 0.5 * (th(i, r) + th(j, r));
    om[r] = th(j, r) - th(i, r);
  }
  rot_cross<Dim>(tb, xi, c);
  for (int d = 0; d < Dim; ++d)
    uh[d] = u(j, d) - u(i, d) - c[d];
  return len2;
}

// Both passes take a family's bonds kBondLanes at a time: a gather loop copies each bond's
// neighbour rows into lane arrays, one loop over the lanes, which the compiler vectorizes
// (`GCC ivdep`; no branch: a broken bond or a padding lane counts with a zero volume), computes
// each bond's terms into per-lane sums or pair states, and the lanes are summed in a fixed order
// at the end. Pass 2 then records and accumulates the bond energy bond by bond from the lanes'
// pair states. Every lane evaluates the scalar expressions operation for operation (IEEE; the
// build contracts nothing into FMAs, CMakeLists.txt), so both ends of a bond still hold exactly
// negated pair states. Only the order of a family's sums (lane by lane, then the lanes in order)
// differs from a plain loop, and it is the same on any rank or thread count.
template <int Dim>
constexpr int kBondLanes = Dim == 2 ? 16 : 8;  // measured best (perf/README.md)

// A block of kBondLanes bonds of point i: its own x, u, theta, and each lane's neighbour's with
// the neighbour's volume (0 for a broken bond or a padding lane, which repeats the block's last
// bond). Both passes gather into it and take each lane's kinematics from it.
template <int Dim>
struct BondLanes {
  static constexpr int R = kRotDim<Dim>;
  static constexpr int L = kBondLanes<Dim>;
  double xo[Dim], uo[Dim], to[R];
  double x[Dim][L], u[Dim][L], t[R][L], v[L];

  template <class X, class U, class T>
  KOKKOS_INLINE_FUNCTION void owner(const X& xv, const U& uv, const T& th, std::size_t i) {
    for (int d = 0; d < Dim; ++d) {
      xo[d] = xv(i, d);
      uo[d] = uv(i, d);
    }
    for (int r = 0; r < R; ++r)
      to[r] = th(i, r);
  }
  // Lane q of the block of n bonds from b0; returns the lane's neighbour.
  template <class N, class I, class V, class X, class U, class T>
  KOKKOS_INLINE_FUNCTION int gather(int q, BondIndex b0, int n, const N& neighbor, const I& intact,
                                    const V& vol, const X& xv, const U& uv, const T& th) {
    const BondIndex b = b0 + (q < n ? q : n - 1);
    const int j = neighbor(b);
    v[q] = q < n && intact(b) ? vol(j) : 0.0;
    for (int d = 0; d < Dim; ++d) {
      x[d][q] = xv(j, d);
      u[d][q] = uv(j, d);
    }
    for (int r = 0; r < R; ++r)
      t[r][q] = th(j, r);
    return j;
  }
  // Lane q's bond kinematics (eqs 2-9, as bond_kinematics): xi, U^, Omega; returns |xi|^2.
  KOKKOS_INLINE_FUNCTION double kinematics(int q, double* xi, double* uh, double* om) const {
    double tb[R], c[Dim], len2 = 0;
#pragma GCC unroll 16
    for (int d = 0; d < Dim; ++d) {
      xi[d] = x[d][q] - xo[d];
      len2 += xi[d] * xi[d];
    }
#pragma GCC unroll 16
    for (int r = 0; r < R; ++r) {
      tb[r] = 0.5 * (to[r] + t[r][q]);
      om[r] = t[r][q] - to[r];
    }
    rot_cross<Dim>(tb, xi, c);
#pragma GCC unroll 16
    for (int d = 0; d < Dim; ++d)
      uh[d] = u[d][q] - uo[d] - c[d];
    return len2;
  }
};

// Pass 1 (per owned point): eps, kappa (with K^-1 of the shape-tensor cache), the constitutive
// update by `law` (sigma-bar, m into pts.stress, pts.couple_stress), Q1, Q2, and the point's
// energy. Law: a pointwise micropolar law with
//   KOKKOS_FUNCTION double stress<Dim>(std::size_t i, const double* eps, const double* kappa,
//                                      double* sigma, double* m) const
// (returns the stored energy density W; i: the point, for a law with a state), chosen once by
// the solver (include/mupm/laws/): MicropolarElastic is eqs 80-81, MicropolarDruckerPrager
// eqs 80-95.
template <int Dim, class Law>
void solid_pass1(const Points<Dim>& pts, const Bonds& bonds, const ShapeTensors<Dim>& shape,
                 const SolidParams& prm, const Law& law, SolidState<Dim>& st) {
  constexpr int R = kRotDim<Dim>;
  auto offsets = bonds.offsets;
  auto neighbor = bonds.neighbor;
  auto intact = bonds.intact;
  auto x = pts.x, u = pts.u, th = pts.theta;
  auto vol = pts.volume, p = pts.p, sr = pts.saturation;
  auto bu = pts.undrained_modulus, ref = pts.vol_strain_ref;
  auto sigma_v = pts.stress, m_v = pts.couple_stress;
  auto eps_v = st.eps, kap_v = st.kappa, P1 = st.P1, P2 = st.P2, winv = st.winv;
  auto degen = st.degenerate;
  auto energy = st.energy;
  auto pstar = st.pstar;
  auto P1w = st.P1w;
  const bool effective = P1w.extent(0) > 0;
  auto P1f = st.P1f;
  auto pf = pts.pf, srf = pts.pf_saturation;
  const bool eq17 = P1f.extent(0) > 0;
  auto Kinv_v = shape.Kinv, fam = shape.family_volume;
  auto sing = shape.singular;
  const double c1 = prm.stabilization * 12.0 * prm.stab_modulus;  // G C1 |xi|^3
  const double c2 = prm.stabilization * prm.stab_modulus;         // G C2 |xi|
  const double inv_vh = 1.0 / prm.horizon_volume;
  const double biot = prm.pore.biot;
  auto fixed = pts.fixed;
  Kokkos::parallel_for(
      "mupm::Solid::pass1", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        // A slaved boundary-layer point (kernels/boundary_conditions.hpp, slave_layer) carries no
        // strain energy: zero states, so its own T_ij = M_ij = 0 and its energy 0; the body's
        // states still reach it (pass 2), which is the force the slaving folds back.
        if (fixed(i) & kFixedNoEnergy) {
          for (int k = 0; k < Dim * Dim; ++k) {
            eps_v(i, k) = P1(i, k) = sigma_v(i, k) = 0;
            if (effective)
              P1w(i, k) = 0;
            if (eq17)
              P1f(i, k) = 0;
          }
          for (int k = 0; k < R * Dim; ++k)
            kap_v(i, k) = P2(i, k) = m_v(i, k) = 0;
          winv(i) = 0;  // no stabilization of its own
          pstar(i) = p(i);
          degen(i) = 0;
          energy(i) = 0;
          return;
        }
        // One loop over the family. Besides A = sum U^ (x) xi V and B = sum Omega (x) xi V (eqs
        // 50-51) it collects the moments the stabilization needs, with g1 = c1/|xi|^3 and
        // g2 = c2/|xi| (alpha = g/w0, eqs 66-70):
        //   Ag = sum g1 U^ (x) xi V, Bg = sum g2 Omega (x) xi V, Mg = sum g xi (x) xi V,
        //   s1 = sum g1 |U^|^2 V, s2 = sum g2 |Omega|^2 V.
        // Then Q1 = sum alpha1 (U^ - eps xi) (x) xi V = (Ag - eps Mg1)/w0, Q2 likewise, and
        // sum alpha1 |U^ - eps xi|^2 V = (s1 - 2 eps:Ag + sum_a eps_a.Mg1.eps_a)/w0: the same
        // sums as a second loop over the residuals, without visiting the family twice (g1, g2
        // below include V_j). The energy is now a difference of sums that nearly cancel where
        // the field is nearly affine: its round-off is that of s1, and a point's stabilization
        // energy may come out a few ulps of s1 below zero (energies only; the forces take Q).
        // The sums are taken in lanes (kBondLanes, above), each lane's own, then added in order.
        constexpr int NS = Dim * (Dim + 1) / 2;  // Mg: symmetric, upper triangle by rows
        constexpr int L = kBondLanes<Dim>;
        double lA[Dim * Dim][L] = {}, lB[R * Dim][L] = {}, lAg[Dim * Dim][L] = {},
                        lBg[R * Dim][L] = {}, lM1[NS][L] = {}, lM2[NS][L] = {}, ls1[L] = {},
                        ls2[L] = {};
        BondLanes<Dim> g;
        g.owner(x, u, th, i);
        const BondIndex end = offsets(i + 1);
        for (BondIndex b0 = offsets(i); b0 < end; b0 += L) {
          const int n = end - b0 < L ? int(end - b0) : L;
          for (int q = 0; q < L; ++q)
            g.gather(q, b0, n, neighbor, intact, vol, x, u, th);
#pragma GCC ivdep
          for (int q = 0; q < L; ++q) {
            const double vj = g.v[q];
            double xi[Dim], uh[Dim], om[R];
            const double len2 = g.kinematics(q, xi, uh, om);
            const double il = 1.0 / std::sqrt(len2);
            const double g1 = c1 * il * il * il * vj, g2 = c2 * il * vj;
            double xv[Dim];
#pragma GCC unroll 16
            for (int k = 0; k < Dim; ++k)
              xv[k] = xi[k] * vj;
#pragma GCC unroll 16
            for (int a = 0; a < Dim; ++a) {
              ls1[q] += g1 * uh[a] * uh[a];
#pragma GCC unroll 16
              for (int k = 0; k < Dim; ++k) {
                lA[a * Dim + k][q] += uh[a] * xv[k];  // U^ (x) xi (eq 50)
                lAg[a * Dim + k][q] += g1 * uh[a] * xi[k];
              }
            }
#pragma GCC unroll 16
            for (int r = 0; r < R; ++r) {
              ls2[q] += g2 * om[r] * om[r];
#pragma GCC unroll 16
              for (int k = 0; k < Dim; ++k) {
                lB[r * Dim + k][q] += om[r] * xv[k];  // eq 51
                lBg[r * Dim + k][q] += g2 * om[r] * xi[k];
              }
            }
#pragma GCC unroll 16
            for (int k = 0; k < Dim; ++k)
#pragma GCC unroll 16
              for (int l = k; l < Dim; ++l) {
                const int n2 = k * Dim - k * (k - 1) / 2 + (l - k);
                lM1[n2][q] += g1 * xi[k] * xi[l];
                lM2[n2][q] += g2 * xi[k] * xi[l];
              }
          }
        }
        double A[Dim * Dim] = {}, B[R * Dim] = {}, Ag[Dim * Dim] = {}, Bg[R * Dim] = {};
        double Mg1[NS] = {}, Mg2[NS] = {}, s1 = 0, s2 = 0;
        for (int q = 0; q < L; ++q) {
          for (int k = 0; k < Dim * Dim; ++k) {
            A[k] += lA[k][q];
            Ag[k] += lAg[k][q];
          }
          for (int k = 0; k < R * Dim; ++k) {
            B[k] += lB[k][q];
            Bg[k] += lBg[k][q];
          }
          for (int k = 0; k < NS; ++k) {
            Mg1[k] += lM1[k][q];
            Mg2[k] += lM2[k][q];
          }
          s1 += ls1[q];
          s2 += ls2[q];
        }
        double Kinv[Dim * Dim], eps[Dim * Dim] = {}, kap[R * Dim] = {};
        for (int k = 0; k < Dim * Dim; ++k)
          Kinv[k] = Kinv_v(i, k);
        const bool singular = sing(i) != 0;
        const double wsum = fam(i);
        if (!singular) {
          mat_mul<Dim, Dim>(A, Kinv, eps);
          mat_mul<R, Dim>(B, Kinv, kap);
        }
        // The pore pressure of the total stress, sigma-bar - biot S_r p* 1 (eq 46): p* of the
        // undrained split (header), with the plastic law's shift of the volumetric strain
        // (plane stress with pore water, laws/micropolar_drucker_prager.hpp; 0 otherwise).
        double pe = p(i);
        if (bu(i) != 0) {
          double tr_eps = law.pore_shift_start(i);
          for (int d = 0; d < Dim; ++d)
            tr_eps += eps[d * Dim + d];
          pe -= bu(i) * (tr_eps - ref(i));  // undrained split (header)
        }
        double sig[Dim * Dim], m[R * Dim];
        double w = law.template stress<Dim>(i, eps, kap, sig, m, sr(i) * pe);
        if (singular)
          w = 0;
        const double w0 = wsum * inv_vh;
        // Stabilization: Q1, Q2 and the energy of the residuals from the moments (above).
        double Q1[Dim * Dim] = {}, Q2[R * Dim] = {};
        double ws = 0;
        const double iw = w0 > 0 ? 1.0 / w0 : 0.0;
        if (w0 > 0) {
          double M1[Dim * Dim], M2[Dim * Dim];
          for (int k = 0, n = 0; k < Dim; ++k)
            for (int l = k; l < Dim; ++l, ++n) {
              M1[k * Dim + l] = M1[l * Dim + k] = Mg1[n];
              M2[k * Dim + l] = M2[l * Dim + k] = Mg2[n];
            }
          double eM[Dim * Dim], kM[R * Dim];
          mat_mul<Dim, Dim>(eps, M1, eM);
          mat_mul<R, Dim>(kap, M2, kM);
          double e1 = s1, e2 = s2;
          for (int k = 0; k < Dim * Dim; ++k) {
            Q1[k] = (Ag[k] - eM[k]) * iw;
            e1 += eps[k] * (eM[k] - 2 * Ag[k]);
          }
          for (int k = 0; k < R * Dim; ++k) {
            Q2[k] = (Bg[k] - kM[k]) * iw;
            e2 += kap[k] * (kM[k] - 2 * Bg[k]);
          }
          ws = 0.5 * (e1 + e2) * iw;
        }
        // Total stress sigma-bar - biot S_r p* 1 (eq 46) less the stabilization stress, times K^-1.
        const double bsp = biot * sr(i) * pe;  // PoreCoupling: biot = 1 but in plane stress
        double S[Dim * Dim], Mm[R * Dim], p1[Dim * Dim], p2[R * Dim];
        for (int a = 0; a < Dim; ++a)
          for (int k = 0; k < Dim; ++k)
            S[a * Dim + k] = sig[a * Dim + k] - (a == k ? bsp : 0.0) - Q1[a * Dim + k];
        for (int k = 0; k < R * Dim; ++k)
          Mm[k] = m[k] - Q2[k];
        mat_mul<Dim, Dim>(S, Kinv, p1);
        mat_mul<R, Dim>(Mm, Kinv, p2);
        for (int k = 0; k < Dim * Dim; ++k) {
          eps_v(i, k) = eps[k];
          P1(i, k) = p1[k];
          sigma_v(i, k) = sig[k];
        }
        for (int k = 0; k < R * Dim; ++k) {
          kap_v(i, k) = kap[k];
          P2(i, k) = p2[k];
          m_v(i, k) = m[k];
        }
        if (effective)
          for (int k = 0; k < Dim * Dim; ++k)
            P1w(i, k) = bsp * Kinv[k];  // the pore-water part of P1, with opposite sign
        if (eq17) {
          const double dp = srf(i) > 0 ? bsp - srf(i) * pf(i) : 0.0;  // eq 17
          for (int k = 0; k < Dim * Dim; ++k)
            P1f(i, k) = dp * Kinv[k];
        }
        winv(i) = iw;
        pstar(i) = pe;
        degen(i) = singular ? 1 : 0;
        energy(i) = vol(i) * (w + ws);
      });
}

// Pass 2 (per owned point, full neighbour list, no atomics): force and moment densities
// (eqs 105-112): f_i = sum_j (T_ij - T_ji) V_j,
// l_i = sum_j (M_ij - M_ji) V_j + 1/2 sum_j xi x (T_ij - T_ji) V_j. Needs the ghosts' u, theta,
// eps, kappa, P1, P2, winv (and increment, P1w when st.work is on).
//
// Bond energy (eq 34), with st.work = Accumulate: per pair of unit volumes,
// dW = (T_ij - T_ji).dU^ + (M_ij - M_ji).dOmega, integrated over the step by the
// trapezoid rule between the pair states of the last evaluation (Bonds::pair_force) and this
// one. Summed over the pairs (times V_i V_j) this is exactly the work of the forces f, l on the
// step's increments, the trapezoid the solid solver books as external work: elastic energy is
// neither made nor lost by the bookkeeping. The pair states are assembled as
// (P1_i xi + P1_j xi) + (stab_i + stab_j), every sum of an i term and a j term, so that the
// copy j -> i evaluates exactly the negated numbers: both copies of a bond hold the same W to the
// last bit on any number of ranks, and break on the same step. The increments dU^, dOmega come
// from the per-point increments the same way (the step's change of U^ and Omega, exactly, as
// both are linear in u and theta).
// Which force state (eq 34 adds S_r T_w to the effective state, making it the total one; the
// text says effective): with st.P1w allocated, the effective state, the pore-water part
// -(S_r p* K^-1 xi) of each end taken out: the skeleton's bonds break by the skeleton's stress
// (Terzaghi). Without it (no fluid, or Fracture->Bond Energy Force State = Total) the total.
//
// The variant (eq 17's water force, recording or accumulating the bond energy, the effective
// force state) is fixed for a run: solid_pass2 picks an instantiation of solid_pass2_variant, whose
// bond loop tests none of them (so that a device backend compiles each as a kernel of its own).
template <bool Eq17, BondWork Work, bool Effective>
struct Pass2Variant {
  static constexpr bool eq17 = Eq17;
  static constexpr bool record = Work != BondWork::Off;
  static constexpr bool accumulate = Work == BondWork::Accumulate;
  static constexpr bool effective = Effective && record;
};

template <int Dim, class V>
void solid_pass2_variant(const Points<Dim>& pts, const Bonds& bonds, const SolidParams& prm,
                         SolidState<Dim>& st) {
  constexpr int R = kRotDim<Dim>;
  constexpr int L = kBondLanes<Dim>;
  constexpr int D2 = Dim * Dim, RD = R * Dim;
  auto offsets = bonds.offsets;
  auto neighbor = bonds.neighbor;
  auto intact = bonds.intact;
  auto W = bonds.energy;
  auto pair = bonds.pair_force;
  auto x = pts.x, u = pts.u, th = pts.theta;
  auto vol = pts.volume;
  auto eps = st.eps, kap = st.kappa, P1 = st.P1, P2 = st.P2, winv = st.winv;
  auto inc = st.increment, P1w = st.P1w, wmax = st.max_energy;
  auto P1f = st.P1f, srf = pts.pf_saturation;
  auto fw = st.water_force;
  auto force = st.force, moment = st.moment;
  const double c1 = prm.stabilization * 12.0 * prm.stab_modulus;
  const double c2 = prm.stabilization * prm.stab_modulus;
  Kokkos::parallel_for(
      "mupm::Solid::pass2", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        double f[Dim] = {}, l[R] = {}, wm = 0, f17[Dim + R] = {};
        // The owned point's rows, read once (the bond loop's stores could alias them).
        BondLanes<Dim> g;
        g.owner(x, u, th, i);
        double P1i[D2], Ei[D2], P2i[RD], Ki[RD], P1fi[D2] = {};
        for (int k = 0; k < D2; ++k) {
          P1i[k] = P1(i, k);
          Ei[k] = eps(i, k);
          if constexpr (V::eq17)
            P1fi[k] = P1f(i, k);
        }
        for (int k = 0; k < RD; ++k) {
          P2i[k] = P2(i, k);
          Ki[k] = kap(i, k);
        }
        const double winv_i = winv(i);
        const bool net_i = V::eq17 && srf(i) > 0;
        const BondIndex end = offsets(i + 1);
        for (BondIndex b0 = offsets(i); b0 < end; b0 += L) {
          const int n = end - b0 < L ? int(end - b0) : L;
          // Gather: lane q holds bond b0 + q (padding lanes repeat the last bond, weight 0).
          double gP1[D2][L], gE[D2][L], gP2[RD][L], gK[RD][L], gw[L], gf[D2][L], gn[L];
          for (int q = 0; q < L; ++q) {
            const int j = g.gather(q, b0, n, neighbor, intact, vol, x, u, th);
            gw[q] = winv(j);
            for (int k = 0; k < D2; ++k) {
              gP1[k][q] = P1(j, k);
              gE[k][q] = eps(j, k);
            }
            for (int k = 0; k < RD; ++k) {
              gP2[k][q] = P2(j, k);
              gK[k][q] = kap(j, k);
            }
            if constexpr (V::eq17) {
              gn[q] = net_i && srf(j) > 0 ? 1.0 : 0.0;
              for (int k = 0; k < D2; ++k)
                gf[k][q] = P1f(j, k);
            }
          }
          // Per lane: xi, the pair states T_ij - T_ji (t) and M_ij - M_ji (m), and their terms.
          double lxi[Dim][L], lt[Dim][L], lm[R][L], lf[Dim][L], ll[R][L], l17[Dim + R][L];
#pragma GCC ivdep
          for (int q = 0; q < L; ++q) {
            const double vj = g.v[q];
            double xi[Dim], Uh[Dim], Om[R];
            const double len2 = g.kinematics(q, xi, Uh, Om);
            const double il = 1.0 / std::sqrt(len2);
            const double a1 = c1 * (il * il * il), a2 = c2 * il;  // eqs 66-70 with w0 = 1
            const double a1i = a1 * winv_i, a2i = a2 * winv_i, a1j = a1 * gw[q], a2j = a2 * gw[q];
            // T_ij - T_ji with xi_ji = -xi, U^_ji = -U^_ij:
            //   T_ij = P1_i xi + a1i (U^ - eps_i xi),  T_ji = -P1_j xi - a1j (U^ - eps_j xi).
            double cf[Dim] = {};
            if constexpr (V::eq17) {  // eq 17: a fracture bond's water is p_f's
#pragma GCC unroll 16
              for (int a = 0; a < Dim; ++a) {
                double ci = 0, cj = 0;
#pragma GCC unroll 16
                for (int k = 0; k < Dim; ++k) {
                  ci += P1fi[a * Dim + k] * xi[k];
                  cj += gf[a * Dim + k][q] * xi[k];
                }
                cf[a] = gn[q] * (ci + cj);
              }
              double xc[R];
              cross<Dim>(xi, cf, xc);
#pragma GCC unroll 16
              for (int a = 0; a < Dim; ++a)
                l17[a][q] = cf[a] * vj;
#pragma GCC unroll 16
              for (int r = 0; r < R; ++r)
                l17[Dim + r][q] = 0.5 * xc[r] * vj;
            }
            double t[Dim], m[R];
#pragma GCC unroll 16
            for (int a = 0; a < Dim; ++a) {
              double pi = 0, pj = 0, ei = 0, ej = 0;
#pragma GCC unroll 16
              for (int k = 0; k < Dim; ++k) {
                pi += P1i[a * Dim + k] * xi[k];
                pj += gP1[a * Dim + k][q] * xi[k];
                ei += Ei[a * Dim + k] * xi[k];
                ej += gE[a * Dim + k][q] * xi[k];
              }
              t[a] = ((pi + pj) + (a1i * (Uh[a] - ei) + a1j * (Uh[a] - ej))) + cf[a];
            }
// M_ij - M_ji, Omega_ji = -Omega_ij.
#pragma GCC unroll 16
            for (int r = 0; r < R; ++r) {
              double pi = 0, pj = 0, ki = 0, kj = 0;
#pragma GCC unroll 16
              for (int k = 0; k < Dim; ++k) {
                pi += P2i[r * Dim + k] * xi[k];
                pj += gP2[r * Dim + k][q] * xi[k];
                ki += Ki[r * Dim + k] * xi[k];
                kj += gK[r * Dim + k][q] * xi[k];
              }
              m[r] = (pi + pj) + (a2i * (Om[r] - ki) + a2j * (Om[r] - kj));
            }
            double xt[R];
            cross<Dim>(xi, t, xt);  // 1/2 xi x (T_ij - T_ji)
#pragma GCC unroll 16
            for (int a = 0; a < Dim; ++a) {
              lxi[a][q] = xi[a];
              lt[a][q] = t[a];
              lf[a][q] = t[a] * vj;
            }
#pragma GCC unroll 16
            for (int r = 0; r < R; ++r) {
              lm[r][q] = m[r];
              ll[r][q] = m[r] * vj + 0.5 * xt[r] * vj;
            }
          }
          for (int q = 0; q < L; ++q) {
            for (int a = 0; a < Dim; ++a)
              f[a] += lf[a][q];
            for (int r = 0; r < R; ++r)
              l[r] += ll[r][q];
            if constexpr (V::eq17)
              for (int c = 0; c < Dim + R; ++c)
                f17[c] += l17[c][q];
          }
          if constexpr (V::record)
            for (int q = 0; q < n; ++q) {
              const BondIndex b = b0 + q;
              if (!intact(b))
                continue;
              const int j = neighbor(b);
              double t[Dim], m[R], xi[Dim];
              for (int a = 0; a < Dim; ++a) {
                t[a] = lt[a][q];
                xi[a] = lxi[a][q];
              }
              for (int r = 0; r < R; ++r)
                m[r] = lm[r][q];
              if constexpr (V::effective)  // take out -(S_r p* K^-1 xi) of both ends (header)
                for (int a = 0; a < Dim; ++a) {
                  double wi = 0, wj = 0, ci = 0, cj = 0;
                  for (int k = 0; k < Dim; ++k) {
                    wi += P1w(i, a * Dim + k) * xi[k];
                    wj += P1w(j, a * Dim + k) * xi[k];
                    if constexpr (V::eq17) {
                      ci += P1fi[a * Dim + k] * xi[k];
                      cj += P1f(j, a * Dim + k) * xi[k];
                    }
                  }
                  // the bond's water part, whichever pressure (cf as the lane computed it)
                  const double cf = V::eq17 ? gn[q] * (ci + cj) : 0.0;
                  t[a] += (wi + wj) - cf;
                }
              if constexpr (V::accumulate) {
                // dU^ = d(u_j - u_i) - (d theta_i + d theta_j)/2 x xi, dOmega = d theta_j - d
                // theta_i.
                double tb[R], c[Dim], dw = 0;
                for (int r = 0; r < R; ++r)
                  tb[r] = 0.5 * (inc(i, Dim + r) + inc(j, Dim + r));
                rot_cross<Dim>(tb, xi, c);
                for (int a = 0; a < Dim; ++a)
                  dw += 0.5 * (pair(b, a) + t[a]) * (inc(j, a) - inc(i, a) - c[a]);
                for (int r = 0; r < R; ++r)
                  dw += 0.5 * (pair(b, Dim + r) + m[r]) * (inc(j, Dim + r) - inc(i, Dim + r));
                W(b) += dw;
                wm = W(b) > wm ? W(b) : wm;
              }
              for (int a = 0; a < Dim; ++a)
                pair(b, a) = t[a];
              for (int r = 0; r < R; ++r)
                pair(b, Dim + r) = m[r];
            }
        }
        for (int d = 0; d < Dim; ++d)
          force(i, d) = f[d];
        for (int r = 0; r < R; ++r)
          moment(i, r) = l[r];
        if constexpr (V::accumulate)
          wmax(i) = wm;
        if constexpr (V::eq17)
          for (int c = 0; c < Dim + R; ++c)
            fw(i, c) = f17[c];
      });
}

template <int Dim>
void solid_pass2(const Points<Dim>& pts, const Bonds& bonds, const SolidParams& prm,
                 SolidState<Dim>& st) {
  constexpr int R = kRotDim<Dim>;
  const bool eq17 = st.P1f.extent(0) > 0, effective = st.P1w.extent(0) > 0;
  const BondWork work = bonds.pair_width == Dim + R ? st.work : BondWork::Off;
  auto run = [&](auto eq17_tag, auto work_tag, auto effective_tag) {
    solid_pass2_variant<Dim, Pass2Variant<decltype(eq17_tag)::value, decltype(work_tag)::value,
                                          decltype(effective_tag)::value>>(pts, bonds, prm, st);
  };
  auto with_work = [&](auto eq17_tag) {
    using T = std::true_type;
    using F = std::false_type;
    using Off = std::integral_constant<BondWork, BondWork::Off>;
    using Rec = std::integral_constant<BondWork, BondWork::Record>;
    using Acc = std::integral_constant<BondWork, BondWork::Accumulate>;
    if (work == BondWork::Off)
      run(eq17_tag, Off{}, F{});
    else if (work == BondWork::Record)
      effective ? run(eq17_tag, Rec{}, T{}) : run(eq17_tag, Rec{}, F{});
    else
      effective ? run(eq17_tag, Acc{}, T{}) : run(eq17_tag, Acc{}, F{});
  };
  eq17 ? with_work(std::true_type{}) : with_work(std::false_type{});
}

// Pass 1 of a uniform total stress sigma ([Dim*Dim], row a = force direction, as P1) with no
// stabilization, for the consistent surface load of a traction (include/mupm/kernels/
// boundary_conditions.hpp, consistent_traction_load): P1 = sigma K^-1 on the points that carry
// energy (0 on slaved layer points and where K is singular), P2 = eps = kappa = 0, winv = 0. Pass 2
// then gives the force and moment densities the discrete operator makes of that stress,
//   f_i = sigma sum_j (K_i^-1 + K_j^-1) xi V_j,   l_i = 1/2 sum_j xi x (T_ij - T_ji) V_j
// (eqs 105-112 with T = sigma K^-1 xi): zero where families are whole and K is the bulk's, the
// surface's share of the divergence of sigma within 2 delta of a face. Sign: f_i V_i summed over
// a strip along a face is -sigma n times the face's area (n outward).
template <int Dim>
void uniform_stress_pass1(const Points<Dim>& pts, const ShapeTensors<Dim>& shape,
                          const Kokkos::Array<double, 9>& sigma, SolidState<Dim>& st) {
  constexpr int R = kRotDim<Dim>;
  auto fixed = pts.fixed;
  auto Kinv_v = shape.Kinv;
  auto sing = shape.singular;
  auto eps_v = st.eps, kap_v = st.kappa, P1 = st.P1, P2 = st.P2, winv = st.winv;
  auto degen = st.degenerate;
  Kokkos::parallel_for(
      "mupm::Solid::uniform_stress_pass1", range(0, pts.n_owned),
      KOKKOS_LAMBDA(const std::size_t i) {
        const bool zero = (fixed(i) & kFixedNoEnergy) || sing(i);
        double Kinv[Dim * Dim], s[Dim * Dim], p1[Dim * Dim];
        for (int k = 0; k < Dim * Dim; ++k) {
          Kinv[k] = Kinv_v(i, k);
          s[k] = sigma[k];
        }
        mat_mul<Dim, Dim>(s, Kinv, p1);
        for (int k = 0; k < Dim * Dim; ++k) {
          eps_v(i, k) = 0;
          P1(i, k) = zero ? 0.0 : p1[k];
        }
        for (int k = 0; k < R * Dim; ++k)
          kap_v(i, k) = P2(i, k) = 0;
        winv(i) = 0;
        degen(i) = 0;
      });
}

}  // namespace mupm

#endif
