// Google Benchmark of the micropolar correspondence kernels on one rank: pass 1 (K, eps, kappa,
// constitutive update, stabilization Q1/Q2 and energy), pass 2 (force and moment densities) and
// the whole force evaluation (solid_forces: pass 1, ghost refresh, pass 2), in 2D (400 x 400)
// and 3D (50^3) at delta = 3.015 dx and 4.015 dx, pass 1 also with the Drucker-Prager law; and what
// bond breakage adds to a step: the force evaluation with the bond-energy accumulation, the
// breakage scan, the damage update; and the fold of slaved boundary layers (Boundary Layer Values
// = Mirrored on a clamp) on the same grids with a clamp's layer on both y faces. Run:
// OMP_NUM_THREADS=T OMP_PROC_BIND=spread OMP_PLACES=threads
// ./perf/bench_solid
#include <cmath>

#include "bench_common.hpp"
#include "mupm/input/model.hpp"
#include "mupm/kernels/fracture.hpp"
#include "mupm/mesh/discretization.hpp"
#include "mupm/solvers/solid_solver.hpp"

namespace {

using namespace mupm;

using bench::self;

// The material of tests/test_solid.cpp: the numbers only need to be realistic
// so that no kernel takes a special path (degenerate K, zero stabilization).
const MicropolarElastic kLaw =
    MicropolarElastic::from_bulk_shear(270.83e6, 220.33e6, 100e6, 7.5e-3);

template <int Dim>
struct Body {
  static constexpr int dim = Dim;
  Discretization<Dim> disc;
  SolidParams prm;
  SolidState<Dim> st;

  explicit Body(const GridSpec<Dim>& g)
      : disc(discretize(self(), g)), prm(solid_params(kLaw, g, 0.5)) {
    st.allocate(disc.points.size(), disc.points.n_owned);
    set_field();
    // Pass 2 reads pass 1's outputs: run the whole evaluation once so that pass 2 alone sees
    // real eps, kappa, P1, P2, winv (and the pages are touched before timing).
    solid_forces(disc, prm, st);
    Kokkos::fence();
  }

