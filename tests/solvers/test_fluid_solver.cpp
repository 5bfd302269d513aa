// The fluid step and the staggered coupling against conservation laws and closed forms:
// fluid mass with impervious boundaries, sources and drained boundaries; decay of a
// checkerboard pressure mode; an unsaturated column reaching uniform suction; Terzaghi's
// consolidation (closed form below); the two staggering orders converging to each other.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <limits>

#include "mupm/input/model.hpp"
#include "mupm/solvers/simulation.hpp"
#include "mupm/solvers/solid_solver.hpp"
#include "mupm/solvers/step_sequence.hpp"
#include "test_utils.hpp"

namespace mupm {
namespace {

double global_sum(double v) {
  MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  return v;
}
double global_max(double v) {
  MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return v;
}

void set_pressure(Points<2>& p, std::function<double(const double*)> f) {
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), p.x);
  auto pw = Kokkos::create_mirror_view(p.p);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double xi[2] = {x(i, 0), x(i, 1)};
    pw(i) = f(xi);
  }
  Kokkos::deep_copy(p.p, pw);
}

using test::box2;

// Water mass with impervious boundaries is constant to round-off; a source adds exactly the
// injected mass; a drained boundary's reported inflow is exactly the mass change.
TEST(FluidSolver, MassConservation) {
  const double dx = 0.01;
  auto g = test::box<2>({20, 16}, 3.015, dx);
  g.region_names = {"well", "drain"};
  g.regions = {box2(0.10, 0.11, 0.08, 0.09), box2(-1, dx, -1, 1)};  // one point; first column
  BoundaryCondition well, drain;
  well.name = "well";
  well.kind = BoundaryCondition::FluidSource;
  well.region_mask = 1u << 0;
  // m^3/s per metre: 1e-4 of the pore volume of the well's point per step, little enough to
  // keep the well unsaturated: a saturated point's storage falls to phi/K_w and with it the
  // stable step.
  well.value = 0;  // set below from the step
  drain.name = "drain";
  drain.kind = BoundaryCondition::PorePressure;
  drain.region_mask = 1u << 1;
  drain.value = -2e3;
  double dt = 0;
  for (int config = 0; config < 3; ++config) {
    auto disc = discretize(test::world(), g);
    Kokkos::deep_copy(disc.points.porosity, 0.35);
    set_pressure(disc.points, [](const double* x) {
      return -10e3 + 4e3 * std::sin(37 * x[0] + 11 * x[1]) + 2e3 * std::cos(91 * x[0] * x[1]);
    });
    auto prm = fluid_params(g, 1e-10, 0.5);
    prm.retention = VanGenuchten::mualem(10e3, 2.0);
    std::vector<BoundaryCondition> bcs;
    well.value = 1e-4 * 0.35 * dx * dx / dt;
    if (config == 1)
      bcs = {well};
    if (config == 2)
      bcs = {drain};
    FluidSolver<2> fluid(disc, prm, bcs, MPI_COMM_WORLD);
    fluid.initialize(0, false);
    if (config == 0)  // the same initial state in every configuration
      dt = 0.5 * fluid.estimate_stable_dt();
    ASSERT_GT(dt, 0);
    const double m0 = fluid.fluid_mass();
    const int steps = 200;
    for (int k = 0; k < steps; ++k)
      fluid.advance(k * dt, dt, 1);
    const double dm = fluid.fluid_mass() - m0;
    SCOPED_TRACE("configuration " + std::to_string(config));
    if (config == 0) {
      EXPECT_NEAR(dm, 0.0, 1e-13 * m0);
    } else if (config == 1) {
      const double injected = 1000 * well.value * g.thickness * steps * dt;
      EXPECT_NEAR(fluid.inflows()[0], injected, 1e-12 * injected);
      EXPECT_NEAR(dm, injected, 1e-13 * m0);
    } else {
      // The drain at -2 kPa is wetter than the body (-10 kPa mean): water flows in.
      EXPECT_GT(fluid.inflows()[0], 0.0);
      EXPECT_NEAR(dm, fluid.inflows()[0], 1e-13 * m0);
    }
  }
}

// The fluid energy balance (eqs 147-149 in power form): stored energy change + coupling work +
// flow dissipation - external work, each booked at the pressure the step applies it at, is the
// explicit scheme's energy identity: round-off on a stable step (0.5 x the estimate here), with
// a positive dissipation. On an unstable one (1.1 x) the dissipation turns negative and the
// stored energy outgrows everything supplied: the driver's divergence check
// (src/solvers/driver/step_checks.hpp) stops the run while the state is still finite (at step 28
// here, where the unstable mode's points wet to saturation and their storage falls 1e4-fold).
TEST(FluidSolver, EnergyBalanceFlagsInstability) {
  const double dx = 0.01;
  auto g = test::box<2>({16, 12}, 3.015, dx);
  g.region_names = {"drain"};
  g.regions = {box2(-1, dx, -1, 1)};
  BoundaryCondition drain;
  drain.name = "drain";
  drain.kind = BoundaryCondition::PorePressure;
  drain.region_mask = 1u;
  drain.value = -9e3;  // close to the body's suction: k_r and C, and the stable step, stay put
  double relative = 0;
  int diverged[2] = {-1, -1};
  for (int k = 0; k < 2; ++k) {
    auto disc = discretize(test::world(), g);
    Kokkos::deep_copy(disc.points.porosity, 0.35);
    set_pressure(disc.points,
                 [](const double* x) { return -10e3 + 1e3 * std::sin(41 * x[0] + 13 * x[1]); });
    auto prm = fluid_params(g, 1e-10, 0.5);
    prm.retention = VanGenuchten::mualem(10e3, 2.0);
    FluidSolver<2> fluid(disc, prm, {drain}, MPI_COMM_WORLD);
    fluid.initialize(0, false);
    const double dt = (k == 0 ? 0.5 : 1.1) * fluid.estimate_stable_dt();
    for (int s = 0; s < 300 && diverged[k] < 0; ++s) {
      fluid.advance(s * dt, dt, 1);
      const auto e = fluid.energy();
      if (k == 0)
        relative = std::max(relative, std::abs(e.balance()) / e.scale());
      // The driver's criteria (StepChecks), from step 2 on: the balance's stored energy 1000
      // times its supply, or (the coupled check, one balance here) 1000 times the external
      // supply and 10 times its terms' magnitudes.
      const auto b = fluid.energy_balances().at(0);
      if (s >= 1 && (b.stored > 1e3 * b.supplied ||
                     (b.stored > 1e3 * b.external && b.stored > 10 * b.gross))) {
        diverged[k] = s;
        EXPECT_TRUE(std::isfinite(e.stored)) << "step " << s;  // before the overflow
      }
    }
    const auto e = fluid.energy();
    if (test::world()->getRank() == 0)
      std::printf(
          "[ fluid energy ] dt = %s stable step: E_s - E_s0 = %.4g J, D = %.4g J, W_ext = "
          "%.4g J, |balance| / largest = %.3g (diverged at step %d)\n",
          k == 0 ? "0.5" : "1.1", e.stored - e.stored0, e.dissipation, e.external_work,
          std::abs(e.balance()) / e.scale(), diverged[k]);
    if (k == 0) {
      EXPECT_GT(e.dissipation, 0.0);
    }
  }
  EXPECT_LT(relative, 1e-10);
  EXPECT_EQ(diverged[0], -1);
  EXPECT_GT(diverged[1], 0);
}

// A point source switched on at t = 0 in a body at rest, on a small step (1/25 of the stable
// one), in unsaturated and in saturated water: its pressure rises fastest in the first steps.
// Every term is booked at the pressure at which the stored energy takes the step's change in
// (fluid_solver.hpp header), so the balance is the scheme's energy identity: round-off from
// the first step on (the unsaturated one's from the stored energy's differences over small
// steps). Measured: 8.6e-12 unsaturated and 6.4e-16 saturated of the largest term. With the
// flow booked at the start pressure, as before, 1.3e-2 saturated at step 21 (false alarms).
TEST(FluidSolver, PointSourceBalanceWithoutFalseAlarm) {
  for (const bool saturated : {false, true}) {
    const double dx = 0.01;
    auto g = test::box<2>({21, 21}, 3.015, dx);
    g.region_names = {"well"};
    g.regions = {box2(0.10, 0.11, 0.10, 0.11)};
    auto disc = discretize(test::world(), g);
    Kokkos::deep_copy(disc.points.porosity, 0.3);
    set_pressure(disc.points, [&](const double*) { return saturated ? 0.0 : -20e3; });
    auto prm = fluid_params(g, 1e-10, 0.5);
    if (!saturated)
      prm.retention = VanGenuchten::mualem(10e3, 2.0);
    BoundaryCondition well;
    well.name = "well";
    well.kind = BoundaryCondition::FluidSource;
    well.region_mask = 1u;
    FluidSolver<2> probe(disc, prm, {}, MPI_COMM_WORLD);
    probe.initialize(0, false);
    const double dt = probe.estimate_stable_dt() / 25;
    // Unsaturated: about 2 % of the well point's pore volume per step (its suction falls by
    // half in ~20 steps); saturated: 1 kPa per step at the well without flow.
    well.value = (saturated ? 1e3 / prm.bulk_modulus : 0.02) * 0.3 * dx * dx / dt;
    FluidSolver<2> fluid(disc, prm, {well}, MPI_COMM_WORLD);
    fluid.initialize(0, false);
    double worst = 0, p_well_start = 0, p_well_end = 0;
    auto pressure_at_well = [&] {
      auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.x);
      auto pw = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.p);
      double v = 0;
      for (std::size_t i = 0; i < disc.points.n_owned; ++i)
        if (std::abs(x(i, 0) - 0.105) < 1e-6 && std::abs(x(i, 1) - 0.105) < 1e-6)
          v = pw(i);
      MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
      return v;
    };
    p_well_start = pressure_at_well();
    for (int s = 0; s < 100; ++s) {
      fluid.advance(s * dt, dt, 1);
      const auto e = fluid.energy();
      worst = std::max(worst, std::abs(e.balance()) / e.scale());
    }
    p_well_end = pressure_at_well();
    if (test::world()->getRank() == 0)
      std::printf(
          "[ source ] %s: well pressure %.4g -> %.4g Pa; largest balance error / largest "
          "term: %.2e\n",
          saturated ? "saturated" : "unsaturated", p_well_start, p_well_end, worst);
    EXPECT_GT(p_well_end - p_well_start, 5e3);  // the source does change the state
    EXPECT_LT(worst, 1e-10);
  }
}

