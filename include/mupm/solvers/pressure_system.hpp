// The linear operators of the semi-implicit pressure step (include/mupm/solvers/
// pressure_projection.hpp), assembled as Tpetra CrsMatrix over the points' map from the bond
// lists: each rank assembles the rows of its owned points; columns reach the ghosts.
//
// 1. The flow operator V H: (V H p)_i = V_i div_i(p), div the flow divergence of the fluid's
//    passes (include/mupm/kernels/fluid.hpp, eqs 59, 72-78, 116) without gravity, at the
//    current k_r and alpha. Multiplying pass 2 by a test field y and summing over all points
//    (intact bonds come in pairs i -> j, j -> i) gives, with g_i(p) = K_i^-1 sum_j (p_j - p_i)
//    xi V_j the nonlocal gradient (eq 59) and lambda_i = k_r,i k / mu_w,
//      sum_i y_i V_i div_i(p) = sum_i V_i lambda_i g_i(p) . g_i(y)                    (flux)
//                             + sum_i alpha_i V_i [sum_j V_j (p_j - p_i)(y_j - y_i)
//                                                  - g_i(p) . K_i g_i(y)]            (eq 72)
//    (the flux part: sum_j (K_i^-1 q_i + K_j^-1 q_j) . xi V_j summed against y is
//    -sum_i V_i K_i^-1 q_i . K_i g_i(y); the stabilization part is sum_i alpha_i V_i sum_j V_j
//    R_ij(p) R_ij(y), R the non-uniform part of eq 72). So
//      V H = Gr^T W Gr + L,   W_i = V_i (lambda_i I - alpha_i K_i) (a Dim x Dim block),
//    Gr the gradient (Dim rows per point), L the graph Laplacian of the bond weights
//    V_i V_j (alpha_i + alpha_j): symmetric, and positive semi-definite (the form above is a
//    sum of squares). Points with a singular K have g = 0 and keep their alpha.
// 2. The coupling B~ = diag(V biot S_r) B (biot: PoreCoupling, 1 but in plane stress), B_i = d(tr
// eps_i)/d(u, theta) the Jacobian of the
//    nonlocal volumetric strain (eqs 50, 117): tr eps_i = sum_j V_j U^_ij . c_ij, c_ij = K_i^-1
//    xi_ij, U^ = u_j - u_i - (theta_i + theta_j)/2 x xi (eqs 2-9), so
//      d/du_j = V_j c_ij,  d/du_i = -sum_j V_j c_ij,  d/dtheta_i += d/dtheta_j = -V_j (xi x c)/2.
//    Its transpose is the pore water's force: the -S_r p 1 part of the total stress (eq 46)
//    through the force and moment states (eqs 64-65, 105-112) gives V_k (f_k, l_k) =
//    (B~^T p)_k, because the solid's states are the derivatives of its energy
//    (include/mupm/kernels/solid.hpp) and the pressure's part is -sum_i V_i S_r p_i tr eps_i.
//    Degenerate points (singular K) and slaved layer points have tr eps = 0: empty rows.
// 3. The projection B~ M^-1 B~^T (M the lumped masses rho V and micro-inertias J V, zero
//    inverse on prescribed components): the volume change, weighted by V S_r, that a pressure
//    increment produces through the velocity it gives the skeleton in one step (dt^2 times).
// The tests (tests/solvers/test_pressure_projection.cpp) compare each with the kernels.
#ifndef MUPM_SOLVERS_PRESSURE_SYSTEM_HPP
#define MUPM_SOLVERS_PRESSURE_SYSTEM_HPP

#include <Teuchos_RCP.hpp>
#include <TpetraExt_MatrixMatrix.hpp>
#include <Tpetra_CrsMatrix.hpp>
#include <Tpetra_Vector.hpp>
#include <algorithm>
#include <vector>

#include "mupm/core/small_matrix.hpp"
#include "mupm/kernels/fluid.hpp"
#include "mupm/mesh/discretization.hpp"
#include "mupm/solvers/kept_matrix.hpp"
#include "mupm/solvers/linear_solve.hpp"

