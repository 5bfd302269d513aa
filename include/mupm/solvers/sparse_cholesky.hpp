// A direct solve of a sparse symmetric positive definite system, for the fracture network
// (include/mupm/solvers/fracture_flow.hpp), by SuiteSparse's CHOLMOD (Debian's
// libsuitesparse-dev): approximate-minimum-degree ordering and a simplicial LDL' factorization.
//
// Why CHOLMOD and these options. The network of a 3D crack is a surface; a banded LU in
// reverse Cuthill-McKee order costs n b^2 with a bandwidth b that grows as the crack's width
// (n = 5000, b = 394 in perf/bench_fluid's 3D body: 1.6e9 flops a step), where a fill-reducing
// ordering costs about n^1.5 for a planar graph. Simplicial (no BLAS) and one fixed ordering
// (AMD, no METIS trial) keep the result the same bits on every rank and thread count: every rank
// factors the same matrix, given in the same order, with the same serial code; CHOLMOD's
// supernodal path calls a BLAS whose threading could change the bits.
#ifndef MUPM_SOLVERS_SPARSE_CHOLESKY_HPP
#define MUPM_SOLVERS_SPARSE_CHOLESKY_HPP

#include <vector>

namespace mupm {

// Lower triangle of an n x n symmetric matrix in compressed columns: column c holds rows
// row[first[c]] .. row[first[c + 1] - 1], ascending, the diagonal first (row == c).
struct LowerCsc {
  int n = 0;
  std::vector<int> first, row;
  std::vector<double> value;
};

struct CholeskyResult {
  bool ok = false;         // factored (positive definite) and solved
  int failed_column = -1;  // where the factorization stopped, if not ok
  double factor_nnz = 0;   // non-zeros of L (the fill), for the benchmarks
};

// Solves A x = b in place (b holds x on return).
CholeskyResult solve_spd(const LowerCsc& a, std::vector<double>& b);

}  // namespace mupm

#endif
