// The pressure solve's preconditioners side by side on one of mupm's own systems, written by a
// run with Diagnostics->Write Pressure System (MatrixMarket):
//
//   mpirun -np R bench_pressure_solve MATRIX.mtx RHS.mtx [PRECONDITIONER...]
//
// PRECONDITIONER: AMG (hypre BoomerAMG, mupm's default), ILU (Ifpack2 ILU(0) of the matrix less
// its entries below Drop Tolerance 0.02, mupm's earlier default), ILU-whole (Drop Tolerance 0),
// Jacobi. Default: all. MUPM_BENCH_DROP, _THETA, _PMAX, _AGG set AMG Drop Tolerance, Strong
// Threshold, Interpolation Entries, Aggressive Levels. For each: the set-up's
// time, CG iterations to mupm's default tolerance (1e-11 of ||b||) from x = 0, the time of a
// solve (median of 5), an apply of the preconditioner and a product with the matrix, and the
// preconditioner's memory (resident growth over its set-up, max over ranks). The rows are
// spread over the ranks as the file gives them (contiguous blocks, not mupm's bisection), the
// same for every preconditioner.
#include <mpi.h>

#include <Kokkos_Core.hpp>
#include <MatrixMarket_Tpetra.hpp>
#include <Teuchos_DefaultMpiComm.hpp>
#include <Tpetra_Core.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "mupm/solvers/amg_preconditioner.hpp"
#include "mupm/solvers/linear_solve.hpp"

namespace {
using namespace mupm;

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double resident_mb() {  // this process's resident set, MB
  std::ifstream f("/proc/self/statm");
  long pages = 0, resident = 0;
  f >> pages >> resident;
  return double(resident) * 4096.0 / 1e6;
}

double max_over_ranks(double v) {
  MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return v;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The median over 20 calls of f's time, max over ranks.
template <class F>
double median_time(F&& f) {
  std::vector<double> t;
  for (int k = 0; k < 20; ++k) {
    MPI_Barrier(MPI_COMM_WORLD);
    const double t0 = now();
    f();
    t.push_back(max_over_ranks(now() - t0));
  }
  return median(t);
}

struct Row {
  std::string name;
  double setup = 0, solve = 0, apply = 0, memory = 0;
  int iterations = 0;
  double residual = 0;
};

// ||b - A x|| / ||b||.
double residual(const CrsMatrix& a, const TpetraVector& b, const TpetraVector& x) {
  TpetraVector r(b.getMap());
  a.apply(x, r);
  r.update(1.0, b, -1.0);
  return r.norm2() / b.norm2();
}

Row with_linear_solve(const std::string& name, const Teuchos::RCP<const CrsMatrix>& a,
                      const TpetraVector& b) {
  LinearSolveSettings s;
  s.method = "CG";
  s.tolerance = 1e-11;
  s.max_iterations = 5000;
  s.preconditioner = name == "ILU-whole" ? "ILU" : name;
  s.drop_tolerance = name == "ILU" ? 0.02 : 0.0;
  if (const char* d = std::getenv("MUPM_BENCH_DROP"))
    s.amg_drop_tolerance = std::atof(d);
  if (const char* t = std::getenv("MUPM_BENCH_THETA"))
    s.amg_strong_threshold = std::atof(t);
  if (const char* t = std::getenv("MUPM_BENCH_PMAX"))
    s.amg_interpolation_entries = std::atoi(t);
  if (const char* t = std::getenv("MUPM_BENCH_AGG"))
    s.amg_aggressive_levels = std::atoi(t);
  Row r;
  r.name = name;
  LinearSolve solve(s);
  MPI_Barrier(MPI_COMM_WORLD);
  const double m0 = resident_mb(), t0 = now();
  solve.set_matrix(a);
  r.setup = max_over_ranks(now() - t0);
  r.memory = max_over_ranks(resident_mb() - m0);
  std::vector<double> times;
  TpetraVector x(b.getMap());
  for (int k = 0; k < 5; ++k) {
    x.putScalar(0.0);
    double scale = 0;
    MPI_Barrier(MPI_COMM_WORLD);
    const double t = now();
    const auto res = solve.solve(b, x, scale);
    times.push_back(max_over_ranks(now() - t));
    r.iterations = res.iterations;
  }
  r.solve = median(times);
  r.residual = residual(*a, b, x);
  if (!solve.amg().is_null()) {
    const double oc = solve.amg()->operator_complexity();
    const int levels = solve.amg()->levels();
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    if (rank == 0)
      std::printf("  AMG: %d levels, operator complexity %.2f\n", levels, oc);
    TpetraVector y(b.getMap());
    r.apply = median_time([&] { solve.amg()->apply(b, y); });
  }
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  Tpetra::ScopeGuard tpetra(&argc, &argv);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (argc < 3) {
    if (rank == 0)
      std::fprintf(stderr,
                   "usage: bench_pressure_solve MATRIX.mtx RHS.mtx [AMG|ILU|ILU-whole|"
                   "Jacobi ...]\n");
    return 1;
  }
  std::vector<std::string> names(argv + 3, argv + argc);
  if (names.empty()) {
    names = {"AMG", "ILU", "ILU-whole", "Jacobi"};
  }
  const auto comm = Tpetra::getDefaultComm();
  using Reader = Tpetra::MatrixMarket::Reader<CrsMatrix>;
  Teuchos::RCP<const CrsMatrix> a = Reader::readSparseFile(argv[1], comm);
  auto range = a->getRangeMap();
  const auto rhs = Reader::readDenseFile(argv[2], comm, range);
  TpetraVector b(a->getRangeMap());
  b.assign(*rhs->getVector(0));
  // A product with the matrix (median of 20).
  TpetraVector y(a->getRangeMap());
  const double product = median_time([&] { a->apply(b, y); });
  if (rank == 0)
    std::printf("%s: %lld rows, %.1f entries a row; a product %.3f ms on %d ranks\n", argv[1],
                (long long)a->getGlobalNumRows(),
                double(a->getGlobalNumEntries()) / double(a->getGlobalNumRows()), 1e3 * product,
                comm->getSize());
  std::vector<Row> rows;
  for (const auto& n : names)
    rows.push_back(with_linear_solve(n, a, b));
  if (rank == 0) {
    std::printf("%-10s %10s %6s %10s %10s %10s %12s\n", "prec", "setup ms", "iter", "solve ms",
                "apply ms", "memory MB", "residual");
    for (const auto& r : rows)
      std::printf("%-10s %10.2f %6d %10.2f %10.3f %10.1f %12.2e\n", r.name.c_str(), 1e3 * r.setup,
                  r.iterations, 1e3 * r.solve, 1e3 * r.apply, r.memory, r.residual);
  }
  return 0;
}
