// Algebraic multigrid for the distributed pressure solves (Pressure Solve -> Preconditioner =
// AMG): hypre's BoomerAMG (classical Ruge-Stueben-type AMG) on a Tpetra CrsMatrix, applied as
// one V-cycle from a zero guess, a fixed linear operator that Belos' CG or GMRES use as a right
// preconditioner.
//
// Why AMG: the projection's matrix V C + dt V H + dt^2 B~ M^-1 B~^T
// (include/mupm/solvers/pressure_projection.hpp) is a nonlocal pressure "Laplacian" two horizons
// wide; one-level preconditioners (ILU per rank, Jacobi) leave its smooth error to the Krylov
// method, whose iterations then grow with the points per horizon-free length and with the
// ranks (perf/README.md, "Semi-implicit pressure solve"). AMG removes the smooth error on
// coarser levels built from the matrix alone; its iterations stay bounded under refinement.
//
// Why the V-cycle is a valid CG preconditioner: the smoother is hypre's l1-scaled hybrid
// Gauss-Seidel, forward on the way down and backward on the way up (relax types 13 and 14), the
// coarsest level (a few points) gets a symmetric Gauss-Seidel sweep, and the restriction is the
// interpolation's transpose: the V-cycle is then a symmetric positive definite operator for a
// symmetric positive definite matrix. A hierarchy built from earlier values of the matrix
// (LinearSolve::refresh keeps it) is still a fixed SPD operator: the Krylov method solves the
// current matrix to its tolerance, only its iterations depend on how close the hierarchy is.
//
// Numbering: hypre's rows are contiguous per rank; rank r owns rows [lower_r, lower_r + n_r)
// in the order of its Tpetra rows, and each column's hypre index comes by an import of these
// indices to the column map. hypre must carry 64-bit global indices (mupm's GlobalId): Debian's
// libhypre64m-dev (HYPRE_MIXEDINT: 32-bit local, 64-bit global), checked at compile time.
//
// Results: the hierarchy depends on the partition (coarsening per rank, HMIS across ranks), so
// solves agree across rank counts to the Krylov tolerance, and bit for bit on the same ranks
// (hypre is built without threads here: the OpenMP threads of a rank do not change it).
#ifndef MUPM_SOLVERS_AMG_PRECONDITIONER_HPP
#define MUPM_SOLVERS_AMG_PRECONDITIONER_HPP

#include <Teuchos_RCP.hpp>
#include <Tpetra_CrsMatrix.hpp>
#include <Tpetra_Operator.hpp>
#include <memory>

#include "mupm/core/types.hpp"
#include "mupm/solvers/linear_solve_settings.hpp"

namespace mupm {

class AmgPreconditioner : public Tpetra::Operator<double, LocalId, GlobalId> {
 public:
  using MV = Tpetra::MultiVector<double, LocalId, GlobalId>;
  using Matrix = Tpetra::CrsMatrix<double, LocalId, GlobalId>;
  using map_type = Tpetra::Map<LocalId, GlobalId>;

  explicit AmgPreconditioner(const LinearSolveSettings& settings);
  ~AmgPreconditioner() override;
  AmgPreconditioner(const AmgPreconditioner&) = delete;
  AmgPreconditioner& operator=(const AmgPreconditioner&) = delete;

  // Builds the hierarchy of `a` (square, rows over its row map = domain = range map): copies
  // its rows into hypre and runs BoomerAMG's set-up. Collective; throws std::runtime_error on
  // every rank where hypre reports a generic or memory error or builds no level (the caller
  // decides together); hypre's argument and convergence flags are counted (warnings()).
  void setup(const Matrix& a);
  // Y = beta Y + alpha M^-1 X, M^-1 one V-cycle of the hierarchy from a zero guess.
  void apply(const MV& x, MV& y, Teuchos::ETransp mode = Teuchos::NO_TRANS, double alpha = 1.0,
             double beta = 0.0) const override;
  Teuchos::RCP<const map_type> getDomainMap() const override { return map_; }
  Teuchos::RCP<const map_type> getRangeMap() const override { return map_; }
  bool hasTransposeApply() const override { return true; }  // symmetric

  // The hierarchy's levels and operator complexity (the nonzeros of all levels over the
  // finest's) of the last set-up, for measurement.
  int levels() const;
  double operator_complexity() const;
  // Set-ups whose hypre error flag held an argument or convergence error, taken as warnings
  // (setup()).
  long long warnings() const { return warnings_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  long long warnings_ = 0;
  Teuchos::RCP<const map_type> map_;
};

}  // namespace mupm

#endif