// A checkerboard pressure mode on a saturated body: with the flow stabilization its storage
// energy sum V C p^2 / 2 falls every step and nearly vanishes; without it (G = 0) the interior
// mode has no gradient and decays only from the faces, far more slowly.
TEST(FluidSolver, CheckerboardDecays) {
  const double dx = 0.01;
  const auto g = test::box<2>({16, 16}, 3.015, dx);
  double remaining[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    const double G = k == 0 ? 0.0 : 0.5;
    auto disc = discretize(test::world(), g);
    Kokkos::deep_copy(disc.points.porosity, 0.3);
    set_pressure(disc.points, [&](const double* x) {
      const long long s = std::llround(std::floor(x[0] / dx)) + std::llround(std::floor(x[1] / dx));
      return s % 2 == 0 ? 1e4 : -1e4;
    });
    FluidSolver<2> fluid(disc, fluid_params(g, 1e-12, G), {}, MPI_COMM_WORLD);
    fluid.initialize(0, false);
    // The same step for both: half the stable step of the stabilized operator.
    FluidSolver<2> stabilized(disc, fluid_params(g, 1e-12, 0.5), {}, MPI_COMM_WORLD);
    stabilized.initialize(0, false);
    const double dt = 0.5 * stabilized.estimate_stable_dt();
    ASSERT_GT(dt, 0.0);
    auto energy = [&] {
      auto p = disc.points.p, vol = disc.points.volume;
      auto C = fluid.state().storage;
      double e = 0;
      Kokkos::parallel_reduce(
          range(0, disc.points.n_owned),
          KOKKOS_LAMBDA(const std::size_t i, double& s) { s += 0.5 * vol(i) * C(i) * p(i) * p(i); },
          e);
      return global_sum(e);
    };
    const double e0 = energy();
    double last = e0;
    for (int s = 0; s < 40; ++s) {
      fluid.advance(s * dt, dt, 1);
      const double e = energy();
      if (G > 0) {
        EXPECT_LT(e, last) << "step " << s;
      }
      last = e;
    }
    remaining[k] = last / e0;
  }
  EXPECT_LT(remaining[1], 1e-3);
  EXPECT_GT(remaining[0], 0.2);
}

// A column with a wet lower half (-5 kPa) and a drier upper half (-12 kPa), impervious, no
// gravity: water moves up until the suction is uniform, at the p_eq that keeps the water
// volume sum phi S_r(p) (1 + p/K_w) V (found by bisection on the closed-form retention curve).
TEST(FluidSolver, UnsaturatedColumnReachesUniformSuction) {
  const double dx = 0.01;
  const int rows = 20;
  const auto g = test::box<2>({4, rows}, 3.015, dx);
  auto disc = discretize(test::world(), g);
  const double phi = 0.4;
  Kokkos::deep_copy(disc.points.porosity, phi);
  const double p_wet = -5e3, p_dry = -12e3;
  set_pressure(disc.points,
               [&](const double* x) { return x[1] < 0.5 * rows * dx ? p_wet : p_dry; });
  auto prm = fluid_params(g, 1e-9, 0.5);
  prm.retention = VanGenuchten::mualem(10e3, 2.0);
  FluidSolver<2> fluid(disc, prm, {}, MPI_COMM_WORLD);
  fluid.initialize(0, false);
  const double dt = 0.4 * fluid.estimate_stable_dt();
  const auto vg = prm.retention;
  auto content = [&](double p) { return phi * vg.saturation(p) * (1 + p / prm.bulk_modulus); };
  const double target = 0.5 * (content(p_wet) + content(p_dry));
  double lo = p_dry, hi = p_wet;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (content(mid) < target ? lo : hi) = mid;
  }
  const double p_eq = 0.5 * (lo + hi);
  for (int s = 0; s < 20000; ++s)
    fluid.advance(s * dt, dt, 1);
  auto p = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.p);
  double pmin = 1e300, pmax = -1e300;
  for (std::size_t i = 0; i < disc.points.n_owned; ++i) {
    pmin = std::min(pmin, p(i));
    pmax = std::max(pmax, p(i));
  }
  pmin = -global_max(-pmin);
  pmax = global_max(pmax);
  const double contrast = p_wet - p_dry;
  EXPECT_LT(pmax - pmin, 1e-3 * contrast) << "not yet uniform";
  // Forward Euler with the storage of the step's start conserves sum V m exactly but moves
  // along the retention curve by chords: p differs from p_eq by a first-order error in dt.
  EXPECT_NEAR(0.5 * (pmin + pmax), p_eq, 1e-3 * contrast) << "p_eq = " << p_eq;
  if (test::world()->getRank() == 0)
    std::printf("[ column ] p_eq = %.2f Pa, reached %.2f .. %.2f Pa\n", p_eq, pmin, pmax);
}

// Terzaghi's one-dimensional consolidation on a 2D column: load q ramped on the top row,
// drained (p = 0) top and bottom layers, u fixed at the bottom, lateral walls u_x = 0. By
// symmetry the doubly drained column of height 2H is the classical layer of thickness H with
// an impervious base at mid-height. With compressible water the closed form keeps its shape
// with storage S = phi/K_w + 1/M (M = lambda + 2 mu, the constrained modulus), c_v = (k/mu_w)/S
// and Skempton's p0 = q (1/M)/S. The load is a ramp of duration t_r, so the closed form is the
// step solution superposed over the ramp:
//   p(z,t) = p0 sum_m (2/M_m) sin(M_m z/H) H^2/(M_m^2 c_v t_r) [e^{-M_m^2 c_v (t - t_r)/H^2} -
//            e^{-M_m^2 c_v t/H^2}],   M_m = (2m+1) pi/2,   t >= t_r.
struct Terzaghi {
  int N = 20;  // rows in H
  double dx = 0.01, H = N * dx, q = 1e4, phi = 0.3, rho_s = 2000, rho_w = 1000;
  MicropolarElastic law = MicropolarElastic::from_bulk_shear(10e6, 6e6, 3e6, 0.01);
  double M = law.lambda + 2 * law.mu;
  double Kw = 10 * M * phi;  // K_w / phi = 10 M
  double S = phi / Kw + 1 / M;
  double p0 = q / M / S;
  double c_u = std::sqrt((M + Kw / phi) / ((1 - phi) * rho_s + phi * rho_w));
  double transit = 2 * H / c_u;
  double t_c = 400 * transit;  // H^2 / c_v: consolidation slow against the waves
  double c_v = H * H / t_c;
  double mobility = c_v * S;
  double t_r = 10 * transit;
  double Gp = 1.0;    // Solver->Pressure Stabilization (Semi-Implicit)
  PoreCoupling pore;  // plane stress: plane_stress_column()

  double closed_form(double z, double t) const {
    double s = 0;
    for (int m = 0; m < 200; ++m) {
      const double Mm = (2 * m + 1) * kPi / 2;
      const double a = Mm * Mm * c_v / (H * H);
      s +=
          2 / Mm * std::sin(Mm * z / H) / (a * t_r) * (std::exp(-a * (t - t_r)) - std::exp(-a * t));
    }
    return p0 * s;
  }
  double closed_form_mean(double t) const {
    double s = 0;
    for (int m = 0; m < 200; ++m) {
      const double Mm = (2 * m + 1) * kPi / 2;
      const double a = Mm * Mm * c_v / (H * H);
      s += 2 / (Mm * Mm) / (a * t_r) * (std::exp(-a * (t - t_r)) - std::exp(-a * t));
    }
    return p0 * s;
  }
};

struct ColumnRun {
  Discretization<2> disc;
  std::unique_ptr<SolidSolver<2>> solid;
  std::unique_ptr<FluidSolver<2>> fluid;
  StepSequence<2> stagger;
  double dt = 0;
  long long step = 0;

