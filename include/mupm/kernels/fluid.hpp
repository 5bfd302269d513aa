// Unsaturated pore-fluid flow in the bulk: nonlocal pressure gradient, Darcy flux, stabilized
// flow states and the mass balance (paper eqs 12, 14, 52, 54, 56, 59, 72, 74, 76, 78, 113-117,
// 121-122, 141-146). Kernels only: no MPI (the solver refreshes the ghosts between the passes,
// include/mupm/solvers/fluid_solver.hpp).
//
// Pass 1 (per point i, intact bonds):
//   K_i = sum_j omega xi (x) xi V_j,   grad p_i = K_i^-1 sum_j omega (p_j - p_i) xi V_j   (eq 59)
//   q_i = -(k_r k / mu_w) (grad p_i - rho_w g)                                    (eq 54, 56)
// Pass 2: the flow divergence, with the flow state of eqs 74 and 121 divided by rho_w,
//   F_ij = omega q_i . K_i^-1 xi - alpha_i R_ij,   R_ij = (p_j - p_i) - grad p_i . xi   (eq 72)
//   div_i = sum_j (F_ij - F_ji) V_j                                                 (eq 116)
//         = sum_j [(K_i^-1 q_i + K_j^-1 q_j) . xi - alpha_i R_ij - alpha_j (p_j - p_i - grad p_j .
//         xi)] V_j
// (F_ji uses j's quantities and xi_ji = -xi, R_ji = -(p_j - p_i) + grad p_j . xi). For a linear
// flux field and a full, symmetric family the first term is exactly div q: sum_j xi.K^-1 (grad q)
// xi V_j = tr(K^-1 grad q K) = div q. The stabilization acts on the non-uniform part R of the
// pressure state only: R = 0 for a linear p, and for a quadratic p (R_ij = R_ji = xi.H xi / 2)
// its two terms cancel where alpha_i = alpha_j. It therefore leaves smooth flow alone.
//
// Sign of the stabilization: the paper's eq 74 writes "+ alpha_3 R_w". With q = -k grad p the
// flux runs down the gradient; a bond's non-uniform pressure difference must drive flow the
// same way, so the flow state carries -alpha R. With it, for a field with grad p = 0 (a
// checkerboard mode), C dp_i/dt = -div_i = sum_j (alpha_i + alpha_j)(p_j - p_i) V_j: bond-wise
// diffusion, which makes sum_i V_i C p_i^2 decrease (dissipative). With "+" the checkerboard
// would grow. The test Fluid.CheckerboardDecays fails on the other sign.
//
// Micro-conductivity (eqs 76, 78), in 2D and 3D. The paper's 3D C_3 = 6k/(pi delta^4) is the
// micro-conductivity of bond-based diffusion with bond flow C_3 (p_j - p_i)/|xi|, matched to
// k lap p for a quadratic field: 1/2 H : int C_3 xi (x) xi / |xi| dV = (C_3 pi delta^4 / 6) tr H.
// Eq 76 makes alpha_3 the same on every bond of a family (no |xi|), so we match the uniform
// bond weight the same way: a bond conductance c on every bond gives
//   sum_j c (p_j - p_i) V_j -> 1/2 c H : int xi (x) xi dV = 1/2 c k2 tr H,
//   k2 = int_H |xi|^2 / Dim dV = 4 pi delta^5 / 15 (3D),   pi h delta^4 / 4 (2D, thickness h),
// so c = 2 lambda / k2 with lambda = k_r k / mu_w. Bond i-j gets alpha_i + alpha_j, hence
//   alpha_i = G lambda_i / (k2 w0_i),
// with G the stabilization parameter in [0, 1] and w0_i = omega_0 / V_H the family's share of a
// full family (eq 68, read as in the solid, include/mupm/kernels/solid.hpp): boundary points, with
// truncated families, get a proportionally larger alpha. (For comparison, the 2D analogue of
// the paper's 1/|xi| form is C_3 = 6k / (pi h delta^3).)
//
// Mass balance (eqs 14, 113-117, 143; the paper's storage phi dS_r/dp alone is zero where the
// point is saturated, so C adds the water's compressibility phi S_r / K_w, keeping C > 0):
//   C_i dp_i/dt = -S_r,i dV_s,i/dt - div_i + s_i,   C = phi dS_r/dp + phi S_r / K_w,
// with dV_s/dt the rate of the volumetric strain tr(eps) of the solid (eq 117) and s_i a source
// [1/s]. Forward Euler (eqs 141, 145 with beta_3 = 0). In plane stress (PoreCoupling,
// include/mupm/laws/micropolar_elastic.hpp) S_r dV_s/dt is biot S_r dV_s/dt and C gains
// c_z S_r d(S_r p)/dp, c_z = 1/(lambda + 2 mu): the thickness's swelling under the pressure.
#ifndef MUPM_FLUID_HPP
#define MUPM_FLUID_HPP

