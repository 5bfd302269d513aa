// The pressure solve's algebraic multigrid (Pressure Solve -> Preconditioner = AMG, hypre's
// BoomerAMG: include/mupm/solvers/amg_preconditioner.hpp) on the semi-implicit step's matrix
// (projection_matrix.hpp), on 1 and 2 ranks. Non-convergence stopping the run (exit 3) and the
// input's range checks are tested from the command line (tests/cli/semi_implicit.sh).
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "mupm/solvers/amg_preconditioner.hpp"
#include "projection_matrix.hpp"
#include "test_utils.hpp"

namespace mupm {
namespace {

using test::ProjectionMatrix;

// CG from x = 0 to 1e-10 of ||b||, b = A x_exact for the smooth field; the residual computed
// here. Returns the iterations.
int solve_smooth(LinearSolve& solve, const ProjectionMatrix& m, const char* what,
                 TpetraVector* out = nullptr) {
  TpetraVector exact(m.owned), b(m.owned), x(m.owned);
  m.problem(0, 1.0, exact, b);
  x.putScalar(0.0);
  double scale = 0;
  const auto r = solve.solve(b, x, scale);
  const double rel = m.residual(b, x);
  EXPECT_TRUE(r.converged) << what;
  EXPECT_LT(rel, 2e-10) << what;
  if (out)
    out->assign(x);
  return r.iterations;
}

LinearSolveSettings cg(const char* preconditioner) {
  LinearSolveSettings s;
  s.method = "CG";
  s.preconditioner = preconditioner;
  s.tolerance = 1e-10;
  s.max_iterations = 5000;
  return s;
}

// The matrix at fixed delta / dx on n x n points, n = 16, 32, 64 (256 to 4096 points; the body
// grows, so its smoothest pressure modes grow smoother against the horizon, as under
// refinement of a fixed body): CG with one V-cycle a step takes at most 1.3 times the
// iterations at 4096 points that it takes at 256, where Jacobi's CG takes at least twice as
// many (the series is one that a one-level preconditioner feels: its iterations grow with n).
TEST(PressureSolve, AmgIterationsStayBoundedUnderRefinement) {
  std::vector<int> amg, jacobi;
  for (int n : {16, 32, 64}) {
    ProjectionMatrix m(n);
    LinearSolve a(cg("AMG")), j(cg("Jacobi"));
    a.set_matrix(m.a);
    j.set_matrix(m.a);
    ASSERT_FALSE(a.amg().is_null());
    amg.push_back(solve_smooth(a, m, "AMG"));
    jacobi.push_back(solve_smooth(j, m, "Jacobi"));
    const int levels = a.amg()->levels();
    const double complexity = a.amg()->operator_complexity();
    if (test::world()->getRank() == 0)
      std::printf(
          "[ %d x %d ] CG iterations: AMG %d (%d levels, operator complexity %.2f), "
          "Jacobi %d\n",
          n, n, amg.back(), levels, complexity, jacobi.back());
    EXPECT_GT(levels, 1);
  }
  EXPECT_LE(amg.back(), 1.3 * amg.front());
  EXPECT_GE(jacobi.back(), 2 * jacobi.front());
}

// Set-up once, values often (Preconditioner Refresh Interval, Refresh Iteration Growth):
//  - new values close to the old keep the hierarchy (no set-up), and CG still solves the
//    current matrix to the tolerance;
//  - a hierarchy of values far from the current ones (a storage 10 times the mean diagonal, then
//    removed) makes the next solve take more than 1.5 times the iterations of the first after
//    the set-up, and the refresh after it sets up again, after which the iterations fall back;
//  - renew() (a checkpoint) sets up at the next refresh: the next solve equals, bit for bit, that
//    of a fresh LinearSolve given the same matrix (a restart from that checkpoint).
TEST(PressureSolve, AmgHierarchyKeptUntilItServesBadlyAndRenewedLikeARestart) {
  ProjectionMatrix m(32);
  LinearSolveSettings set = cg("AMG");
  set.refresh_interval = 1000;
  set.refresh_growth = 1.5;
  LinearSolve solve(set);
  const double big = 10 * m.mean_diagonal();
  m.add_to_diagonal(big);
  solve.set_matrix(m.a);
  const int first = solve_smooth(solve, m, "AMG of the stiff-storage matrix");
  m.add_to_diagonal(0.01 * big);
  solve.refresh();
  EXPECT_EQ(solve.setups(), 1) << "a small change set the hierarchy up again";
  solve_smooth(solve, m, "AMG of values a step old");
  m.add_to_diagonal(-1.01 * big);  // back to the small storage
  solve.refresh();
  EXPECT_EQ(solve.setups(), 1) << "set up before any solve served badly";
  const int stale = solve_smooth(solve, m, "AMG of far values");
  solve.refresh();
  EXPECT_EQ(solve.setups(), 2) << "the stale hierarchy was kept";
  const int fresh = solve_smooth(solve, m, "AMG set up again");
  if (test::world()->getRank() == 0)
    std::printf(
        "[ kept hierarchy ] CG iterations: %d after its set-up, %d with far values, %d "
        "after the set-up the growth asked for\n",
        first, stale, fresh);
  EXPECT_GT(stale, 1.5 * first);
  EXPECT_LT(fresh, stale);
  // A restart at a checkpoint: renewed against fresh.
  m.add_to_diagonal(0.02 * m.mean_diagonal());
  solve.renew();
  solve.refresh();
  EXPECT_EQ(solve.setups(), 3);
  LinearSolve restarted(set);
  restarted.set_matrix(m.a);
  TpetraVector x(m.owned), y(m.owned);
  solve_smooth(solve, m, "renewed", &x);
  solve_smooth(restarted, m, "restarted", &y);
  EXPECT_EQ(test::differing(x, y), 0u) << "renewed AMG and a fresh one";
}

// The V-cycle is a symmetric operator (CG needs it): x^T M^-1 y = y^T M^-1 x for rough x, y, to
// round-off; and positive: x^T M^-1 x > 0.
TEST(PressureSolve, AmgVCycleIsSymmetricPositiveDefinite) {
  ProjectionMatrix m(24);
  LinearSolve solve(cg("AMG"));
  solve.set_matrix(m.a);
  const auto& amg = *solve.amg();
  const auto& p = m.body.disc.points;
  TpetraVector x(m.owned), y(m.owned), mx(m.owned), my(m.owned);
  for (int k = 0; k < 4; ++k) {
    {
      auto xv = x.getLocalViewHost(Tpetra::Access::OverwriteAll);
      auto yv = y.getLocalViewHost(Tpetra::Access::OverwriteAll);
      for (std::size_t i = 0; i < p.n_owned; ++i) {
        const double g = double(p.gid(i));
        xv(i, 0) = std::sin(0.37 * (k + 1) * g) + 0.1 * k;
        yv(i, 0) = std::cos(1.3 * g + k) * (1 + 0.5 * std::sin(0.01 * g));
      }
    }
    amg.apply(x, mx);
    amg.apply(y, my);
    const double xmy = x.dot(my), ymx = y.dot(mx), xmx = x.dot(mx);
    const double size = std::sqrt(xmx * y.dot(my));
    EXPECT_NEAR(xmy, ymx, 1e-10 * size) << k;
    EXPECT_GT(xmx, 0) << k;
  }
}

}  // namespace
}  // namespace mupm