  // semi_implicit: Solver->Pressure Integration = Semi-Implicit (dt_factor of the drained
  // skeleton's stable step, the only one then).
  ColumnRun(const Terzaghi& tz, int rows_h, bool fluid_first, double dt_factor, bool damped = true,
            bool mirrored = false, bool semi_implicit = false, bool sealed = false)
      : disc(discretize(test::world(), column_grid(tz, rows_h, mirrored))) {
    const auto& g = disc.grid;
    Kokkos::deep_copy(disc.points.porosity, tz.phi);
    Kokkos::deep_copy(disc.points.saturation, 1.0);
    std::vector<BoundaryCondition> bcs;
    auto add = [&](const char* name, BoundaryCondition::Kind kind, int region, int comp,
                   double value) {
      BoundaryCondition bc;
      bc.name = name;
      bc.kind = kind;
      bc.region_mask = 1u << region;
      bc.component = comp;
      bc.value = value;
      bcs.push_back(bc);
    };
    add("wall_left", BoundaryCondition::Displacement, 0, 0, 0.0);
    add("wall_right", BoundaryCondition::Displacement, 1, 0, 0.0);
    add("base_x", BoundaryCondition::Displacement, 2, 0, 0.0);
    add("base_y", BoundaryCondition::Displacement, 2, 1, 0.0);
    add("load", BoundaryCondition::Traction, 4, 1, -tz.q);
    bcs.back().time.kind = TimeFunction::Ramp;
    bcs.back().time.ramp_time = tz.t_r;
    if (!sealed) {
      add("drain_base", BoundaryCondition::PorePressure, 2, 0, 0.0);
      add("drain_top", BoundaryCondition::PorePressure, 3, 0, 0.0);
    }
    for (auto& bc : bcs)
      bc.mirrored = mirrored && bc.kind == BoundaryCondition::PorePressure;
    SolidParams sp = solid_params(tz.law, g, 0.5);
    sp.pore = tz.pore;
    SolidSolver<2>::Settings set;
    set.rho_s = tz.rho_s;
    set.rho_w = tz.rho_w;
    // About half the critical damping of the column's first undrained mode (fixed-free).
    set.damping = damped ? kPi / (2 * tz.transit) : 0.0;
    auto fp = fluid_params(g, tz.mobility, 0.5);
    fp.bulk_modulus = tz.Kw;
    fp.water_density = tz.rho_w;
    fp.semi_implicit = semi_implicit;
    fp.projection_stabilization = tz.Gp;
    fp.pore = tz.pore;
    set.semi_implicit = semi_implicit;
    fluid = std::make_unique<FluidSolver<2>>(disc, fp, bcs, MPI_COMM_WORLD);
    if (semi_implicit)
      fluid->enable_semi_implicit(LinearSolveSettings());
    solid = std::make_unique<SolidSolver<2>>(disc, sp, bcs, set, MPI_COMM_WORLD);
    fluid->initialize(0, false);
    solid->initialize(0, false);
    fluid->reset_strain_reference();
    dt = dt_factor * solid->estimate_stable_dt();
    const double dt_f = semi_implicit ? dt : 0.5 * fluid->estimate_stable_dt();
    stagger = {solid.get(), fluid.get(), nullptr,
               fluid_first, 1,           std::max(1, int(std::ceil(dt / dt_f)))};
    if (semi_implicit)
      stagger.skeleton = solid.get();
  }
  static GridSpec<2> column_grid(const Terzaghi& tz, int rows_h, bool mirrored) {
    auto g = test::box<2>({6, 2 * rows_h}, 3.015, tz.dx);
    g.mirrored_layers = mirrored;
    const int L = 6;  // 2 horizons
    g.layers = {{{L, L}, {L, L}}};
    const double W = 6 * tz.dx, top = 2 * rows_h * tz.dx, d = tz.dx;
    g.region_names = {"wall_left", "wall_right", "base", "top_layer", "top_row"};
    g.regions = {box2(-1, -0.25 * d, -1, 2), box2(W + 0.25 * d, 1, -1, 2),
                 box2(-1, 2, -1, -0.25 * d), box2(-1, 2, top + 0.25 * d, 2),
                 box2(-1, 2, top - d, top)};
    return g;
  }
  void run_to(double t) {
    while ((step + 1) * dt <= t + 1e-12 * dt) {
      stagger.step(step, step * dt, dt);
      ++step;
    }
  }
  double time() const { return step * dt; }
};

// max |p_a - p_b| over the points of two runs of the same column (all ranks).
double max_pressure_difference(const ColumnRun& a, const ColumnRun& b) {
  auto pa = Kokkos::create_mirror_view_and_copy(HostSpace(), a.disc.points.p);
  auto pb = Kokkos::create_mirror_view_and_copy(HostSpace(), b.disc.points.p);
  double d = 0;
  for (std::size_t i = 0; i < a.disc.points.n_owned; ++i)
    d = std::max(d, std::abs(pa(i) - pb(i)));
  return global_max(d);
}

// The boundary-layer drained condition (p = 0 on the layer points, the paper's method) puts
// a kink in p at the face that the nonlocal gradient smears over the horizon: the face drains
// as if about 2.3 dx farther away, an error of first order in delta/H (measured: the error
// of U at T_v = 0.5 is 0.106, 0.054, 0.029 at H = 10, 20, 40 dx). The test therefore runs
// H = 10 dx and 20 dx, checks that the error halves, and holds the Richardson extrapolation
// 2 f(20) - f(10) of the degree of consolidation U and of p at the impervious plane to 3 % of
// p0, the target tolerance of this case away from the first few dx at the drained face.
namespace {
struct TerzaghiResult {
  double U[3], U_cf[3], base[3], base_cf[3], worst[3];
};
const double kTvs[3] = {0.1, 0.2, 0.5};
// The column with H = N dx to T_v = 0.1, 0.2, 0.5: the worst |p - p_cf| / p0 beyond `skip`
// spacings from the drained face, the degree of consolidation U and p at the impervious plane.
// The consolidation time t_c = H^2 / c_v is `transits` times the undrained wave's transit time
// 2H / c_u: the closed form is quasi-static, the column is not (its skeleton lags the load by its
// inertia and damping), an error that goes as 1 / transits whatever dx (H = 20 dx, mirrored
// layers, T_v = 0.1: 3.7 % at 400 transits, 0.83 % at 1600; H = 40 dx: 3.0, 1.4, 0.67 % at 400,
// 800, 1600 transits).
// The column with H = N dx, its times from the wave speed tz.c_u: t_c = H^2 / c_v is `transits`
// of the transit times 2H / c_u, the load ramp t_r 10 of them.
Terzaghi column(int N, double transits, Terzaghi tz = Terzaghi()) {
  tz.N = N;
  tz.H = N * tz.dx;
  tz.transit = 2 * tz.H / tz.c_u;
  tz.t_c = transits * tz.transit;
  tz.c_v = tz.H * tz.H / tz.t_c;
  tz.mobility = tz.c_v * tz.S;
  tz.t_r = 10 * tz.transit;
  return tz;
}
TerzaghiResult solve_terzaghi(const Terzaghi& tz, bool mirrored, double skip,
                              bool semi_implicit = false) {
  const double* Tvs = kTvs;
  using Result = TerzaghiResult;
  const int N = tz.N;
  ColumnRun run(tz, N, false, 0.5, true, mirrored, semi_implicit);
  const auto& pts = run.disc.points;
  Result r{};
  for (int k = 0; k < 3; ++k) {
    run.run_to(Tvs[k] * tz.t_c);
    const double t = run.time();
    auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.x);
    auto p = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.p);
    auto flags = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.flags);
    double worst = 0, sum = 0, count = 0, base = 0, base_n = 0;
    for (std::size_t i = 0; i < pts.n_owned; ++i) {
      if (flags(i) & kFlagBoundaryLayer)
        continue;
      // Distance from the nearer drained face (y = 0 or 2H): the layer's coordinate z.
      const double z = std::min(x(i, 1), 2 * tz.H - x(i, 1));
      sum += p(i);
      count += 1;
      if (z > skip * tz.dx)
        worst = std::max(worst, std::abs(p(i) - tz.closed_form(z, t)) / tz.p0);
      if (z > tz.H - tz.dx) {  // the two rows next to the impervious plane z = H
        base += p(i);
        base_n += 1;
      }
    }
    r.worst[k] = global_max(worst);
    r.U[k] = 1 - global_sum(sum) / global_sum(count) / tz.p0;
    r.U_cf[k] = 1 - tz.closed_form_mean(t) / tz.p0;
    r.base[k] = global_sum(base) / global_sum(base_n) / tz.p0;
    r.base_cf[k] = tz.closed_form(tz.H, t) / tz.p0;
    if (test::world()->getRank() == 0)
      std::printf(
          "[ terzaghi ] %s%s layers, H = %2d dx, T_v = %.3f: max |p - p_cf|/p0 = %.4f (z > %g "
          "dx), U = %.4f (closed form %.4f), p/p0 at z = H %.4f (closed form %.4f)\n",
          semi_implicit ? "semi-implicit, " : "", mirrored ? "mirrored" : "constant", N,
          tz.c_v * t / (tz.H * tz.H), r.worst[k], skip, r.U[k], r.U_cf[k], r.base[k], r.base_cf[k]);
  }
  return r;
}
}  // namespace

// The first-order face error of constant drained layers: from H = 10 dx to 20 dx the error of U
// at least nearly halves, and the Richardson extrapolation 2 f(20) - f(10) of U and of p at the
// impervious plane is within 3 % of p0 of the closed form, at each T_v.
void check_richardson(const TerzaghiResult& coarse, const TerzaghiResult& fine, const char* what) {
  for (int k = 0; k < 3; ++k) {
    SCOPED_TRACE("T_v = " + std::to_string(kTvs[k]));
    EXPECT_LT(std::abs(fine.U[k] - fine.U_cf[k]), 0.6 * std::abs(coarse.U[k] - coarse.U_cf[k]));
    const double U_x = 2 * fine.U[k] - coarse.U[k], base_x = 2 * fine.base[k] - coarse.base[k];
    if (test::world()->getRank() == 0)
      std::printf(
          "[ terzaghi ] %sextrapolated T_v = %.1f: U = %.4f (closed form %.4f), p/p0 at "
          "z = H %.4f (closed form %.4f)\n",
          what, kTvs[k], U_x, fine.U_cf[k], base_x, fine.base_cf[k]);
    EXPECT_NEAR(U_x, fine.U_cf[k], 0.03);
    EXPECT_NEAR(base_x, fine.base_cf[k], 0.03);
  }
}

TEST(FluidSolverLong, TerzaghiConsolidation) {
  const double* Tvs = kTvs;
  using Result = TerzaghiResult;
  const Result coarse = solve_terzaghi(column(10, 400), false, 3),
               fine = solve_terzaghi(column(20, 400), false, 3);
  for (int k = 0; k < 3; ++k) {
    SCOPED_TRACE("T_v = " + std::to_string(Tvs[k]));
    EXPECT_LT(fine.worst[k], coarse.worst[k]);
  }
  check_richardson(coarse, fine, "");
}