#include <vector>

#include "mupm/core/small_matrix.hpp"
#include "mupm/data/bonds.hpp"
#include "mupm/data/points.hpp"
#include "mupm/data/shape_tensors.hpp"
#include "mupm/laws/micropolar_elastic.hpp"
#include "mupm/laws/unsaturated.hpp"

namespace mupm {

struct FluidParams {
  VanGenuchten retention;       // disabled: saturated everywhere
  double mobility = 0;          // k / mu_w [m^2/(Pa s)] (= K_h / (rho_w g))
  double water_density = 1000;  // rho_w [kg/m^3]
  double bulk_modulus = 2.2e9;  // K_w [Pa]
  double stabilization = 0.5;   // G (eq 76)
  // Solver->Pressure Integration = Semi-Implicit (include/mupm/solvers/pressure_projection.hpp):
  // the solid sees p itself, no undrained split (Points::undrained_modulus = 0).
  bool semi_implicit = false;
  // G_p of the projection's pressure stabilization (Semi-Implicit only; include/mupm/solvers/
  // pressure_projection.hpp).
  double projection_stabilization = 1.0;
  PoreCoupling pore;  // the skeleton's coefficient and plane stress's lateral compliance c_z
  double horizon_volume = 0;           // V_H: volume of a full continuous family
  double second_moment = 0;            // k2 = int_H |xi|^2 / Dim dV
  Kokkos::Array<double, 3> gravity{};  // g in Darcy's law (all zero: no gravity term)
};

template <int Dim>
struct FluidState {
  Scalars storage;  // C_i [1/Pa] (owned)
  Vectors grad;     // nonlocal pressure gradient (eq 59) [Pa/m] (owned + ghosts)
  Vectors qk;       // K_i^-1 q_i (owned + ghosts)
  Scalars alpha;    // stabilization coefficient alpha_i (owned + ghosts)
  Scalars flow;     // div_i = sum_j (F_ij - F_ji) V_j [1/s] (owned)

  void allocate(std::size_t n_all, std::size_t n_owned) {
    storage = Scalars("mupm::storage", n_owned);
    grad = Vectors("mupm::pressure_gradient", n_all, Dim);
    qk = Vectors("mupm::flux_projection", n_all, Dim);
    alpha = Scalars("mupm::flow_stabilization", n_all);
    flow = Scalars("mupm::flow_divergence", n_owned);
  }
  std::vector<Vectors> pass2_ghosts() const { return {grad, qk, as_vectors(alpha)}; }
};

// Energy stored in the pore water per unit volume, psi(p) = int_0^p C(q) q dq (the work of
// the pressure on the water content, dm = C dp): phi p^2 / (2 K_w) for p >= 0, and for p < 0
// (unsaturated) the capillary part phi int q dS_r plus the compressional part, by 8-point
// Gauss-Legendre quadrature on [p, 0]. In plane stress the storage's c_z S_r d(S_r p)/dp adds
// c_z (S_r p)^2 / 2 (exactly: c_z = PoreCoupling::lateral_compliance, 0 but in plane stress). A
// state function: the fluid energy balance (eqs 147-149) compares its change with the power the
// update books step by step.
//
// The nodes are q_k = t_k p with fixed t_k in (0, 1), so (-q_k / s_a)^n = (-p / s_a)^n t_k^n:
// RetentionEnergy holds the t_k^n of a curve (the hot loops make one before their launch;
// stored_energy_density and entry_pressure(vg, ...) one per call), and a point then takes one
// power for (-p / s_a)^n and one per node for S_r = (1 + x^n)^(-m), ten in all where evaluating
// the curve at each node would take eighteen.
struct RetentionEnergy {
  static constexpr int kNodes = 8;
  VanGenuchten vg;
  Kokkos::Array<double, kNodes> t, w, tn;  // nodes on [0, 1] (of p), weights, t^n

  KOKKOS_INLINE_FUNCTION explicit RetentionEnergy(const VanGenuchten& v) : vg(v) {
    const double x[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                         0.9602898564975363};
    const double wx[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                          0.1012285362903763};
    for (int k = 0; k < 4; ++k)
      for (int sign = 0; sign < 2; ++sign) {
        const int j = 2 * k + sign;
        t[j] = 0.5 * (1 + (sign ? x[k] : -x[k]));
        w[j] = wx[k];
        tn[j] = std::pow(t[j], v.n);
      }
  }

