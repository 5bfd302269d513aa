// Fracture flow (include/mupm/kernels/fracture_flow.hpp, include/mupm/solvers/fracture_flow.hpp):
// a slot of fixed aperture carries the cubic-law rate a^3 dp/(12 mu L) per unit width; a
// fracture held at p_f drains the bulk at the rate of eq 19 (with the implicit exchange's
// factor); the bulk, the fracture and the conditions' inflows conserve water to round-off; the
// crack's water pushes each face with p_f per unit area; a mirrored Fracture Pressure on the
// layers a slot runs into gives the closed-form gradient.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>
#include <vector>

#include "mupm/input/model.hpp"
#include "mupm/kernels/fracture_flow.hpp"
#include "mupm/solvers/damage.hpp"
#include "mupm/solvers/fluid_solver.hpp"
#include "mupm/solvers/fracture_flow.hpp"
#include "mupm/solvers/linear_solve.hpp"
#include "mupm/solvers/solid_solver.hpp"
#include "mupm/solvers/step_sequence.hpp"
#include "slot.hpp"
#include "test_utils.hpp"

namespace mupm {
namespace {

using test::condition;
using test::flow_params;
using test::kDx;
using test::kNx;
using test::kNy;
using test::Slot;
using test::sum_owned;

// The least-squares line p_f = a x + b over the fracture points of region `mask`: (a, b).
std::pair<double, double> fit_pf_along_x(const Points<2>& p, std::uint32_t mask) {
  auto on = [&](std::size_t i) { return p.pf_saturation(i) > 0 && (p.regions(i) & mask); };
  const double n = sum_owned(p, [&](std::size_t i) { return on(i) ? 1.0 : 0.0; });
  const double sx = sum_owned(p, [&](std::size_t i) { return on(i) ? p.x(i, 0) : 0.0; });
  const double sp = sum_owned(p, [&](std::size_t i) { return on(i) ? p.pf(i) : 0.0; });
  const double sxx =
      sum_owned(p, [&](std::size_t i) { return on(i) ? p.x(i, 0) * p.x(i, 0) : 0.0; });
  const double sxp = sum_owned(p, [&](std::size_t i) { return on(i) ? p.x(i, 0) * p.pf(i) : 0.0; });
  const double a = (n * sxp - sx * sp) / (n * sxx - sx * sx);
  return {a, (sp - a * sx) / n};
}

// Fluid with fracture flow (semi-implicit when fprm.semi_implicit), solid and damage on one
// plate, initialized at t = 0, stepped by Algorithm 1's step sequence.
struct CoupledCrack {
  FluidSolver<2> fluid;
  bool enabled;  // fracture flow (and the semi-implicit pressure) enabled before the solid
  SolidSolver<2> solid;
  Damage<2> damage;
  StepSequence<2> seq;
  CoupledCrack(Discretization<2>& disc, const GridSpec<2>& g, const FluidParams& fprm,
               const MicropolarElastic& law, const SolidSolver<2>::Settings& set,
               const std::vector<BoundaryCondition>& bcs)
      : fluid(disc, fprm, bcs, MPI_COMM_WORLD),
        enabled(enable(fluid, set, fprm.semi_implicit)),
        solid(disc, solid_params(law, g, 0.5), bcs, set, MPI_COMM_WORLD),
        damage(disc, set.fracture.critical_damage, MPI_COMM_WORLD),
        seq{&solid, &fluid, &damage} {
    fluid.initialize(0, false);
    solid.initialize(0, false);
    fluid.reset_strain_reference();
    damage.update();
    if (fprm.semi_implicit)
      seq.skeleton = &solid;
  }
  static bool enable(FluidSolver<2>& f, const SolidSolver<2>::Settings& set, bool semi_implicit) {
    f.enable_fracture_flow(set.fracture);
    if (semi_implicit)
      f.enable_semi_implicit(LinearSolveSettings());
    return true;
  }
};

// The network's solve (FractureFlow::solve_settings, include/mupm/solvers/linear_solve.hpp) on
// the shape of its systems: a chain of n points with storage s and conductance c to the next two
// (conductances 1e6 times the storage, as along an open crack), distributed over the ranks,
// against the exact solution by Gaussian elimination in long double computed here. The
// residual reaches round-off of ||D x|| (D the diagonal: the tolerance's scale, as the network
// step uses it), and the solution is as close as a backward-stable solve's can be: within
// kappa eps of its largest value, kappa = 4 c / s the condition number (a double direct
// solve has the same bound).
TEST(FractureFlow, NetworkSolveMatchesTheExactSolution) {
  const int n = 300;
  const double s = 1e-6, c = 1.0;
  std::vector<std::vector<long double>> dense(n, std::vector<long double>(n + 1, 0.0L));
  for (int k = 0; k < n; ++k) {
    dense[k][k] += s;
    for (int step = 1; step <= 2; ++step)
      if (k + step < n) {
        dense[k][k] += c;
        dense[k + step][k + step] += c;
        dense[k][k + step] -= c;
        dense[k + step][k] -= c;
      }
  }
  std::vector<double> diag(n);
  for (int k = 0; k < n; ++k)
    diag[std::size_t(k)] = double(dense[k][k]);
  auto rhs = [](int k) { return std::sin(0.1 * k) + (k == 17 ? 1.0 : 0.0); };
  for (int k = 0; k < n; ++k)
    dense[k][n] = rhs(k);
  for (int k = 0; k < n; ++k)  // symmetric positive definite: no pivoting needed
    for (int r = k + 1; r < n; ++r) {
      const long double f = dense[r][k] / dense[k][k];
      if (f != 0)
        for (int q = k; q <= n; ++q)
          dense[r][q] -= f * dense[k][q];
    }
  std::vector<long double> exact(n);
  for (int k = n - 1; k >= 0; --k) {
    long double v = dense[k][n];
    for (int q = k + 1; q < n; ++q)
      v -= dense[k][q] * exact[q];
    exact[k] = v / dense[k][k];
  }
  auto map = Teuchos::rcp(new Map(n, 0, test::world()));
  auto a = Teuchos::rcp(new CrsMatrix(map, 5));
  TpetraVector b(map), x(map);
  {
    auto bv = b.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t l = 0; l < map->getNodeNumElements(); ++l) {
      const GlobalId k = map->getGlobalElement(LocalId(l));
      std::vector<GlobalId> cols;
      std::vector<double> vals;
      for (GlobalId q = std::max<GlobalId>(0, k - 2); q <= std::min<GlobalId>(n - 1, k + 2); ++q) {
        cols.push_back(q);
        vals.push_back(q == k ? diag[std::size_t(k)] : -c);
      }
      a->insertGlobalValues(k, Teuchos::ArrayView<const GlobalId>(cols),
                            Teuchos::ArrayView<const double>(vals));
      bv(l, 0) = rhs(int(k));
    }
  }
  a->fillComplete();
  LinearSolve solve(FractureFlow<2>::solve_settings());
  solve.set_matrix(a);
  // The scale of the network step's tolerance: ||D x|| at its start value (here x itself).
  double scale = 0;
  for (int k = 0; k < n; ++k)
    scale += std::pow(diag[std::size_t(k)] * double(exact[std::size_t(k)]), 2);
  scale = std::sqrt(scale);
  const LinearSolveResult r = solve.solve(b, x, scale);
  ASSERT_TRUE(r.converged);
  double worst = 0, largest = 0;
  {
    auto xv = x.getLocalViewHost(Tpetra::Access::ReadOnly);
    for (std::size_t l = 0; l < map->getNodeNumElements(); ++l) {
      const long double e = exact[std::size_t(map->getGlobalElement(LocalId(l)))];
      worst = std::max(worst, double(std::abs(xv(l, 0) - e)));
    }
  }
  for (int k = 0; k < n; ++k)
    largest = std::max(largest, double(std::abs(exact[k])));
  MPI_Allreduce(MPI_IN_PLACE, &worst, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0)
    std::printf("network solve: %d GMRES iterations, max |x - x_exact| = %.2e of max |x|\n",
                r.iterations, worst / largest);
  EXPECT_LT(r.residual, 1e-12);
  const double kappa = 4 * c / s;
  EXPECT_LT(worst, kappa * std::numeric_limits<double>::epsilon() * largest);
}

// A slot of aperture a between an inlet held at p1 and an outlet at 0, impervious bulk: at
// steady state the rate through it is a^3 h g / (12 mu), g the pressure gradient along it.
TEST(FractureFlow, CubicLawSlot) {
  Slot s;
  const double a = 1e-4, p1 = 1e5, mu = 1e-3;
  s.open(a);
  auto prm = fluid_params(s.g, 0.0, 0.5);  // impervious bulk: no exchange
  FluidSolver<2> fluid(s.disc, prm,
                       {condition(BoundaryCondition::FracturePressure, "inlet", 0, p1),
                        condition(BoundaryCondition::FracturePressure, "outlet", 1, 0.0)},
                       MPI_COMM_WORLD);
  fluid.enable_fracture_flow(flow_params());
  fluid.initialize(0.0, false);
  // Far beyond the slot's diffusion time L^2 (12 mu) / (a^2 K_w) ~ 7e-6 s: steady by then.
  const double dt = 1e-3;
  std::vector<double> in(2);
  for (int n = 0; n < 6; ++n) {
    const auto& q = fluid.fracture_flow()->inflows();
    in = {q[0], q[1]};
    fluid.advance(n * dt, dt, 1);
  }
  const auto& q = fluid.fracture_flow()->inflows();
  const double rate_in = (q[0] - in[0]) / (prm.water_density * dt);    // m^3/s
  const double rate_out = -(q[1] - in[1]) / (prm.water_density * dt);  // leaves at the outlet
  // The gradient in the middle half, by least squares over its fracture points.
  auto& p = s.disc.points;
  const double grad = fit_pf_along_x(p, 1u << 2).first;
  const double cubic = a * a * a * s.g.thickness * (-grad) / (12 * mu);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0)
    std::printf("slot: rate in %.6e, out %.6e, cubic law %.6e m^3/s (ratio %.5f), dp/dx %.4e\n",
                rate_in, rate_out, cubic, rate_in / cubic, grad);
  RecordProperty("rate_over_cubic_law", std::to_string(rate_in / cubic));
  EXPECT_LT(grad, 0.0);
  EXPECT_NEAR(rate_in, rate_out, 1e-9 * rate_in);  // steady: what enters leaves
  EXPECT_NEAR(rate_in / cubic, 1.0, 0.05);
  // The gradient is that of a linear drop over roughly the distance between the conditions.
  EXPECT_NEAR(-grad * (s.L - 6 * kDx), p1, 0.2 * p1);
}

