// CHOLMOD behind include/mupm/solvers/sparse_cholesky.hpp (options and reasons there).
#include "mupm/solvers/sparse_cholesky.hpp"

#include <cholmod.h>

#include <algorithm>

namespace mupm {

namespace {
// cholmod_common with start/finish tied to a scope.
struct Common {
  cholmod_common c;
  Common() {
    cholmod_start(&c);
    c.nmethods = 1;
    c.method[0].ordering = CHOLMOD_AMD;
    c.postorder = 1;
    c.supernodal = CHOLMOD_SIMPLICIAL;
    c.final_ll = 0;  // LDL'
    c.print = 0;
    c.error_handler = nullptr;
  }
  ~Common() { cholmod_finish(&c); }
  Common(const Common&) = delete;
  Common& operator=(const Common&) = delete;
};
}  // namespace

CholeskyResult solve_spd(const LowerCsc& a, std::vector<double>& b) {
  CholeskyResult out;
  const int n = a.n;
  if (n == 0) {
    out.ok = true;
    return out;
  }
  Common com;
  cholmod_common* c = &com.c;
  const std::size_t nnz = a.row.size();
  // stype -1: the lower triangle is used; sorted, packed.
  cholmod_sparse* A = cholmod_allocate_sparse(n, n, nnz, 1, 1, -1, CHOLMOD_REAL, c);
  cholmod_dense* B = cholmod_allocate_dense(n, 1, n, CHOLMOD_REAL, c);
  cholmod_factor* L = nullptr;
  cholmod_dense* X = nullptr;
  if (A && B) {
    std::copy(a.first.begin(), a.first.end(), static_cast<int*>(A->p));
    std::copy(a.row.begin(), a.row.end(), static_cast<int*>(A->i));
    std::copy(a.value.begin(), a.value.end(), static_cast<double*>(A->x));
    std::copy(b.begin(), b.begin() + n, static_cast<double*>(B->x));
    L = cholmod_analyze(A, c);
    if (L && cholmod_factorize(A, L, c) && c->status == CHOLMOD_OK && int(L->minor) == n) {
      X = cholmod_solve(CHOLMOD_A, L, B, c);
      out.factor_nnz = c->lnz;
    } else if (L) {
      out.failed_column = int(L->minor);
    }
  }
  if (X) {
    const double* x = static_cast<const double*>(X->x);
    std::copy(x, x + n, b.begin());
    out.ok = true;
  }
  cholmod_free_dense(&X, c);
  cholmod_free_factor(&L, c);
  cholmod_free_dense(&B, c);
  cholmod_free_sparse(&A, c);
  return out;
}

}  // namespace mupm
