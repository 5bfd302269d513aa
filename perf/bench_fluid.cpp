// Google Benchmark of the pore-fluid kernels and of the whole coupled step on one rank:
// fluid pass 1 (K, grad p, Darcy flux, alpha), pass 2 (flow divergence), the flow evaluation
// (pass 1, ghost refresh, pass 2), and one staggered hydro-mechanical step (solid step, fluid
// step with its constitutive update, energy and mass bookkeeping), in 2D (400 x 400) and 3D
// (50^3) at delta = 3.015 dx and 4.015 dx; and the coupled step with a water-filled crack cut
// through the body (fracture flow).
// Run: OMP_NUM_THREADS=T OMP_PROC_BIND=spread OMP_PLACES=threads ./perf/bench_fluid
#include <cmath>
#include <memory>

#include "bench_common.hpp"
#include "mupm/input/model.hpp"
#include "mupm/kernels/fracture_flow.hpp"
#include "mupm/solvers/damage.hpp"
#include "mupm/solvers/fracture_flow.hpp"
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

// The coupled body cut through its middle by a pre-crack (a line across the 2D body, a plane
// across the 3D one) that carries water: fracture flow on, water injected at the crack's
// x = 0 edge. The fracture step (gather, assembly, sparse Cholesky solve, scatter), the exchange
// and the crack water's face forces come on top of the coupled step.
template <int Dim>
struct FractureBody {
  static constexpr int dim = Dim;
  Discretization<Dim> disc;
  std::unique_ptr<FluidSolver<Dim>> fluid;
  std::unique_ptr<SolidSolver<Dim>> solid;
  std::unique_ptr<Damage<Dim>> damage;
  StepSequence<Dim> stagger;
  double dt = 0;
  long long step = 0;

  static GridSpec<Dim> cut(GridSpec<Dim> g) {
    Crack c;
    const double L = double(g.counts[0]) * g.dx, H = double(g.counts[1]) * g.dx;
    c.a[0] = -1;
    c.a[1] = 0.5 * H;
    c.b[0] = Dim == 2 ? L + 1 : L + 2;  // 2D: the end; 3D: edge 1 along x
    c.b[1] = Dim == 2 ? 0.5 * H : 0;
    if (Dim == 3)
      c.c[2] = double(g.counts[2]) * g.dx + 2;  // edge 2 along z
    if (Dim == 3)
      c.a[2] = -1;
    g.cracks = {c};
    Box mouth;
    for (int d = 0; d < 3; ++d) {
      mouth.lo[d] = -1;
      mouth.hi[d] = 1e9;
    }
    mouth.hi[0] = g.dx;
    g.region_names = {"mouth"};
    g.regions = {mouth};
    return g;
  }

  explicit FractureBody(const GridSpec<Dim>& g) : disc(discretize(bench::self(), cut(g))) {
    Kokkos::deep_copy(disc.points.porosity, 0.3);
    set_pressure(disc.points, g.dx);
    const SolidParams sp =
        solid_params(MicropolarElastic::from_bulk_shear(270.83e6, 220.33e6, 100e6, 7.5e-3), g, 0.5);
    typename SolidSolver<Dim>::Settings set;
    set.fracture.flow = true;
    set.fracture.min_aperture = 1e-4;
    BoundaryCondition inject;
    inject.kind = BoundaryCondition::FractureSource;
    inject.name = "inject";
    inject.region_mask = 1u;
    inject.value = 5e-5;
    fluid = std::make_unique<FluidSolver<Dim>>(
        disc, bench_fluid_params(g), std::vector<BoundaryCondition>{inject}, MPI_COMM_SELF);
    fluid->enable_fracture_flow(set.fracture);
    solid = std::make_unique<SolidSolver<Dim>>(disc, sp, std::vector<BoundaryCondition>{}, set,
                                               MPI_COMM_SELF);
    damage = std::make_unique<Damage<Dim>>(disc, 0.3, MPI_COMM_SELF);
    damage->update();
    damage->update_aperture();
    fluid->initialize(0, false);
    solid->initialize(0, false);
    fluid->reset_strain_reference();
    dt = 1e-3 * solid->estimate_stable_dt(20);
    stagger = {solid.get(), fluid.get(), damage.get(), false, 1, 1};
    stagger.damage_seen = 0;
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

// The coupled step with a water-filled crack through the body (FractureBody); the counter
// fracture_points is the network's size, solve_iterations the last step's GMRES iterations.
template <int Dim>
void BM_CoupledStepWithFractureFlow(benchmark::State& state) {
  auto& b = bench::body<FractureBody<Dim>>(state);
  for (auto _ : state) {
    b.stagger.step(b.step, b.step * b.dt, b.dt);
    ++b.step;
    Kokkos::fence();
  }
  counters(state, b);
  state.counters["fracture_points"] = double(b.fluid->fracture_flow()->network_size());
  state.counters["solve_iterations"] = b.fluid->fracture_flow()->last_iterations();
}

// UseRealTime: wall clock (see perf/bench_solid.cpp).
#define MUPM_FLUID_BENCH(Dim, n, factor)                  \
  BENCHMARK_TEMPLATE(BM_FluidPass1, Dim)                  \
      ->Args({n, factor})                                 \
      ->Unit(benchmark::kMillisecond)                     \
      ->UseRealTime();                                    \
  BENCHMARK_TEMPLATE(BM_FluidPass2, Dim)                  \
      ->Args({n, factor})                                 \
      ->Unit(benchmark::kMillisecond)                     \
      ->UseRealTime();                                    \
  BENCHMARK_TEMPLATE(BM_FluidFlow, Dim)                   \
      ->Args({n, factor})                                 \
      ->Unit(benchmark::kMillisecond)                     \
      ->UseRealTime();                                    \
  BENCHMARK_TEMPLATE(BM_CoupledStep, Dim)                 \
      ->Args({n, factor})                                 \
      ->Unit(benchmark::kMillisecond)                     \
      ->UseRealTime();                                    \
  BENCHMARK_TEMPLATE(BM_CoupledStepWithFractureFlow, Dim) \
      ->Args({n, factor})                                 \
      ->Unit(benchmark::kMillisecond)                     \
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