// Mirrored Fracture Pressure (the boundary-layer issue): the slot of CubicLawSlot with
// boundary layers of 2 delta at both ends, the crack running through them, the inlet p1 held on
// the left layer and the outlet 0 on the right one. Steady flow through a slot of uniform
// aperture has p_f linear between the faces: p1 at x = 0, 0 at x = L. Mirrored layers
// (2 g - p_f of the mirror) continue that line into the layers, so the interior gradient must be
// -p1 / L; constant layers hold p1 and 0 beyond the faces and the smeared kink makes the slot act
// longer (reported as the extra length per face, against the ~0.7 delta of the bulk's layers).
double layered_slot_gradient(bool mirrored, double& face_value) {
  auto g = Slot::make();
  g.layers[0] = {6, 6};
  g.mirrored_layers = mirrored;
  const double L = kNx * kDx;
  Box left, right, middle;
  for (Box* b : {&left, &right, &middle}) {
    b->lo[0] = b->lo[1] = -1;
    b->hi[0] = b->hi[1] = 1;
  }
  left.hi[0] = -0.25 * kDx;
  right.lo[0] = L + 0.25 * kDx;
  middle.lo[0] = 0.25 * L;
  middle.hi[0] = 0.75 * L;
  g.regions = {left, right, middle};
  auto disc = discretize(test::world(), g);
  Damage<2> damage(disc, 0.3, MPI_COMM_WORLD);
  damage.update();
  const double a = 1e-4, p1 = 1e5, H = kNy * kDx;
  {
    auto x = disc.points.x, u = disc.points.u;
    Kokkos::parallel_for(
        range(0, disc.points.size()),
        KOKKOS_LAMBDA(const std::size_t i) { u(i, 1) = x(i, 1) > 0.5 * H ? 0.5 * a : -0.5 * a; });
    compute_aperture(disc.bonds, disc.points);
  }
  auto prm = fluid_params(g, 0.0, 0.5);  // impervious bulk: no exchange
  auto inlet = condition(BoundaryCondition::FracturePressure, "inlet", 0, p1);
  auto outlet = condition(BoundaryCondition::FracturePressure, "outlet", 1, 0.0);
  inlet.mirrored = outlet.mirrored = mirrored;
  FluidSolver<2> fluid(disc, prm, {inlet, outlet}, MPI_COMM_WORLD);
  fluid.enable_fracture_flow(flow_params());
  fluid.initialize(0.0, false);
  // Each step is far beyond the slot's diffusion time; the relaxed mirror value settles by a
  // factor of at most 1/2 per step (src/solvers/fracture_flow.cpp, assemble): 80 steps reach
  // round-off.
  const double dt = 1e-3;
  const double mass0 = fluid.fluid_mass() + fluid.fracture_flow()->mass();
  for (int n = 0; n < 80; ++n)
    fluid.advance(n * dt, dt, 1);
  // Water: bulk + fracture - start - what the two conditions supplied and the slot's volume
  // when it joined (FractureFlow::joined), to round-off.
  const auto& q = fluid.fracture_flow()->inflows();
  const double through = std::abs(q[0]);
  const double water = fluid.fluid_mass() + fluid.fracture_flow()->mass() - mass0 - q[0] - q[1] -
                       fluid.fracture_flow()->joined();
  EXPECT_LT(std::abs(water), 1e-9 * through) << "water not conserved";
  auto& p = disc.points;
  const auto [grad, at0] = fit_pf_along_x(p, 1u << 2);
  face_value = at0;  // the fitted line at x = 0
  return grad;
}

