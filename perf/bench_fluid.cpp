// Google Benchmark of the pore-fluid kernels and of the whole coupled step on one rank:
// fluid pass 1 (K, grad p, Darcy flux, alpha), pass 2 (flow divergence), the flow evaluation
// (pass 1, ghost refresh, pass 2), and one staggered hydro-mechanical step (solid step, fluid
// step with its constitutive update, energy and mass bookkeeping), in 2D (400 x 400) and 3D
// (50^3) at delta = 3.015 dx and 4.015 dx.
// Run: OMP_NUM_THREADS=T OMP_PROC_BIND=spread OMP_PLACES=threads ./perf/bench_fluid
#include <cmath>
#include <memory>

#include "bench_common.hpp"
#include "mupm/input/model.hpp"
#include "mupm/solvers/solid_solver.hpp"
#include "mupm/solvers/step_sequence.hpp"

namespace {

using namespace mupm;

template <int Dim>
FluidParams bench_fluid_params(const GridSpec<Dim>& g) {
  FluidParams f = fluid_params(g, 1e-10);
  f.retention = VanGenuchten::mualem(10e3, 2.0);  // unsaturated: every retention branch runs
  return f;
}

// Suction field -20 kPa +- 5 kPa in sinusoids not commensurate with dx.
template <int Dim>
void set_pressure(Points<Dim>& p, double dx) {
  auto x = p.x;
  auto pw = p.p;
  const double k = 2 * kPi / (37 * dx);
  Kokkos::parallel_for(
      "bench::set_pressure", range(0, p.size()), KOKKOS_LAMBDA(const std::size_t i) {
        double s = -20e3;
        for (int d = 0; d < Dim; ++d)
          s += 5e3 / Dim * std::sin(k * x(i, d) + d);
        pw(i) = s;
      });
  Kokkos::fence();
}

template <int Dim>
struct FlowBody {
  static constexpr int dim = Dim;
  Discretization<Dim> disc;
  FluidParams prm;
  FluidState<Dim> st;

  explicit FlowBody(const GridSpec<Dim>& g) : disc(discretize(bench::self(), g)) {
    prm = bench_fluid_params(g);
    st.allocate(disc.points.size(), disc.points.n_owned);
    Kokkos::deep_copy(disc.points.porosity, 0.3);
    set_pressure(disc.points, g.dx);
    fluid_constitutive(disc.points, prm, st);
    fluid_flow(disc, prm, st, disc.points.p);
    Kokkos::fence();
  }
};

// A free unsaturated micropolar body advanced by the staggered scheme (solid first).
template <int Dim>
struct CoupledBody {
  static constexpr int dim = Dim;
  Discretization<Dim> disc;
  std::unique_ptr<FluidSolver<Dim>> fluid;
  std::unique_ptr<SolidSolver<Dim>> solid;
  StepSequence<Dim> stagger;
  double dt = 0;
  long long step = 0;

  explicit CoupledBody(const GridSpec<Dim>& g) : disc(discretize(bench::self(), g)) {
    Kokkos::deep_copy(disc.points.porosity, 0.3);
    set_pressure(disc.points, g.dx);
    const SolidParams sp =
        solid_params(MicropolarElastic::from_bulk_shear(270.83e6, 220.33e6, 100e6, 7.5e-3), g, 0.5);
    fluid = std::make_unique<FluidSolver<Dim>>(disc, bench_fluid_params(g),
                                               std::vector<BoundaryCondition>{}, MPI_COMM_SELF);
    solid =
        std::make_unique<SolidSolver<Dim>>(disc, sp, std::vector<BoundaryCondition>{},
                                           typename SolidSolver<Dim>::Settings{}, MPI_COMM_SELF);
    fluid->initialize(0, false);
    solid->initialize(0, false);
    fluid->reset_strain_reference();
    // A step well inside both limits; the benchmark times work per step, not stability.
    dt = 1e-3 * solid->estimate_stable_dt(20);
    stagger = {solid.get(), fluid.get(), nullptr, false, 1, 1};
  }
};

template <class B>
void counters(benchmark::State& state, const B& b) {
  bench::set_counters(state, double(b.disc.bonds.size()), double(b.disc.points.n_owned));
}

template <int Dim>
void BM_FluidPass1(benchmark::State& state) {
  auto& b = bench::body<FlowBody<Dim>>(state);
  for (auto _ : state) {
    fluid_pass1(b.disc.points, b.disc.bonds, b.disc.shape, b.prm, b.st, b.disc.points.p);
    Kokkos::fence();
  }
  counters(state, b);
}

template <int Dim>
void BM_FluidPass2(benchmark::State& state) {
  auto& b = bench::body<FlowBody<Dim>>(state);
  for (auto _ : state) {
    fluid_pass2(b.disc.points, b.disc.bonds, b.st, b.disc.points.p);
    Kokkos::fence();
  }
  counters(state, b);
}

template <int Dim>
void BM_FluidFlow(benchmark::State& state) {
  auto& b = bench::body<FlowBody<Dim>>(state);
  for (auto _ : state) {
    fluid_flow(b.disc, b.prm, b.st, b.disc.points.p);
    Kokkos::fence();
  }
  counters(state, b);
}

// One whole hydro-mechanical step: bond_updates_per_s counts each bond once per step.
template <int Dim>
void BM_CoupledStep(benchmark::State& state) {
  auto& b = bench::body<CoupledBody<Dim>>(state);
  for (auto _ : state) {
    b.stagger.step(b.step, b.step * b.dt, b.dt);
    ++b.step;
    Kokkos::fence();
  }
  counters(state, b);
}

// UseRealTime: wall clock (see perf/bench_solid.cpp).
#define MUPM_FLUID_BENCH(Dim, n, factor)  \
  BENCHMARK_TEMPLATE(BM_FluidPass1, Dim)  \
      ->Args({n, factor})                 \
      ->Unit(benchmark::kMillisecond)     \
      ->UseRealTime();                    \
  BENCHMARK_TEMPLATE(BM_FluidPass2, Dim)  \
      ->Args({n, factor})                 \
      ->Unit(benchmark::kMillisecond)     \
      ->UseRealTime();                    \
  BENCHMARK_TEMPLATE(BM_FluidFlow, Dim)   \
      ->Args({n, factor})                 \
      ->Unit(benchmark::kMillisecond)     \
      ->UseRealTime();                    \
  BENCHMARK_TEMPLATE(BM_CoupledStep, Dim) \
      ->Args({n, factor})                 \
      ->Unit(benchmark::kMillisecond)     \
      ->UseRealTime()

MUPM_FLUID_BENCH(2, 400, 3015);
MUPM_FLUID_BENCH(2, 400, 4015);
MUPM_FLUID_BENCH(3, 50, 3015);
MUPM_FLUID_BENCH(3, 50, 4015);

}  // namespace

int main(int argc, char** argv) {
  // The cached bodies' Views must go before the scope guard finalizes Kokkos.
  return mupm::bench::run(argc, argv, mupm::bench::release_bodies);
}
