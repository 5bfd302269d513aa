// Micropolar Drucker-Prager plasticity with linear softening (paper eqs 82-95): the return
// mapping at one point, and the law of pass 1 (include/mupm/kernels/solid.hpp) that applies it
// with the points' plastic state.
//
// The model, as the paper writes it (eqs 84-91, taken literally: f's slope and intercept differ
// from the usual outer-cone matching by factors 3 and sqrt3; the paper's example 3 yields at
// about 2.6 % axial strain this way, and not at all within its 5 % stroke with the outer cone):
//   sigma-tilde = -tr(sigma) 1 + 3/2 (sigma + sigma^T)                       (eq 86)
//   q^2 = 1/2 (sigma : sigma-tilde + 3 m : m / l^2)                          (eq 84)
//       = 3/2 (|s|^2 + |m|^2 / l^2),  s = dev sym(sigma)
//   (with p = tr(sigma)/3, sigma : sigma-tilde = 3/2 (s:s + s:s^T) of the deviator, and
//   1/2 (s:s + s:s^T) = |dev sym sigma|^2: the skew stress does not enter q, mu_c acts
//   elastically only)
//   p-bar = tr(sigma)/3 (eq 85), tension positive
//   f = q + sqrt3 a1 p-bar + a2,  g = q + sqrt3 a3 p-bar + a2               (eqs 87-88)
//   a1 = 2 sin(phi) / (sqrt3 (3 - sin phi)), a3 likewise with psi,
//   a2 = -k c, k = 6 cos(phi) / (sqrt3 (3 - sin phi))                        (eqs 89-91)
//   c = max(c_r, c0 + h eps-hat^p)                                           (eq 92, c_r: input)
// Flow (eqs 93-94), d lambda >= 0:
//   d eps^p = d lambda [3/(2q) s + a3/sqrt3 1]   (symmetric: the skew stress is untouched)
//   d kappa^p = d lambda 3/(2q) m / l^2
// Equivalent plastic strain (eq 95) with the curvature term weighted by l^2:
//   d eps-hat^p = sqrt(1/3 de_s:de_s + 1/3 de_s:de_s^T + 2/3 l^2 dk:dk) = d lambda
// (eq 95 as printed, 2/3 dk:dk, adds 1/m^2 to a dimensionless strain; with l^2 it is the dual
// of q's weights: s : de_s + m : dk = q d lambda, the deviatoric plastic work).
//
// Plane strain (2D): eps_zz = 0, and the state keeps eps^p_zz: sigma_zz = lambda tr(eps^e) +
// 2 mu eps^e_zz with eps^e_zz = -eps^p_zz, and p-bar, s, q are those of the 3x3 stress.
// Plane stress (2D, Discretization->Plane = Stress): sigma_zz = 0 with eps_zz free. The return
// is the same 3D return with the total eps_zz as a parameter, eps^e_zz = eps_zz - eps^p_zz, and
// eps_zz is the root of sigma_zz(eps_zz) = 0 (drucker_prager_return_plane_stress): it starts
// from the elastic plane-stress value eps^p_zz - lambda tr(eps^e) / (lambda + 2 mu) (exact where
// the point stays elastic), then a step -sigma_zz / (lambda + 2 mu), secant steps, and bisection
// once the root is bracketed (the plastic slope d sigma_zz / d eps_zz may exceed the elastic one
// when psi != phi, or fall with softening: the bracket keeps the iteration safe). The state keeps
// eps^p_zz as in plane strain; eps_zz itself follows from the strain and the state, so it is not
// kept. q, p-bar and the flow are the 3D ones: the yield stress under in-plane uniaxial stress is
// the 3D one, k c / (1 + a1 / sqrt3) in tension (tests/kernels/test_plasticity.cpp).
// Plane stress with pore water (Bishop's sigma-bar - S_r p 1, eq 46): the total sigma_zz = 0, so
// the return solves sigma-bar_zz(eps_zz) = s = S_r p* (p* the pressure of pass 1) instead of 0,
// and the yield function sees the effective stress with that sigma-bar_zz. What the skeleton and
// the water then need, with t = tr eps (in-plane), e = eps_zz, L = lambda + 2 mu:
//  - Thickness: sigma-bar_zz = lambda tr(eps^e) + 2 mu e^e = s (3D trace) gives
//      e = eps^p_zz + (s - lambda (t - tr2 eps^p)) / L,
//    so the 3D volume change is t + e = biot t + c_z s + Pi with the elastic PoreCoupling's
//    biot = 2 mu / L, c_z = 1 / L (micropolar_elastic.hpp) and the plastic part
//      Pi = (lambda tr eps^p + 2 mu eps^p_zz) / L   (tr eps^p over the 3 axes).
//    The water's balance (eq 117) takes S_r d(t + e): the elastic coupling's terms plus S_r dPi.
//    The law gives the solver t + Pi / biot as the volumetric strain (pore_shift): with it the
//    water's biot S_r d(volumetric strain), the undrained split and the solid's pore work are
//    the elastic coupling's expressions, and the plastic thickness change is in all three.
//  - In-plane stress: the total is sigma-bar_in - s 1; the solid subtracts biot s 1 (as for the
//    elastic law), so the law returns sigma-bar_in - (lambda / L) s 1, which while elastic is
//    exactly the plane-stress elastic law (lambda* of micropolar_elastic.hpp).
//  - Energy: with W3 the 3D stored energy of eps^e, the law returns W3 - s^2 / (2 L): while
//    elastic this is the plane-stress law's W, and s^2 / (2 L) is the thickness energy the water's
//    stored energy holds (kernels/fluid.hpp, c_z). Over a step, exactly for the trapezoid,
//      1/2 (sig0 + sig1) : dt-eps (returned stresses) = d(W3 - s^2 / (2 L)) + D - s-bar dPi,
//    D the 3D plastic dissipation (with its sigma-bar_zz d eps^p_zz term, dissipation()), so the
//    solid's ledger closes with the pore work biot s-bar d(t + Pi / biot).
// The water's share of the split uses the plastic state at the step's start (the return that
// gives the new Pi needs p* itself): the plastic thickness change reaches p* a step late, the
// water's balance on the step it happens (mass is exact).
//
// Return mapping (backward Euler, closest point in the energy norm). With x = d lambda and the
// trial state (s_t, m_t, p_t) of the elastic predictor:
//   s = s_t q / (q + 3 mu x),  m = m_t q / (q + 3/4 mu x),  p = p_t - sqrt3 K a3 x
// (the couple modulus B = mu l^2 / 2 of eq 81 gives m its own factor: B 3/(2q) / l^2 =
// 3 mu / (4 q), against 2 mu 3/(2q) = 3 mu / q for s), so q(x) solves
//   1 = q_s^2 / (q + 3 mu x)^2 + q_m^2 / (q + 3/4 mu x)^2,  q_s^2 = 3/2 |s_t|^2,
//   q_m^2 = 3/2 |m_t|^2 / l^2,
// a convex decreasing function of q, solved by Newton from its lower bound (monotone); then a
// scalar Newton (bisection-safeguarded) on x for f(x) = 0. q reaches 0 at x_apex =
// sqrt(q_s^2 + 16 q_m^2) / (3 mu); if f(x_apex) > 0 the return goes to the apex: s = m = 0,
// eps-hat grows by x_apex (eq 95 of the removed deviatoric strains), and x solves the
// volumetric part alone. The plastic strains are the stress change through the compliance, so
// sigma = C (eps - eps^p) holds to round-off. On a proportional path (fixed direction of s and
// m) the return is exact: one step or a thousand give the same state.
#ifndef MUPM_MICROPOLAR_DRUCKER_PRAGER_HPP
#define MUPM_MICROPOLAR_DRUCKER_PRAGER_HPP