  KOKKOS_INLINE_FUNCTION double density(double phi, double inv_kw, double p, double cz = 0) const {
    if (p >= 0 || !vg.enabled)
      return 0.5 * (phi * inv_kw + cz) * p * p;
    const double x = -p / vg.air_entry;
    const double xn = std::pow(x, vg.n);
    const double sp = vg.saturation_from(xn) * p;  // S_r(p) p
    double s = 0;
    for (int k = 0; k < kNodes; ++k) {
      // S_r and dS_r/dp at q = t p, from x t and (x t)^n = x^n t^n.
      const double xk = x * t[k], xnk = xn * tn[k];
      const double sq = vg.saturation_from(xnk);
      const double dsq = vg.slope_from(xk, xnk, sq);
      s += w[k] * phi * (dsq + sq * inv_kw) * (t[k] * p);
    }
    return 0.5 * p * s +
           0.5 * cz * sp * sp;  // int_0^p f dq = (p/2) sum_k w_k f(q_k), nodes on [p, 0]
  }
};

KOKKOS_INLINE_FUNCTION double stored_energy_density(const VanGenuchten& vg, double phi,
                                                    double inv_kw, double p, double cz = 0) {
  if (p >= 0 || !vg.enabled)
    return 0.5 * (phi * inv_kw + cz) * p * p;
  return RetentionEnergy(vg).density(phi, inv_kw, p, cz);
}

// The pressure at which the stored energy takes in a step's change of content C dp at a point,
// from p0 by dp: [psi(p0 + dp) - psi(p0)] / (C dp), psi0 and psi1 the stored energy densities
// at both ends. It is the step's mean p0 + dp/2 where C is constant (saturated, or no
// retention curve: `varies` false), and is taken as that where the step is too small against
// p0 for the difference to hold its digits (the difference's relative error is about
// 1e-16 |p0 / dp|: at |dp| <= 1e-8 |p0| the mean is nearer, off by (dC/dp / C) dp / 2).
KOKKOS_INLINE_FUNCTION double entry_pressure(double p0, double dp, double C, double psi0,
                                             double psi1, bool varies) {
  if (!varies || !(std::abs(dp) > 1e-8 * std::abs(p0)) || C * dp == 0)
    return p0 + 0.5 * dp;
  return (psi1 - psi0) / (C * dp);
}
// Whether C varies over a step from p0 to p1 (the retention curve's range, p < 0).
KOKKOS_INLINE_FUNCTION bool storage_varies(const VanGenuchten& vg, double p0, double p1) {
  return vg.enabled && (p0 < 0 || p1 < 0);
}
KOKKOS_INLINE_FUNCTION double entry_pressure(const RetentionEnergy& e, double phi, double inv_kw,
                                             double p0, double dp, double C, double cz = 0) {
  if (!storage_varies(e.vg, p0, p0 + dp))
    return p0 + 0.5 * dp;
  return entry_pressure(p0, dp, C, e.density(phi, inv_kw, p0, cz),
                        e.density(phi, inv_kw, p0 + dp, cz), true);
}
KOKKOS_INLINE_FUNCTION double entry_pressure(const VanGenuchten& vg, double phi, double inv_kw,
                                             double p0, double dp, double C, double cz = 0) {
  if (!storage_varies(vg, p0, p0 + dp))
    return p0 + 0.5 * dp;
  return entry_pressure(RetentionEnergy(vg), phi, inv_kw, p0, dp, C, cz);
}

// Saturation (eq 12), relative permeability (eq 56), storage C (with plane stress's c_z term,
// header) and the undrained modulus biot S_r / C (for the solid's undrained split,
// include/mupm/kernels/solid.hpp) of the owned points.
template <int Dim>
void fluid_constitutive(const Points<Dim>& pts, const FluidParams& prm, FluidState<Dim>& st) {
  auto p = pts.p, phi = pts.porosity, sr = pts.saturation, kr = pts.rel_perm;
  auto bu = pts.undrained_modulus;
  auto fixed = pts.fixed;
  auto C = st.storage;
  const VanGenuchten vg = prm.retention;
  const double inv_kw = 1.0 / prm.bulk_modulus;
  const bool split = !prm.semi_implicit;
  const double biot = prm.pore.biot, cz = prm.pore.lateral_compliance;
  Kokkos::parallel_for(
      "mupm::Fluid::constitutive", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        double s, ds;
        vg.saturation_and_slope(p(i), s, ds);
        sr(i) = s;
        kr(i) = vg.relative_permeability(s);
        const double c = phi(i) * (ds + s * inv_kw) + cz * s * (s + p(i) * ds);
        C(i) = c;
        bu(i) = !split || (fixed(i) & kFixedPressure) || !(c > 0) ? 0.0 : biot * s / c;
      });
}

