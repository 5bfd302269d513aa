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

namespace detail {
// A matrix with the given maps, from rows of (local column, value), owned rows in order.
inline Teuchos::RCP<CrsMatrix> from_rows(
    const Teuchos::RCP<const Map>& rows, const Teuchos::RCP<const Map>& cols,
    const Teuchos::RCP<const Map>& domain, const Teuchos::RCP<const Map>& range,
    const std::vector<std::vector<std::pair<LocalId, double>>>& entries) {
  std::size_t longest = 1;
  for (const auto& r : entries)
    longest = std::max(longest, r.size());
  auto a = Teuchos::rcp(new CrsMatrix(rows, cols, longest));
  std::vector<LocalId> c;
  std::vector<double> v;
  for (std::size_t r = 0; r < entries.size(); ++r) {
    c.clear();
    v.clear();
    for (const auto& e : entries[r]) {
      c.push_back(e.first);
      v.push_back(e.second);
    }
    if (!c.empty())
      a->insertLocalValues(LocalId(r), Teuchos::ArrayView<const LocalId>(c),
                           Teuchos::ArrayView<const double>(v));
  }
  a->fillComplete(domain, range);
  return a;
}
}  // namespace detail

// V H (header, 1) with the stabilization coefficients `alpha` (owned + ghosts: the fluid
// state's alpha after FluidSolver's evaluate(), or more, pressure_projection.hpp) and the
// points' current k_r.
template <int Dim>
Teuchos::RCP<CrsMatrix> assemble_flow_operator(const Discretization<Dim>& disc,
                                               const FluidParams& prm, const Scalars& alpha) {
  const auto& p = disc.points;
  const auto& b = disc.bonds;
  const auto& sh = disc.shape;
  const auto grad_map = component_map(disc, Dim, false);
  const auto& owned = disc.dist.owned_map();
  const auto& overlap = disc.dist.overlap_map();
  const std::size_t n = p.n_owned;
  std::vector<std::vector<std::pair<LocalId, double>>> gr(n * Dim), wgr(n * Dim), lap(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double vi = p.volume(i), ai = alpha(i);
    double self_lap = 0;
    const bool singular = sh.singular(i) != 0;
    double Kinv[Dim * Dim], K[Dim * Dim], W[Dim * Dim];
    for (int k = 0; k < Dim * Dim; ++k)
      Kinv[k] = sh.Kinv(i, k);
    std::vector<std::pair<LocalId, double>> row[Dim];
    double self[Dim] = {};
    for (BondIndex e = b.offsets(i); e < b.offsets(i + 1); ++e) {
      if (!b.intact(e))
        continue;
      const LocalId j = b.neighbor(e);
      const double vj = p.volume(j);
      const double w = vi * vj * (ai + alpha(j));
      lap[i].push_back({j, -w});
      self_lap += w;
      if (singular)
        continue;
      double xi[Dim], c[Dim];
      for (int d = 0; d < Dim; ++d)
        xi[d] = p.x(j, d) - p.x(i, d);
      mat_vec<Dim, Dim>(Kinv, xi, c);
      for (int d = 0; d < Dim; ++d) {
        row[d].push_back({j, c[d] * vj});
        self[d] -= c[d] * vj;
      }
    }
    lap[i].push_back({LocalId(i), self_lap});
    if (singular)
      continue;
    invert<Dim>(Kinv, K);
    const double lambda = p.rel_perm(i) * prm.mobility;
    for (int r = 0; r < Dim; ++r)
      for (int c = 0; c < Dim; ++c)
        W[r * Dim + c] = vi * ((r == c ? lambda : 0.0) - ai * K[r * Dim + c]);
    for (int d = 0; d < Dim; ++d) {
      row[d].push_back({LocalId(i), self[d]});
      gr[i * Dim + d] = row[d];
    }
    // W Gr: row (i, d) = sum_e W_de Gr(i, e); the rows share their columns.
    for (int d = 0; d < Dim; ++d) {
      auto& out = wgr[i * Dim + d];
      out = row[0];
      for (std::size_t k = 0; k < out.size(); ++k) {
        double s = 0;
        for (int e2 = 0; e2 < Dim; ++e2)
          s += W[d * Dim + e2] * row[e2][k].second;
        out[k].second = s;
      }
    }
  }
  const auto G = detail::from_rows(grad_map, overlap, owned, grad_map, gr);
  const auto WG = detail::from_rows(grad_map, overlap, owned, grad_map, wgr);
  const auto L = detail::from_rows(owned, overlap, owned, owned, lap);
  auto flux = Teuchos::rcp(new CrsMatrix(owned, 0));
  Tpetra::MatrixMatrix::Multiply(*G, true, *WG, false, *flux);
  return Tpetra::MatrixMatrix::add(1.0, false, *flux, 1.0, false, *L);
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

// B~ (header, 2), over the owned points (rows) and their (u, theta) components (columns:
// component_map(disc, Dim + R, ...)).
template <int Dim>
Teuchos::RCP<CrsMatrix> assemble_volume_coupling(const Discretization<Dim>& disc, double biot = 1) {
  constexpr int R = kRotDim<Dim>, NC = Dim + R;
  const auto& p = disc.points;
  const auto& b = disc.bonds;
  const auto& sh = disc.shape;
  const auto dofs = component_map(disc, NC, false), dofs_all = component_map(disc, NC, true);
  const std::size_t n = p.n_owned;
  std::vector<std::vector<std::pair<LocalId, double>>> rows(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (sh.singular(i) || (p.fixed(i) & kFixedNoEnergy))
      continue;
    const double s = p.volume(i) * biot * p.saturation(i);
    double Kinv[Dim * Dim];
    for (int k = 0; k < Dim * Dim; ++k)
      Kinv[k] = sh.Kinv(i, k);
    double self[NC] = {};
    auto& row = rows[i];
    for (BondIndex e = b.offsets(i); e < b.offsets(i + 1); ++e) {
      if (!b.intact(e))
        continue;
      const LocalId j = b.neighbor(e);
      const double vj = p.volume(j);
      double xi[Dim], c[Dim], rot[R];
      for (int d = 0; d < Dim; ++d)
        xi[d] = p.x(j, d) - p.x(i, d);
      mat_vec<Dim, Dim>(Kinv, xi, c);
      cross<Dim>(xi, c, rot);
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
  return detail::from_rows(disc.dist.owned_map(), dofs_all, dofs, disc.dist.owned_map(), rows);
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

namespace detail {
// `a`'s rows (none: no rows) under their global ids, plus `extra` rows (global row, (global
// column, value)), as a matrix over `rows` (which holds both) with the given domain and range.
inline Teuchos::RCP<CrsMatrix> with_rows(
    const CrsMatrix* a, const Teuchos::RCP<const Map>& rows,
    const std::vector<std::pair<GlobalId, std::vector<std::pair<GlobalId, double>>>>& extra,
    const Teuchos::RCP<const Map>& domain, const Teuchos::RCP<const Map>& range) {
  std::size_t longest = a ? std::max<std::size_t>(1, a->getNodeMaxNumRowEntries()) : 1;
  for (const auto& r : extra)
    longest = std::max(longest, r.second.size());
  auto out = Teuchos::rcp(new CrsMatrix(rows, longest));
  std::vector<GlobalId> cols;
  std::vector<double> vals;
  const LocalId nrows = a ? LocalId(a->getRowMap()->getNodeNumElements()) : 0;
  for (LocalId r = 0; r < nrows; ++r) {
    const auto& arows = *a->getRowMap();
    const auto& acols = *a->getColMap();
    CrsMatrix::local_inds_host_view_type idx;
    CrsMatrix::values_host_view_type v;
    a->getLocalRowView(r, idx, v);
    cols.resize(idx.extent(0));
    vals.resize(idx.extent(0));
    for (std::size_t k = 0; k < idx.extent(0); ++k) {
      cols[k] = acols.getGlobalElement(idx(k));
      vals[k] = v(k);
    }
    if (!cols.empty())
      out->insertGlobalValues(arows.getGlobalElement(r), Teuchos::ArrayView<const GlobalId>(cols),
                              Teuchos::ArrayView<const double>(vals));
  }
  for (const auto& r : extra) {
    cols.clear();
    vals.clear();
    for (const auto& e : r.second) {
      cols.push_back(e.first);
      vals.push_back(e.second);
    }
    if (!cols.empty())
      out->insertGlobalValues(r.first, Teuchos::ArrayView<const GlobalId>(cols),
                              Teuchos::ArrayView<const double>(vals));
  }
  out->fillComplete(domain, range);
  return out;
}
}  // namespace detail

// A diagonal matrix over `map` with the values of `diag`.
inline Teuchos::RCP<CrsMatrix> diagonal_matrix(const TpetraVector& diag) {
  const auto map = diag.getMap();
  auto a = Teuchos::rcp(new CrsMatrix(map, map, 1));
  auto d = diag.getLocalViewHost(Tpetra::Access::ReadOnly);
  for (LocalId r = 0; r < LocalId(map->getNodeNumElements()); ++r) {
    const LocalId c = r;
    const double v = d(r, 0);
    a->insertLocalValues(r, Teuchos::ArrayView<const LocalId>(&c, 1),
                         Teuchos::ArrayView<const double>(&v, 1));
  }
  a->fillComplete(map, map);
  return a;
}

}  // namespace mupm

#endif