#include <cmath>

#include <Kokkos_Core.hpp>

#include "mupm/core/types.hpp"
#include "mupm/laws/micropolar_elastic.hpp"

namespace mupm {

// Yield and softening parameters (Materials->Model = Micropolar Drucker-Prager).
struct DruckerPragerParams {
  double friction = 0;       // phi [rad]
  double dilation = 0;       // psi [rad]
  double cohesion = 0;       // c0 [Pa]
  double residual = 0;       // c_r [Pa], the lower bound of c
  double softening = 0;      // h [Pa] (negative softens)
  double tolerance = 1e-10;  // f <= tolerance * (k c0) after a return

  KOKKOS_INLINE_FUNCTION double a1() const {
    return 2 * std::sin(friction) / (std::sqrt(3.0) * (3 - std::sin(friction)));
  }
  KOKKOS_INLINE_FUNCTION double a3() const {
    return 2 * std::sin(dilation) / (std::sqrt(3.0) * (3 - std::sin(dilation)));
  }
  // a2 = -k c (eq 90).
  KOKKOS_INLINE_FUNCTION double k() const {
    return 6 * std::cos(friction) / (std::sqrt(3.0) * (3 - std::sin(friction)));
  }
  // c after an equivalent plastic strain e (eq 92, bounded below by c_r).
  KOKKOS_INLINE_FUNCTION double cohesion_at(double e) const {
    const double c = cohesion + softening * e;
    return c > residual ? c : residual;
  }
};

// The plastic state of a point: eps^p (Dim x Dim row-major, symmetric increments but stored
// whole), eps^p_zz (plane strain; unused in 3D, where eps^p holds it), kappa^p (RotDim x Dim),
// eps-hat^p.
template <int Dim>
struct PlasticPoint {
  double ep[Dim * Dim] = {};
  double ezz = 0;
  double kp[kRotDim<Dim> * Dim] = {};
  double eq = 0;
};

// What a return did (tests, diagnostics).
struct ReturnInfo {
  double dlambda = 0;  // x
  double f = 0;        // yield function after the return
  bool plastic = false;
  bool apex = false;
  bool converged = true;  // plane stress: sigma_zz = 0 reached (drucker_prager_return_plane_stress)
};

namespace dp_detail {
// q(x) of the header: the root of q_s^2/(q + a)^2 + q_m^2/(q + b)^2 = 1, a = 3 mu x,
// b = 3/4 mu x, with dq/dx through *dq (0 where q = 0).
KOKKOS_INLINE_FUNCTION double q_of(double qs, double qm, double mu, double x, double* dq) {
  const double a = 3 * mu * x, b = 0.75 * mu * x;
  if (qm == 0 || qs == 0) {  // one factor: the radial return's closed form
    const double q = qm == 0 ? qs - a : qm - b;
    *dq = q > 0 ? (qm == 0 ? -3 * mu : -0.75 * mu) : 0.0;
    return q > 0 ? q : 0.0;
  }
  double q = qs - a > qm - b ? qs - a : qm - b;  // a lower bound of the root
  if (q < 0)
    q = 0;
  for (int it = 0; it < 100; ++it) {
    const double ra = qs / (q + a), rb = qm / (q + b);
    const double F = ra * ra + rb * rb - 1;
    if (F <= 0)
      break;
    const double Fq = -2 * (ra * ra / (q + a) + rb * rb / (q + b));
    const double dq_step = -F / Fq;
    q += dq_step;
    if (dq_step <= 1e-15 * q)
      break;
  }
  if (q <= 0) {
    *dq = 0;
    return 0;
  }
  const double ra = qs / (q + a), rb = qm / (q + b);
  const double Gq = -2 * (ra * ra / (q + a) + rb * rb / (q + b));
  const double Gx = -2 * (ra * ra / (q + a) * 3 * mu + rb * rb / (q + b) * 0.75 * mu);
  *dq = -Gx / Gq;
  return q;
}
}  // namespace dp_detail

// Elastic predictor and return mapping at one point. eps (Dim x Dim) and kappa (RotDim x Dim)
// are the total nonlocal strain and wryness (eqs 50-51); `old` the state at the start of the
// step. Writes the new state, sigma-bar (Dim x Dim), its zz component (*szz, plane strain; the
// 3D trace is in sigma) and m; returns the stored (elastic) energy density
// 1/2 (sigma : eps^e + m : kappa^e). `ezz` (2D, with `given_ezz`): the total eps_zz (plane
// stress's iterate); otherwise 0 (plane strain).
template <int Dim>
KOKKOS_INLINE_FUNCTION double drucker_prager_return(
    const MicropolarElastic& el, const DruckerPragerParams& dp, const double* eps,
    const double* kappa, const PlasticPoint<Dim>& old, PlasticPoint<Dim>& nw, double* sigma,
    double* szz, double* m, ReturnInfo* info = nullptr, bool given_ezz = false, double ezz = 0) {
  constexpr int R = kRotDim<Dim>;
  const double mu = el.mu, mc = el.mu_c, lam = el.lambda, K = lam + 2 * mu / 3;
  const double B = el.couple_modulus(), l2 = el.length * el.length;
  // Elastic trial strain, 3 x 3 (plane strain: eps_zz = 0, eps^e_zz = -eps^p_zz).
  double ee[3][3] = {};
  for (int a = 0; a < Dim; ++a)
    for (int b = 0; b < Dim; ++b)
      ee[a][b] = eps[a * Dim + b] - old.ep[a * Dim + b];
  if (Dim == 2)
    ee[2][2] = given_ezz ? ezz - old.ezz : -old.ezz;
  const double tr = ee[0][0] + ee[1][1] + ee[2][2];
  double st[3][3];  // trial stress (eq 80)
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      st[a][b] = (a == b ? lam * tr : 0.0) + (mu + mc) * ee[a][b] + (mu - mc) * ee[b][a];
  double mt[R * Dim];
  for (int k = 0; k < R * Dim; ++k)
    mt[k] = B * (kappa[k] - old.kp[k]);  // eq 81
  const double pt = (st[0][0] + st[1][1] + st[2][2]) / 3;
  double s[3][3], ss = 0, mm = 0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      s[a][b] = 0.5 * (st[a][b] + st[b][a]) - (a == b ? pt : 0.0);
      ss += s[a][b] * s[a][b];
    }
  for (int k = 0; k < R * Dim; ++k)
    mm += mt[k] * mt[k];
  const double qs = std::sqrt(1.5 * ss), qm = l2 > 0 ? std::sqrt(1.5 * mm / l2) : 0.0;
  const double a1 = dp.a1(), a3 = dp.a3(), kc = dp.k(), s3 = std::sqrt(3.0);
  const double tol = dp.tolerance * kc * (dp.cohesion > dp.residual ? dp.cohesion : dp.residual);
  const double f_trial = std::sqrt(qs * qs + qm * qm) + s3 * a1 * pt - kc * dp.cohesion_at(old.eq);
  nw = old;
  double x = 0, q_new = 0, deq = 0, f = f_trial;
  bool apex = false;
  const bool plastic = f_trial > tol;
  if (plastic) {
    // f(x) on the cone (x <= x_apex); eps-hat grows by x there.
    auto f_of = [&](double xx, double* df, double* qq) {
      double dq;
      const double q = dp_detail::q_of(qs, qm, mu, xx, &dq);
      const double e = old.eq + xx;
      const double c0h = dp.cohesion + dp.softening * e;
      const bool residual = !(c0h > dp.residual);
      *qq = q;
      *df = dq - 3 * a1 * a3 * K - (residual ? 0.0 : kc * dp.softening);
      return q + s3 * a1 * (pt - s3 * K * a3 * xx) - kc * dp.cohesion_at(e);
    };
    const double x_apex = std::sqrt(qs * qs + 16 * qm * qm) / (3 * mu);
    double df, qq;
    const double f_apex = f_of(x_apex, &df, &qq);
    if (f_apex > 0) {  // apex return: the deviatoric part is gone, the volume takes the rest
      apex = true;
      deq = x_apex;
      const double c = dp.cohesion_at(old.eq + x_apex);
      const double den = 3 * a1 * a3 * K;
      x = den > 0 ? (s3 * a1 * pt - kc * c) / den : x_apex;
      if (x < x_apex)
        x = x_apex;
      q_new = 0;
      f = s3 * a1 * (pt - s3 * K * a3 * x) - kc * c;
    } else {  // Newton on x in [0, x_apex], bisection where it leaves the bracket
      double lo = 0, hi = x_apex;
      x = 0;
      f = f_trial;
      f = f_of(x, &df, &qq);
      for (int it = 0; it < 100 && std::fabs(f) > tol; ++it) {
        if (f > 0)
          lo = x;
        else
          hi = x;
        double xn = df < 0 ? x - f / df : 0.5 * (lo + hi);
        if (!(xn > lo && xn < hi))
          xn = 0.5 * (lo + hi);
        x = xn;
        f = f_of(x, &df, &qq);
      }
      q_new = qq;
      deq = x;
    }
  }
  // The returned stress: s and m scaled, p moved, the skew part kept.
  const double fs = plastic ? (apex || q_new <= 0 ? 0.0 : q_new / (q_new + 3 * mu * x)) : 1.0;
  const double fm = plastic ? (apex || q_new <= 0 ? 0.0 : q_new / (q_new + 0.75 * mu * x)) : 1.0;
  const double pn = plastic ? pt - s3 * K * a3 * x : pt;
  double sn[3][3];
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      sn[a][b] = fs * s[a][b] + (a == b ? pn : 0.0) + 0.5 * (st[a][b] - st[b][a]);
  double mn[R * Dim];
  for (int k = 0; k < R * Dim; ++k)
    mn[k] = fm * mt[k];
  // Plastic increments: the stress change through the compliance (deviatoric / 2 mu,
  // volumetric / 3K, couple / B).
  if (plastic) {
    double de[3][3];
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        de[a][b] = (1 - fs) * s[a][b] / (2 * mu) + (a == b ? (pt - pn) / (3 * K) : 0.0);
    for (int a = 0; a < Dim; ++a)
      for (int b = 0; b < Dim; ++b)
        nw.ep[a * Dim + b] = old.ep[a * Dim + b] + de[a][b];
    if (Dim == 2)
      nw.ezz = old.ezz + de[2][2];
    for (int k = 0; k < R * Dim; ++k)
      nw.kp[k] = old.kp[k] + (B > 0 ? (1 - fm) * mt[k] / B : 0.0);
    nw.eq = old.eq + deq;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        ee[a][b] -= de[a][b];
  }
  double w = 0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      w += 0.5 * sn[a][b] * ee[a][b];
  for (int k = 0; k < R * Dim; ++k)
    w += 0.5 * mn[k] * (kappa[k] - nw.kp[k]);
  for (int a = 0; a < Dim; ++a)
    for (int b = 0; b < Dim; ++b)
      sigma[a * Dim + b] = sn[a][b];
  *szz = sn[2][2];
  for (int k = 0; k < R * Dim; ++k)
    m[k] = mn[k];
  if (info) {
    info->dlambda = x;
    info->f = plastic ? f : f_trial;
    info->plastic = plastic;
    info->apex = apex;
  }
  return w;
}

