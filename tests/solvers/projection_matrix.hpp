// Shared by the pressure-solve tests (test_pressure_projection.cpp, test_amg.cpp): a smooth
// test field and the semi-implicit step's matrix (include/mupm/solvers/pressure_projection.hpp).
#ifndef MUPM_TESTS_PROJECTION_MATRIX_HPP
#define MUPM_TESTS_PROJECTION_MATRIX_HPP

#include <mpi.h>
#include <cmath>
#include <limits>
#include <map>

#include "mupm/solvers/fluid_solver.hpp"
#include "mupm/solvers/linear_solve.hpp"
#include "mupm/solvers/pressure_system.hpp"
#include "solid_body.hpp"

namespace mupm {
namespace test {

// A smooth field with a rough part, the same on every rank (a function of the position).
inline double field(const double* x, int c) {
  return std::sin(37 * x[0] + 3 * c) * std::cos(23 * x[1] - c) + 0.3 * std::sin(91 * x[0] * x[1]) +
         (x[2] != 0 ? 0.2 * std::cos(53 * x[2]) : 0.0);
}

// The largest |a_ij - b_ij| over every rank, each entry of a against b's at the same global row
// and column; -1 where their graphs differ.
inline double entry_difference(const CrsMatrix& a, const CrsMatrix& b) {
  double d = a.getNodeNumEntries() == b.getNodeNumEntries() ? 0.0 : -1.0;
  for (LocalId r = 0; d >= 0 && r < LocalId(a.getRowMap()->getNodeNumElements()); ++r) {
    const GlobalId g = a.getRowMap()->getGlobalElement(r);
    CrsMatrix::local_inds_host_view_type ia, ib;
    CrsMatrix::values_host_view_type va, vb;
    a.getLocalRowView(r, ia, va);
    b.getLocalRowView(b.getRowMap()->getLocalElement(g), ib, vb);
    std::map<GlobalId, double> row;
    for (std::size_t k = 0; k < ia.extent(0); ++k)
      row[a.getColMap()->getGlobalElement(ia(k))] = va(k);
    if (ib.extent(0) != ia.extent(0))
      d = -1;
    for (std::size_t k = 0; d >= 0 && k < ib.extent(0); ++k) {
      const auto it = row.find(b.getColMap()->getGlobalElement(ib(k)));
      const double e = it == row.end() ? -1.0 : std::abs(it->second - vb(k));
      d = e < 0 ? -1.0 : std::isnan(e) ? std::numeric_limits<double>::infinity() : std::max(d, e);
    }
  }
  double all[2] = {d < 0 ? 1.0 : 0.0, d};
  MPI_Allreduce(MPI_IN_PLACE, all, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return all[0] > 0 ? -1.0 : all[1];
}

// The projection's matrix A = dt^2 B~ M^-1 B~^T + dt V H + V C of the semi-implicit step for
// incompressible water in a tight soil (k = 0: the flow is the pressure stabilization alone),
// 2D, delta = 3.015 dx (two horizons wide), on an n x n body, with a small storage that
// varies from point to point: 1e-3 of the mean diagonal times 1 + 0.5 sin(gid).
struct ProjectionMatrix {
  static constexpr double rho = 1900, dt = 3e-6;
  test::Body<2> body;
  Teuchos::RCP<CrsMatrix> a;
  Teuchos::RCP<const Tpetra::Map<LocalId, GlobalId>> owned;
  TpetraVector d;  // A's diagonal before any storage

  explicit ProjectionMatrix(int n = 24)
      : body(test::box<2>({n, n}, 3.015), MicropolarElastic::from_bulk_shear(10e6, 6e6, 3e6, 0.01),
             0.5, StabilizationModulus::Automatic, rho) {
    auto& disc = body.disc;
    auto& p = disc.points;
    Kokkos::deep_copy(p.saturation, 1.0);
    const auto B = assemble_volume_coupling(disc);
    const auto dofs = component_map(disc, 3, false);
    TpetraVector minv(dofs);
    {
      const double J = micro_inertia(0.2, rho, 0.01);
      auto v = minv.getLocalViewHost(Tpetra::Access::OverwriteAll);
      for (std::size_t i = 0; i < p.n_owned; ++i)
        for (int k = 0; k < 3; ++k)
          v(i * 3 + k, 0) = 1.0 / (p.volume(i) * (k < 2 ? rho : J));
    }
    auto fp = fluid_params(disc.grid, 0.0, 0.5);
    fp.projection_stabilization = 1.0;
    Scalars alpha("alpha", p.size()), density("rho", p.n_owned);
    Kokkos::deep_copy(density, rho);
    add_pressure_stabilization(disc, fp, dt, density, alpha);
    a = Tpetra::MatrixMatrix::add(dt * dt, false, *projection_operator(*B, minv), dt, false,
                                  *assemble_flow_operator(disc, fp, alpha));
    owned = disc.dist.owned_map();
    d = TpetraVector(owned);
    a->getLocalDiagCopy(d);
    add_to_diagonal(1e-3 * mean_diagonal());
  }
  double mean_diagonal() const { return d.norm1() / double(owned->getGlobalNumElements()); }
  // s (1 + 0.5 sin(gid)) added to the diagonal, in place (the graph has the diagonal).
  void add_to_diagonal(double s) {
    const auto l = a->getLocalMatrixHost();
    const auto v = a->getLocalValuesView();
    for (LocalId r = 0; r < LocalId(l.numRows()); ++r)
      for (auto q = l.graph.row_map(r); q < l.graph.row_map(r + 1); ++q)
        if (a->getColMap()->getGlobalElement(l.graph.entries(q)) == owned->getGlobalElement(r))
          v(q) += s * (1 + 0.5 * std::sin(double(owned->getGlobalElement(r))));
  }
  // exact = `factor` times the smooth field's component c, b = A exact.
  void problem(int c, double factor, TpetraVector& exact, TpetraVector& b) const {
    const auto& p = body.disc.points;
    {
      auto v = exact.getLocalViewHost(Tpetra::Access::OverwriteAll);
      for (std::size_t i = 0; i < p.n_owned; ++i) {
        const double xi[3] = {p.x(i, 0), p.x(i, 1), 0};
        v(i, 0) = factor * field(xi, c);
      }
    }
    a->apply(exact, b);
  }
  // ||b - A x|| / ||b||.
  double residual(const TpetraVector& b, const TpetraVector& x) const {
    TpetraVector r(owned);
    a->apply(x, r);
    r.update(1.0, b, -1.0);
    return r.norm2() / b.norm2();
  }
};

// The entries of this rank in which x and y differ (bit for bit).
inline std::size_t differing(const TpetraVector& x, const TpetraVector& y) {
  const auto xv = x.getLocalViewHost(Tpetra::Access::ReadOnly);
  const auto yv = y.getLocalViewHost(Tpetra::Access::ReadOnly);
  std::size_t n = 0;
  for (std::size_t i = 0; i < xv.extent(0); ++i)
    n += xv(i, 0) != yv(i, 0);
  return n;
}

}  // namespace test
}  // namespace mupm

#endif
