// Shared by the benchmark programs: the one-rank communicator, the benchmark grid, and main.
#ifndef MUPM_BENCH_COMMON_HPP
#define MUPM_BENCH_COMMON_HPP

#include <benchmark/benchmark.h>

#include <Teuchos_DefaultMpiComm.hpp>
#include <Tpetra_Core.hpp>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <tuple>

#include "mupm/core/timers.hpp"
#include "mupm/mesh/grid.hpp"

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

// Set-up (discretization and neighbour build, up to seconds in 3D) is shared by the benchmarks
// of a configuration and by the repeated calls Google Benchmark makes of each: one Body per
// (type, points per axis, horizon factor), built on first use, dropped by release_bodies().
using Key = std::tuple<const void*, long long, long long>;
inline std::map<Key, std::shared_ptr<void>>& bodies() {
  static std::map<Key, std::shared_ptr<void>> cache;
  return cache;
}
template <class Body>
Body& body(const benchmark::State& state) {
  static const char tag = 0;  // one address per Body type
  auto& slot = bodies()[Key{&tag, state.range(0), state.range(1)}];
  if (!slot)
    slot = std::make_shared<Body>(grid<Body::dim>(state));
  return *std::static_pointer_cast<Body>(slot);
}
inline void release_bodies() {
  bodies().clear();
}

// Counters of a benchmark over n_bonds bonds and n_points points per iteration.
inline void set_counters(benchmark::State& state, double n_bonds, double n_points) {
  state.counters["points"] = n_points;
  state.counters["bonds"] = n_bonds;
  state.counters["bond_updates_per_s"] =
      benchmark::Counter(n_bonds, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["points_per_s"] =
      benchmark::Counter(n_points, benchmark::Counter::kIsIterationInvariantRate);
}

// Runs the registered benchmarks between MPI/Kokkos initialization and finalization;
// `release` drops any Views kept between benchmarks before Kokkos is finalized. With
// MUPM_BENCH_TIMERS=1 the kernels' and regions' times over the whole run (set-up included, and
// every repetition Google Benchmark makes) are printed to stderr at the end, as a run prints them.
inline int run(int argc, char** argv, const std::function<void()>& release = {}) {
  Tpetra::ScopeGuard scope(&argc, &argv);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv))
    return 1;
  const char* env = std::getenv("MUPM_BENCH_TIMERS");
  const bool timed = env && std::string(env) == "1" && timers::enable();
  benchmark::RunSpecifiedBenchmarks();
  if (timed) {
    timers::report(MPI_COMM_SELF, std::cerr);
    timers::disable();
  }
  benchmark::Shutdown();
  if (release)
    release();
  return 0;
}

}  // namespace mupm::bench

#endif