// Plane stress (header): the return of drucker_prager_return<2> with the total eps_zz that makes
// sigma-bar_zz = target (0 when dry; S_r p* with pore water, header), to |sigma-bar_zz - target|
// <= the larger of 1e-12 of the stress's scale (the largest of |sigma|, |m| / l, |target| and
// k c0) and twice the inner return's tolerance on f (sigma_zz(eps_zz) is continuous only to
// that). `el` is the 3D law (not its plane_stress()). *szz is the sigma-bar_zz reached;
// info->converged is false if 100 returns or a bracket of a few ulps did not reach it.
KOKKOS_INLINE_FUNCTION double drucker_prager_return_plane_stress(
    const MicropolarElastic& el, const DruckerPragerParams& dp, const double* eps,
    const double* kappa, const PlasticPoint<2>& old, PlasticPoint<2>& nw, double* sigma,
    double* szz, double* m, ReturnInfo* info = nullptr, double target = 0) {
  const double stiff = el.lambda + 2 * el.mu;  // the elastic d sigma_zz / d eps_zz, an upper bound
  const double tr = eps[0] - old.ep[0] + eps[3] - old.ep[3];
  double e = old.ezz + (target - el.lambda * tr) / stiff;  // the elastic plane-stress eps_zz
  double w = drucker_prager_return<2>(el, dp, eps, kappa, old, nw, sigma, szz, m, info, true, e);
  double scale = dp.k() * (dp.cohesion > dp.residual ? dp.cohesion : dp.residual);
  for (int k = 0; k < 4; ++k)
    scale = std::fabs(sigma[k]) > scale ? std::fabs(sigma[k]) : scale;
  const double l = el.length > 0 ? el.length : 1.0;
  for (int k = 0; k < 2; ++k)
    scale = std::fabs(m[k]) / l > scale ? std::fabs(m[k]) / l : scale;
  const double inner =
      2 * dp.tolerance * dp.k() * (dp.cohesion > dp.residual ? dp.cohesion : dp.residual);
  scale = std::fabs(target) > scale ? std::fabs(target) : scale;
  const double tol = 1e-12 * scale > inner ? 1e-12 * scale : inner;
  double g = *szz - target, e_prev = e, g_prev = g;
  bool have_lo = false, have_hi = false;  // bracket: g(lo) < 0 < g(hi)
  double lo = 0, hi = 0;
  for (int it = 0; it < 100 && std::fabs(g) > tol; ++it) {
    if (g < 0) {
      lo = e;
      have_lo = true;
    } else {
      hi = e;
      have_hi = true;
    }
    double next = e - g / stiff;  // the first step, and where the secant is not increasing
    if (it > 0 && e != e_prev) {
      const double slope = (g - g_prev) / (e - e_prev);
      if (slope > 0)
        next = e - g / slope;
    }
    if (have_lo && have_hi) {
      if (hi - lo <= 4e-16 * (std::fabs(lo) + std::fabs(hi)))
        break;  // a bracket of a few ulps: sigma_zz jumps across it
      if (!(next > lo && next < hi))
        next = 0.5 * (lo + hi);
    }
    e_prev = e;
    g_prev = g;
    e = next;
    w = drucker_prager_return<2>(el, dp, eps, kappa, old, nw, sigma, szz, m, info, true, e);
    g = *szz - target;
  }
  if (info)
    info->converged = std::fabs(g) <= tol;
  return w;
}

