// The solid step with boundary conditions: a bar under traction (static equilibrium against
// the closed form and exact reaction), and the stable-step estimate against the actual
// stability limit of the central-difference scheme.
#include <gtest/gtest.h>

#include <cmath>

#include "mupm/input/model.hpp"
#include "mupm/solvers/solid_solver.hpp"
#include "test_utils.hpp"

namespace mupm {
namespace {

SolidParams params(const MicropolarElastic& law, const GridSpec<2>& g) {
  return solid_params(law, g, 0.5);
}

const MicropolarElastic kLaw =
    MicropolarElastic::from_bulk_shear(270.83e6, 220.33e6, 100e6, 7.5e-3);

// Bar 0 <= x <= L, 0 <= y <= H, held at x = 0 by a boundary layer (u_x = 0), traction t on the
// outermost column at x = L. At rest: sigma_xx = t, sigma_yy = 0 (free sides), plane strain:
// eps_xx = t (1 - nu^2) / E; the reaction equals -t H exactly.
TEST(SolidSolver, BarUnderTraction) {
  const double dx = 2.5e-3, t = 1e5;
  auto g = test::box<2>({40, 8}, 3.015, dx);
  g.layers[0] = {6, 0};
  const double L = 40 * dx, H = 8 * dx;
  Box left, right;
  left.lo[0] = -1;
  left.hi[0] = -0.25 * dx;
  left.lo[1] = -1;
  left.hi[1] = 1;
  right.lo[0] = L - dx;
  right.hi[0] = L;
  right.lo[1] = -1;
  right.hi[1] = 1;
  g.region_names = {"left", "right"};
  g.regions = {left, right};
  auto disc = discretize(test::world(), g);
  Kokkos::deep_copy(disc.points.saturation, 1.0);
  BoundaryCondition hold, pull;
  hold.name = "hold";
  hold.kind = BoundaryCondition::Displacement;
  hold.region_mask = 1u << 0;
  hold.component = 0;
  pull.name = "pull";
  pull.kind = BoundaryCondition::Traction;
  pull.region_mask = 1u << 1;
  pull.component = 0;
  pull.value = t;
  typename SolidSolver<2>::Settings set;
  const double c_p = std::sqrt((kLaw.lambda + 2 * kLaw.mu) / set.rho_s);
  set.damping = 2 * kPi * c_p / (4 * L) * 2;  // about critical for the first axial mode
  SolidSolver<2> solver(disc, params(kLaw, g), {hold, pull}, set, MPI_COMM_WORLD);
  solver.initialize(0.0, false);
  const double dt = 0.5 * solver.estimate_stable_dt();
  double time = 0;
  for (int n = 0; n < 6000; ++n, time += dt)
    solver.step(time, dt);

  const double E = kLaw.young(), nu = kLaw.poisson();
  const double strain = t * (1 - nu * nu) / E;
  // Strain from the displacement of the middle row between x = L/4 and 3L/4.
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.x);
  auto u = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.u);
  double ua = 0, ub = 0;
  for (std::size_t i = 0; i < disc.points.n_owned; ++i) {
    if (std::abs(x(i, 1) - 4.5 * dx) > 0.1 * dx)
      continue;
    if (std::abs(x(i, 0) - 10.5 * dx) < 0.1 * dx)
      ua = u(i, 0);
    if (std::abs(x(i, 0) - 30.5 * dx) < 0.1 * dx)
      ub = u(i, 0);
  }
  MPI_Allreduce(MPI_IN_PLACE, &ua, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &ub, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  const double measured = (ub - ua) / (20 * dx);
  RecordProperty("strain_ratio", std::to_string(measured / strain));
  EXPECT_NEAR(measured / strain, 1.0, 0.03) << measured << " vs " << strain;
  const auto r = solver.reactions();
  ASSERT_EQ(r.size(), 1u);
  EXPECT_NEAR(r[0], -t * H * g.thickness, 1e-3 * t * H) << "reaction";
  const auto e = solver.energy();
  EXPECT_LT(e.kinetic, 1e-6 * e.internal);  // at rest
  EXPECT_LT(std::abs(e.balance()), 1e-3 * e.external_work);
}

// A uniform body couple m on a body whose displacements are held: at rest the Cosserat
// coupling balances it, -4 mu_c theta + m = 0 (from sigma_xy - sigma_yx = 4 mu_c theta, eq 80),
// so theta = m / (4 mu_c) (uniform: no couple stress, and free faces need d theta/dn = 0).
// The truncated families at the faces perturb theta there (17 % at the face, still 0.6 % at
// 6 dx inside); the centre of this body, 18 dx inside, is checked to 1e-3.
TEST(SolidSolver, BodyCoupleAgainstCosseratCoupling) {
  const double dx = 2.5e-3;
  auto g = test::box<2>({40, 40}, 3.015, dx);
  auto disc = discretize(test::world(), g);
  Kokkos::deep_copy(disc.points.saturation, 1.0);
  BoundaryCondition hold_x, hold_y, couple;
  hold_x.kind = hold_y.kind = BoundaryCondition::Displacement;
  hold_x.name = "hx";
  hold_y.name = "hy";
  hold_y.component = 1;
  couple.kind = BoundaryCondition::BodyCouple;
  couple.name = "m";
  couple.value = 4e4;  // N m / m^3
  typename SolidSolver<2>::Settings set;
  set.damping = 5e4;  // near critical for the rotation: omega = sqrt(4 mu_c / J) = 4.7e4 /s
  SolidSolver<2> solver(disc, params(kLaw, g), {hold_x, hold_y, couple}, set, MPI_COMM_WORLD);
  solver.initialize(0.0, false);
  const double dt = 0.5 * solver.estimate_stable_dt();
  double time = 0;
  for (int n = 0; n < 3000; ++n, time += dt)
    solver.step(time, dt);
  auto th = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.theta);
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.x);
  const double expected = couple.value / (4 * kLaw.mu_c);
  int n = 0;
  for (std::size_t i = 0; i < disc.points.n_owned; ++i) {
    if (x(i, 0) < 18 * dx || x(i, 0) > 22 * dx || x(i, 1) < 18 * dx || x(i, 1) > 22 * dx)
      continue;
    ++n;
    EXPECT_NEAR(th(i, 0), expected, 1e-3 * expected) << "point " << i;
  }
  MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(n, 16);
  const auto e = solver.energy();
  EXPECT_LT(std::abs(e.balance()), 1e-3 * e.external_work);
  EXPECT_GT(e.external_work, 0.0);
}