// Mirrored drained layers (Boundary Layer Values = Mirrored: p = -p(mirror) in the layers) put
// the drained face where it is: the boundary-layer issue's acceptance, max |p - p_cf| / p0 <= 2 %
// at H = 20 dx and <= 1 % at H = 40 dx beyond the first 2 dx, and U within 1 % at H = 20 dx, at
// T_v = 0.1, 0.2, 0.5. The column consolidates over 1600 wave transits, so that its inertia and
// damping (an error of 1 / transits, see solve_terzaghi) stay below the face's error. Measured
// at T_v = 0.1, 0.2, 0.5 (the paper's constant layers in the same column for comparison: H = 20 dx
// 10.9, 7.7, 5.6 %, U off by 5.4, 5.7, 5.2 %): H = 20 dx 0.83, 0.39, 0.51 %, U off by 0.06,
// 0.19, 0.34 %; H = 40 dx 0.67, 0.15, 0.25 %.
TEST(FluidSolverLong, TerzaghiMirroredLayers) {
  const TerzaghiResult r20 = solve_terzaghi(column(20, 1600), true, 2),
                       r40 = solve_terzaghi(column(40, 1600), true, 2);
  for (int k = 0; k < 3; ++k) {
    SCOPED_TRACE("T_v = " + std::to_string(kTvs[k]));
    EXPECT_LE(r20.worst[k], 0.02);
    EXPECT_NEAR(r20.U[k], r20.U_cf[k], 0.01);
    EXPECT_LE(r40.worst[k], 0.01);
  }
}

// Solver->Pressure Integration = Semi-Implicit (include/mupm/solvers/pressure_projection.hpp):
// the mirrored column at half the drained skeleton's stable step, as the explicit runs take
// half of theirs: the water's stiffness is in the pressure solve, not in the step. The column's
// times follow the drained wave (the undrained wave of incompressible water is infinitely
// fast): t_c = H^2 / c_v is `transits` of its transit times 2H / c_d, t_r 10 of them.
Terzaghi semi_implicit_column(double Kw, int N, double transits) {
  Terzaghi tz;
  tz.Kw = Kw;
  tz.S = tz.phi / Kw + 1 / tz.M;
  tz.p0 = tz.q / tz.M / tz.S;
  tz.c_u = std::sqrt(tz.M / ((1 - tz.phi) * tz.rho_s + tz.phi * tz.rho_w));  // drained here
  return column(N, transits, tz);
}

// Mirrored drained layers, at half the drained skeleton's step, with real water (K_w = 2.2 GPa:
// K_w / phi = 400 M, whose explicit step is 20 times shorter than the drained one) and
// incompressible water: max |p - p_cf| / p0 within 1 % at T_v = 0.2 and 0.5 beyond the first
// 2 dx, as the explicit runs reach. (Without the pressure stabilization these columns grew
// without bound: their images answered the checkerboard modes, pressure_projection.hpp.) The
// explicit tests' softer water (K_w / phi = 10 M: a storage of the skeleton's order) runs
// semi-implicit in FluidSolverSemiImplicit.AgreesWithExplicitAsDtShrinks (fast tier); its
// 500-transit column here (~60 s) was left out to keep .ci/run within its 40 minutes.
TEST(FluidSolverSemiImplicitLong, TerzaghiSemiImplicitMirrored) {
  for (const double Kw : {2.2e9, std::numeric_limits<double>::infinity()}) {
    SCOPED_TRACE("K_w = " + std::to_string(Kw));
    if (test::world()->getRank() == 0)
      std::printf("[ terzaghi ] K_w = %g Pa\n", Kw);
    const TerzaghiResult r = solve_terzaghi(semi_implicit_column(Kw, 20, 500), true, 2, true);
    for (int k = 1; k < 3; ++k) {
      SCOPED_TRACE("T_v = " + std::to_string(kTvs[k]));
      EXPECT_LE(r.worst[k], 0.01);
      EXPECT_NEAR(r.U[k], r.U_cf[k], 0.01);
    }
  }
}

// Terzaghi in plane stress (Discretization->Plane = Stress with pore water: the law's
// plane_stress() and its PoreCoupling, include/mupm/laws/micropolar_elastic.hpp). The closed form
// keeps its shape; its constants follow from the 3D lambda, mu with eps_xx = 0 (walls) and the
// total sigma_zz = lambda (eps_yy + eps_zz) + 2 mu eps_zz - p = 0:
//   eps_zz = (p - lambda eps_yy) / (lambda + 2 mu),
//   sigma_yy = M* eps_yy - b p,   M* = 4 mu (lambda + mu) / (lambda + 2 mu),   b = 2 mu / (lambda +
//   2 mu), water: (phi / K_w) dp/dt + d(eps_yy + eps_zz)/dt = flow,   eps_yy + eps_zz = b eps_yy +
//   p / (lambda + 2 mu).
// Under the load q (sigma_yy = -q) d eps_yy = (b dp - dq) / M*, so the storage is S = phi/K_w +
// 1/(lambda + 2 mu) + b^2/M* = phi/K_w + 1/(lambda + mu), c_v = (k/mu_w) / S and Skempton's
// p0 = q b / (M* S) = q / (2 (lambda + mu) S): incompressible water takes half the load (plane
// strain: all of it). The wave that sets the explicit step is the undrained one, M* + b^2 /
// (phi/K_w + 1/(lambda + 2 mu)); semi-implicit, the drained M*.
Terzaghi plane_stress_column(double Kw, int N, double transits, bool semi_implicit) {
  Terzaghi tz;
  const double lam = tz.law.lambda, mu = tz.law.mu;
  tz.pore = tz.law.plane_stress_coupling();
  tz.law = tz.law.plane_stress();
  tz.Kw = Kw;
  tz.M = 4 * mu * (lam + mu) / (lam + 2 * mu);
  tz.S = tz.phi / Kw + 1 / (lam + mu);
  tz.p0 = tz.q / (2 * (lam + mu) * tz.S);
  const double b = 2 * mu / (lam + 2 * mu);
  const double modulus = semi_implicit ? tz.M : tz.M + b * b / (tz.phi / Kw + 1 / (lam + 2 * mu));
  tz.c_u = std::sqrt(modulus / ((1 - tz.phi) * tz.rho_s + tz.phi * tz.rho_w));
  return column(N, transits, tz);
}

// The mirrored column in plane stress, H = 20 dx, explicit (the explicit tests' water, K_w / phi
// = 10 (lambda + 2 mu), 1600 transits) and semi-implicit (incompressible, 500 transits), with the
// plane-strain columns' bounds (TerzaghiMirroredLayers, TerzaghiSemiImplicitMirrored): at T_v =
// 0.2 and 0.5 max |p - p_cf| / p0 beyond the first 2 dx within 2 % (explicit) and 1 %
// (semi-implicit), U within 0.01. Without the plane-stress coupling (biot = 1,
// no lateral compliance) the incompressible column would take p0 = q, not q / 2.
TEST(FluidSolverLong, TerzaghiPlaneStress) {
  for (const bool semi_implicit : {false, true}) {
    SCOPED_TRACE(semi_implicit ? "semi-implicit" : "explicit");
    const Terzaghi plane_strain;
    const double Kw = semi_implicit ? std::numeric_limits<double>::infinity() : plane_strain.Kw;
    const Terzaghi tz = plane_stress_column(Kw, 20, semi_implicit ? 500 : 1600, semi_implicit);
    if (test::world()->getRank() == 0)
      std::printf("[ terzaghi ] plane stress, K_w = %g Pa: p0 / q = %.4f\n", Kw, tz.p0 / tz.q);
    const TerzaghiResult r = solve_terzaghi(tz, true, 2, semi_implicit);
    for (int k = 1; k < 3; ++k) {
      SCOPED_TRACE("T_v = " + std::to_string(kTvs[k]));
      EXPECT_LE(r.worst[k], semi_implicit ? 0.01 : 0.02);
      EXPECT_NEAR(r.U[k], r.U_cf[k], 0.01);
    }
  }
}

// Incompressible water (no explicit step at all) with the paper's constant drained layers,
// whose kink at the face is an error of first order in delta / H: check_richardson.
TEST(FluidSolverSemiImplicitLong, TerzaghiSemiImplicitIncompressible) {
  const double inf = std::numeric_limits<double>::infinity();
  const TerzaghiResult coarse = solve_terzaghi(semi_implicit_column(inf, 10, 400), false, 3, true),
                       fine = solve_terzaghi(semi_implicit_column(inf, 20, 400), false, 3, true);
  check_richardson(coarse, fine, "semi-implicit, incompressible, ");
}

// Incompressible water in a tight soil (the column's consolidation 1e7 times slower than its
// drained wave, k / mu_w = 2.9e-14 m^2/(Pa s)): undrained, the water takes the load (p = q
// beyond the drains' reach). The pressure modes the skeleton does not feel are held by the
// pressure stabilization (pressure_projection.hpp) alone: without it (G_p = 0) the first
// solve stalls, or the modes fill the field. Shortly after the ramp the mean pressure beyond 5 dx
// from the drains is q to 2.5 % and no point beyond 3 dx is off by more than 10 %. Measured: 0.983
// and 6.8 % (with G_p = 2, 4: 0.981, 0.986 and 7.8, 6.1 %: the 1.7 % the skeleton carries is the
// narrow column's, not the stabilization's); with G_p = 1/4 and 1/16 the modes show: 23 % and 59 %.
TEST(FluidSolverSemiImplicit, TightSoilIncompressibleTakesTheLoad) {
  Terzaghi tz = semi_implicit_column(std::numeric_limits<double>::infinity(), 10, 1e7);
  // The mean p / q beyond 5 dx from the drains and the worst |p / q - 1| beyond 3 dx.
  auto measure = [&](const ColumnRun& run, double& mean, double& worst) {
    const auto& pts = run.disc.points;
    double sum = 0, count = 0;
    worst = 0;
    for (std::size_t i = 0; i < pts.n_owned; ++i) {
      if (pts.flags(i) & kFlagBoundaryLayer)
        continue;
      const double z = std::min(pts.x(i, 1), 2 * tz.H - pts.x(i, 1));
      if (z < 3 * tz.dx)
        continue;
      worst = std::max(worst, std::abs(pts.p(i) / tz.q - 1));
      if (z >= 5 * tz.dx) {
        sum += pts.p(i);
        count += 1;
      }
    }
    mean = global_sum(sum) / global_sum(count) / tz.q;
    worst = global_max(worst);
  };
  double mean = 0, worst = 0;
  {
    // Without the stabilization the solve stalls (1 rank: exit 3), or, when the per-rank ILU
    // lets GMRES through (2 ranks), the modes fill the field.
    Terzaghi bare = tz;
    bare.Gp = 0;
    ColumnRun run(bare, bare.N, false, 0.5, true, false, true);
    bool stalled = false;
    try {
      run.run_to(1.5 * bare.t_r);
      measure(run, mean, worst);
    } catch (const CollectiveError&) {
      stalled = true;
    }
    if (test::world()->getRank() == 0)
      std::printf(
          "[ tight soil ] G_p = 0: %s\n",
          stalled ? "the solve stalled" : ("max |p/q - 1| = " + std::to_string(worst)).c_str());
    EXPECT_TRUE(stalled || !(worst < 0.1)) << "stable without stabilization";
  }
  ColumnRun run(tz, tz.N, false, 0.5, true, false, true);
  run.run_to(1.5 * tz.t_r);
  measure(run, mean, worst);
  if (test::world()->getRank() == 0)
    std::printf(
        "[ tight soil ] k/mu_w = %.2e: mean p/q = %.5f (z >= 5 dx), max |p/q - 1| = %.4f "
        "(z >= 3 dx)\n",
        tz.mobility, mean, worst);
  EXPECT_NEAR(mean, 1.0, 0.025);
  EXPECT_LT(worst, 0.1);
}

