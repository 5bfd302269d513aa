// The pressure solve's preconditioners side by side on one of mupm's own systems, written by a
// run with Diagnostics->Write Pressure System (MatrixMarket, rows in global-id order):
//
//   mpirun -np R bench_pressure_solve MATRIX.mtx RHS.mtx [PRECONDITIONER...]
//
// PRECONDITIONER: AMG (hypre BoomerAMG, mupm's default), ILU (Ifpack2 ILU(0) of the matrix less
// its entries below Drop Tolerance 0.02, mupm's earlier default), ILU-whole (Drop Tolerance 0),
// Jacobi, and MueLu (smoothed aggregation, Chebyshev smoothing, where this build found a
// MueLu: cmake -DMUPM_MUELU_PREFIX=...; perf/README.md). Default: all. For each: the set-up's
// time, CG iterations to mupm's default tolerance (1e-11 of ||b||) from x = 0, the time of a
// solve (median of 5), an apply of the preconditioner and a product with the matrix, and the
// preconditioner's memory (resident growth over its set-up, max over ranks). The rows are
// spread over the ranks as the file gives them (contiguous blocks, not mupm's bisection), the
// same for every preconditioner.
#include <mpi.h>

#include <BelosLinearProblem.hpp>
#include <BelosSolverFactory.hpp>
#include <BelosTpetraAdapter.hpp>
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

#ifdef MUPM_HAVE_MUELU
#include <MueLu_CreateTpetraPreconditioner.hpp>
#endif

namespace {
using namespace mupm;
using MV = Tpetra::MultiVector<double, LocalId, GlobalId>;
using OP = Tpetra::Operator<double, LocalId, GlobalId>;

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
  s.drop_tolerance = name == "ILU" || name == "AMG" ? 0.02 : 0.0;
  if (const char* d = std::getenv("MUPM_BENCH_DROP"))
    s.drop_tolerance = std::atof(d);
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
    std::vector<double> ap;
    for (int k = 0; k < 20; ++k) {
      MPI_Barrier(MPI_COMM_WORLD);
      const double t = now();
      solve.amg()->apply(b, y);
      ap.push_back(max_over_ranks(now() - t));
    }
    r.apply = median(ap);
  }
  return r;
}

#ifdef MUPM_HAVE_MUELU
// MueLu's smoothed aggregation with its defaults for a scalar elliptic problem: uncoupled
// aggregation, Chebyshev smoothing of degree 2, the coarsest level solved by relaxation
// (no Amesos2 in the trimmed build).
Row with_muelu(const Teuchos::RCP<const CrsMatrix>& a, const TpetraVector& b) {
  Row r;
  r.name = "MueLu";
  Teuchos::ParameterList p;
  p.set("verbosity", "none");
  p.set("multigrid algorithm", "sa");
  p.set("smoother: type", "CHEBYSHEV");
  p.set("coarse: type", "RELAXATION");
  p.set("coarse: max size", 500);
  if (const char* d = std::getenv("MUPM_BENCH_DROP"))
    p.set("aggregation: drop tol", std::atof(d));
  MPI_Barrier(MPI_COMM_WORLD);
  const double m0 = resident_mb(), t0 = now();
  Teuchos::RCP<OP> op = Teuchos::rcp_const_cast<CrsMatrix>(a);
  auto prec = MueLu::CreateTpetraPreconditioner(op, p);
  r.setup = max_over_ranks(now() - t0);
  r.memory = max_over_ranks(resident_mb() - m0);
  auto params = Teuchos::parameterList();
  params->set("Convergence Tolerance", 1e-11);
  params->set("Maximum Iterations", 5000);
  params->set("Residual Scaling", std::string("Norm of RHS"));
  Belos::SolverFactory<double, MV, OP> factory;
  auto solver = factory.create("CG", params);
  auto problem = Teuchos::rcp(new Belos::LinearProblem<double, MV, OP>());
  problem->setOperator(a);
  problem->setRightPrec(prec);
  TpetraVector x(b.getMap());
  std::vector<double> times;
  for (int k = 0; k < 5; ++k) {
    x.putScalar(0.0);
    problem->setLHS(Teuchos::rcpFromRef(static_cast<MV&>(x)));
    problem->setRHS(Teuchos::rcpFromRef(static_cast<const MV&>(b)));
    problem->setProblem();
    solver->setProblem(problem);
    MPI_Barrier(MPI_COMM_WORLD);
    const double t = now();
    solver->solve();
    times.push_back(max_over_ranks(now() - t));
    r.iterations = solver->getNumIters();
  }
  r.solve = median(times);
  r.residual = residual(*a, b, x);
  TpetraVector y(b.getMap());
  std::vector<double> ap;
  for (int k = 0; k < 20; ++k) {
    MPI_Barrier(MPI_COMM_WORLD);
    const double t = now();
    prec->apply(b, y);
    ap.push_back(max_over_ranks(now() - t));
  }
  r.apply = median(ap);
  return r;
}
#endif
}  // namespace

int main(int argc, char** argv) {
  Tpetra::ScopeGuard tpetra(&argc, &argv);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (argc < 3) {
    if (rank == 0)
      std::fprintf(stderr,
                   "usage: bench_pressure_solve MATRIX.mtx RHS.mtx [AMG|ILU|ILU-whole|"
                   "Jacobi|MueLu ...]\n");
    return 1;
  }
  std::vector<std::string> names(argv + 3, argv + argc);
  if (names.empty()) {
    names = {"AMG", "ILU", "ILU-whole", "Jacobi"};
#ifdef MUPM_HAVE_MUELU
    names.push_back("MueLu");
#endif
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
  std::vector<double> products;
  for (int k = 0; k < 20; ++k) {
    MPI_Barrier(MPI_COMM_WORLD);
    const double t = now();
    a->apply(b, y);
    products.push_back(max_over_ranks(now() - t));
  }
  if (rank == 0)
    std::printf("%s: %lld rows, %.1f entries a row; a product %.3f ms on %d ranks\n", argv[1],
                (long long)a->getGlobalNumRows(),
                double(a->getGlobalNumEntries()) / double(a->getGlobalNumRows()),
                1e3 * median(products), comm->getSize());
  std::vector<Row> rows;
  for (const auto& n : names) {
#ifdef MUPM_HAVE_MUELU
    if (n == "MueLu") {
      rows.push_back(with_muelu(a, b));
      continue;
    }
#endif
    rows.push_back(with_linear_solve(n, a, b));
  }
  if (rank == 0) {
    std::printf("%-10s %10s %6s %10s %10s %10s %12s\n", "prec", "setup ms", "iter", "solve ms",
                "apply ms", "memory MB", "residual");
    for (const auto& r : rows)
      std::printf("%-10s %10.2f %6d %10.2f %10.3f %10.1f %12.2e\n", r.name.c_str(), 1e3 * r.setup,
                  r.iterations, 1e3 * r.solve, 1e3 * r.apply, r.memory, r.residual);
  }
  return 0;
}
