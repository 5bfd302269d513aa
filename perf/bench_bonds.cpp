// Google Benchmark of the bond infrastructure on one rank: the neighbour build (cell binning,
// count -> scan -> fill, rows sorted by global id) and a bond loop that gathers neighbour data
// (the shape tensor of pass 1, eq 45), in 2D and 3D at delta = 3.015 dx and 4.015 dx.
// Run: OMP_NUM_THREADS=T OMP_PROC_BIND=spread OMP_PLACES=threads ./perf/bench_bonds
#include "bench_common.hpp"
#include "mupm/kernels/shape_tensor.hpp"
#include "mupm/mesh/discretization.hpp"

namespace {

using namespace mupm;

using bench::self;

// state.range(0): points per axis; state.range(1): horizon factor x 1000.
template <int Dim>
void BM_NeighborBuild(benchmark::State& state) {
  const auto g = bench::grid<Dim>(state);
  auto disc = discretize(self(), g);
  for (auto _ : state) {
    auto bonds = build_bonds(disc.points, g.horizon, g.cracks);
    Kokkos::fence();
    benchmark::DoNotOptimize(bonds.neighbor.data());
  }
  const double n_bonds = double(disc.bonds.size()), n_points = double(disc.points.n_owned);
  state.counters["points"] = n_points;
  state.counters["bonds_per_point"] = n_bonds / n_points;
  state.counters["bond_updates_per_s"] =
      benchmark::Counter(n_bonds, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["points_per_s"] =
      benchmark::Counter(n_points, benchmark::Counter::kIsIterationInvariantRate);
}

template <int Dim>
void BM_ShapeTensorBondLoop(benchmark::State& state) {
  const auto g = bench::grid<Dim>(state);
  auto disc = discretize(self(), g);
  Vectors K("K", disc.points.n_owned, Dim * Dim);
  compute_shape_tensor(disc.points, disc.bonds, K);  // warm-up
  Kokkos::fence();
  for (auto _ : state) {
    compute_shape_tensor(disc.points, disc.bonds, K);
    Kokkos::fence();
  }
  const double n_bonds = double(disc.bonds.size()), n_points = double(disc.points.n_owned);
  state.counters["points"] = n_points;
  state.counters["bytes_per_bond"] = double(disc.bonds.bytes_per_bond());
  state.counters["bytes_per_point"] = double(Points<Dim>::bytes_per_point());
  state.counters["bond_updates_per_s"] =
      benchmark::Counter(n_bonds, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["points_per_s"] =
      benchmark::Counter(n_points, benchmark::Counter::kIsIterationInvariantRate);
}

// UseRealTime: Google Benchmark's default clock (and so every rate counter) is the CPU time of
// the calling thread alone, not the wall time of the parallel region: on a loaded machine the
// main thread waits off-CPU while the other OpenMP threads finish, and the rates come out up
// to T times too high.
BENCHMARK_TEMPLATE(BM_NeighborBuild, 2)
    ->Args({400, 3015})
    ->Args({400, 4015})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_TEMPLATE(BM_NeighborBuild, 3)
    ->Args({50, 3015})
    ->Args({50, 4015})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_TEMPLATE(BM_ShapeTensorBondLoop, 2)
    ->Args({400, 3015})
    ->Args({400, 4015})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_TEMPLATE(BM_ShapeTensorBondLoop, 3)
    ->Args({50, 3015})
    ->Args({50, 4015})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  return mupm::bench::run(argc, argv);
}