TEST(FractureFlow, MirroredFracturePressureLayers) {
  const double p1 = 1e5, L = kNx * kDx, delta = 3 * kDx;
  double f_const = 0, f_mirr = 0;
  const double g_const = layered_slot_gradient(false, f_const);
  const double g_mirr = layered_slot_gradient(true, f_mirr);
  const double exact = -p1 / L;
  const double extra = (p1 / -g_const - L) / 2;  // per face
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0)
    std::printf(
        "layered slot: dp/dx constant %.6e (%+.3f %%, %.3f delta more per face), "
        "mirrored %.6e (%+.2e), closed form %.6e; p_f(0) %.6e / %.6e of %.0e\n",
        g_const, 100 * (g_const / exact - 1), extra / delta, g_mirr, g_mirr / exact - 1, exact,
        f_const, f_mirr, p1);
  RecordProperty("gradient_error_constant", std::to_string(g_const / exact - 1));
  RecordProperty("gradient_error_mirrored", std::to_string(g_mirr / exact - 1));
  EXPECT_NEAR(g_mirr / exact, 1.0, 1e-6);
  EXPECT_NEAR(f_mirr, p1, 1e-6 * p1);
  EXPECT_GT(std::abs(g_const / exact - 1), 100 * std::abs(g_mirr / exact - 1));
}