// The law of pass 1 (the Law of include/mupm/kernels/solid.hpp) with the points' plastic state
// (include/mupm/data/points.hpp). Two states: the one at the start of the step (packed in
// Points::plastic_step_start, with the stress the step starts from) and the current one
// (Points::plastic_strain, ...), which every evaluation of pass 1 recomputes from the start
// state and the current strain. The solver commits (current -> start) at the start of each step,
// before its forces: the other evaluations between two steps (after a breakage, the stable-step
// estimate's closing one, a restart's first one) start from the same state as the step's own,
// so they reproduce or replace its result, never add plastic flow twice, and a restart needs
// nothing but the checkpoint. The stable-step power iteration uses the elastic law (the elastic
// stiffness bounds the tangent one).
template <int Dim>
struct MicropolarDruckerPrager {
  static constexpr bool plastic = true;
  static constexpr int R = kRotDim<Dim>;
  // Layout of Points::plastic_step_start: eps^p, eps^p_zz, kappa^p, eps-hat^p, sigma-bar,
  // sigma_zz, m.
  static constexpr int kEp = 0, kEzz = Dim * Dim, kKp = kEzz + 1, kEq = kKp + R * Dim,
                       kSig = kEq + 1, kSzz = kSig + Dim * Dim, kM = kSzz + 1,
                       kStartWidth = kM + R * Dim;

