#include "mupm/solvers/linear_solve.hpp"

#include <BelosLinearProblem.hpp>
#include <BelosRCGSolMgr.hpp>
#include <BelosSolverFactory.hpp>
#include <BelosTpetraAdapter.hpp>
#include <Ifpack2_Factory.hpp>
#include <MatrixMarket_Tpetra.hpp>
#include <Teuchos_CommHelpers.hpp>
#include <Teuchos_ParameterList.hpp>
#include <Tpetra_Import.hpp>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "mupm/core/timers.hpp"
#include "mupm/solvers/amg_preconditioner.hpp"

namespace mupm {

namespace {
using MV = Tpetra::MultiVector<double, LocalId, GlobalId>;
using OP = Tpetra::Operator<double, LocalId, GlobalId>;
using RowMatrix = Tpetra::RowMatrix<double, LocalId, GlobalId>;
using Preconditioner = Ifpack2::Preconditioner<double, LocalId, GlobalId>;

// Runs f on every rank; true when it threw on any. Decided together, so that every rank then
// takes the same path. `what`: the exception's text on a rank where it threw.
template <class F>
bool fails_anywhere(const Teuchos::Comm<int>& comm, F&& f, std::string* what = nullptr) {
  int failed = 0, anywhere = 0;
  try {
    f();
  } catch (const std::exception& e) {
    failed = 1;
    if (what)
      *what = e.what();
  }
  Teuchos::reduceAll(comm, Teuchos::REDUCE_MAX, failed, Teuchos::outArg(anywhere));
  return anywhere != 0;
}

// The preconditioner's matrix for a drop tolerance theta > 0 (LinearSolveSettings): A without
// its entries |a_ij| < theta sqrt(|a_ii a_jj|), each dropped |a_ij| added to a_ii. The rule is
// symmetric (a pair is dropped on both sides), and each dropped pair changes the matrix by
// |a_ij| (e_i - s e_j)(e_i - s e_j)^T, s = sign(a_ij), positive semi-definite: P >= A, so P is
// symmetric positive definite where A is (the preconditioner CG needs).
Teuchos::RCP<CrsMatrix> sparsified(const CrsMatrix& a, double theta) {
  TpetraVector d(a.getRowMap()), dc(a.getColMap());
  a.getLocalDiagCopy(d);
  Tpetra::Import<LocalId, GlobalId> imp(a.getRowMap(), a.getColMap());
  dc.doImport(d, imp, Tpetra::INSERT);
  const auto dv = d.getLocalViewHost(Tpetra::Access::ReadOnly);
  const auto cv = dc.getLocalViewHost(Tpetra::Access::ReadOnly);
  const auto l = a.getLocalMatrixHost();
  const auto& rows = *a.getRowMap();
  const auto& cols = *a.getColMap();
  const LocalId n = LocalId(l.numRows());
  std::vector<std::vector<LocalId>> keep(n);
  std::vector<std::vector<double>> vals(n);
  std::size_t longest = 1;
  for (LocalId r = 0; r < n; ++r) {
    const GlobalId g = rows.getGlobalElement(r);
    double extra = 0;
    std::size_t diag = std::size_t(-1);
    for (auto q = l.graph.row_map(r); q < l.graph.row_map(r + 1); ++q) {
      const LocalId c = l.graph.entries(q);
      const double v = l.values(q);
      const bool is_diag = cols.getGlobalElement(c) == g;
      if (is_diag || std::fabs(v) >= theta * std::sqrt(std::fabs(dv(r, 0) * cv(c, 0)))) {
        if (is_diag)
          diag = keep[r].size();
        keep[r].push_back(c);
        vals[r].push_back(v);
      } else {
        extra += std::fabs(v);
      }
    }
    if (diag != std::size_t(-1))
      vals[r][diag] += extra;
    longest = std::max(longest, keep[r].size());
  }
  auto p = Teuchos::rcp(new CrsMatrix(a.getRowMap(), a.getColMap(), longest));
  for (LocalId r = 0; r < n; ++r)
    if (!keep[r].empty())
      p->insertLocalValues(r, Teuchos::ArrayView<const LocalId>(keep[r]),
                           Teuchos::ArrayView<const double>(vals[r]));
  p->fillComplete(a.getDomainMap(), a.getRangeMap());
  return p;
}
// Writes A and b as MatrixMarket files (Diagnostics->Write Pressure System), with the rows
// numbered contiguously (contiguous_numbering: MatrixMarket needs indices below the size).
void write_system(const CrsMatrix& a, const TpetraVector& b, const std::string& prefix,
                  const std::string& n) {
  using Map = Tpetra::Map<LocalId, GlobalId>;
  const std::size_t mine = a.getRowMap()->getNodeNumElements();
  const auto invalid = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
  auto contiguous = Teuchos::rcp(new Map(invalid, mine, 0, a.getRowMap()->getComm()));
  const auto numbering = contiguous_numbering(a);
  const auto l = a.getLocalMatrixHost();
  auto c = Teuchos::rcp(new CrsMatrix(contiguous, a.getNodeMaxNumRowEntries()));
  std::vector<GlobalId> idx;
  std::vector<double> val;
  for (LocalId r = 0; r < LocalId(mine); ++r) {
    idx.clear();
    val.clear();
    for (auto q = l.graph.row_map(r); q < l.graph.row_map(r + 1); ++q) {
      idx.push_back(numbering.column[std::size_t(l.graph.entries(q))]);
      val.push_back(l.values(q));
    }
    c->insertGlobalValues(contiguous->getGlobalElement(r), Teuchos::ArrayView<const GlobalId>(idx),
                          Teuchos::ArrayView<const double>(val));
  }
  c->fillComplete();
  TpetraVector cb(contiguous);
  {
    auto to = cb.getLocalViewHost(Tpetra::Access::OverwriteAll);
    const auto from = b.getLocalViewHost(Tpetra::Access::ReadOnly);
    for (std::size_t r = 0; r < mine; ++r)
      to(r, 0) = from(r, 0);
  }
  using Writer = Tpetra::MatrixMarket::Writer<CrsMatrix>;
  Writer::writeSparseFile(prefix + "pressure_system_" + n + ".mtx", c);
  Writer::writeDenseFile(prefix + "pressure_rhs_" + n + ".mtx", cb);
}
}  // namespace

ContiguousNumbering contiguous_numbering(const CrsMatrix& a) {
  const auto& rows = a.getRowMap();
  const LocalId n = LocalId(rows->getNodeNumElements());
  ContiguousNumbering out;
  long long mine = n, first = 0;
  const auto comm = rows->getComm();
  Teuchos::scan(*comm, Teuchos::REDUCE_SUM, mine, Teuchos::outArg(first));
  out.first = first - mine;  // the inclusive scan less this rank's own
  // The numbers travel as doubles (exact below 2^53).
  TpetraVector own(rows), cols(a.getColMap());
  {
    auto v = own.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (LocalId r = 0; r < n; ++r)
      v(r, 0) = double(out.first + r);
  }
  cols.doImport(own, Tpetra::Import<LocalId, GlobalId>(rows, a.getColMap()), Tpetra::INSERT);
  const auto cv = cols.getLocalViewHost(Tpetra::Access::ReadOnly);
  out.column.resize(cv.extent(0));
  for (std::size_t c = 0; c < out.column.size(); ++c)
    out.column[c] = GlobalId(cv(c, 0));
  return out;
}

struct LinearSolve::Impl {
  Teuchos::RCP<Teuchos::ParameterList> params;
  Teuchos::RCP<const CrsMatrix> a;
  Teuchos::RCP<Preconditioner> prec;
  Teuchos::RCP<AmgPreconditioner> amg;
  Teuchos::RCP<const CrsMatrix> pm;  // the matrix prec was computed from
  Teuchos::RCP<Belos::LinearProblem<double, MV, OP>> problem;
  Teuchos::RCP<Belos::SolverManager<double, MV, OP>> solver;
  // solve()'s copy of the initial guess and (RCG) its residual, kept while their map is
  Teuchos::RCP<TpetraVector> x0, r0;
};

LinearSolve::LinearSolve(const LinearSolveSettings& settings)
    : set_(settings), impl_(Teuchos::rcp(new Impl)) {
  if (set_.preconditioner != "AMG" && set_.preconditioner != "ILU" &&
      set_.preconditioner != "Jacobi" && set_.preconditioner != "None")
    throw std::invalid_argument("LinearSolve: preconditioner '" + set_.preconditioner +
                                "' is not AMG, ILU, Jacobi or None");
  if (set_.method != "GMRES" && set_.method != "CG")
    throw std::invalid_argument("LinearSolve: method '" + set_.method + "' is not GMRES or CG");
  auto params = Teuchos::parameterList();
  params->set("Convergence Tolerance", set_.tolerance);
  params->set("Maximum Iterations", set_.max_iterations);
  params->set("Verbosity", 0);
  // Relative to ||b|| (Belos' default is the initial residual, which a good initial guess
  // makes small and the test then needlessly strict).
  if (set_.recycle < 0)
    throw std::invalid_argument("LinearSolve: a recycle space of " + std::to_string(set_.recycle) +
                                " vectors");
  if (method() == "RCG") {
    if (set_.recycle >= kRcgCycle)
      throw std::invalid_argument("LinearSolve: a recycle space of " +
                                  std::to_string(set_.recycle) + " vectors; at most " +
                                  std::to_string(kRcgCycle - 1) + " (Belos' RCG cycle)");
    // RCG's convergence test is relative to the initial residual, which solve() computes.
    params->set("Num Blocks", kRcgCycle);
    params->set("Num Recycled Blocks", set_.recycle);
  } else if (set_.method == "GMRES") {
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

std::string LinearSolve::method() const {
  return set_.method == "CG" && set_.recycle > 0 ? "RCG" : set_.method;
}

// A Krylov solver without history (RCG: no recycle space) on the current problem. RCG is made
// directly: Belos' factory does not register it for Tpetra.
void LinearSolve::new_krylov() {
  if (method() == "RCG") {
    impl_->solver = Teuchos::rcp(new Belos::RCGSolMgr<double, MV, OP>());
    impl_->solver->setParameters(impl_->params);
  } else {
    Belos::SolverFactory<double, MV, OP> factory;
    impl_->solver = factory.create(set_.method, impl_->params);
  }
  forget_ = false;
}

Teuchos::RCP<const CrsMatrix> LinearSolve::preconditioner_matrix() const {
  return impl_->pm;
}

Teuchos::RCP<const AmgPreconditioner> LinearSolve::amg() const {
  return impl_->amg;
}

void LinearSolve::set_matrix(const Teuchos::RCP<const CrsMatrix>& a) {
  ScopedRegion region("mupm::LinearSolve::setup");
  impl_->a = a;
  // A new problem and solver for every matrix: Belos keeps vectors of the last problem's map,
  // and a matrix may come with another map (the fracture network grows).
  new_krylov();
  impl_->problem = Teuchos::rcp(new Belos::LinearProblem<double, MV, OP>());
  impl_->problem->setOperator(a);
  jacobi_ = set_.preconditioner == "Jacobi";
  ilu_ = false;
  precondition();
  ++setups_;
  kept_ = 0;
  renew_ = false;
}

void LinearSolve::refresh() {
  ScopedRegion region("mupm::LinearSolve::refresh");
  if (impl_->a.is_null())
    throw std::logic_error("LinearSolve::refresh before set_matrix");
  // Kept factors: the same decision on every rank (the calls and renewals are collective, the
  // iteration counts global). Stale: the last solve took more than refresh_growth times the
  // first after the set-up.
  const bool stale = set_.refresh_growth > 1 && base_iterations_ > 0 &&
                     last_iterations_ > set_.refresh_growth * base_iterations_;
  if (!renew_ && !stale && ++kept_ < set_.refresh_interval)
    return;
  kept_ = 0;
  renew_ = false;
  ++setups_;
  if (set_.preconditioner == "None")
    return;
  // Every new set of values starts with the settings' preconditioner, as set_matrix does: a
  // restart, which calls set_matrix, then takes the same path as the straight run (after an ILU
  // breakdown each step pays a failed ILU solve before Jacobi's).
  const bool jacobi = set_.preconditioner == "Jacobi";
  if ((impl_->prec.is_null() && impl_->amg.is_null()) || jacobi_ != jacobi || ilu_) {
    jacobi_ = jacobi;
    ilu_ = false;
    precondition();
    return;
  }
  compute_factors();
}

// The ILU of the current values: the numeric part again on the kept symbolic one, or (with a
// drop tolerance, whose pattern follows the values) the whole set-up. An ILU whose factorization
// throws: Jacobi for these values at once, as precondition() does.
void LinearSolve::compute_factors() {
  if (set_.drop_tolerance > 0 || !impl_->amg.is_null()) {  // AMG: a new hierarchy
    precondition();
    return;
  }
  if (fails_anywhere(*impl_->a->getComm(), [&] { impl_->prec->compute(); })) {
    fall_back_to_jacobi();
    precondition();
  }
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
  impl_->amg = Teuchos::null;
  impl_->pm = Teuchos::null;
  fresh_ = true;
  if (set_.preconditioner == "None") {
    impl_->problem->setRightPrec(Teuchos::null);
    return;
  }
  if (set_.preconditioner == "AMG" && !jacobi_ && !ilu_) {
    impl_->pm = impl_->a;
    if (set_.amg_drop_tolerance > 0)
      impl_->pm = sparsified(*impl_->a, set_.amg_drop_tolerance);
    auto amg = Teuchos::rcp(new AmgPreconditioner(set_));
    std::string what = "a set-up failure on another rank";
    if (!fails_anywhere(
            *impl_->a->getComm(), [&] { amg->setup(*impl_->pm); }, &what)) {
      impl_->amg = amg;
      impl_->problem->setRightPrec(amg);
      return;
    }
    if (!set_.amg_fallback)
      throw std::runtime_error(
          "the pressure solve's algebraic multigrid (hypre BoomerAMG) could not be set up: " +
          what +
          ". Set Solver->Pressure Solve->AMG Fallback = true to continue with ILU for such "
          "matrices, or choose Solver->Pressure Solve->Preconditioner = ILU.");
    ilu_ = true;  // ILU for these values (AMG Fallback)
    ++fallbacks_;
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
    impl_->pm = impl_->a;
    if (set_.drop_tolerance > 0 && !jacobi_)
      impl_->pm = sparsified(*impl_->a, set_.drop_tolerance);
    Teuchos::RCP<const RowMatrix> rows = impl_->pm;
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
  if (!std::isfinite(bn)) {  // not converged: the caller stops the run
    r.finite_rhs = false;
    r.residual = bn;
    return r;
  }
  scale = std::max(scale, bn);
  if (++solves_ == set_.write_at)
    write_system(*impl_->a, b, set_.write_prefix, std::to_string(solves_));
  if (!(bn > 0)) {
    x.putScalar(0.0);
    r.converged = true;
    return r;
  }
  // RCG tests ||r|| against the initial residual's norm rn, CG and GMRES against ||b||.
  double rn = bn;
  if (method() == "RCG") {
    TpetraVector& r0 = kept_vector(impl_->r0, b.getMap());
    impl_->a->apply(x, r0);
    r0.update(1.0, b, -1.0);
    rn = r0.norm2();
    if (!(rn > set_.tolerance * scale)) {  // x solves it already (rn is finite: b and x are)
      r.converged = true;
      r.residual = rn / scale;
      return r;
    }
  }
  const double tol = std::min(0.5, set_.tolerance * scale / rn);
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
  // ILU is therefore tried again from the same initial guess: with the ILU of this matrix's
  // values where the factors were of earlier ones (refresh_interval), else with Jacobi, kept
  // for this matrix's values. Otherwise a failed solve, for the caller to report.
  TpetraVector& x0 = kept_vector(impl_->x0, x.getMap());
  x0.assign(x);
  if (forget_)
    new_krylov();
  for (;;) {
    impl_->solver->setProblem(impl_->problem);
    try {
      r.converged = impl_->solver->solve() == Belos::Converged;
      r.iterations = impl_->solver->getNumIters();
      r.residual = impl_->solver->achievedTol() * rn / scale;
    } catch (const std::exception&) {
      r.converged = false;
      r.iterations = impl_->solver->getNumIters();
      r.residual = std::numeric_limits<double>::quiet_NaN();
    }
    if (r.converged && fresh_)
      base_iterations_ = r.iterations;
    fresh_ = false;
    last_iterations_ = r.iterations;
    const bool ilu = set_.preconditioner == "ILU" || ilu_;
    if (r.converged || jacobi_ || (!ilu && !(set_.preconditioner == "AMG" && kept_ > 0)))
      return r;
    if (kept_ > 0) {
      // Factors of earlier values (refresh_interval): first the ILU of these values.
      kept_ = 0;
      ++setups_;
      compute_factors();
    } else {
      fall_back_to_jacobi();
      precondition();
    }
    x.assign(x0);
    if (!impl_->problem->setProblem())
      throw std::logic_error("LinearSolve: Belos could not set up the problem");
  }
}

}  // namespace mupm