// A fracture held at p_f = 0 in a saturated bulk at p0 (no bulk flow: p is uniform): in one step
// dt each fracture point's bulk loses dt G' p0 per unit volume, G = 2 k / (mu dx^2) (eq 19 with
// l_x = dx/2, A/V = 1/dx), G' = G C / (C + dt G) (the implicit exchange); bulk + fracture +
// reservoir water is conserved.
TEST(FractureFlow, ExchangeDrainsTheBulkAtTheRateOfEq19) {
  Slot s;
  s.open(1e-4);
  const double k_mu = 1e-12, p0 = 2e5, phi = 0.2;
  auto prm = fluid_params(s.g, k_mu, 0.5);
  auto& p = s.disc.points;
  Kokkos::deep_copy(p.porosity, phi);
  Kokkos::deep_copy(p.p, p0);
  FluidSolver<2> fluid(s.disc, prm,
                       {condition(BoundaryCondition::FracturePressure, "drain", -1, 0.0)},
                       MPI_COMM_WORLD);
  fluid.enable_fracture_flow(flow_params());
  fluid.initialize(0.0, false);
  const double C = phi / prm.bulk_modulus, G = 2 * k_mu / (kDx * kDx);
  const double dt = 0.2 * C / G;  // dt G / C = 0.2: G' = G / 1.2
  const double Gp = G * C / (C + dt * G);
  std::vector<double> m0(p.n_owned);
  for (std::size_t i = 0; i < p.n_owned; ++i)
    m0[i] = p.fluid_content(i);
  const double mass0 = fluid.fluid_mass();
  fluid.advance(0.0, dt, 1);
  double worst = 0, far = 0, n = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const double dm = p.fluid_content(i) - m0[i];
    if (p.fracture(i)) {
      worst = std::max(worst, std::abs(dm + dt * Gp * p0) / (dt * Gp * p0));
      n += 1;
    } else {
      far = std::max(far, std::abs(dm));
    }
  }
  MPI_Allreduce(MPI_IN_PLACE, &worst, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &far, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(n, 2.0 * kNx);  // one row each side of the crack
  EXPECT_LT(worst, 1e-9);   // every fracture point's bulk lost dt G' p0
  EXPECT_LT(far, 1e-9 * dt * Gp * p0);
  // The bulk pressure of a fracture point fell to p0 C / (C + dt G).
  double pw = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i)
    if (p.fracture(i))
      pw = std::max(pw, std::abs(p.p(i) - p0 * C / (C + dt * G)) / p0);
  MPI_Allreduce(MPI_IN_PLACE, &pw, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  EXPECT_LT(pw, 1e-9);
  // Water: the bulk lost what the fracture and its reservoir took (besides the crack's volume
  // when it joined, FractureFlow::joined).
  const double lost = mass0 - fluid.fluid_mass();
  const double taken = fluid.fracture_flow()->mass() - fluid.fracture_flow()->inflows()[0] -
                       fluid.fracture_flow()->joined();
  EXPECT_GT(lost, 0.0);
  EXPECT_NEAR(taken, lost, 1e-12 * mass0);
}

// Injection into a closed slot in a permeable bulk, with the crack's aperture changing every
// step: over many steps the water in the bulk plus the fracture equals the initial water plus
// the injected, to round-off of the total; the pressure rose at the mouth first.
TEST(FractureFlow, InjectionConservesWater) {
  Slot s;
  auto prm = fluid_params(s.g, 1e-13, 0.5);
  auto& p = s.disc.points;
  Kokkos::deep_copy(p.porosity, 0.2);
  const double q = 5e-5;
  FluidSolver<2> fluid(s.disc, prm, {condition(BoundaryCondition::FractureSource, "mouth", 0, q)},
                       MPI_COMM_WORLD);
  fluid.enable_fracture_flow(flow_params());
  fluid.initialize(0.0, false);
  const double mass0 = fluid.fluid_mass();
  const double dt = 1e-5;
  double worst = 0;
  for (int n = 0; n < 40; ++n) {
    s.open(1e-5 * (1 + 0.1 * n));  // the aperture grows: conductance and storage change
    fluid.advance(n * dt, dt, 1);
    const double total = fluid.fluid_mass() + fluid.fracture_flow()->mass();
    const double in = fluid.fracture_flow()->inflows()[0] + fluid.fracture_flow()->joined();
    worst = std::max(worst, std::abs(total - mass0 - in) / mass0);
  }
  const double injected = fluid.fracture_flow()->inflows()[0];
  EXPECT_NEAR(injected, 1000 * q * 40 * dt, 1e-12 * injected);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0)
    std::printf("injection: water error %.3e of the body's water, %.3e of the injected\n", worst,
                worst * mass0 / injected);
  EXPECT_LT(worst, 1e-12);
  EXPECT_GT(fluid.fracture_flow()->mass(), 0.0);
}