  // Small sinusoids in u and theta (owned and ghosts): a non-affine field, so eps, kappa and
  // the stabilization residuals are non-zero and no arithmetic is skipped or trivially zero.
  void set_field() {
    auto x = disc.points.x, u = disc.points.u, th = disc.points.theta;
    const double k = 2 * kPi / (37 * disc.grid.dx);  // wavelength not commensurate with dx
    Kokkos::parallel_for(
        "bench::set_field", range(0, disc.points.size()), KOKKOS_LAMBDA(const std::size_t i) {
          for (int d = 0; d < Dim; ++d)
            u(i, d) = 1e-6 * std::sin(k * x(i, d) + d) * std::cos(k * x(i, (d + 1) % Dim));
          for (int r = 0; r < kRotDim<Dim>; ++r)
            th(i, r) = 1e-4 * std::cos(k * x(i, r % Dim) - r);
        });
    Kokkos::fence();
  }
};

template <int Dim>
Body<Dim>& body(const benchmark::State& state) {
  return bench::body<Body<Dim>>(state);
}
template <int Dim>
void set_counters(benchmark::State& state, const Body<Dim>& b) {
  bench::set_counters(state, double(b.disc.bonds.size()), double(b.disc.points.n_owned));
}

template <int Dim>
void BM_SolidPass1(benchmark::State& state) {
  auto& b = body<Dim>(state);
  for (auto _ : state) {
    solid_pass1(b.disc.points, b.disc.bonds, b.disc.shape, b.prm, b.prm.law, b.st);
    Kokkos::fence();
  }
  set_counters(state, b);
}

// Pass 1 with Micropolar Drucker-Prager (eqs 82-95), every point plastic (c0 = 10 Pa against
// stresses of kPa, the Example 3 angles and softening): the return-mapping's worst case, to set
// against BM_SolidPass1 (the elastic law).
template <int Dim>
void BM_SolidPass1Plastic(benchmark::State& state) {
  auto& b = body<Dim>(state);
  DruckerPragerParams dp;
  dp.friction = dp.dilation = 35 * kPi / 180;
  dp.cohesion = 10;
  dp.residual = 2.5;
  dp.softening = -1e7;
  const MicropolarDruckerPrager<Dim> law(b.prm.law, dp, b.disc.points);
  for (auto _ : state) {
    solid_pass1(b.disc.points, b.disc.bonds, b.disc.shape, b.prm, law, b.st);
    Kokkos::fence();
  }
  double plastic = 0;
  auto eq = b.disc.points.equivalent_plastic_strain;
  Kokkos::parallel_reduce(
      "bench::plastic_points", range(0, b.disc.points.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, double& acc) { acc += eq(i) > 0 ? 1.0 : 0.0; }, plastic);
  state.counters["plastic_fraction"] = plastic / double(b.disc.points.n_owned);
  set_counters(state, b);
}

template <int Dim>
void BM_SolidPass2(benchmark::State& state) {
  auto& b = body<Dim>(state);
  for (auto _ : state) {
    solid_pass2(b.disc.points, b.disc.bonds, b.prm, b.st);
    Kokkos::fence();
  }
  set_counters(state, b);
}

// What one explicit step spends on the solid: pass 1, the refresh of the pass-2 ghost fields
// (a Tpetra import, no ghosts on one rank but its fixed cost is paid) and pass 2.
template <int Dim>
void BM_SolidForces(benchmark::State& state) {
  auto& b = body<Dim>(state);
  for (auto _ : state) {
    solid_forces(b.disc, b.prm, b.st);
    Kokkos::fence();
  }
  set_counters(state, b);
}

// Bond breakage's share of a step (include/mupm/kernels/fracture.hpp): the force evaluation
// with the bond energy accumulated in pass 2 (BondWork::Accumulate: the pair states recorded
// and the trapezoid over a step increment of 1e-3 of the field), then the scan for W >= W_cr
// (here nothing breaks: the scan's cost, a point loop over the largest W of each family).
// Steps that break nothing update no damage (StepSequence). Compare with BM_SolidForces of the
// same grid.
template <int Dim>
void BM_SolidForcesWithBreakage(benchmark::State& state) {
  auto& b = body<Dim>(state);
  auto& p = b.disc.points;
  if (b.disc.bonds.pair_width == 0) {
    b.disc.bonds.hold_pair_forces(Dim + kRotDim<Dim>);
    b.st.increment = Vectors("increment", p.size(), Dim + kRotDim<Dim>);
    b.st.max_energy = Scalars("max_energy", p.n_owned);
    auto inc = b.st.increment, u = p.u, th = p.theta;
    Kokkos::parallel_for(
        "bench::increment", range(0, p.size()), KOKKOS_LAMBDA(const std::size_t i) {
          for (int d = 0; d < Dim; ++d)
            inc(i, d) = 1e-3 * u(i, d);
          for (int r = 0; r < kRotDim<Dim>; ++r)
            inc(i, Dim + r) = 1e-3 * th(i, r);
        });
  }
  Scalars released("released", p.n_owned);
  const double w_cr = 1e30;
  b.st.work = BondWork::Accumulate;
  for (auto _ : state) {
    solid_forces(b.disc, b.prm, b.st);
    break_bonds(p, b.disc.bonds, w_cr, b.st.max_energy, released);
    Kokkos::fence();
  }
  b.st.work = BondWork::Off;
  set_counters(state, b);
}

// The same body with one-horizon boundary layers on both y faces, every point of them slaved (a
// clamp: all components held, energy-free), for the fold of their forces onto their mirrors
// (kernels/boundary_conditions.hpp; SolidBoundary::fold): zero the buffer, pack, the Tpetra
// export that adds ghost rows into their owners (on one rank its fixed cost and the copies of all
// rows in and out), add. What a step with slaved layers adds to BM_SolidForces.
template <int Dim>
struct LayeredBody : Body<Dim> {
  static GridSpec<Dim> layered(GridSpec<Dim> g) {
    g.layers[1] = {g.horizon_cells(), g.horizon_cells()};
    g.mirrored_layers = true;
    return g;
  }
  explicit LayeredBody(const GridSpec<Dim>& g) : Body<Dim>(layered(g)) {
    auto& p = this->disc.points;
    auto fixed = p.fixed;
    auto mirror = this->disc.mirror;
    constexpr std::uint32_t all = (1u << (Dim + kRotDim<Dim>)) - 1;
    Kokkos::parallel_for(
        "bench::mark_slaved", range(0, p.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
          if (mirror(i, Dim) >= 0)
            fixed(i) |= all | kFixedNoEnergy;
        });
    Kokkos::fence();
  }
};

template <int Dim>
void BM_SolidFold(benchmark::State& state) {
  auto& b = bench::body<LayeredBody<Dim>>(state);
  auto& p = b.disc.points;
  constexpr int N = Dim + kRotDim<Dim>;
  const FaceSlots slots{-1, -1, 0, 1, -1, -1};  // the two y faces
  Vectors fold("fold", p.size(), 2 * N);
  solid_forces(b.disc, b.prm, b.st);
  double slaved = 0;
  auto fixed = p.fixed;
  Kokkos::parallel_reduce(
      "bench::slaved_points", range(0, p.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, double& acc) {
        acc += (fixed(i) & kFixedNoEnergy) ? 1.0 : 0.0;
      },
      slaved);
  for (auto _ : state) {
    fold_layer_forces(b.disc, slots, b.st.force, b.st.moment, fold);
  }
  state.counters["slaved_points"] = slaved;
  set_counters(state, b);
}

// Grouped by configuration so that the output reads pass1, pass2, forces for each grid.
// UseRealTime: Google Benchmark's default clock (and so every rate counter) is the CPU time of
// the calling thread alone, not the wall time of the parallel region: on a loaded machine the
// main thread waits off-CPU while the other OpenMP threads finish, and the rates come out up
// to T times too high.
#define MUPM_SOLID_BENCH(Dim, n, factor)              \
  BENCHMARK_TEMPLATE(BM_SolidPass1, Dim)              \
      ->Args({n, factor})                             \
      ->Unit(benchmark::kMillisecond)                 \
      ->UseRealTime();                                \
  BENCHMARK_TEMPLATE(BM_SolidPass1Plastic, Dim)       \
      ->Args({n, factor})                             \
      ->Unit(benchmark::kMillisecond)                 \
      ->UseRealTime();                                \
  BENCHMARK_TEMPLATE(BM_SolidPass2, Dim)              \
      ->Args({n, factor})                             \
      ->Unit(benchmark::kMillisecond)                 \
      ->UseRealTime();                                \
  BENCHMARK_TEMPLATE(BM_SolidForces, Dim)             \
      ->Args({n, factor})                             \
      ->Unit(benchmark::kMillisecond)                 \
      ->UseRealTime();                                \
  BENCHMARK_TEMPLATE(BM_SolidForcesWithBreakage, Dim) \
      ->Args({n, factor})                             \
      ->Unit(benchmark::kMillisecond)                 \
      ->UseRealTime();                                \
  BENCHMARK_TEMPLATE(BM_SolidFold, Dim)               \
      ->Args({n, factor})                             \
      ->Unit(benchmark::kMillisecond)                 \
      ->UseRealTime()

MUPM_SOLID_BENCH(2, 400, 3015);
MUPM_SOLID_BENCH(2, 400, 4015);
MUPM_SOLID_BENCH(3, 50, 3015);
MUPM_SOLID_BENCH(3, 50, 4015);

}  // namespace

int main(int argc, char** argv) {
  // The cached bodies' Views must go before the scope guard finalizes Kokkos.
  return mupm::bench::run(argc, argv, mupm::bench::release_bodies);
}
