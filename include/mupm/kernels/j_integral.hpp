// The micropolar J-integral on rectangular contours around a crack tip (paper eqs 30, 125,
// 126). 2D (plane strain or stress, thickness h). Kernels only: the per-point terms; the solver
// sums them over the ranks exactly, in any order (include/mupm/solvers/j_integral.hpp).
//
// Derivation (the paper's eq 30 carries its cross term with one xi for two bonds; this is the
// reading that follows from the model's own energy: the discrete energy Psi whose derivatives are
// the force and moment states of pass 2, eqs 105-112, include/mupm/kernels/solid.hpp). A point's
// energy rate is
//   dW_i/dt = sum_j [T_ij.(du_j - du_i - (dth_i + dth_j)/2 x xi_ij) + M_ij.(dth_j - dth_i)] V_j.
// Summed over a region B1, the pairs inside cancel against B1's share of the force and moment
// balances (f_i = 0, l_i = 0 in equilibrium), and what is left is the power that crosses the
// contour through the bonds i in B1, j outside (B2):
//   P = sum_{i in B1, j in B2} V_i V_j [ T_ij.du_j - T_ji.du_i + M_ij.dth_j - M_ji.dth_i
//                                        - 1/2 ((xi_ij x T_ij).dth_j + (xi_ij x T_ji).dth_i) ].
// For a crack tip moving steadily along the crack direction d (x_1), du = -v du/dx_1 and the
// region's energy flux is v int W n_1 dA, so the energy released per unit crack advance is
//   J = int_{dB1} W n.d dA - sum_{i in B1, j in B2} V_i V_j [ T_ij.u_1(j) - T_ji.u_1(i)
//       + M_ij th_1(j) - M_ji th_1(i) - 1/2 ((xi x T_ij) th_1(j) + (xi x T_ji) th_1(i)) ],
// with u_1 = (grad u) d, th_1 = kappa d the derivatives along d from the nonlocal gradients:
// grad u = eps + the rotation eps subtracts (eq 50 with U^ = U - Omega-bar x xi; 2D, theta
// counterclockwise: eps_xy = du_x/dy + theta, eps_yx = du_y/dx - theta, so du_x/dy = eps_xy -
// theta, du_y/dx = eps_yx + theta). For an affine field the bond sum is t.u_1 integrated over
// the contour (t = sigma n: sum_{B1,B2} (T_ij - T_ji) V_i V_j is the force B2 exerts on B1), so
// this is the continuum micropolar J, int (W n_1 - t.u_1 - m th_1) dA. J per unit thickness (the
// paper's Pa m, G = J/h of eq 126) divides by h.
//
// The parts (the paper's Tables 1 and 3): translational = the W term and the u terms; micro-
// rotational = the theta terms (the M terms and the 1/2 xi x T terms). The paper's tables add up
// to J this way (20.3 + 0.18 = 20.48, 6.49 + 4.02 = 10.51).
//
// The discrete contour. Each contour is an axis-aligned rectangle whose edges lie on cell faces
// (between lattice lines): B1 is the points inside, B2 those outside. The W term of an edge is
// int W n.d ds with W at the edge the mean of the two points that straddle it (the row or column
// just inside and just outside, each at dx/2 from it): each of them adds W_i dx (n.d)/2 for the
// part of the edge its row spans. W is the point's energy density with the stabilization
// energy (solid pass 1, SolidState::energy / V). Bonds across the crack are broken and carry no
// power; an edge that crosses the crack is cut by it. A contour reaching past a face of the body
// (the crack's mouth, or the face ahead of a long crack) runs along that face inside the box:
// there no bond crosses, and the W term is int W n.d ds along the face, with the W of the
// points of the last row (dx/2 inside it) at full weight.
//
// The crack water's forces on the faces (Fracture Flow with Crack Water Force = Face Pressure,
// kernels/fracture_flow.hpp), not in the paper's J. Rice's J assumes traction-free faces; with
// a load on them the divergence theorem over the region between the contour and a small one
// around the tip, in equilibrium with the body force density b, gives
//   J_tip = J_Gamma - int_{B1} b.u_1 dA,
// since div(W d - sigma^T u_1) = -div(sigma).u_1 = b.u_1 (W_1 = sigma : grad u_1; the micropolar
// terms add m : grad th_1, balanced the same way by the couple stresses, and a pressure applies
// no couple, so no th_1 term follows). For a pressure p on the faces of an opening w (b the face
// traction p n over each face) this is J_Gamma + int_0^{s_Gamma} p (dw/ds) ds, s the distance
// behind the tip up to the contour: for a Griffith crack J_Gamma alone is short by the fraction
// (4/pi) sqrt(2r/a - (r/a)^2) of J, r the distance the contour runs behind the tip. mupm applies
// the water as force densities on the fracture points (Points::applied_crack_force, the ones the
// step applied), so the face term is a sum over the points in B1, split at a cut, a line across
// the crack at the distance r_c behind the tip (s the distance behind the tip along d):
//   J_face = - sum_{s_i > r_c} b_i.u_1(i) V_i + sum_{|s_i - r_c| = dx/2} b_i.u_i V_i / (2 dx).
// Behind the cut the field is smooth and the point's u_1 (its nonlocal gradient, one-sided at a
// face) makes the sum path-independent. Between the tip and the cut the load is taken as
// uniform along d, t(s) = t(r_c) on each line parallel to d, so that its integral is exact:
// - int_0^{r_c} t.u_1 ds = t(r_c).(u(r_c) - u(0)) on each face, and the u(0) of the two faces
// cancel (equal and opposite loads, the faces meeting at the tip): p w(r_c) for a pressure, with
// t(r_c) u(r_c) the mean of b V u/dx of the points at dx/2 either side of the cut, on every line
// that crosses it inside the contour. The sum over the points themselves is not: u_1 ~ 1/sqrt(s)
// at the tip, and the lattice's points sample it too coarsely there; the midpoint rule alone
// misses 0.3 of the last cell's int dw, and with the nonlocal gradient J came out short by
// 0.88 sqrt(dx/a) of LEFM's for Sneddon's crack (0.78 at a = 16 dx), where J with the cut is
// within 2 % (1.018) and equals the lattice's energy release rate from two static solves within
// 0.4 % (tests/solvers/test_j_integral_tips.cpp). What the cut leaves out is the pressure's
// change between the tip and the cut, int_0^{r_c} w dp, of order (r_c/a) p w(r_c) for a
// pressure that varies on the crack's scale. r_c is one spacing beyond the horizon's rows
// ((floor(delta/dx) + 1) dx: the gradients behind it do not reach the tip's last cell), or a
// contour's half size when that is smaller; both on cell faces, the contours being centred on the
// tip placed on cell faces (solvers/j_integral.cpp).
// With Crack Water Force = Eq 17 (the water on the bonds) the face term is left out.
//
// Left out, as in the paper's J: kinetic energy (J is that of a static field; in a running crack
// the contours differ).
//
// Force state: the one the bond energy uses (Fracture->Bond Energy Force State): with pore water
// and Effective (default), the skeleton's, T-bar = T + S_r p* K^-1 xi (the paper's eqs 23, 30:
// the effective force state). Without pore pressure both are the same.
#ifndef MUPM_J_INTEGRAL_HPP
#define MUPM_J_INTEGRAL_HPP

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "mupm/core/geometry.hpp"
#include "mupm/kernels/solid.hpp"

