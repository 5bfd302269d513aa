// A distributed sparse linear solve on Trilinos' stack: a Tpetra CrsMatrix over the points' map
// (or the fracture network's), Belos' GMRES (or CG for a symmetric positive definite matrix) and
// a preconditioner: hypre's algebraic multigrid (AMG, include/mupm/solvers/amg_preconditioner.hpp),
// Ifpack2's ILU(k) or Jacobi (LinearSolveSettings::preconditioner; the fracture network's own
// solve takes ILU), built once per matrix and reused for every right-hand side until the matrix
// changes (set_matrix; refresh when only its values do, which may keep the factors or the
// hierarchy of earlier values for a while: refresh_interval, refresh_growth). No rank ever
// holds more than its own rows.
//
// Results across rank counts: the Krylov iterates depend on the order of the reductions and on
// the preconditioner's subdomains (ILU per rank, additive Schwarz without overlap; AMG's
// coarsening per rank), so the solution agrees across rank counts to the solve's tolerance, not
// to the bit. The tolerance is on ||b - A x|| relative to the largest ||b|| solved so far
// (solve()).
#ifndef MUPM_SOLVERS_LINEAR_SOLVE_HPP
#define MUPM_SOLVERS_LINEAR_SOLVE_HPP

#include <Teuchos_RCP.hpp>
#include <Tpetra_CrsMatrix.hpp>
#include <Tpetra_Vector.hpp>
#include <string>
#include <vector>

#include "mupm/core/types.hpp"
#include "mupm/solvers/linear_solve_settings.hpp"

namespace mupm {

using CrsMatrix = Tpetra::CrsMatrix<double, LocalId, GlobalId>;
using TpetraVector = Tpetra::Vector<double, LocalId, GlobalId>;

// A work vector kept between calls: `kept`, made anew (zeroed) only when it is not over `map`.
inline TpetraVector& kept_vector(Teuchos::RCP<TpetraVector>& kept,
                                 const Teuchos::RCP<const TpetraVector::map_type>& map) {
  if (kept.is_null() || kept->getMap().get() != map.get())
    kept = Teuchos::rcp(new TpetraVector(map));
  return *kept;
}

struct LinearSolveResult {
  bool converged = false;
  int iterations = 0;
  double residual = 0;     // the achieved ||b - A x|| / the largest ||b|| (Belos' estimate)
  bool finite_rhs = true;  // false: b held an inf or NaN, no solve was tried
};

class AmgPreconditioner;

// The rows of `a` numbered 0, 1, ... rank by rank in each rank's row order (this rank's first is
// `first`), and the number of each of its local columns in that numbering (an import of the
// rows' numbers to the column map). Collective. For libraries and files that need contiguous
// indices (hypre, MatrixMarket); the projection's joint numbering has gaps (crack_offset).
struct ContiguousNumbering {
  GlobalId first = 0;
  std::vector<GlobalId> column;  // [the column map's local index]
};
ContiguousNumbering contiguous_numbering(const CrsMatrix& a);

class LinearSolve {
 public:
  explicit LinearSolve(const LinearSolveSettings& settings);
  ~LinearSolve();
  LinearSolve(const LinearSolve&) = delete;
  LinearSolve& operator=(const LinearSolve&) = delete;

  // A new matrix: the preconditioner is set up again (symbolic and numeric parts).
  void set_matrix(const Teuchos::RCP<const CrsMatrix>& a);
  // The matrix of the last set_matrix has new values on the same graph: the preconditioner's
  // numeric part again (an ILU's factors; its symbolic part is kept) on every
  // settings().refresh_interval-th call since the last set-up, else nothing. The same factors
  // as set_matrix would give: a restart that calls set_matrix instead reproduces the run, when
  // the run renewed at the restart's step (renew). Collective.
  void refresh();
  // The next refresh computes the numeric part (and counts from there), and the next solve
  // starts without a recycle space: called where a checkpoint was written, so that the run
  // goes on with the factors and space a restart from it builds.
  void renew() {
    renew_ = true;
    forget_ = true;
  }
  bool renewal_pending() const { return renew_; }
  // Solves A x = b (x: the initial guess on entry) to the tolerance times `scale`, the largest
  // ||b|| so far (updated here; a caller that restarts keeps it). Collective.
  LinearSolveResult solve(const TpetraVector& b, TpetraVector& x, double& scale);
  const LinearSolveSettings& settings() const { return set_; }
  // Preconditioner set-ups (set_matrix and the refreshes that computed) since construction.
  long long setups() const { return setups_; }
  // The matrix the current preconditioner was computed from: the last set_matrix's, or its
  // sparsified copy with a drop tolerance (null before set_matrix; for tests).
  Teuchos::RCP<const CrsMatrix> preconditioner_matrix() const;
  // The algebraic multigrid in use (null unless Preconditioner = AMG and its set-up succeeded).
  Teuchos::RCP<const AmgPreconditioner> amg() const;
  // ILU breakdowns since construction, each answered with Jacobi for that matrix's values
  // (solve()), and AMG set-up failures answered with ILU (amg_fallback).
  long long fallbacks() const { return fallbacks_; }
  // "CG", "RCG" (CG with settings().recycle > 0) or "GMRES".
  std::string method() const;

 private:
  void new_krylov();
  void precondition();
  void compute_factors();
  // After an ILU breakdown: Jacobi from now on (counted); an error if Jacobi itself failed.
  void fall_back_to_jacobi();
  struct Impl;
  LinearSolveSettings set_;
  Teuchos::RCP<Impl> impl_;
  long long setups_ = 0, fallbacks_ = 0;
  bool jacobi_ = false;  // the current matrix's preconditioner is Jacobi
  int kept_ = 0;         // refresh() calls since the factors were computed
  bool renew_ = false;
  bool forget_ = false;  // the next solve starts without a recycle space (renew)
  bool ilu_ = false;     // the current matrix's preconditioner is ILU after an AMG failure
  // refresh_growth's rule: the first solve's iterations after a set-up, and the last solve's
  bool fresh_ = true;
  int base_iterations_ = 0, last_iterations_ = 0;
  long long solves_ = 0;  // solve() calls with a finite right-hand side
};

}  // namespace mupm

#endif
