// The kept product (include/mupm/solvers/kept_matrix.hpp) on the projection's own factors,
// B_0 M^-1 (B_0)^T diag(s) on a 2D body, on 1 and 2 ranks: against Tpetra's product to round-off,
// a refill that forms only the rows a change reaches, and those rows and the kept ones equal to
// the bit a fresh build on the new values (what a restart builds).
#include <gtest/gtest.h>

#include <cmath>

#include "mupm/solvers/kept_matrix.hpp"
#include "mupm/solvers/pressure_system.hpp"
#include "projection_matrix.hpp"
#include "test_utils.hpp"

namespace mupm {
namespace {

long long global_sum(long long v) {
  MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  return v;
}

// x's entries set by its global numbers: f(g) on each owned g.
template <class F>
void set_by_gid(TpetraVector& x, F&& f) {
  auto v = x.getLocalViewHost(Tpetra::Access::OverwriteAll);
  const auto& map = *x.getMap();
  for (LocalId i = 0; i < LocalId(map.getNodeNumElements()); ++i)
    v(i, 0) = f(map.getGlobalElement(i));
}

// Tpetra's a b diag(s), and its entries' Frobenius norm.
Teuchos::RCP<CrsMatrix> tpetra_product(const CrsMatrix& a, const CrsMatrix& b,
                                       const TpetraVector& s) {
  auto c = Teuchos::rcp(new CrsMatrix(a.getRowMap(), 0));
  Tpetra::MatrixMatrix::Multiply(a, false, b, false, *c);
  c->rightScale(s);
  return c;
}

TEST(KeptMatrix, ProductFormsOnlyTheRowsAChangeReachesAndEqualsAFreshBuild) {
  auto disc = discretize(test::world(), test::box<2>({14, 10}, 3.015));
  auto& p = disc.points;
  VolumeCoupling<2> b0;
  b0.build(disc, 0.8);
  KeptTranspose bt;
  bt.build(b0.matrix());
  // a = B_0 M^-1 with a mass that varies from dof to dof, s from point to point.
  TpetraVector m(b0.matrix()->getDomainMap()), s(b0.matrix()->getRangeMap());
  set_by_gid(m, [](GlobalId g) { return 1.0 / (2.0 + std::sin(0.7 * double(g))); });
  set_by_gid(s, [](GlobalId g) { return 0.5 + 0.25 * std::cos(1.3 * double(g)); });
  Teuchos::RCP<CrsMatrix> a;
  const auto scaled = [&] {
    copy_values(a, *b0.matrix(), a.is_null());
    a->rightScale(m);
  };
  scaled();
  KeptProduct c;
  c.build(*a, *bt.matrix(), &s);
  const long long rows = global_sum((long long)c.matrix()->getNodeNumRows());
  EXPECT_EQ(global_sum((long long)c.rows_formed()), rows);
  auto ref = tpetra_product(*a, *bt.matrix(), s);
  const double norm = ref->getFrobeniusNorm();
  ASSERT_GT(norm, 0);
  const double d0 = test::entry_difference(*c.matrix(), *ref);
  EXPECT_GE(d0, 0) << "the kept product's graph is Tpetra's";
  EXPECT_LT(d0, 1e-14 * norm);

  // The same inputs: no row formed, nothing changed.
  const auto before = Teuchos::rcp(new CrsMatrix(*c.matrix(), Teuchos::Copy));
  c.fill(*a, *bt.matrix(), &s);
  EXPECT_EQ(global_sum((long long)c.rows_formed()), 0);
  EXPECT_EQ(test::entry_difference(*c.matrix(), *before), 0);

  // A mass changed at one dof: a's entries in that column change, b does not; exactly the rows
  // of a that change are formed (a's rows are the product's).
  {
    const auto a_before = Teuchos::rcp(new CrsMatrix(*a, Teuchos::Copy));
    const GlobalId g = m.getMap()->getMaxAllGlobalIndex() / 2;
    set_by_gid(m,
               [&](GlobalId h) { return h == g ? 0.1 : 1.0 / (2.0 + std::sin(0.7 * double(h))); });
    scaled();
    long long changed = 0;
    for (LocalId r = 0; r < LocalId(a->getNodeNumRows()); ++r) {
      CrsMatrix::local_inds_host_view_type i0, i1;
      CrsMatrix::values_host_view_type v0, v1;
      a_before->getLocalRowView(r, i0, v0);
      a->getLocalRowView(r, i1, v1);
      bool row = false;
      for (std::size_t k = 0; k < v1.extent(0); ++k)
        row = row || v0(k) != v1(k);
      changed += row;
    }
    c.fill(*a, *bt.matrix(), &s);
    EXPECT_EQ(global_sum((long long)c.rows_formed()), global_sum(changed));
    EXPECT_GT(global_sum(changed), 5);
    EXPECT_LT(global_sum(changed), rows);
    KeptProduct fresh;
    fresh.build(*a, *bt.matrix(), &s);
    EXPECT_EQ(test::entry_difference(*c.matrix(), *fresh.matrix()), 0);
  }

  // Break the bonds across x0 (both ends agree on every rank): the rows of B_0 M^-1 at the broken
  // bonds' ends and the dofs' rows of B_0^T around them change, and the product's rows that
  // reach them are formed again, not all.
  const double x0 = disc.grid.origin[0] + 6.5 * disc.grid.dx;
  long long broken = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i)
    for (BondIndex e = disc.bonds.offsets(i); e < disc.bonds.offsets(i + 1); ++e)
      if (p.x(i, 1) > disc.grid.origin[1] + 4.5 * disc.grid.dx &&
          (p.x(i, 0) - x0) * (p.x(disc.bonds.neighbor(e), 0) - x0) < 0) {
        disc.bonds.intact(e) = 0;
        ++broken;
      }
  ASSERT_GT(global_sum(broken), 20);
  disc.update_shape();
  b0.fill(disc, 0.8);
  bt.fill(*b0.matrix());
  scaled();
  c.fill(*a, *bt.matrix(), &s);
  const long long formed = global_sum((long long)c.rows_formed());
  EXPECT_GT(formed, 0);
  EXPECT_LT(formed, rows) << "rows that no broken bond reaches are kept";
  KeptProduct fresh;
  fresh.build(*a, *bt.matrix(), &s);
  EXPECT_EQ(test::entry_difference(*c.matrix(), *fresh.matrix()), 0);
  EXPECT_GT(test::entry_difference(*c.matrix(), *before), 0) << "the refill changed the product";
  ref = tpetra_product(*a, *bt.matrix(), s);
  EXPECT_LT(test::entry_difference(*c.matrix(), *ref), 1e-14 * norm);