namespace mupm {

constexpr int kMaxContours = 8;

// The J-Integral input (include/mupm/solvers/j_integral.hpp).
struct JIntegralParams {
  std::vector<std::array<double, 2>> half;  // half width (x) and half height (y) per contour [m]
  bool criterion = false;                   // Fracture->Bond Breakage = J-Integral
  double critical = 0;                      // G_cr [J/m^2]
  double increment = 0;                     // Delta a [m]
  double max_speed = 0;                     // the tip's speed cap c_R [m/s] (0: none)
  bool face = false;  // the crack water's face term (Fracture Flow with Face Pressure; header)
  bool cut = false;   // an increment's points become fracture points (criterion, Fracture Flow)
};

// A crack tip of the J-integral: an end of a pre-crack (2D segment Start -> End) that lies
// strictly inside the real body, the direction d (unit) in which it grows (End: Start -> End;
// Start: End -> Start), the pre-crack it belongs to, and its share of that crack's length inside
// the body at the start (half of it when both ends are tips, all of it when one is).
struct CrackTip {
  std::array<double, 2> x{}, d{};
  std::size_t crack = 0;
  double base = 0;
};

// The tips of `cracks` inside `body`, crack by crack, End before Start.
inline std::vector<CrackTip> crack_tips(const std::vector<Crack>& cracks, const Box& body) {
  std::vector<CrackTip> tips;
  for (std::size_t c = 0; c < cracks.size(); ++c) {
    const Crack& k = cracks[c];
    const double len = std::hypot(k.b[0] - k.a[0], k.b[1] - k.a[1]);
    if (!(len > 0))
      continue;
    auto inside = [&](const double* p) {
      return p[0] > body.lo[0] && p[0] < body.hi[0] && p[1] > body.lo[1] && p[1] < body.hi[1];
    };
    const bool end = inside(k.b), start = inside(k.a);
    // The part inside the body: all of it with both ends inside, else clipped (crack_inside).
    const CrackPart part = crack_inside<2>(k, body);
    const double share = std::max(part.s1 - part.s0, 0.0) * len / (end && start ? 2.0 : 1.0);
    const double d[2] = {(k.b[0] - k.a[0]) / len, (k.b[1] - k.a[1]) / len};
    if (end)
      tips.push_back({{k.b[0], k.b[1]}, {d[0], d[1]}, c, share});
    if (start)
      tips.push_back({{k.a[0], k.a[1]}, {-d[0], -d[1]}, c, share});
  }
  return tips;
}

// Contours (faces on cell faces), the crack direction d (unit), and the thickness h.
struct JContours {
  int count = 0;
  Kokkos::Array<Box, kMaxContours> box;
  double d[2] = {1, 0};
  double thickness = 1;
  double dx = 0;
  Box body;  // the lattice (real body and boundary layers): its faces are free or held faces
  double tip[2] = {0, 0};                   // the tip on the nearest cell faces (the boxes' centre)
  Kokkos::Array<double, kMaxContours> cut;  // the face term's cut r_c behind the tip (header)
  // The distance of x behind the tip along d.
  KOKKOS_INLINE_FUNCTION double tip_s(const double* x) const {
    return (tip[0] - x[0]) * d[0] + (tip[1] - x[1]) * d[1];
  }
};

// Per owned point i and contour c: out(i, 4c + 0) the W term, 4c + 1 the u terms, 4c + 2 the
// theta terms, 4c + 3 the face term of the force density `face` (owned points; none when not
// allocated) (each already signed as it enters J, per unit thickness). u, theta, eps, kappa, P1,
// P2, winv (and P1w when allocated) current on the ghosts, as solid pass 2 leaves them.
// Effective: the bond forces include P1w's pore-water part (P1w allocated), a compile-time
// choice so that the bond loop tests no run-time option (j_integral_terms dispatches).
template <bool Effective>
void j_integral_terms_variant(const Points<2>& pts, const Bonds& bonds, const SolidParams& prm,
                              const SolidState<2>& st, const JContours& jc, const Vectors& face,
                              const Vectors& out) {
  constexpr int Dim = 2, R = 1;
  const bool loaded = face.extent(0) > 0;
  auto offsets = bonds.offsets;
  auto neighbor = bonds.neighbor;
  auto intact = bonds.intact;
  auto x = pts.x, u = pts.u, th = pts.theta;
  auto vol = pts.volume;
  auto eps = st.eps, kap = st.kappa, P1 = st.P1, P2 = st.P2, P1w = st.P1w;
  auto winv = st.winv, energy = st.energy;
  const double c1 = prm.stabilization * 12.0 * prm.stab_modulus;
  const double c2 = prm.stabilization * prm.stab_modulus;
  const JContours c = jc;
  Kokkos::parallel_for(
      "mupm::JIntegral::terms", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        const double xi_[2] = {x(i, 0), x(i, 1)};
        // u_1 = (grad u) d and th_1 = kappa d of a point (header).
        auto derivs = [&](int k, double* g, double& h) {
          const double t = th(k, 0);
          const double G[4] = {eps(k, 0), eps(k, 1) - t, eps(k, 2) + t, eps(k, 3)};
          g[0] = G[0] * c.d[0] + G[1] * c.d[1];
          g[1] = G[2] * c.d[0] + G[3] * c.d[1];
          h = kap(k, 0) * c.d[0] + kap(k, 1) * c.d[1];
        };
        double gi[2], hi;
        derivs(int(i), gi, hi);
        const double Wi = energy(i) / vol(i);
        const double si = c.tip_s(xi_);  // the distance behind the tip (the face term's cut)
        for (int ci = 0; ci < c.count; ++ci) {
          const Box& b = c.box[ci];
          double w = 0, tr = 0, rot = 0, fc = 0;
          // W term: the points at dx/2 from an edge, within the edge's span; an edge at or
          // beyond the body's face runs along the face, where the last row carries W (header).
          for (int a = 0; a < Dim; ++a) {
            const int o = 1 - a;  // the edge runs along axis o
            if (!(xi_[o] > b.lo[o] && xi_[o] < b.hi[o]))
              continue;
            const double inside = 0.25 * c.dx;  // edges and faces lie on cell faces
            if (b.hi[a] < c.body.hi[a] - inside) {
              if (std::abs(xi_[a] - b.hi[a]) < c.dx)
                w += 0.5 * Wi * c.dx * c.d[a];  // edge x_a = hi: n = +e_a
            } else if (std::abs(xi_[a] - (c.body.hi[a] - 0.5 * c.dx)) < 0.5 * c.dx) {
              w += Wi * c.dx * c.d[a];  // along the face x_a = hi
            }
            if (b.lo[a] > c.body.lo[a] + inside) {
              if (std::abs(xi_[a] - b.lo[a]) < c.dx)
                w -= 0.5 * Wi * c.dx * c.d[a];  // edge x_a = lo: n = -e_a
            } else if (std::abs(xi_[a] - (c.body.lo[a] + 0.5 * c.dx)) < 0.5 * c.dx) {
              w -= Wi * c.dx * c.d[a];  // along the face x_a = lo
            }
          }
          // Bond terms: i in B1 (inside), j in B2 (outside); the face term of i in B1.
          if (in_box<Dim>(b, xi_, 0.0)) {
            if (loaded && si > c.cut[ci] + 0.25 * c.dx)  // behind the cut (header)
              fc = -(face(i, 0) * gi[0] + face(i, 1) * gi[1]) * vol(i) / c.thickness;
            for (BondIndex bd = offsets(i); bd < offsets(i + 1); ++bd) {
              if (!intact(bd))
                continue;
              const int j = neighbor(bd);
              const double xj_[2] = {x(j, 0), x(j, 1)};
              if (in_box<Dim>(b, xj_, 0.0))
                continue;
              double xi[Dim], Uh[Dim], Om[R];
              const double len2 = bond_kinematics<Dim>(x, u, th, int(i), j, xi, Uh, Om);
              const double il = 1.0 / std::sqrt(len2);
              const double a1 = c1 * (il * il * il), a2 = c2 * il;  // as solid_pass2
              const double a1i = a1 * winv(i), a2i = a2 * winv(i);
              const double a1j = a1 * winv(j), a2j = a2 * winv(j);
              // T_ij = P1_i xi + a1i (U^ - eps_i xi); T_ji = -(P1_j xi + a1j (U^ - eps_j xi)).
              double Tij[Dim], Tji[Dim];
              for (int d = 0; d < Dim; ++d) {
                double pi = 0, pj = 0, ei = 0, ej = 0, wi = 0, wj = 0;
                for (int k = 0; k < Dim; ++k) {
                  pi += P1(i, d * Dim + k) * xi[k];
                  pj += P1(j, d * Dim + k) * xi[k];
                  ei += eps(i, d * Dim + k) * xi[k];
                  ej += eps(j, d * Dim + k) * xi[k];
                  if constexpr (Effective) {
                    wi += P1w(i, d * Dim + k) * xi[k];
                    wj += P1w(j, d * Dim + k) * xi[k];
                  }
                }
                Tij[d] = pi + a1i * (Uh[d] - ei) + wi;
                Tji[d] = -(pj + a1j * (Uh[d] - ej)) - wj;
              }
              // M_ij = P2_i xi + a2i (Omega - kappa_i xi); M_ji = -(P2_j xi + a2j (...)).
              double pi = 0, pj = 0, ki = 0, kj = 0;
              for (int k = 0; k < Dim; ++k) {
                pi += P2(i, k) * xi[k];
                pj += P2(j, k) * xi[k];
                ki += kap(i, k) * xi[k];
                kj += kap(j, k) * xi[k];
              }
              const double Mij = pi + a2i * (Om[0] - ki);
              const double Mji = -(pj + a2j * (Om[0] - kj));
              double gj[2], hj;
              derivs(j, gj, hj);
              const double vv = vol(i) * vol(j) / c.thickness;
              const double xTij = xi[0] * Tij[1] - xi[1] * Tij[0];
              const double xTji = xi[0] * Tji[1] - xi[1] * Tji[0];
              tr -= (Tij[0] * gj[0] + Tij[1] * gj[1] - Tji[0] * gi[0] - Tji[1] * gi[1]) * vv;
              rot -= (Mij * hj - Mji * hi - 0.5 * (xTij * hj + xTji * hi)) * vv;
            }
          }
          // The cut's term t.u(r_c): the points at dx/2 either side of the cut whose line
          // parallel to d crosses it inside the box (header).
          const double sc = si - c.cut[ci];
          if (loaded && std::abs(sc) < 0.75 * c.dx) {
            const double q[2] = {xi_[0] + (sc + 0.25 * c.dx) * c.d[0],
                                 xi_[1] + (sc + 0.25 * c.dx) * c.d[1]};
            if (in_box<Dim>(b, q, 0.0))
              fc +=
                  (face(i, 0) * u(i, 0) + face(i, 1) * u(i, 1)) * vol(i) / (2 * c.dx * c.thickness);
          }
          out(i, 4 * ci + 0) = w;
          out(i, 4 * ci + 1) = tr;
          out(i, 4 * ci + 2) = rot;
          out(i, 4 * ci + 3) = fc;
        }
      });
}

inline void j_integral_terms(const Points<2>& pts, const Bonds& bonds, const SolidParams& prm,
                             const SolidState<2>& st, const JContours& jc, const Vectors& face,
                             const Vectors& out) {
  if (st.P1w.extent(0) > 0)
    j_integral_terms_variant<true>(pts, bonds, prm, st, jc, face, out);
  else
    j_integral_terms_variant<false>(pts, bonds, prm, st, jc, face, out);
}

}  // namespace mupm

#endif
