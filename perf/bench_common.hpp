// Shared by the benchmark programs: the one-rank communicator, the benchmark grid, and main.
#ifndef MUPM_BENCH_COMMON_HPP
#define MUPM_BENCH_COMMON_HPP

#include <benchmark/benchmark.h>

#include <Teuchos_DefaultMpiComm.hpp>
#include <Tpetra_Core.hpp>
#include <functional>

#include "mupm/grid.hpp"

namespace mupm::bench {

inline Teuchos::RCP<const Teuchos::Comm<int>> self() {
  return Teuchos::rcp(new Teuchos::MpiComm<int>(MPI_COMM_SELF));
}

// A cube of state.range(0) points per axis, dx = 1 mm, delta = state.range(1) / 1000 dx.
template <int Dim>
GridSpec<Dim> grid(const benchmark::State& state) {
  GridSpec<Dim> g;
  g.counts.fill(state.range(0));
  g.dx = 1e-3;
  g.horizon = double(state.range(1)) / 1000.0 * g.dx;
  return g;
}

// Runs the registered benchmarks between MPI/Kokkos initialization and finalization;
// `release` drops any Views kept between benchmarks before Kokkos is finalized.
inline int run(int argc, char** argv, const std::function<void()>& release = {}) {
  Tpetra::ScopeGuard scope(&argc, &argv);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv))
    return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  if (release)
    release();
  return 0;
}

}  // namespace mupm::bench

#endif