// Below the estimated stable step the undamped scheme stays bounded; above it, it blows up.
double energy_growth(double factor) {
  auto g = test::box<2>({12, 10}, 3.015, 2.5e-3);
  auto disc = discretize(test::world(), g);
  Kokkos::deep_copy(disc.points.saturation, 1.0);
  typename SolidSolver<2>::Settings set;
  SolidSolver<2> solver(disc, params(kLaw, g), {}, set, MPI_COMM_WORLD);
  auto v = Kokkos::create_mirror_view(disc.points.v);
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.gid);
  for (std::size_t i = 0; i < disc.points.size(); ++i) {
    v(i, 0) = 1e-3 * std::sin(2.1 * double(gid(i)));
    v(i, 1) = 1e-3 * std::cos(1.3 * double(gid(i)));
  }
  Kokkos::deep_copy(disc.points.v, v);
  solver.initialize(0.0, false);
  const double dt = factor * solver.estimate_stable_dt();
  const double e0 = solver.energy().kinetic;
  double time = 0;
  for (int n = 0; n < 2000; ++n, time += dt)
    solver.step(time, dt);
  const auto e = solver.energy();
  return (e.internal + e.kinetic) / e0;
}

TEST(SolidSolver, StableStepEstimate) {
  const double below = energy_growth(0.95), above = energy_growth(1.05);
  RecordProperty("growth_below", std::to_string(below));
  RecordProperty("growth_above", std::to_string(above));
  // Bounded, not growing: near the limit the energy measured at full steps departs from the
  // conserved (shadow) energy by up to 1 / (1 - (omega dt / 2)^2), 10x at 0.95 of the limit;
  // measured here: 1.4 at 0.8, 1.6 at 0.9, 2.0 at 0.95, 2.5 at 0.99; NaN at 1.05.
  EXPECT_LT(below, 10.0);
  EXPECT_TRUE(!(above < 1e3)) << above;  // exponential growth (or Inf/NaN)
}

}  // namespace
}  // namespace mupm