// Undrained loading of a sealed saturated body with incompressible water: a free square under
// the same normal traction q(t) on its four faces (Traction Distribution = Consistent, so that
// u = 0 with the uniform total stress -q 1 is the discrete equilibrium). No point may change its
// volume: the pore water takes the whole load at once, p = q (Skempton's B = 1), and the
// skeleton does not move. The pressure of step n + 1 balances the load of step n (the skeleton's
// impulse over the step centred at t_n carries p_{n+1}, pressure_projection.hpp): p(t_{n+1}) =
// q(t_n) on every point, to the solve's tolerance.
// A sealed 16 x 16 saturated body, semi-implicit, with water of bulk modulus K_w (incompressible
// by default), under a pressure q on its four faces (consistent tractions) whose time function is
// `time`. 16 spacings: the strips of opposite faces' consistent loads (2 delta + dx deep) must
// not overlap.
struct SealedBody {
  static constexpr double dx = 0.01, L = 16 * dx, q = 1e4, phi = 0.3;
  GridSpec<2> g = test::box<2>({16, 16}, 3.015, dx);
  Discretization<2> disc;
  static MicropolarElastic material() {
    return MicropolarElastic::from_bulk_shear(10e6, 6e6, 3e6, 0.01);
  }
  // The drained plane-stress wave speed of material() with the saturated mixture's density.
  static double drained_wave_speed() {
    const MicropolarElastic m = material();
    const double rho = (1 - phi) * 2000 + phi * 1000;
    return std::sqrt(4 * m.mu * (m.lambda + m.mu) / (m.lambda + 2 * m.mu) / rho);
  }
  // A ramp of the load over `transits` transits of that wave across the body.
  static TimeFunction ramp(double transits) {
    TimeFunction r;
    r.kind = TimeFunction::Ramp;
    r.ramp_time = transits * L / drained_wave_speed();
    return r;
  }
  MicropolarElastic law = material();  // in plane stress, its plane_stress()
  std::vector<BoundaryCondition> bcs;
  std::unique_ptr<FluidSolver<2>> fluid;
  std::unique_ptr<SolidSolver<2>> solid;
  std::unique_ptr<SolidSolver<2, MicropolarDruckerPrager<2>>> plastic;  // with `yield`
  StepSequence<2> seq;
  double dt = 0;

  // plane_stress: Discretization->Plane = Stress (the law's plane_stress() and its
  // PoreCoupling); explicit: Pressure Integration = Explicit (undrained split, fluid substeps);
  // damping [1/s] of the skeleton; yield: Drucker-Prager of material() (`plastic`, not `solid`).
  explicit SealedBody(const TimeFunction& time,
                      double k_w = std::numeric_limits<double>::infinity(),
                      bool plane_stress = false, bool explicit_water = false, double damping = 0,
                      const DruckerPragerParams* yield = nullptr,
                      const LinearSolveSettings& solve = LinearSolveSettings()) {
    g.region_names = {"left", "right", "bottom", "top"};
    g.regions = {box2(-1, 0.5 * dx, -1, 1), box2(L - 0.5 * dx, 1, -1, 1), box2(-1, 1, -1, 0.5 * dx),
                 box2(-1, 1, L - 0.5 * dx, 1)};
    disc = discretize(test::world(), g);
    Kokkos::deep_copy(disc.points.porosity, phi);
    Kokkos::deep_copy(disc.points.saturation, 1.0);
    for (int face = 0; face < 4; ++face) {
      BoundaryCondition bc;
      bc.name = g.region_names[std::size_t(face)];
      bc.kind = BoundaryCondition::Traction;
      bc.region_mask = 1u << face;
      bc.component = face / 2;
      bc.face = face;
      bc.consistent = true;
      bc.value = face % 2 ? -q : q;  // sigma n = -q n
      bc.time = time;
      bcs.push_back(bc);
    }
    auto fp = fluid_params(g, 1e-12, 0.5);
    fp.bulk_modulus = k_w;
    fp.semi_implicit = !explicit_water;
    SolidSolver<2>::Settings set;
    set.semi_implicit = !explicit_water;
    set.damping = damping;
    if (plane_stress)
      law = law.plane_stress();
    auto sp = solid_params(law, g, 0.5);
    if (plane_stress)
      sp.pore = fp.pore = material().plane_stress_coupling();
    fluid = std::make_unique<FluidSolver<2>>(disc, fp, bcs, MPI_COMM_WORLD);
    if (!explicit_water)
      fluid->enable_semi_implicit(solve);
    if (yield)
      start(*fluid,
            plastic = std::make_unique<SolidSolver<2, MicropolarDruckerPrager<2>>>(
                disc, sp, bcs, set, MPI_COMM_WORLD,
                MicropolarDruckerPrager<2>(material(), *yield, disc.points, plane_stress, true)),
            explicit_water);
    else
      start(*fluid, solid = std::make_unique<SolidSolver<2>>(disc, sp, bcs, set, MPI_COMM_WORLD),
            explicit_water);
  }
  template <class Solid>
  void start(FluidSolver<2>& water, const std::unique_ptr<Solid>& skeleton, bool explicit_water) {
    water.initialize(0, false);
    skeleton->initialize(0, false);
    water.reset_strain_reference();
    seq.mechanics = skeleton.get();
    seq.fluid = &water;
    dt = 0.5 * skeleton->estimate_stable_dt();
    skeleton->set_time_step(dt);
    if (explicit_water)
      seq.substeps = std::max(1, int(std::ceil(dt / (0.5 * water.estimate_stable_dt()))));
    else
      seq.skeleton = skeleton.get();
  }
};

// Undrained loading of the sealed body with incompressible water: p follows the load q (the
// closed form p = q, the skeleton does not move), with the pressure solve preconditioned by ILU
// or by AMG (the input's default, include/mupm/solvers/amg_preconditioner.hpp).
void check_sealed_incompressible(const char* preconditioner) {
  const double t_r = 2e-3, q = SealedBody::q;
  TimeFunction ramp;
  ramp.kind = TimeFunction::Ramp;
  ramp.ramp_time = t_r;
  LinearSolveSettings solve;
  solve.preconditioner = preconditioner;
  SealedBody b(ramp, std::numeric_limits<double>::infinity(), false, false, 0, nullptr, solve);
  const auto& pts = b.disc.points;
  long long n = 0;
  for (const double t_check : {0.5 * t_r, 1.5 * t_r}) {
    for (; (n + 1) * b.dt <= t_check; ++n)
      b.seq.step(n, n * b.dt, b.dt);
    const double t = n * b.dt, q_prev = q * std::min(1.0, (t - b.dt) / t_r);
    double worst = 0, moved = 0;
    for (std::size_t i = 0; i < pts.n_owned; ++i) {
      worst = std::max(worst, std::abs(pts.p(i) / q_prev - 1));
      for (int d = 0; d < 2; ++d)
        moved = std::max(moved, std::abs(pts.u(i, d)));
    }
    worst = global_max(worst);
    moved = global_max(moved);
    // The skeleton's drained response to q would be q L / (2 (K + mu)) at the faces.
    const double drained = q * SealedBody::L / (2 * (b.law.lambda + 2 * b.law.mu));
    if (test::world()->getRank() == 0)
      std::printf(
          "[ undrained, %s ] t = %.3g t_r: max |p(t_n+1)/q(t_n) - 1| = %.2e, max |u| = %.2e "
          "(%.1e of the drained face displacement)\n",
          preconditioner, t / t_r, worst, moved, moved / drained);
    EXPECT_LT(worst, 1e-6) << preconditioner;
    EXPECT_LT(moved, 1e-6 * drained) << preconditioner;
  }
}

TEST(FluidSolverSemiImplicit, SealedIncompressibleBodyTakesTheLoad) {
  check_sealed_incompressible("ILU");
}
TEST(FluidSolverSemiImplicit, SealedIncompressibleBodyTakesTheLoadWithAmg) {
  check_sealed_incompressible("AMG");
}