namespace mupm {

// A map of `ncomp` entries per point (global index gid * ncomp + c) over the owned points, or
// over the owned and ghost points (the points' local order, ghosts after the owned).
template <int Dim>
Teuchos::RCP<const Map> component_map(const Discretization<Dim>& disc, int ncomp, bool ghosts) {
  const auto& p = disc.points;
  const std::size_t n = ghosts ? p.size() : p.n_owned;
  std::vector<GlobalId> ids(n * std::size_t(ncomp));
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < ncomp; ++c)
      ids[i * std::size_t(ncomp) + std::size_t(c)] = p.gid(i) * ncomp + c;
  const auto invalid = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
  return Teuchos::rcp(
      new Map(invalid, Teuchos::ArrayView<const GlobalId>(ids), 0, disc.dist.comm()));
}

// The factors of V H (header, 1): the gradient Gr, W Gr and the graph Laplacian L, over every
// bond in the lists (a broken bond's entries and a singular point's gradient are zero, so the
// graphs do not change when bonds break: include/mupm/solvers/kept_matrix.hpp), with the
// stabilization coefficients `alpha` (owned + ghosts) and the points' current k_r.
struct FlowRows {
  LocalRows gr, wgr, lap;
};
template <int Dim>
void flow_rows(const Discretization<Dim>& disc, const FluidParams& prm, const Scalars& alpha,
               FlowRows& out) {
  const auto& p = disc.points;
  const auto& b = disc.bonds;
  const auto& sh = disc.shape;
  const std::size_t n = p.n_owned;
  clear_rows(out.gr, n * Dim);
  clear_rows(out.wgr, n * Dim);
  clear_rows(out.lap, n);
  for (std::size_t i = 0; i < n; ++i) {
    const double vi = p.volume(i), ai = alpha(i);
    double self_lap = 0;
    const bool singular = sh.singular(i) != 0;
    double Kinv[Dim * Dim], K[Dim * Dim], W[Dim * Dim] = {};
    for (int k = 0; k < Dim * Dim; ++k)
      Kinv[k] = sh.Kinv(i, k);
    auto& lap = out.lap[i];
    std::vector<std::pair<LocalId, double>>* row[Dim];  // Gr's rows of i
    for (int d = 0; d < Dim; ++d)
      row[d] = &out.gr[i * Dim + d];
    double self[Dim] = {};
    for (BondIndex e = b.offsets(i); e < b.offsets(i + 1); ++e) {
      const LocalId j = b.neighbor(e);
      const bool intact = b.intact(e) != 0;
      const double vj = p.volume(j);
      const double w = intact ? vi * vj * (ai + alpha(j)) : 0.0;
      lap.push_back({j, -w});
      self_lap += w;
      double c[Dim] = {};
      if (intact && !singular) {
        double xi[Dim];
        for (int d = 0; d < Dim; ++d)
          xi[d] = p.x(j, d) - p.x(i, d);
        mat_vec<Dim, Dim>(Kinv, xi, c);
      }
      for (int d = 0; d < Dim; ++d) {
        row[d]->push_back({j, c[d] * vj});
        self[d] -= c[d] * vj;
      }
    }
    lap.push_back({LocalId(i), self_lap});
    if (!singular) {
      invert<Dim>(Kinv, K);
      const double lambda = p.rel_perm(i) * prm.mobility;
      for (int r = 0; r < Dim; ++r)
        for (int c = 0; c < Dim; ++c)
          W[r * Dim + c] = vi * ((r == c ? lambda : 0.0) - ai * K[r * Dim + c]);
    }
    for (int d = 0; d < Dim; ++d)
      row[d]->push_back({LocalId(i), self[d]});
    // W Gr: row (i, d) = sum_e W_de Gr(i, e); the rows share their columns.
    for (int d = 0; d < Dim; ++d) {
      auto& w = out.wgr[i * Dim + d];
      w = *row[0];
      for (std::size_t k = 0; k < w.size(); ++k) {
        double s = 0;
        for (int e2 = 0; e2 < Dim; ++e2)
          s += W[d * Dim + e2] * (*row[e2])[k].second;
        w[k].second = s;
      }
    }
  }
}