  MicropolarElastic elastic;  // the 3D law (in plane stress too: the return is 3D)
  DruckerPragerParams dp;
  bool plane_stress = false;       // 2D, Discretization->Plane = Stress
  bool pore_water = false;         // plane stress with pore water: sigma-bar_zz = S_r p* (header)
  Vectors start;                   // Points::plastic_step_start
  Vectors ep, kp;                  // current eps^p, kappa^p
  Scalars ezz, eq, vol, coh, szz;  // eps^p_zz, eps-hat^p, tr eps^p, c, sigma_zz

  MicropolarDruckerPrager() = default;
  template <class Points>
  MicropolarDruckerPrager(const MicropolarElastic& el, const DruckerPragerParams& d,
                          const Points& p, bool plane = false, bool water = false)
      : elastic(el),
        dp(d),
        plane_stress(Dim == 2 && plane),
        pore_water(Dim == 2 && plane && water),
        start(p.plastic_step_start),
        ep(p.plastic_strain),
        kp(p.plastic_wryness),
        ezz(p.plastic_strain_zz),
        eq(p.equivalent_plastic_strain),
        vol(p.plastic_volumetric_strain),
        coh(p.cohesion),
        szz(p.stress_zz) {}

  // Pass 1's constitutive update at owned point i (eqs 80-95): the return from the start state.
  // srp: S_r p* of the point (pass 1's pressure), the target of sigma-bar_zz in plane stress
  // with pore water (header); not used otherwise.
  template <int D>
  KOKKOS_INLINE_FUNCTION double stress(std::size_t i, const double* eps, const double* kappa,
                                       double* sigma, double* m, double srp = 0) const {
    static_assert(D == Dim, "the law's dimension");
    PlasticPoint<Dim> old, nw;
    for (int k = 0; k < Dim * Dim; ++k)
      old.ep[k] = start(i, kEp + k);
    old.ezz = start(i, kEzz);
    for (int k = 0; k < R * Dim; ++k)
      old.kp[k] = start(i, kKp + k);
    old.eq = start(i, kEq);
    double sz = 0;
    double w;
    if constexpr (Dim == 2) {
      if (plane_stress) {
        const double s = pore_water ? srp : 0.0;
        w = drucker_prager_return_plane_stress(elastic, dp, eps, kappa, old, nw, sigma, &sz, m,
                                               nullptr, s);
        if (pore_water) {  // the solid subtracts biot s 1, the total needs s 1 (header)
          const double L = elastic.lambda + 2 * elastic.mu;
          sigma[0] -= elastic.lambda / L * s;
          sigma[3] -= elastic.lambda / L * s;
          w -= 0.5 * s * s / L;
        }
      } else {
        w = drucker_prager_return<Dim>(elastic, dp, eps, kappa, old, nw, sigma, &sz, m);
      }
    } else
      w = drucker_prager_return<Dim>(elastic, dp, eps, kappa, old, nw, sigma, &sz, m);
    double tr = Dim == 2 ? nw.ezz : 0.0;
    for (int k = 0; k < Dim * Dim; ++k)
      ep(i, k) = nw.ep[k];
    for (int d = 0; d < Dim; ++d)
      tr += nw.ep[d * Dim + d];
    for (int k = 0; k < R * Dim; ++k)
      kp(i, k) = nw.kp[k];
    ezz(i) = nw.ezz;
    eq(i) = nw.eq;
    vol(i) = tr;
    coh(i) = dp.cohesion_at(nw.eq);
    szz(i) = sz;
    return w;
  }