// Plane stress (Discretization->Plane = Stress with pore water, PoreCoupling in
// include/mupm/laws/micropolar_elastic.hpp): the sealed body under the in-plane pressure q, with
// sigma_zz,total = 0. Closed form from the 3D lambda, mu: the uniform in-plane strain e (eps_xx =
// eps_yy = e) and eps_zz = (p - 2 lambda e) / (lambda + 2 mu) satisfy the in-plane balance
// 2 lambda e + 2 mu e + lambda eps_zz - p = -q and the water's, phi p / K_w + 2 e + eps_zz = 0
// (no flow), solved below. With incompressible water p = 2q/3 (the mean effective stress must
// vanish, and the out-of-plane one is p), not plane strain's q, and the skeleton moves: e =
// -q / (6 mu). The load is ramped over 10 transits of the drained wave, the skeleton damped
// (about half critical),
// so the body is near its static state after the ramp: the mean p within 1 % of the closed
// form, for the semi-implicit water (incompressible) and the explicit one (K_w / phi = 10 (lambda +
// 2 mu): the undrained split and the fluid's storage with the thickness's compliance).
TEST(FluidSolverHydroMechanical, SealedBodyPlaneStress) {
  const double q = SealedBody::q, L = SealedBody::L, phi = SealedBody::phi;
  const double lam = SealedBody::material().lambda, mu = SealedBody::material().mu;
  const double c_d = SealedBody::drained_wave_speed();
  const TimeFunction ramp = SealedBody::ramp(10);
  const double t_r = ramp.ramp_time;
  for (const bool explicit_water : {false, true}) {
    const double k_w =
        explicit_water ? 10 * (lam + 2 * mu) * phi : std::numeric_limits<double>::infinity();
    // Unknowns e, eps_zz, p: the in-plane and out-of-plane total stresses and the water balance.
    //   (2 lam + 2 mu) e + lam eps_zz - p = -q,   2 lam e + (lam + 2 mu) eps_zz - p = 0,
    //   2 e + eps_zz + (phi / K_w) p = 0.
    const double s = phi / k_w;
    // From the second and third: eps_zz = -2 e - s p, so (2 lam - 2 (lam + 2 mu)) e - ((lam + 2 mu)
    // s + 1) p = 0, e = -((lam + 2 mu) s + 1) p / (4 mu); the first then gives p.
    const double e_per_p = -((lam + 2 * mu) * s + 1) / (4 * mu);
    const double p_exact = -q / ((2 * lam + 2 * mu) * e_per_p + lam * (-2 * e_per_p - s) - 1);
    SealedBody b(ramp, k_w, true, explicit_water, kPi * c_d / L);
    const auto& pts = b.disc.points;
    long long n = 0;
    for (; (n + 1) * b.dt <= 1.5 * t_r; ++n)
      b.seq.step(n, n * b.dt, b.dt);
    double sum = 0, count = 0, strain = 0;
    for (std::size_t i = 0; i < pts.n_owned; ++i) {
      sum += pts.p(i);
      count += 1;
      strain += pts.vol_strain(i);
    }
    const double mean = global_sum(sum) / global_sum(count);
    const double e = 0.5 * global_sum(strain) / global_sum(count);
    if (test::world()->getRank() == 0)
      std::printf(
          "[ plane stress ] %s, K_w = %.3g Pa: mean p / q = %.5f (closed form %.5f; plane "
          "strain's %.5f), in-plane strain %.4e (closed form %.4e)\n",
          explicit_water ? "explicit" : "semi-implicit", k_w, mean / q, p_exact / q,
          1 / (1 + s * (lam + mu)), e, e_per_p * p_exact);
    EXPECT_NEAR(mean / p_exact, 1.0, 0.01);
    EXPECT_NEAR(e / (e_per_p * p_exact), 1.0, 0.02);
  }
}

// Drucker-Prager in plane stress with pore water (laws/micropolar_drucker_prager.hpp): the
// sealed body of SealedBodyPlaneStress (S_r = 1) under the in-plane all-round load q has the
// effective stress sigma-bar = diag(p - q, p - q, p) (the total sigma_zz = 0), whose deviator is
// the load's alone: q_vM = q. Once the body yields, f = q + sqrt3 a1 (p - 2q/3) - k c = 0 fixes
//   p = 2q/3 + (k c - q) / (sqrt3 a1),
// whatever the water's stiffness: the dilatancy (psi > 0) lets the sealed body hold the load
// beyond k c (undrained dilatant hardening), the water taking the plastic thickness change. At
// q = 1.25 k c this p is a quarter of the elastic 2q/3, so a water balance without the plastic
// thickness change (or with it twice, or of the wrong sign) is far from it. Run explicit (K_w /
// phi = 10 (lambda + 2 mu)), semi-implicit at the same K_w and at the explicit run's step (the
// plastic thickness change a step late, fluid_solver.hpp lagged_plastic_source) and
// semi-implicit with incompressible water at its own step; the semi-implicit runs keep the water
// mass to the solve's tolerance. The load is ramped over 40 transits of the drained wave
// (quasi-static: over 10, as SealedBodyPlaneStress does, the ramp's waves lock residual stresses
// into the yielded body and the mean p is 0.23-0.25 q in all three runs; over 40 and 160, within
// 0.3 % of the closed form).
TEST(FluidSolverHydroMechanical, SealedBodyPlaneStressDruckerPrager) {
  const double q = SealedBody::q, L = SealedBody::L, phi = SealedBody::phi;
  const double lam = SealedBody::material().lambda, mu = SealedBody::material().mu;
  const double c_d = SealedBody::drained_wave_speed();
  const TimeFunction ramp = SealedBody::ramp(40);
  const double t_r = ramp.ramp_time;
  DruckerPragerParams dp;
  dp.friction = 30 * kPi / 180;
  dp.dilation = 10 * kPi / 180;
  dp.cohesion = q / (1.25 * dp.k());
  dp.residual = dp.cohesion;
  const double a1 = dp.a1(), kc = dp.k() * dp.cohesion;
  const double p_exact = 2 * q / 3 + (kc - q) / (std::sqrt(3.0) * a1);
  const double k_w = 10 * (lam + 2 * mu) * phi, inf = std::numeric_limits<double>::infinity();
  double explicit_dt = 0;
  for (const int run : {0, 1, 2}) {  // explicit, semi-implicit at K_w, incompressible
    const bool explicit_water = run == 0;
    SealedBody b(ramp, run == 2 ? inf : k_w, true, explicit_water, kPi * c_d / L, &dp);
    if (run == 0)
      explicit_dt = b.dt;
    if (run == 1) {
      b.dt = explicit_dt;
      b.plastic->set_time_step(b.dt);
    }
    const auto& pts = b.disc.points;
    const double m0 = b.fluid->fluid_mass();
    long long n = 0;
    for (; (n + 1) * b.dt <= 1.5 * t_r; ++n)
      b.seq.step(n, n * b.dt, b.dt);
    double sum = 0, count = 0, yielded = 0;
    for (std::size_t i = 0; i < pts.n_owned; ++i) {
      sum += pts.p(i);
      count += 1;
      yielded += pts.equivalent_plastic_strain(i) > 0 ? 1 : 0;
    }
    const double mean = global_sum(sum) / global_sum(count);
    yielded = global_sum(yielded) / global_sum(count);
    const double mass_error = (b.fluid->fluid_mass() - m0) / m0;
    if (test::world()->getRank() == 0)
      std::printf(
          "[ plane stress, Drucker-Prager ] %s, K_w = %.3g Pa, dt = %.3g s: mean p / q = %.5f "
          "(closed form %.5f; elastic %.5f), %.0f %% of the points yielded, water mass error "
          "%.2e\n",
          explicit_water ? "explicit" : "semi-implicit", run == 2 ? inf : k_w, b.dt, mean / q,
          p_exact / q, 2.0 / 3.0, 100 * yielded, mass_error);
    EXPECT_NEAR(mean / p_exact, 1.0, 0.01);
    EXPECT_EQ(yielded, 1.0);
    if (!explicit_water) {
      EXPECT_LT(std::abs(mass_error), 1e-8);
    }
  }
}

// The solid's energy balance of the semi-implicit step (pressure_projection.hpp, header: the
// projection work over the centred interval (u_{n+1} - u_{n-1}) / 2) closes to round-off from
// the first step of a sudden load, where the pressure jumps from 0 to nearly q in one step; with
// real water (K_w = 2.2 GPa) the body compresses and rings. The correction's work is not small
// here: booked over (u_{n+1} - u_n) instead, the balance is off by up to 6.6 times its largest term
// (measured).
TEST(FluidSolverSemiImplicit, ImpulsiveStartBalanceCloses) {
  SealedBody b(TimeFunction{}, 2.2e9);  // Constant: the full load from t = 0
  const double b0 = b.solid->energy().balance();
  double worst = 0, projection = 0;
  for (long long n = 0; n < 40; ++n) {
    b.seq.step(n, n * b.dt, b.dt);
    const auto e = b.solid->energy();
    worst = std::max(worst, std::abs(e.balance() - b0) / e.scale());
    projection = std::max(projection, std::abs(b.solid->projection_work()) / e.scale());
  }
  if (test::world()->getRank() == 0)
    std::printf("[ impulsive ] balance error / largest term %.2e, |projection work| up to %.2e\n",
                worst, projection);
  EXPECT_LT(worst, 1e-10);
  EXPECT_GT(projection, 1e-2);  // the correction's work is a term the balance must get right
}

// The same coupled problem run Explicit and Semi-Implicit at the explicit step (the water of
// the explicit tests, K_w / phi = 10 M), after the load ramp: two first-order splittings of the
// same equations (the explicit one lags the pressure's force by the undrained split, the
// semi-implicit one leads it by a step), so their pore pressures differ by O(dt): halving dt
// halves the difference. The water mass is kept to the solves' tolerance.
TEST(FluidSolverSemiImplicit, AgreesWithExplicitAsDtShrinks) {
  Terzaghi tz;
  const double t_end = 1.5 * tz.t_r;
  double diff[2];
  for (int k = 0; k < 2; ++k) {
    const double f = k == 0 ? 0.4 : 0.2;
    ColumnRun ex(tz, 8, false, f), si(tz, 8, false, f, true, false, true);
    si.dt = ex.dt;
    const double m0 = si.fluid->fluid_mass();
    ex.run_to(t_end);
    si.run_to(t_end);
    ASSERT_EQ(ex.step, si.step);
    diff[k] = max_pressure_difference(ex, si) / tz.p0;
    double drained = 0;
    for (double v : si.fluid->inflows())
      drained += v;
    const double mass_error = si.fluid->fluid_mass() - m0 - drained;
    if (test::world()->getRank() == 0)
      std::printf(
          "[ semi-implicit ] dt = %.1f of the explicit stable step: max |p_si - "
          "p_explicit| / p0 = %.3e, water mass error %.2e of %.4g kg\n",
          f, diff[k], mass_error, m0);
    EXPECT_LT(std::abs(mass_error), 1e-8 * m0);
  }
  EXPECT_GT(diff[1], 0.0);
  EXPECT_LT(diff[1], 0.6 * diff[0]);
}