// V H = Gr^T W Gr + L on kept graphs (build, then fill with new alpha, k_r or bonds' state).
// Gr^T is kept as a matrix and transposed again only when the bonds changed (`geometry`): the
// product then needs no transpose when only W (k_r, alpha) changed.
template <int Dim>
class FlowOperator {
 public:
  void build(const Discretization<Dim>& disc, const FluidParams& prm, const Scalars& alpha) {
    flow_rows(disc, prm, alpha, rows_);
    const auto grad_map = component_map(disc, Dim, false);
    const auto& owned = disc.dist.owned_map();
    const auto& overlap = disc.dist.overlap_map();
    g_.build(grad_map, overlap, owned, grad_map, rows_.gr);
    wg_.build(grad_map, overlap, owned, grad_map, rows_.wgr);
    l_.build(owned, overlap, owned, owned, rows_.lap);
    gt_.build(g_.matrix());
    flux_.build(*gt_.matrix(), *wg_.matrix());
    sum_.build(1.0, *flux_.matrix(), 1.0, *l_.matrix());
  }
  void fill(const Discretization<Dim>& disc, const FluidParams& prm, const Scalars& alpha,
            bool geometry) {
    flow_rows(disc, prm, alpha, rows_);
    if (geometry) {
      g_.fill(rows_.gr);
      gt_.fill(*g_.matrix());
    }
    wg_.fill(rows_.wgr);
    l_.fill(rows_.lap);
    flux_.fill(*gt_.matrix(), *wg_.matrix());
    sum_.fill(1.0, *flux_.matrix(), 1.0, *l_.matrix());
  }
  const Teuchos::RCP<CrsMatrix>& matrix() const { return sum_.matrix(); }

 private:
  FlowRows rows_;
  KeptRows g_, wg_, l_;
  KeptTranspose gt_;
  KeptProduct flux_;
  KeptSum sum_;
};

// V H (header, 1) with the stabilization coefficients `alpha` (owned + ghosts: the fluid
// state's alpha after FluidSolver's evaluate(), or more, pressure_projection.hpp) and the
// points' current k_r.
template <int Dim>
Teuchos::RCP<CrsMatrix> assemble_flow_operator(const Discretization<Dim>& disc,
                                               const FluidParams& prm, const Scalars& alpha) {
  FlowOperator<Dim> h;
  h.build(disc, prm, alpha);
  return h.matrix();
}

// The pressure stabilization of the semi-implicit step (derivation in pressure_projection.hpp):
// alpha_i += G_p (biot S_r,i)^2 dt / (rho_i k2 w0_i) on the owned points, w0_i = omega_0,i / V_H
// (eq 76), rho the lumped mass density; then the ghosts are refreshed (collective).
template <int Dim>
void add_pressure_stabilization(Discretization<Dim>& disc, const FluidParams& prm, double dt,
                                const Scalars& density, const Scalars& alpha) {
  const auto& p = disc.points;
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const double w0 = disc.shape.family_volume(i) / prm.horizon_volume,
                 s = prm.pore.biot * p.saturation(i);
    const double rho = density(i);
    if (w0 > 0 && rho > 0)
      alpha(i) += prm.projection_stabilization * s * s * dt / (rho * prm.second_moment * w0);
  }
  disc.dist.refresh({as_vectors(alpha)});
}

// The rows of B~ (header, 2) over every bond in the lists (zero for a broken bond and on a
// singular point, so that the graph does not change when bonds break), columns in the
// component map over the owned and ghost points (component_map(disc, Dim + R, true)).
template <int Dim>
void volume_coupling_rows(const Discretization<Dim>& disc, double biot, bool saturation,
                          LocalRows& rows) {
  constexpr int R = kRotDim<Dim>, NC = Dim + R;
  const auto& p = disc.points;
  const auto& b = disc.bonds;
  const auto& sh = disc.shape;
  const std::size_t n = p.n_owned;
  clear_rows(rows, n);
  for (std::size_t i = 0; i < n; ++i) {
    if (p.fixed(i) & kFixedNoEnergy)
      continue;
    const bool singular = sh.singular(i) != 0;
    const double s = p.volume(i) * biot * (saturation ? p.saturation(i) : 1.0);
    double Kinv[Dim * Dim];
    for (int k = 0; k < Dim * Dim; ++k)
      Kinv[k] = sh.Kinv(i, k);
    double self[NC] = {};
    auto& row = rows[i];
    for (BondIndex e = b.offsets(i); e < b.offsets(i + 1); ++e) {
      const LocalId j = b.neighbor(e);
      const double vj = p.volume(j);
      double c[Dim] = {}, rot[R] = {};
      if (b.intact(e) && !singular) {
        double xi[Dim];
        for (int d = 0; d < Dim; ++d)
          xi[d] = p.x(j, d) - p.x(i, d);
        mat_vec<Dim, Dim>(Kinv, xi, c);
        cross<Dim>(xi, c, rot);
      }
      for (int d = 0; d < Dim; ++d) {
        row.push_back({LocalId(j * NC + d), s * vj * c[d]});
        self[d] -= s * vj * c[d];
      }
      for (int r = 0; r < R; ++r) {
        const double w = -0.5 * s * vj * rot[r];
        row.push_back({LocalId(j * NC + Dim + r), w});
        self[Dim + r] += w;
      }
    }
    for (int k = 0; k < NC; ++k)
      row.push_back({LocalId(i * NC + std::size_t(k)), self[k]});
  }
}