// The crack's volume change (fracture_flow.hpp header), in an impervious bulk. A closed slot
// opened from a0 to a1 at fixed water content loses p_f by K_w (a1 - a0)/(a1 + a_min)
// (saturated; a_min the film in the storage). Water
// injected at q into a slot whose crack volume grows by exactly q h dt per step keeps its
// crack-volume-weighted mean p_f (without the opening term it would rise by K_w q h dt / V_f per
// step). A wrong sign or factor of the opening term fails both. The solid's undrained p_f*
// (kernels/fracture_flow.hpp) predicts each step's p_f of the closed slot.
TEST(FractureFlow, OpeningCrackStoresWater) {
  const double p0 = 1e6, a0 = 1e-4, q = 5e-5, dt = 1e-6, amin = flow_params().min_aperture;
  for (const bool inject : {false, true}) {
    Slot s;
    s.open(a0);
    auto prm = fluid_params(s.g, 0.0, 0.5);
    auto& p = s.disc.points;
    Kokkos::deep_copy(p.p, p0);
    std::vector<BoundaryCondition> bcs;
    if (inject) {
      bcs.push_back(condition(BoundaryCondition::FractureSource, "everywhere", -1, q));
      bcs.back().time.kind = TimeFunction::Table;  // none during the first step
      bcs.back().time.times = {0.0, dt};
      bcs.back().time.values = {0.0, 1.0};
    }
    FluidSolver<2> fluid(s.disc, prm, bcs, MPI_COMM_WORLD);
    fluid.enable_fracture_flow(flow_params());
    fluid.initialize(0.0, false);
    fluid.advance(0.0, dt, 1);  // the crack joins the network at a0, filled at p0
    auto on = [&](std::size_t i) { return p.pf_saturation(i) > 0; };
    // Crack volume per unit opening s: sum V a_i / (n_i dx) / s, n_i = 2 rows (apertures at
    // the slot's ends are below s: their families are one-sided).
    const double h = s.g.thickness;
    const double k_vol =
        sum_owned(p, [&](std::size_t i) { return on(i) ? p.volume(i) * p.aperture(i) : 0.0; }) /
        (2 * kDx * a0);
    double a = a0, expected = p0;
    // The crack water's work on the opening faces, int p dV_crack, by the trapezoid over the
    // closed form's pressures (closed slot), and the injection's work at p0 (header of
    // solvers/fracture_flow.hpp: both booked at the step's mean pressure).
    double w_open = 0, w_inject = 0;
    const int steps = 5;
    for (int n = 1; n <= steps; ++n) {
      const double a1 = inject ? a + q * h * dt / k_vol : a * 1.0001;
      const double before = expected;
      if (!inject)
        expected -= prm.bulk_modulus * (a1 - a) / (a1 + amin);  // backward Euler, dp = -K_w da/a
      w_open += 0.5 * (before + expected) * k_vol * (a1 - a);
      w_inject += p0 * q * h * dt;
      a = a1;
      s.open(a);
      // The solid's undrained p_f* at the new opening (kernels/fracture_flow.hpp) is the p_f the
      // step reaches where no water moves (closed slot, uniform opening but for the ends).
      Scalars pstar("pstar", p.size());
      undrained_fracture_pressure(s.disc.bonds, p, pstar);
      fluid.advance(n * dt, dt, 1);
      if (!inject) {
        double dev = 0, mid = 0;
        for (std::size_t i = 0; i < p.n_owned; ++i)
          if (on(i) && (p.regions(i) & (1u << 2))) {
            dev = std::max(dev, std::abs(pstar(i) - p.pf(i)));
            mid = std::max(mid, std::abs(p.pf(i) - p0));
          }
        MPI_Allreduce(MPI_IN_PLACE, &dev, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
        EXPECT_LT(dev, 1e-3 * mid) << "step " << n << ": p_f* off the step's p_f by " << dev;
      }
    }
    const double n_net = sum_owned(p, [&](std::size_t i) { return on(i) ? 1.0 : 0.0; });
    EXPECT_EQ(n_net, 2.0 * kNx);
    if (!inject) {
      double worst = 0;
      for (std::size_t i = 0; i < p.n_owned; ++i)
        if (on(i))
          worst = std::max(worst, std::abs(p.pf(i) - expected));
      MPI_Allreduce(MPI_IN_PLACE, &worst, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
      EXPECT_LT(expected, p0 - 1e6);  // a drop of ~1.1 MPa
      // Uniform but for the slot's ends, whose apertures (one-sided families) are below a while
      // the film a_min is not: measured 5.4 Pa of the 1.1 MPa drop.
      EXPECT_LT(worst, 1e-4 * (p0 - expected)) << "closed slot: p_f off by " << worst << " Pa";
    } else {
      const double vf = k_vol * a;  // the crack's volume now (the film adds 0.1 %)
      const double mean =
          sum_owned(p,
                    [&](std::size_t i) {
                      return on(i) ? p.volume(i) * (p.aperture(i) + amin) * (p.pf(i) - p0) : 0.0;
                    }) /
          (2 * kDx * vf);
      const double rise = prm.bulk_modulus * steps * q * h * dt / vf;  // without the term
      int rank = 0;
      MPI_Comm_rank(MPI_COMM_WORLD, &rank);
      if (rank == 0)
        std::printf("opening slot: mean p_f change %.3e Pa (%.2e Pa without the opening term)\n",
                    mean, rise);
      // The weights take n_i = 2 rows everywhere; at the slot's corners the one-sided families
      // tilt the crack normal past 30 degrees and the solver counts n_i = 1 (measured: 1.3 % of
      // the rise). A missing opening term gives 100 %, a wrong sign 200 %, a factor 2 100 %.
      EXPECT_GT(rise, 4e4);
      EXPECT_LT(std::abs(mean), 0.05 * rise);
    }
    // The crack water's energy (solvers/fracture_flow.hpp header): saturated, so its balance
    // closes to round-off; its terms against the closed forms. Closed slot: the water's content
    // is fixed, its pressure energy pays for the opening, W_sk = -(E - E_0) = int p dV.
    // Injection: the injected water enters at p0 (its mean pressure moves by < 0.05 rise, 0.2 %
    // of p0) and opens the slot by its volume, so W_sk = W_ext up to the compression that rise
    // is. The network's volume change is measured 1.25 % below k_vol da, step after step, in
    // both cases: the slot's end points, whose one-sided families tilt the crack normal, count
    // their rows n_i otherwise than k_vol's 2 (the 1.3 % of the rise above), hence 2 %. A term
    // with the wrong sign or a factor 2 is off by 100 % or more.
    const auto& fe = fluid.fracture_flow()->energy();
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    if (rank == 0)
      std::printf(
          "crack water energy (%s): E - E_0 %.6e J, W_sk %.6e J, D %.3e J, W_ext %.6e J, "
          "W_x %.3e J, balance %.3e J; closed form int p dV %.6e J, p0 Q t %.6e J\n",
          inject ? "injection" : "closed slot", fe.stored, fe.skeleton_work, fe.dissipation,
          fe.external_work, fe.exchange_work, fe.balance(), w_open, w_inject);
    EXPECT_LT(std::abs(fe.balance()), 1e-10 * fe.scale());
    EXPECT_EQ(fe.exchange_work, 0.0);  // impervious bulk
    if (!inject) {
      EXPECT_GT(w_open, 0.0);
      EXPECT_NEAR(fe.skeleton_work, w_open, 0.02 * w_open);
      EXPECT_NEAR(fe.stored, -fe.skeleton_work, 1e-6 * w_open);  // D: the ends' 5 Pa
      EXPECT_EQ(fe.external_work, 0.0);
    } else {
      EXPECT_NEAR(fe.external_work, w_inject, 5e-3 * w_inject);
      EXPECT_NEAR(fe.skeleton_work, w_inject, 0.02 * w_inject);
    }
  }
}

// A uniform p_f on a straight crack pushes each face apart with p_f per unit area: the force on
// the points above the crack, over the middle half of its length (full families), is
// p_f * (L/2) * h along +y, exactly (kernels/fracture_flow.hpp: each network point's share
// A_i = V_i / (n_i dx) of the face, n_i = 2 rows here, pushes both faces). The previous force
// (central pairs over the continuum's crossing measure) gave 0.97458 of it.
TEST(FractureFlow, FacePressure) {
  Slot s;
  auto& p = s.disc.points;
  const double pf = 3e5;
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    p.pf(i) = p.fracture(i) ? pf : 0.0;
    p.pf_saturation(i) = p.fracture(i) ? 1.0 : 0.0;
    p.pf_area(i) = p.fracture(i) ? p.volume(i) / (2 * kDx) : 0.0;
  }
  Vectors g("g", p.size(), 2), body("body", p.n_owned, 2);
  crack_face_load(s.disc.bonds, p, p.pf, g);
  s.disc.dist.refresh({g});
  crack_pressure_force(s.disc.bonds, p, g, body);
  const std::uint32_t mid = 1u << 2;
  double fy[2] = {0, 0}, fx = 0, total[2] = {0, 0};
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    for (int d = 0; d < 2; ++d)
      total[d] += body(i, d) * p.volume(i);
    if (!(p.regions(i) & mid))
      continue;
    fy[p.x(i, 1) > 0.5 * s.H ? 0 : 1] += body(i, 1) * p.volume(i);
    fx += body(i, 0) * p.volume(i);
  }
  MPI_Allreduce(MPI_IN_PLACE, fy, 2, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &fx, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, total, 2, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  const double expected = pf * 0.5 * s.L * s.g.thickness;
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0)
    std::printf("face force: upper %.6e, lower %.6e, p_f A %.6e (ratio %.8f)\n", fy[0], fy[1],
                expected, fy[0] / expected);
  RecordProperty("face_force_over_pA", std::to_string(fy[0] / expected));
  EXPECT_NEAR(fy[0] / expected, 1.0, 1e-12);  // the upper face is pushed up with p_f A
  EXPECT_NEAR(fy[1], -fy[0], 1e-12 * fy[0]);  // and the lower one down, equally
  EXPECT_NEAR(fx, 0.0, 1e-12 * fy[0]);        // no force along the crack
  // Equal and opposite pair forces: no net force on the body.
  EXPECT_NEAR(total[0], 0.0, 1e-12 * fy[0]);
  EXPECT_NEAR(total[1], 0.0, 1e-12 * fy[0]);
}