// Pass 1 (per owned point): grad p, Darcy flux q (into pts.darcy_flux), K^-1 q, alpha.
// `p` is the pressure field (owned + ghosts current); `with_gravity` false drops rho_w g (the
// stable-step estimate uses the linear operator only). Points whose K is singular (see
// invert_shape_tensor, include/mupm/kernels/shape_tensor.hpp) get grad p = 0, q = 0: their bonds
// carry the stabilization flow only.
template <int Dim>
void fluid_pass1(const Points<Dim>& pts, const Bonds& bonds, const ShapeTensors<Dim>& shape,
                 const FluidParams& prm, FluidState<Dim>& st, const Scalars& p,
                 bool with_gravity = true) {
  auto offsets = bonds.offsets;
  auto neighbor = bonds.neighbor;
  auto intact = bonds.intact;
  auto x = pts.x, q = pts.darcy_flux;
  auto vol = pts.volume, kr = pts.rel_perm;
  auto grad = st.grad, qk = st.qk, alpha = st.alpha;
  auto Kinv_v = shape.Kinv, fam = shape.family_volume;
  auto sing = shape.singular;
  const double k0 = prm.mobility, rho_w = prm.water_density;
  const double a0 = prm.stabilization * k0 / prm.second_moment;
  const double inv_vh = 1.0 / prm.horizon_volume;
  Kokkos::Array<double, 3> g{};
  for (int d = 0; d < 3; ++d)
    g[d] = with_gravity ? prm.gravity[d] : 0.0;
  Kokkos::parallel_for(
      "mupm::Fluid::pass1", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        double b[Dim] = {};
        const double pi = p(i);
        for (BondIndex e = offsets(i); e < offsets(i + 1); ++e) {
          if (!intact(e))
            continue;
          const int j = neighbor(e);
          const double vj = vol(j);
          const double dp = p(j) - pi;
          double xi[Dim];
          for (int d = 0; d < Dim; ++d)
            xi[d] = x(j, d) - x(i, d);
          for (int a = 0; a < Dim; ++a)
            b[a] += dp * xi[a] * vj;  // eq 59
        }
        double Kinv[Dim * Dim];
        for (int k = 0; k < Dim * Dim; ++k)
          Kinv[k] = Kinv_v(i, k);
        const bool singular = sing(i) != 0;
        const double wsum = fam(i);
        const double lambda = kr(i) * k0;
        double gp[Dim] = {}, qi[Dim] = {}, qki[Dim] = {};
        if (!singular) {
          mat_vec<Dim, Dim>(Kinv, b, gp);
          for (int d = 0; d < Dim; ++d)
            qi[d] = -lambda * (gp[d] - rho_w * g[d]);  // eq 54
          mat_vec<Dim, Dim>(Kinv, qi, qki);
        }
        for (int d = 0; d < Dim; ++d) {
          grad(i, d) = gp[d];
          q(i, d) = qi[d];
          qk(i, d) = qki[d];
        }
        const double w0 = wsum * inv_vh;
        alpha(i) = w0 > 0 ? a0 * kr(i) / w0 : 0.0;  // eq 76, 2D/3D constant in the header
      });
}

// Pass 2 (per owned point, full neighbour list): the flow divergence div_i (eq 116 with the
// flow states of eqs 121-122). Needs grad, qk, alpha and p current on the ghosts.
template <int Dim>
void fluid_pass2(const Points<Dim>& pts, const Bonds& bonds, FluidState<Dim>& st,
                 const Scalars& p) {
  auto offsets = bonds.offsets;
  auto neighbor = bonds.neighbor;
  auto intact = bonds.intact;
  auto x = pts.x, vol = pts.volume;
  auto grad = st.grad, qk = st.qk, alpha = st.alpha, flow = st.flow;
  Kokkos::parallel_for(
      "mupm::Fluid::pass2", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        double div = 0;
        const double pi = p(i), ai = alpha(i);
        for (BondIndex e = offsets(i); e < offsets(i + 1); ++e) {
          if (!intact(e))
            continue;
          const int j = neighbor(e);
          double qx = 0, gi = 0, gj = 0;
          for (int d = 0; d < Dim; ++d) {
            const double xi = x(j, d) - x(i, d);
            qx += (qk(i, d) + qk(j, d)) * xi;
            gi += grad(i, d) * xi;
            gj += grad(j, d) * xi;
          }
          const double dp = p(j) - pi;
          div += (qx - ai * (dp - gi) - alpha(j) * (dp - gj)) * vol(j);  // eqs 72, 74, 116
        }
        flow(i) = div;
      });
}

}  // namespace mupm

#endif