// B~ (header, 2) without its factor S_r (B_0, B~ = diag(S_r) B_0: the graph and values that
// change with the bonds only) on a kept graph, over the owned points (rows) and their
// (u, theta) components (columns: component_map(disc, Dim + R, ...)).
template <int Dim>
class VolumeCoupling {
 public:
  void build(const Discretization<Dim>& disc, double biot) {
    constexpr int NC = Dim + kRotDim<Dim>;
    volume_coupling_rows(disc, biot, false, rows_);
    m_.build(disc.dist.owned_map(), component_map(disc, NC, true), component_map(disc, NC, false),
             disc.dist.owned_map(), rows_);
  }
  void fill(const Discretization<Dim>& disc, double biot) {
    volume_coupling_rows(disc, biot, false, rows_);
    m_.fill(rows_);
  }
  const Teuchos::RCP<CrsMatrix>& matrix() const { return m_.matrix(); }

 private:
  LocalRows rows_;
  KeptRows m_;
};

// B~ (header, 2).
template <int Dim>
Teuchos::RCP<CrsMatrix> assemble_volume_coupling(const Discretization<Dim>& disc, double biot = 1) {
  constexpr int NC = Dim + kRotDim<Dim>;
  LocalRows rows;
  volume_coupling_rows(disc, biot, true, rows);
  KeptRows b;
  b.build(disc.dist.owned_map(), component_map(disc, NC, true), component_map(disc, NC, false),
          disc.dist.owned_map(), rows);
  return b.matrix();
}

// B~ M^-1 B~^T (header, 3); `inverse_mass` on the owned components (0 where prescribed).
inline Teuchos::RCP<CrsMatrix> projection_operator(const CrsMatrix& coupling,
                                                   const TpetraVector& inverse_mass) {
  auto scaled = Teuchos::rcp(new CrsMatrix(coupling, Teuchos::Copy));
  scaled->rightScale(inverse_mass);
  auto out = Teuchos::rcp(new CrsMatrix(coupling.getRowMap(), 0));
  Tpetra::MatrixMatrix::Multiply(*scaled, false, coupling, true, *out);
  return out;
}

// The fracture network's rows of the joint semi-implicit system (include/mupm/solvers/
// fracture_flow.hpp, Pressure Integration = Semi-Implicit; derivation in pressure_projection.hpp),
// written by the network each step. Joint numbering: a point's pore pressure is its gid, its
// fracture pressure offset + gid. Per owned network point k (in `point` order):
struct CrackBlock {
  GlobalId offset = 0;         // the fracture pressures' gid offset (the points' count)
  std::vector<LocalId> point;  // the point's local id
  std::vector<char> held;      // p_f prescribed (Fracture Pressure): its increment is given
  std::vector<double> start;   // held: the prescribed increment; free: the solve's first guess
  std::vector<double> pf0;     // p_f^n [Pa] (the bulk's p^n for a point that joins now)
  // The part of p_f^n whose face force the skeleton has not felt: p_f^n on a point that joins
  // now (its face force starts with this step's correction), else 0 [Pa]
  std::vector<double> unfelt;
  std::vector<double> rhs;       // the free row's right-hand side at the increments' zero [m^3]
  std::vector<double> storage;   // V C_f [m^3/Pa]
  std::vector<double> exchange;  // dt V G, the implicit exchange with the bulk [m^3/Pa]
  // dt Lambda_e to the network neighbours (joint gids) [m^3/Pa]
  std::vector<std::vector<std::pair<GlobalId, double>>> flow;
  // B_f: the crack volume's Jacobian S_rf A dc/d(u, theta) (component gids of
  // component_map(disc, Dim + R, ...)) [m^2]; empty rows without the face pressure
  std::vector<std::vector<std::pair<GlobalId, double>>> coupling;
};

}  // namespace mupm

#endif
