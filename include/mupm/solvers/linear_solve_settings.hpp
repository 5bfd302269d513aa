// The settings of a distributed sparse linear solve (include/mupm/solvers/linear_solve.hpp), apart
// so that the input model and the solvers' declarations take them without Tpetra's headers.
#ifndef MUPM_SOLVERS_LINEAR_SOLVE_SETTINGS_HPP
#define MUPM_SOLVERS_LINEAR_SOLVE_SETTINGS_HPP

#include <string>

namespace mupm {

// Belos' RCG: iterations a cycle, at whose end the recycle space is gathered; a space of at most
// kRcgCycle - 1 vectors (LinearSolveSettings::recycle).
inline constexpr int kRcgCycle = 25;

struct LinearSolveSettings {
  // "GMRES" | "CG": CG needs a symmetric positive definite matrix and preconditioner (ILU(k) of
  // a symmetric matrix is L D L^T up to round-off); it keeps no basis, so an iteration costs a
  // product, a preconditioner apply and three reductions, GMRES's also an orthogonalization
  // against every earlier vector.
  std::string method = "GMRES";
  // "AMG" (hypre BoomerAMG, include/mupm/solvers/amg_preconditioner.hpp) | "ILU" (Ifpack2
  // RILUK) | "Jacobi" | "None". The input's default is AMG (Solver->Pressure Solve->
  // Preconditioner); this one stays ILU for the solvers' unit tests, whose closed-form runs were
  // timed with it (tests/CMakeLists.txt), and for the fracture network's own solve.
  std::string preconditioner = "ILU";
  int fill_level = 0;        // ILU(k)
  double tolerance = 1e-11;  // ||b - A x|| / the largest ||b|| so far
  int max_iterations = 1000;
  int restart = 100;  // GMRES restart length (not used by CG)
  // refresh() computes the preconditioner's numeric part on every refresh_interval-th call
  // since the last set-up, and keeps the factors of the earlier values in between: the Krylov
  // method still solves the current matrix to the tolerance (any fixed symmetric positive
  // definite preconditioner serves CG), only its iteration count depends on how close the
  // factors are. 1: every call.
  int refresh_interval = 1;
  // > 1: refresh() also computes the preconditioner again when the last solve took more than
  // this many times the iterations of the first solve after its set-up (a kept preconditioner
  // gone stale: the values drifted). <= 1: no such rule.
  double refresh_growth = 0;
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
  // AMG: BoomerAMG's strength threshold (a connection a_ij is strong where -a_ij >= this x the
  // row's largest -a_ik), its interpolation's largest entries a row, and the number of levels
  // coarsened aggressively (each a coarser, sparser hierarchy for more iterations).
  double amg_strong_threshold = 0.25;
  int amg_interpolation_entries = 4;
  int amg_aggressive_levels = 0;
  // AMG: > 0, the hierarchy is of A less its entries below this (as drop_tolerance for ILU). Each
  // dropped |a_ij| on the diagonal adds |a_ij| (e_i + e_j)(e_i + e_j)^T for a negative a_ij: a
  // mass on the smoothest modes, which AMG's coarse levels then see instead of A's, so the
  // iterations grow under refinement (measured: perf/README.md). 0: the whole matrix.
  double amg_drop_tolerance = 0;
  // AMG: after a set-up failure, ILU for this matrix's values instead of stopping the run.
  bool amg_fallback = false;
  // > 0: the write_at-th solve writes its matrix and right-hand side (MatrixMarket, gathered on
  // rank 0) to <write_prefix>pressure_system_<write_at>.mtx and pressure_rhs_<write_at>.mtx.
  int write_at = 0;
  std::string write_prefix;
};

}  // namespace mupm

#endif
