#include "mupm/solvers/linear_solve.hpp"

#include <BelosLinearProblem.hpp>
#include <BelosSolverFactory.hpp>
#include <BelosTpetraAdapter.hpp>
#include <Ifpack2_Factory.hpp>
#include <Teuchos_CommHelpers.hpp>
#include <Teuchos_ParameterList.hpp>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "mupm/core/timers.hpp"

namespace mupm {

namespace {
using MV = Tpetra::MultiVector<double, LocalId, GlobalId>;
using OP = Tpetra::Operator<double, LocalId, GlobalId>;
using RowMatrix = Tpetra::RowMatrix<double, LocalId, GlobalId>;
using Preconditioner = Ifpack2::Preconditioner<double, LocalId, GlobalId>;

// Runs f on every rank; true when it threw on any. Decided together, so that every rank then
// takes the same path.
template <class F>
bool fails_anywhere(const Teuchos::Comm<int>& comm, F&& f) {
  int failed = 0, anywhere = 0;
  try {
    f();
  } catch (const std::exception&) {
    failed = 1;
  }
  Teuchos::reduceAll(comm, Teuchos::REDUCE_MAX, failed, Teuchos::outArg(anywhere));
  return anywhere != 0;
}
}  // namespace

struct LinearSolve::Impl {
  Teuchos::RCP<Teuchos::ParameterList> params;
  Teuchos::RCP<const CrsMatrix> a;
  Teuchos::RCP<Preconditioner> prec;
  Teuchos::RCP<Belos::LinearProblem<double, MV, OP>> problem;
  Teuchos::RCP<Belos::SolverManager<double, MV, OP>> solver;
};

LinearSolve::LinearSolve(const LinearSolveSettings& settings)
    : set_(settings), impl_(Teuchos::rcp(new Impl)) {
  if (set_.preconditioner != "ILU" && set_.preconditioner != "Jacobi" &&
      set_.preconditioner != "None")
    throw std::invalid_argument("LinearSolve: preconditioner '" + set_.preconditioner +
                                "' is not ILU, Jacobi or None");
  if (set_.method != "GMRES" && set_.method != "CG")
    throw std::invalid_argument("LinearSolve: method '" + set_.method + "' is not GMRES or CG");
  auto params = Teuchos::parameterList();
  params->set("Convergence Tolerance", set_.tolerance);
  params->set("Maximum Iterations", set_.max_iterations);
  params->set("Verbosity", 0);
  // Relative to ||b|| (Belos' default is the initial residual, which a good initial guess
  // makes small and the test then needlessly strict).
  if (set_.method == "GMRES") {
    params->set("Num Blocks", set_.restart);
    params->set("Maximum Restarts", set_.max_iterations / std::max(1, set_.restart) + 1);
    params->set("Implicit Residual Scaling", std::string("Norm of RHS"));
    params->set("Explicit Residual Scaling", std::string("Norm of RHS"));
  } else {
    params->set("Residual Scaling", std::string("Norm of RHS"));
  }
  impl_->params = params;
}

LinearSolve::~LinearSolve() = default;

void LinearSolve::set_matrix(const Teuchos::RCP<const CrsMatrix>& a) {
  ScopedRegion region("mupm::LinearSolve::setup");
  impl_->a = a;
  // A new problem and solver for every matrix: Belos keeps vectors of the last problem's map,
  // and a matrix may come with another map (the fracture network grows).
  Belos::SolverFactory<double, MV, OP> factory;
  impl_->solver = factory.create(set_.method, impl_->params);
  impl_->problem = Teuchos::rcp(new Belos::LinearProblem<double, MV, OP>());
  impl_->problem->setOperator(a);
  jacobi_ = set_.preconditioner == "Jacobi";
  precondition();
  ++setups_;
}

void LinearSolve::refresh() {
  ScopedRegion region("mupm::LinearSolve::refresh");
  if (impl_->a.is_null())
    throw std::logic_error("LinearSolve::refresh before set_matrix");
  ++setups_;
  if (set_.preconditioner == "None")
    return;
  // Every new set of values starts with the settings' preconditioner, as set_matrix does: a
  // restart, which calls set_matrix, then takes the same path as the straight run (after an ILU
  // breakdown each step pays a failed ILU solve before Jacobi's).
  const bool jacobi = set_.preconditioner == "Jacobi";
  if (impl_->prec.is_null() || jacobi_ != jacobi) {
    jacobi_ = jacobi;
    precondition();
    return;
  }
  if (!fails_anywhere(*impl_->a->getComm(), [&] { impl_->prec->compute(); }))
    return;
  // An ILU whose factorization throws: Jacobi for these values at once, as precondition() does
  // (trying the ILU again there would only fail again).
  fall_back_to_jacobi();
  precondition();
}

void LinearSolve::fall_back_to_jacobi() {
  if (jacobi_)
    throw std::runtime_error("LinearSolve: the Jacobi preconditioner could not be computed");
  jacobi_ = true;
  ++fallbacks_;
}

// The preconditioner of the current matrix: the settings', or Jacobi after an ILU breakdown.
// An ILU whose factorization throws (a zero pivot caught by Ifpack2) falls back at once.
void LinearSolve::precondition() {
  impl_->prec = Teuchos::null;
  if (set_.preconditioner == "None") {
    impl_->problem->setRightPrec(Teuchos::null);
    return;
  }
  for (;;) {
    Teuchos::ParameterList p;
    if (!jacobi_) {
      p.set("fact: iluk level-of-fill", set_.fill_level);
      // KokkosKernels' factorization (level sets): 3.4 times faster than Ifpack2's serial one
      // on the projection's matrix (perf/README.md), the same factors to round-off; the
      // triangular solves stay Ifpack2's (KokkosKernels' were 3.6 times slower on one thread).
      p.set("fact: type", std::string("KSPILUK"));
    } else {
      p.set("relaxation: type", "Jacobi");
      p.set("relaxation: sweeps", 1);
    }
    Teuchos::RCP<const RowMatrix> rows = impl_->a;
    if (!fails_anywhere(*impl_->a->getComm(), [&] {
          impl_->prec = Ifpack2::Factory::create<RowMatrix>(jacobi_ ? "RELAXATION" : "RILUK", rows);
          impl_->prec->setParameters(p);
          impl_->prec->initialize();
          impl_->prec->compute();
        }))
      break;
    fall_back_to_jacobi();
  }
  impl_->problem->setRightPrec(impl_->prec);
}

LinearSolveResult LinearSolve::solve(const TpetraVector& b, TpetraVector& x, double& scale) {
  ScopedRegion region("mupm::LinearSolve::solve");
  if (impl_->a.is_null())
    throw std::logic_error("LinearSolve::solve before set_matrix");
  // The tolerance holds for ||b - A x|| against the largest ||b|| of the run so far, not this
  // one's: a step whose right-hand side is round-off (a steady state) needs no digits of it.
  LinearSolveResult r;
  const double bn = b.norm2();
  if (!std::isfinite(bn))
    return r;  // not converged: the caller stops the run
  scale = std::max(scale, bn);
  if (!(bn > 0)) {
    x.putScalar(0.0);
    r.converged = true;
    return r;
  }
  const double tol = std::min(0.5, set_.tolerance * scale / bn);
  impl_->params->set("Convergence Tolerance", tol);
  impl_->solver->setParameters(impl_->params);
  Teuchos::RCP<MV> xv = Teuchos::rcpFromRef(static_cast<MV&>(x));
  Teuchos::RCP<const MV> bv = Teuchos::rcpFromRef(static_cast<const MV&>(b));
  impl_->problem->setLHS(xv);
  impl_->problem->setRHS(bv);
  if (!impl_->problem->setProblem())
    throw std::logic_error("LinearSolve: Belos could not set up the problem");
  // Belos throws when its residual turns NaN (a singular preconditioner, a matrix gone
  // non-finite); the same on every rank (its norms are global). An ILU(k) can meet a zero
  // pivot on a matrix that is not an M-matrix (the projection's, measured on Example 1 case 2
  // once the crack grew); KokkosKernels' factorization then puts 1e-6 in its place, a
  // preconditioner that stalls the solve or turns its residual NaN. A solve that fails with
  // ILU is therefore tried again from the same initial guess with Jacobi, kept for this
  // matrix's values. Otherwise a failed solve, for the caller to report.
  TpetraVector x0(x, Teuchos::Copy);
  for (;;) {
    impl_->solver->setProblem(impl_->problem);
    try {
      r.converged = impl_->solver->solve() == Belos::Converged;
      r.iterations = impl_->solver->getNumIters();
      r.residual = impl_->solver->achievedTol() * bn / scale;
    } catch (const std::exception&) {
      r.converged = false;
      r.iterations = impl_->solver->getNumIters();
      r.residual = std::numeric_limits<double>::quiet_NaN();
    }
    if (r.converged || jacobi_ || set_.preconditioner != "ILU")
      return r;
    jacobi_ = true;
    ++fallbacks_;
    precondition();
    x.assign(x0);
    if (!impl_->problem->setProblem())
      throw std::logic_error("LinearSolve: Belos could not set up the problem");
  }
}

}  // namespace mupm