// The crack water's work on the skeleton is booked twice, by the solid as its face forces' work
// (SolidSolver::Energy::crack_work, part of W_ext) and by the network as sum V p_m S_rf dphi_f
// (solvers/fracture_flow.hpp header, from the points' mean openings): the coupled pair conserves
// energy only if the two agree. The slot, cut through the plate, is held at p_f = p0 and its two
// halves are pushed apart for 400 steps (undamped, impervious bulk). The solid's force is the
// conjugate of the network's crack volume (kernels/fracture_flow.hpp), and with p_f held both
// are p0 times the same volume change: equal to round-off, whatever the halves' deformation.
// (The previous central pair force gave the solid 0.97423 of the network's work here.) A wrong
// sign or factor of either, or a force not conjugate to the volume, is off by percents or more.
TEST(FractureFlow, CrackForceWorkMatchesTheCrackWaterWork) {
  Slot s;
  const double p0 = 1e5;
  const auto law = MicropolarElastic::from_bulk_shear(270.83e6, 220.33e6, 100e6, 7.5e-3);
  auto fprm = fluid_params(s.g, 0.0, 0.5);  // impervious bulk: no exchange
  SolidSolver<2>::Settings set;
  set.fracture = flow_params();
  set.fracture.min_aperture = 1e-5;
  set.fracture.water_modulus = fprm.bulk_modulus;
  const std::vector<BoundaryCondition> bcs = {
      condition(BoundaryCondition::FracturePressure, "crack", -1, p0)};
  Kokkos::deep_copy(s.disc.points.saturation, 1.0);
  Kokkos::deep_copy(s.disc.points.porosity, 0.2);
  CoupledCrack run(s.disc, s.g, fprm, law, set, bcs);
  const double dt = 0.5 * run.solid.estimate_stable_dt();
  const int steps = 400;
  for (int n = 0; n < steps; ++n)
    run.seq.step(n, n * dt, dt);
  const double w_solid = run.solid.energy().crack_work;
  const auto& fe = run.fluid.fracture_flow()->energy();
  const double ratio = w_solid / fe.skeleton_work;
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0)
    std::printf(
        "crack water's work on the skeleton: solid (face forces) %.6e J, network "
        "(sum V p S dphi_f) %.6e J, ratio %.5f; crack water balance %.2e J of %.3e J\n",
        w_solid, fe.skeleton_work, ratio, fe.balance(), fe.scale());
  RecordProperty("crack_force_over_network_work", std::to_string(ratio));
  EXPECT_GT(fe.skeleton_work, 0.0);  // the faces move apart under the water's push
  EXPECT_NEAR(ratio, 1.0, 1e-9);
  EXPECT_LT(std::abs(fe.balance()), 1e-10 * fe.scale());
}