  // Pi / biot of the header (plane stress with pore water; 0 otherwise): what the solver adds to
  // tr eps for the water's volumetric strain, with the current plastic state (after the step's
  // return) or the step's start state.
  KOKKOS_INLINE_FUNCTION double pore_shift(std::size_t i) const {
    return pore_water ? shift(vol(i), ezz(i)) : 0.0;
  }
  KOKKOS_INLINE_FUNCTION double pore_shift_start(std::size_t i) const {
    if (!pore_water)
      return 0.0;
    const double tr = start(i, kEp) + start(i, kEp + Dim * Dim - 1) + start(i, kEzz);
    return shift(tr, start(i, kEzz));
  }
  // (lambda tr eps^p + 2 mu eps^p_zz) / L divided by biot = 2 mu / L.
  KOKKOS_INLINE_FUNCTION double shift(double tr_ep, double ep_zz) const {
    return (elastic.lambda * tr_ep + 2 * elastic.mu * ep_zz) / (2 * elastic.mu);
  }

  // Plastic dissipation of the step at point i per unit volume: the trapezoid
  // 1/2 (sigma_start + sigma) : d eps^p + 1/2 (m_start + m) : d kappa^p (3 x 3 with the zz
  // terms in 2D) of the effective stress sigma-bar. With W quadratic in the elastic strain this is
  // exactly the part of the trapezoid work 1/2 (sigma_start + sigma) : d eps that the stored energy
  // does not take, so the energy balance (eq 140) closes with it.
  template <class Stress>
  KOKKOS_INLINE_FUNCTION double dissipation(std::size_t i, const Stress& sigma,
                                            const Stress& m) const {
    double d = 0;
    for (int k = 0; k < Dim * Dim; ++k)
      d += 0.5 * (start(i, kSig + k) + sigma(i, k)) * (ep(i, k) - start(i, kEp + k));
    if (Dim == 2)
      d += 0.5 * (start(i, kSzz) + szz(i)) * (ezz(i) - start(i, kEzz));
    for (int k = 0; k < R * Dim; ++k)
      d += 0.5 * (start(i, kM + k) + m(i, k)) * (kp(i, k) - start(i, kKp + k));
    if (pore_water) {  // sigma holds sigma-bar_in - (lambda / L) S_r p* 1 (stress()): add it back
      const double c = elastic.lambda / (elastic.lambda + 2 * elastic.mu);
      for (int a = 0; a < Dim; ++a)
        d += 0.5 * c * (start(i, kSzz) + szz(i)) *
             (ep(i, a * Dim + a) - start(i, kEp + a * Dim + a));
    }
    return d;
  }

  // current -> start, with the stress the next step starts from.
  template <class Stress>
  KOKKOS_INLINE_FUNCTION void commit(std::size_t i, const Stress& sigma, const Stress& m) const {
    for (int k = 0; k < Dim * Dim; ++k) {
      start(i, kEp + k) = ep(i, k);
      start(i, kSig + k) = sigma(i, k);
    }
    start(i, kEzz) = ezz(i);
    start(i, kSzz) = szz(i);
    for (int k = 0; k < R * Dim; ++k) {
      start(i, kKp + k) = kp(i, k);
      start(i, kM + k) = m(i, k);
    }
    start(i, kEq) = eq(i);
  }
};

}  // namespace mupm

#endif