  // s changed at one point: exactly the rows whose graph holds its column are formed.
  const GlobalId g = b0.matrix()->getRangeMap()->getMaxAllGlobalIndex() / 2;
  set_by_gid(s, [&](GlobalId h) { return h == g ? 3.0 : 0.5 + 0.25 * std::cos(1.3 * double(h)); });
  long long holding = 0;
  {
    const auto l = c.matrix()->getLocalMatrixHost();
    const LocalId lc = c.matrix()->getColMap()->getLocalElement(g);
    for (LocalId r = 0; r < LocalId(l.numRows()); ++r)
      for (auto q = l.graph.row_map(r); q < l.graph.row_map(r + 1); ++q)
        holding += l.graph.entries(q) == lc;
  }
  c.fill(*a, *bt.matrix(), &s);
  EXPECT_EQ(global_sum((long long)c.rows_formed()), global_sum(holding));
  EXPECT_GT(global_sum(holding), 10);
  fresh.build(*a, *bt.matrix(), &s);
  EXPECT_EQ(test::entry_difference(*c.matrix(), *fresh.matrix()), 0);
  // Without the scaling: every row again, and Tpetra's a b.
  c.fill(*a, *bt.matrix());
  EXPECT_EQ(global_sum((long long)c.rows_formed()), rows);
  auto unscaled = Teuchos::rcp(new CrsMatrix(a->getRowMap(), 0));
  Tpetra::MatrixMatrix::Multiply(*a, false, *bt.matrix(), false, *unscaled);
  EXPECT_LT(test::entry_difference(*c.matrix(), *unscaled), 1e-14 * unscaled->getFrobeniusNorm());
  // And scaled again: every row.
  c.fill(*a, *bt.matrix(), &s);
  EXPECT_EQ(global_sum((long long)c.rows_formed()), rows);
  EXPECT_EQ(test::entry_difference(*c.matrix(), *fresh.matrix()), 0);
}

}  // namespace
}  // namespace mupm