// Crack Water Force = Eq 17: a bond between two network points carries the water part of p_f
// in place of p's. With every point in the network at p_f = p0 and p = 0, every bond is such a
// bond: the forces must equal those of p = p0 without fracture flow (a wrong sign or factor of
// the replacement would not).
TEST(FractureFlow, Eq17ReplacesThePorePressureOnFractureBonds) {
  Slot s;
  auto& p = s.disc.points;
  const double p0 = 4e5;
  Kokkos::deep_copy(p.saturation, 1.0);
  const auto law = MicropolarElastic::from_bulk_shear(270.83e6, 220.33e6, 100e6, 7.5e-3);
  const auto prm = solid_params(law, s.g, 0.5);
  auto forces = [&](bool eq17) {
    SolidState<2> st;
    st.allocate(p.size(), p.n_owned);
    if (eq17)
      st.allocate_eq17(p.size(), p.n_owned);
    Kokkos::deep_copy(p.p, eq17 ? 0.0 : p0);
    Kokkos::deep_copy(p.pf, eq17 ? p0 : 0.0);
    Kokkos::deep_copy(p.pf_saturation, eq17 ? 1.0 : 0.0);
    solid_forces(s.disc, prm, st);
    return st.force;
  };
  const auto ref = forces(false), f17 = forces(true);
  double diff = 0, scale = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i)
    for (int d = 0; d < 2; ++d) {
      diff = std::max(diff, std::abs(f17(i, d) - ref(i, d)));
      scale = std::max(scale, std::abs(ref(i, d)));
    }
  MPI_Allreduce(MPI_IN_PLACE, &diff, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &scale, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  EXPECT_GT(scale, 0.0);  // p0 pushes the free faces
  EXPECT_LT(diff, 1e-9 * scale);
}

// Pressure Integration = Semi-Implicit with fracture flow (include/mupm/solvers/
// pressure_projection.hpp): the crack water's pressure comes from the joint solve, the solid
// applies it without the undrained spring, and the step is the drained skeleton's. Water is
// injected (ramped up over 20 steps, then constant) into the slot cut through the plate, whose
// halves are free; bulk and crack water are incompressible and the bulk impervious, so the
// crack must open by exactly the water injected: sum_i S_rf A_i c_i (the crack volume of the
// face force's conjugate, c_i the mean opening of eq 39 at the displacement reached) equals the
// injected volume to the solve's tolerance. Water and the crack water's energy are conserved,
// and the solid's balance closes. The film a_min = 1e-5 m would hold the explicit scheme to the
// crack water's K_w / a_min step (infinite here). Measured: B_f (the crack volume's Jacobian in
// the solve) of the wrong sign diverges; twice its value leaves the volume within 5e-4 (each
// step's right-hand side takes the opening actually reached) but the crack water's balance off
// by 40 % of its scale (the face force then does other work than the network books).
TEST(FractureFlowSemiImplicit, IncompressibleCrackOpensByTheInjectedVolume) {
  Slot s;
  auto& p = s.disc.points;
  const double q = 2e-5, inf = std::numeric_limits<double>::infinity();
  const auto law = MicropolarElastic::from_bulk_shear(270.83e6, 220.33e6, 100e6, 7.5e-3);
  auto fprm = fluid_params(s.g, 0.0, 0.5);  // impervious bulk: no exchange
  fprm.bulk_modulus = inf;
  fprm.semi_implicit = true;
  SolidSolver<2>::Settings set;
  set.fracture = flow_params();
  set.fracture.min_aperture = 1e-5;
  set.fracture.water_modulus = inf;
  set.semi_implicit = true;
  std::vector<BoundaryCondition> bcs = {
      condition(BoundaryCondition::FractureSource, "everywhere", -1, q)};
  Kokkos::deep_copy(p.saturation, 1.0);
  Kokkos::deep_copy(p.porosity, 0.2);
  // The drained skeleton's step (the solid's estimate, semi-implicit: no crack water in it), on
  // a copy of the plate, to ramp the injection over 20 steps.
  double dt = 0;
  {
    Slot s0;
    Kokkos::deep_copy(s0.disc.points.saturation, 1.0);
    SolidSolver<2> solid0(s0.disc, solid_params(law, s0.g, 0.5), {}, set, MPI_COMM_WORLD);
    solid0.initialize(0, false);
    dt = 0.5 * solid0.estimate_stable_dt();
  }
  bcs[0].time.kind = TimeFunction::Table;
  bcs[0].time.times = {0.0, 20 * dt};
  bcs[0].time.values = {0.0, 1.0};
  CoupledCrack run(s.disc, s.g, fprm, law, set, bcs);
  auto& fluid = run.fluid;
  const int steps = 100;
  for (int n = 0; n < steps; ++n)
    run.seq.step(n, n * dt, dt);
  const auto& b = s.disc.bonds;
  const double crack = sum_owned(p, [&](std::size_t i) {
    return p.pf_saturation(i) > 0
               ? p.pf_saturation(i) * p.pf_area(i) *
                     mean_opening<2>(b.offsets, b.neighbor, b.intact, p.x, p.u, p.volume, i)
               : 0.0;
  });
  const auto* ff = fluid.fracture_flow();
  const double injected = ff->inflows()[0] / fprm.water_density;
  double expected = 0;  // the source's rate at each step's start (fracture_flow.hpp)
  for (int n = 0; n < steps; ++n)
    expected += q * s.g.thickness * std::min(1.0, n / 20.0) * dt;
  const auto& fe = ff->energy();
  const auto e = run.solid.energy();
  const double water = fluid.fluid_mass() + ff->mass();
  const double water0 = fprm.water_density * 0.2 * s.L * s.H * s.g.thickness;
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0)
    std::printf(
        "semi-implicit crack: dt %.3e s; crack volume %.9e m^3, injected %.9e m^3 (ratio "
        "%.10f); water error %.2e kg; crack water balance %.2e J of %.2e J; solid %.2e J of "
        "%.2e J\n",
        dt, crack, injected, crack / injected, water - water0 - ff->inflows()[0] - ff->joined(),
        fe.balance(), fe.scale(), e.balance(), e.scale());
  EXPECT_NEAR(injected, expected, 1e-12 * expected);
  EXPECT_GT(crack, 0.0);
  EXPECT_NEAR(crack / injected, 1.0, 1e-6);
  EXPECT_LT(std::abs(water - water0 - ff->inflows()[0] - ff->joined()), 1e-12 * water0);
  EXPECT_LT(std::abs(fe.balance()), 1e-10 * fe.scale());
  EXPECT_LT(std::abs(e.balance()), 1e-3 * e.scale());
  EXPECT_GT(dt, 1e-6);  // the drained skeleton's step (K_w / a_min would make it zero)
}

