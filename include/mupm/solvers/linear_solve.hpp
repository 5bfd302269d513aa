// A distributed sparse linear solve on Trilinos' stack: a Tpetra CrsMatrix over the points' map
// (or the fracture network's), Belos' GMRES (or CG for a symmetric positive definite matrix) and
// an Ifpack2 preconditioner (ILU(k) by default, or Jacobi), built once per matrix and reused for
// every right-hand side until the matrix changes (set_matrix; refresh when only its values do,
// which may keep the factors of earlier values for a while: refresh_interval). No rank ever
// holds more than its own rows.
//
// Results across rank counts: the Krylov iterates depend on the order of the reductions and on
// the preconditioner's subdomains (Ifpack2 builds ILU per rank, additive Schwarz without
// overlap), so the solution agrees across rank counts to the solve's tolerance, not to the bit.
// The tolerance is on ||b - A x|| relative to the largest ||b|| solved so far (solve()).
#ifndef MUPM_SOLVERS_LINEAR_SOLVE_HPP
#define MUPM_SOLVERS_LINEAR_SOLVE_HPP

#include <Teuchos_RCP.hpp>
#include <Tpetra_CrsMatrix.hpp>
#include <Tpetra_Vector.hpp>
#include <string>

#include "mupm/core/types.hpp"

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

struct LinearSolveSettings {
  // "GMRES" | "CG": CG needs a symmetric positive definite matrix and preconditioner (ILU(k) of
  // a symmetric matrix is L D L^T up to round-off); it keeps no basis, so an iteration costs a
  // product, a preconditioner apply and three reductions, GMRES's also an orthogonalization
  // against every earlier vector.
  std::string method = "GMRES";
  std::string preconditioner = "ILU";  // "ILU" (Ifpack2 RILUK) | "Jacobi" | "None"
  int fill_level = 0;                  // ILU(k)
  double tolerance = 1e-11;            // ||b - A x|| / the largest ||b|| so far
  int max_iterations = 1000;
  int restart = 100;  // GMRES restart length (not used by CG)
  // refresh() computes the preconditioner's numeric part on every refresh_interval-th call
  // since the last set-up, and keeps the factors of the earlier values in between: the Krylov
  // method still solves the current matrix to the tolerance (any fixed symmetric positive
  // definite preconditioner serves CG), only its iteration count depends on how close the
  // factors are. 1: every call.
  int refresh_interval = 1;
  // CG only, > 0: Belos' recycling CG (RCG, Parks et al. 2006) with a recycle space of this many
  // vectors, approximate eigenvectors of the preconditioned matrix's smallest eigenvalues
  // gathered over the solves and deflated from every later one. A sequence of systems with
  // the same or slowly changing matrix (the projection's, step after step) then converges in
  // fewer iterations, for `recycle` products and preconditioner applies per solve (A U of the
  // current matrix) and a small eigenproblem every 25 iterations. The space is dropped with
  // every new matrix and at renew(), so that a restart, which starts without one, continues
  // the run bit for bit. 0: CG (measured: perf/README.md).
  int recycle = 0;
  // > 0: the ILU is of A without its entries |a_ij| < drop_tolerance sqrt(|a_ii a_jj|) (each
  // added to the diagonal, so that the preconditioner stays symmetric positive definite; the
  // Krylov method still solves A). The projection's matrix is two horizons wide and its far
  // entries small: its ILU(0) then costs a quarter of one of A's per apply, for more
  // iterations (perf/README.md).
  double drop_tolerance = 0;
};

struct LinearSolveResult {
  bool converged = false;
  int iterations = 0;
  double residual = 0;     // the achieved ||b - A x|| / the largest ||b|| (Belos' estimate)
  bool finite_rhs = true;  // false: b held an inf or NaN, no solve was tried
};

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
  // ILU breakdowns since construction, each answered with Jacobi for that matrix's values
  // (solve()).
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
};

}  // namespace mupm

#endif