// Solid First and Fluid First are two first-order splittings of the same equations: their
// pore pressures after the load ramp differ by O(dt), so halving dt halves the difference.
TEST(FluidSolverHydroMechanical, StaggeringOrdersAgreeAsDtShrinks) {
  Terzaghi tz;
  const double t_end = 1.5 * tz.t_r;
  double diff[2];
  for (int k = 0; k < 2; ++k) {
    const double f = k == 0 ? 0.4 : 0.2;
    ColumnRun a(tz, 8, false, f), b(tz, 8, true, f);
    b.stagger.substeps = a.stagger.substeps;
    a.run_to(t_end);
    b.run_to(t_end);
    ASSERT_EQ(a.step, b.step);
    diff[k] = max_pressure_difference(a, b) / tz.p0;
  }
  if (test::world()->getRank() == 0)
    std::printf("[ orders ] max |p_solid_first - p_fluid_first| / p0: %.3e (dt), %.3e (dt/2)\n",
                diff[0], diff[1]);
  EXPECT_GT(diff[0], 0.0);
  EXPECT_LT(diff[1], 0.7 * diff[0]);
}

}  // namespace
}  // namespace mupm

namespace mupm {
namespace {

// The solid's energy balance with pore water (eq 140 plus the work of -S_r p* 1 on the
// skeleton): E_int + E_kin + D - W_ext - W_pore stays at its initial value to O(dt^2) while
// the load is ramped onto an undamped column. (Undamped: the damping dissipation is booked by
// the midpoint rule, c rho v(n+1/2)^2 dt, which is first order against the forces the scheme
// applies.) The compressed water takes most of the work (its
// undrained modulus K_w/phi is 10 M here), so W_pore is negative and larger than the strain
// energy: a wrong sign or factor of the pore work, or of p* in the stress, breaks the balance.
// In plane stress (the pressure's coefficient biot = 2 mu / (lambda + 2 mu) in the force and in
// the pore work) the same balance closes (booked with S_r p alone, the pore work was off by
// 13 % of the largest term).
TEST(FluidSolverHydroMechanical, SolidEnergyBalanceWithPoreWork) {
  for (const bool plane_stress : {false, true}) {
    SCOPED_TRACE(plane_stress ? "plane stress" : "plane strain");
    const Terzaghi tz =
        plane_stress ? plane_stress_column(Terzaghi().Kw, 20, 400, false) : Terzaghi();
    ColumnRun run(tz, 8, false, 0.5, false);
    const double b0 = run.solid->energy().balance();
    double worst = 0;
    SolidSolver<2>::Energy e;
    for (int k = 1; k <= 8; ++k) {
      run.run_to(k * tz.t_r / 8);
      e = run.solid->energy();
      worst = std::max(worst, std::abs(e.balance() - b0) / e.scale());
    }
    if (test::world()->getRank() == 0)
      std::printf(
          "[ energy ] %s: W_ext = %.4g J, E_int = %.4g J, E_kin = %.3g J, D = %.3g J, W_pore = "
          "%.4g J, largest balance error / largest term = %.2e\n",
          plane_stress ? "plane stress" : "plane strain", e.external_work, e.internal, e.kinetic,
          e.dissipation, e.pore_work, worst);
    // The water takes most of the work in plane strain, about a third of it in plane stress
    // (where its undrained share of the load is 0.47 q, not 0.91 q).
    EXPECT_LT(e.pore_work, (plane_stress ? -0.2 : -1.0) * e.internal);
    EXPECT_LT(worst, 1e-3);
  }
}

}  // namespace
}  // namespace mupm

namespace mupm {
namespace {

// Sub-cycling and larger fluid steps are other first-order splittings of the same step: on
// the consolidation column after the load ramp, a fluid step every 2 solid steps (over their
// interval) and 3 fluid substeps per solid step give pore pressures within 1e-2 p0 of the
// one-to-one step (the two staggering orders differ by about 1e-3 p0 at this step).
TEST(FluidSolverHydroMechanical, SubcyclingAgrees) {
  Terzaghi tz;
  const double t_end = 1.5 * tz.t_r;
  ColumnRun base(tz, 8, false, 0.4), every2(tz, 8, false, 0.4), sub3(tz, 8, true, 0.4);
  every2.stagger.fluid_every = 2;
  every2.stagger.substeps = 2 * base.stagger.substeps;
  sub3.stagger.substeps = 3 * base.stagger.substeps;
  const double m0 = sub3.fluid->fluid_mass();
  for (auto* r : {&base, &every2, &sub3})
    r->run_to(t_end);
  ASSERT_EQ(base.step % 2, 0) << "the interval of 2 steps must be complete";
  auto pb = Kokkos::create_mirror_view_and_copy(HostSpace(), base.disc.points.p);
  double d[2] = {0, 0};
  int k = 0;
  for (auto* r : {&every2, &sub3}) {
    auto p = Kokkos::create_mirror_view_and_copy(HostSpace(), r->disc.points.p);
    for (std::size_t i = 0; i < base.disc.points.n_owned; ++i)
      d[k] = std::max(d[k], std::abs(p(i) - pb(i)));
    d[k] = global_max(d[k]) / tz.p0;
    ++k;
  }
  if (test::world()->getRank() == 0)
    std::printf(
        "[ subcycling ] max |p - p_1:1| / p0: %.3e (fluid every 2 steps), %.3e (3 "
        "substeps, fluid first)\n",
        d[0], d[1]);
  EXPECT_LT(d[0], 1e-2);
  EXPECT_LT(d[1], 1e-2);
  // Water leaves only through the drains, sub-cycled or not.
  double drained = 0;
  for (double v : sub3.fluid->inflows())
    drained += v;
  EXPECT_NEAR(sub3.fluid->fluid_mass() - m0, drained, 1e-12 * m0);
}

// The fluid step in 3D: an unsaturated cube with impervious faces keeps its water mass to
// round-off while the suction evens out.
TEST(FluidSolver, MassConservation3D) {
  auto g = test::box<3>({8, 7, 6}, 3.015, 0.01);
  auto disc = discretize(test::world(), g);
  Kokkos::deep_copy(disc.points.porosity, 0.3);
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.x);
  auto pw = Kokkos::create_mirror_view(disc.points.p);
  for (std::size_t i = 0; i < disc.points.size(); ++i)
    pw(i) = -15e3 + 5e3 * std::sin(57 * x(i, 0) + 31 * x(i, 1) - 23 * x(i, 2));
  Kokkos::deep_copy(disc.points.p, pw);
  auto prm = fluid_params(g, 1e-10, 0.5);
  prm.retention = VanGenuchten::mualem(10e3, 2.0);
  FluidSolver<3> fluid(disc, prm, {}, MPI_COMM_WORLD);
  fluid.initialize(0, false);
  const double dt = 0.5 * fluid.estimate_stable_dt();
  const double m0 = fluid.fluid_mass();
  auto spread = [&] {
    auto p = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.p);
    double lo = 1e300, hi = -1e300;
    for (std::size_t i = 0; i < disc.points.n_owned; ++i) {
      lo = std::min(lo, p(i));
      hi = std::max(hi, p(i));
    }
    return global_max(hi) + global_max(-lo);
  };
  const double s0 = spread();
  for (int s = 0; s < 100; ++s)
    fluid.advance(s * dt, dt, 1);
  EXPECT_NEAR(fluid.fluid_mass(), m0, 1e-13 * m0);
  EXPECT_LT(spread(), 0.5 * s0);
}

}  // namespace
}  // namespace mupm

namespace mupm {
namespace {

// Initial condition "Hydrostatic Pore Pressure": p = rho_w g.(x - x0) (x0 on the water table),
// which Darcy's law with gravity leaves at rest: unsaturated above the table, saturated below,
// nothing flows and p stays put.
TEST(FluidSolver, HydrostaticInitialStateStaysAtRest) {
  auto g = test::box<2>({6, 20}, 3.015, 0.01);
  auto disc = discretize(test::world(), g);
  Kokkos::deep_copy(disc.points.porosity, 0.3);
  InitialCondition ic;
  ic.field = "Hydrostatic Pore Pressure";
  ic.value = {0.0, 0.12};  // water table at y = 0.12 m
  apply_initial_conditions<2>({ic}, disc.points, {0.0, 1000 * -9.81, 0.0});
  auto prm = fluid_params(g, 1e-10, 0.5);
  prm.retention = VanGenuchten::mualem(1e3, 2.0);
  prm.gravity[1] = -9.81;
  FluidSolver<2> fluid(disc, prm, {}, MPI_COMM_WORLD);
  fluid.initialize(0, false);
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.x);
  auto p0 = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.p);
  for (std::size_t i = 0; i < disc.points.n_owned; ++i)
    EXPECT_NEAR(p0(i), 1000 * 9.81 * (0.12 - x(i, 1)), 1e-9);
  const double dt = 0.5 * fluid.estimate_stable_dt();
  for (int s = 0; s < 50; ++s)
    fluid.advance(s * dt, dt, 1);
  auto p = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.p);
  auto q = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.darcy_flux);
  for (std::size_t i = 0; i < disc.points.n_owned; ++i) {
    EXPECT_NEAR(p(i), p0(i), 1e-9 * 1000 * 9.81 * 0.2);
    EXPECT_NEAR(q(i, 1), 0.0, 1e-9 * 1e-10 * 1000 * 9.81);
  }
}

}  // namespace
}  // namespace mupm