// The same scheme through bond breakage: water injected at the mouth of an edge crack in a free
// plate (real water, a film a_min = 1e-5 m, a weak skeleton) breaks bonds at the crack's tip.
// The crack water's balance is booked with the opening over the bonds the solve used, and the
// broken bonds' jump of the mean opening enters the next step's water balance: the balance
// closes to round-off through the breakage (measured with the opening taken after the
// breakage instead: off by 58 % of its scale here), and water is conserved. The solid's balance
// closes through the first breakage step.
TEST(FractureFlowSemiImplicit, CrackWaterBalanceHoldsThroughBreakage) {
  constexpr double dx = 5e-3;
  auto g = test::box<2>({32, 16}, 2.0, dx);
  const double L = 32 * dx, H = 16 * dx;
  Crack c;
  c.a[0] = -1;
  c.a[1] = 0.5 * H;
  c.b[0] = 0.4 * L;
  c.b[1] = 0.5 * H;
  g.cracks = {c};
  g.region_names = {"mouth"};
  g.regions = {test::box2(-1, 2 * dx, -1, 1)};
  Discretization<2> disc = discretize(test::world(), g);
  auto& p = disc.points;
  const auto law = MicropolarElastic::from_bulk_shear(270.83e6, 220.33e6, 100e6, 1e-3);
  auto fprm = fluid_params(g, 1e-16, 0.5);
  fprm.semi_implicit = true;
  SolidSolver<2>::Settings set;
  set.fracture = flow_params();
  set.fracture.viscosity = 1e-5;
  set.fracture.min_aperture = 1e-5;
  set.fracture.criterion = BondBreaking::Energy;
  set.fracture.effective_state = false;
  set.fracture.critical_energy = critical_bond_energy<2>(0.05, g.horizon, g.thickness);
  set.semi_implicit = true;
  const std::vector<BoundaryCondition> bcs = {
      condition(BoundaryCondition::FractureSource, "mouth", 0, 1e-3)};
  Kokkos::deep_copy(p.saturation, 1.0);
  Kokkos::deep_copy(p.porosity, 0.2);
  CoupledCrack run(disc, g, fprm, law, set, bcs);
  auto& fluid = run.fluid;
  auto& solid = run.solid;
  auto& seq = run.seq;
  const double dt = 0.5 * solid.estimate_stable_dt();
  solid.set_time_step(dt);  // the ledger's kinetic shift (SolidSolver::Energy)
  const long long broken0 = solid.broken_pairs();
  const double water0 = fluid.fluid_mass();
  const auto* ff = fluid.fracture_flow();
  double worst = 0, solid_worst = 0, solid_first = -1;
  const double solid0 = solid.energy().balance();
  int n = 0, after = 0;
  for (; n < 1500 && after < 100; ++n) {
    seq.step(n, n * dt, dt);
    worst = std::max(worst, std::abs(ff->energy().balance()) / ff->energy().scale());
    const auto e = solid.energy();
    const double solid_error = std::abs(e.balance() - solid0) / e.scale();
    solid_worst = std::max(solid_worst, solid_error);
    if (solid.broken_pairs() > broken0 && after++ == 0)
      solid_first = solid_error;  // the step of the first breakage
  }
  const double water = fluid.fluid_mass() + ff->mass();
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0)
    std::printf(
        "semi-implicit crack through breakage: %lld pairs broken in %d steps of %.3e s; crack "
        "water balance at most %.2e of its scale; water error %.2e kg of %.3e kg; solid balance "
        "%.2e of its scale after the first breakage step, at most %.2e\n",
        solid.broken_pairs() - broken0, n, dt, worst,
        water - water0 - ff->inflows()[0] - ff->joined(), water0, solid_first, solid_worst);
  EXPECT_GT(solid.broken_pairs(), broken0);  // the tip broke
  EXPECT_LT(worst, 1e-10);
  EXPECT_LT(std::abs(water - water0 - ff->inflows()[0] - ff->joined()), 1e-12 * water0);
  // The solid's balance through the first breakage step: the jump of the kinetic shift with the
  // accelerations is booked with the fracture dissipation (SolidSolver::after_breakage): closed
  // to round-off (unbooked, 1.4e-3 of the scale). Later steps here drift by up to 0.34 of the
  // scale as the crack runs through the plate (282 pairs in 106 steps, points joining the
  // network): not closed, recorded in inputs/README.md (Example 1 case 1, semi-implicit).
  EXPECT_GE(solid_first, 0.0);
  EXPECT_LT(solid_first, 1e-12);
}

}  // namespace
}  // namespace mupm