namespace mupm {
namespace {

// Steady Darcy flow through a column (H = 20 dx, 6 wide, impervious sides without layers):
// water enters through the bottom face at q_n and leaves through a drained top layer
// (mirrored, p = g_top at the face y = H). Saturated without gravity p = (q_n / lambda)(H - y),
// lambda = k / mu_w. Two ways in: a Fluid Source on the bottom row (q_n W per metre, spread over
// the row), and a Fluid Flux on a bottom boundary layer (the body's p continued with the flux's
// gradient). Each starts from the closed form and runs three diffusion times (the state no
// longer changes).
// - Both: the far field carries the flux exactly (the mass balance and the nonlocal flux, exact
//   for a linear field): the source row's distortion decays to 4.8e-4 of p's scale at 2 delta
//   from the bottom and below 1e-4 beyond 3 delta (asserted there).
// - The source row: the truncated families at the face distort p within a horizon of it.
//   Measured: the source row 0.42 % of p(0) = q_n H / lambda above the closed form, the next row
//   5.4 % below (-1.09 q_n dx / lambda), 0.45 % and 0.2 % below and above on the next two
//   (H = 20 dx; at 40 dx the same pressures, so half the fractions).
// - The Fluid Flux layer: exact for a linear field, so p matches the closed form everywhere to
//   1e-6 of its scale, and the water it lets in is q_n W per metre, booked as its inflow.
// With gravity (g = -9.81 m/s^2 along y) Darcy's law q_y = -lambda (dp/dy + rho_w g) makes the
// saturated profile p = (q_n / lambda + rho_w g)(H - y), still linear. Unsaturated (van
// Genuchten-Mualem, the top held at a suction): lambda = k_r(p) k / mu_w and
//   dp/dy = -q_n / (lambda(p)) - rho_w g,  p(H) = g_top,
// integrated here by RK4 (steps of dx/200) as the reference.
struct FaceInflow {
  double far = 0, worst = 0, face_row = 0, second_row = 0, inflow_rate = 0;
};
struct InflowCase {
  bool flux_layer = false;
  bool gravity = false;
  double suction = 0;      // > 0: unsaturated, the top face held at p = -suction [Pa]
  double q_n = 1e-6;       // [m/s]
  double air_entry = 1e4;  // van Genuchten's pressure scale [Pa] (n = 2) when unsaturated
};
FaceInflow face_inflow(const InflowCase& c) {
  const double dx = 0.01, mob = 1e-10, phi = 0.3, Kw = 1e8, grav = c.gravity ? 9.81 : 0.0;
  const int N = 20, W = 6;
  const double H = N * dx, q_n = c.q_n, delta = 3.015 * dx;
  const bool flux_layer = c.flux_layer;
  auto g = test::box<2>({W, N}, 3.015, dx);
  g.layers = {{{0, 0}, {flux_layer ? 6 : 0, 6}}};
  g.mirrored_layers = true;
  g.region_names = {"inflow", "drain"};
  g.regions = {flux_layer ? box2(-1, 2, -1, -0.25 * dx) : box2(-1, 2, 0, dx),
               box2(-1, 2, H + 0.25 * dx, 2)};
  auto disc = discretize(test::world(), g);
  Kokkos::deep_copy(disc.points.porosity, phi);
  auto prm = fluid_params(g, mob, 0.5);
  prm.bulk_modulus = Kw;
  prm.gravity[1] = -grav;
  if (c.suction > 0)
    prm.retention = VanGenuchten::mualem(c.air_entry, 2.0);
  const double rho_g = prm.water_density * grav;
  // The reference p(y) on [0, H] (table of spacing dx/200 from the top, linear in between).
  const VanGenuchten vg = prm.retention;
  const int fine = 200 * N;
  const double h = H / fine;
  std::vector<double> table(fine + 1);
  auto slope = [&](double p) {
    return -q_n / (mob * vg.relative_permeability(vg.saturation(p))) - rho_g;
  };
  table[fine] = -c.suction;
  for (int k = fine; k > 0; --k) {  // from y = H down: dp = -h slope
    const double p = table[k], k1 = slope(p), k2 = slope(p - 0.5 * h * k1),
                 k3 = slope(p - 0.5 * h * k2), k4 = slope(p - h * k3);
    table[k - 1] = p - h * (k1 + 2 * k2 + 2 * k3 + k4) / 6;
  }
  auto exact = [&](double y) {
    // Saturated: the line. Outside [0, H] (the layers, which the conditions overwrite): the line.
    if (c.suction == 0 || y > H || y < 0)
      return (q_n / mob + rho_g) * (H - y) - c.suction;
    const int k = std::min(int(y / h), fine - 1);
    const double f = y / h - k;
    return (1 - f) * table[k] + f * table[k + 1];
  };
  set_pressure(disc.points, [&](const double* x) { return exact(x[1]); });
  BoundaryCondition in, drain;
  in.name = "inflow";
  in.kind = flux_layer ? BoundaryCondition::FluidFlux : BoundaryCondition::FluidSource;
  in.region_mask = 1u;
  in.value = flux_layer ? q_n : q_n * W * dx;
  in.mirrored = flux_layer;
  drain.name = "drain";
  drain.kind = BoundaryCondition::PorePressure;
  drain.region_mask = 2u;
  drain.value = -c.suction;
  drain.mirrored = true;
  FluidSolver<2> fluid(disc, prm, {in, drain}, MPI_COMM_WORLD);
  fluid.initialize(0, false);
  const double dt = 0.5 * fluid.estimate_stable_dt();
  // Three diffusion times of the slowest point of the reference (storage over mobility).
  double diffusivity = mob * Kw / phi;
  for (double p : table) {
    const double s = vg.saturation(p);
    diffusivity = std::min(
        diffusivity, mob * vg.relative_permeability(s) / (phi * (vg.dsaturation_dp(p) + s / Kw)));
  }
  const long steps = long(3 * H * H / diffusivity / dt), tail = steps / 10;
  double in0 = 0;
  for (long k = 0; k < steps; ++k) {
    if (k == steps - tail)
      in0 = fluid.inflows()[0];
    fluid.advance(k * dt, dt, 1);
  }
  FaceInflow r;
  r.inflow_rate = (fluid.inflows()[0] - in0) / (tail * dt) / (prm.water_density * g.thickness);
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.x);
  auto p = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.p);
  auto flags = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.flags);
  const double scale = exact(0) - exact(H);
  double face = 0, second = 0;
  for (std::size_t i = 0; i < disc.points.n_owned; ++i) {
    if (flags(i) & kFlagBoundaryLayer)
      continue;
    const double y = x(i, 1), e = (p(i) - exact(y)) / scale;
    r.worst = std::max(r.worst, std::abs(e));
    if (y > 3 * delta)
      r.far = std::max(r.far, std::abs(e));
    if (y < dx)
      face += e / W;
    else if (y < 2 * dx)
      second += e / W;
  }
  r.far = global_max(r.far);
  r.worst = global_max(r.worst);
  r.face_row = global_sum(face);
  r.second_row = global_sum(second);
  if (test::world()->getRank() == 0)
    std::printf(
        "[ inflow face ] %s%s%s: max |p - p_cf| / (p(0) - p(H)) %.2e (beyond 3 delta %.2e), first "
        "row %+.4f, second row %+.4f, inflow %.6e m/s per unit width (q_n %.6e), %ld steps\n",
        flux_layer ? "Fluid Flux layer" : "Fluid Source row", c.gravity ? ", gravity" : "",
        c.suction > 0 ? ", unsaturated" : "", r.worst, r.far, r.face_row, r.second_row,
        r.inflow_rate / (W * dx), q_n, steps);
  return r;
}

TEST(FluidSolver, InflowFaceAgainstDarcy) {
  const double q_n = 1e-6, width = 6 * 0.01;
  const FaceInflow row = face_inflow({false}), layer = face_inflow({true});
  EXPECT_LT(row.far, 1e-4);
  EXPECT_LT(std::abs(row.face_row), 0.01);  // the face's pressure, 0.42 % measured
  EXPECT_GT(row.worst, 0.01);               // the surface's distortion the layer removes
  EXPECT_LT(layer.worst, 1e-6);
  EXPECT_NEAR(layer.inflow_rate, q_n * width, 1e-6 * q_n * width);
}

}  // namespace
}  // namespace mupm

namespace mupm {
namespace {

// The Fluid Flux face with gravity, saturated (a linear profile: exact to round-off, and the
// inflow is q_n) and unsaturated: van Genuchten-Mualem with a 10 kPa scale (n = 2), the top held
// at -5 kPa, q_n = 1e-8 m/s, where k_r rises from 0.29 at the top to 0.50 at the bottom (gravity
// carries most of the gradient: q_n / lambda is 2-3.5 % of rho_w g). The layer's gradient is
// q_n / lambda at each layer point's mirror, so where k_r changes across the face the face lets
// in more than q_n (the mirror is drier than the face). Measured: inflow +2.35 % (+5.4 % with
// the layer's own k_r instead of its mirror's, FluidSolver::mirror_rel_perm; +8 to +10 % with a
// 3 kPa scale, where k_r changes faster), p within 5.9e-4 of its range. The bounds are those
// measurements with a margin: they catch the mirror's k_r being lost, not a physical limit.
TEST(FluidSolver, InflowFaceWithGravityAndUnsaturated) {
  const double width = 6 * 0.01;
  const FaceInflow wet = face_inflow({true, true});
  EXPECT_LT(wet.worst, 1e-6);
  EXPECT_NEAR(wet.inflow_rate, 1e-6 * width, 1e-6 * 1e-6 * width);
  const double q_n = 1e-8;
  const FaceInflow dry = face_inflow({true, true, 5e3, q_n, 1e4});
  EXPECT_LT(dry.worst, 1e-3);
  EXPECT_GT(dry.inflow_rate, q_n * width);  // the excess explained above, not its absence
  EXPECT_LT(dry.inflow_rate, 1.03 * q_n * width);
}

}  // namespace
}  // namespace mupm
