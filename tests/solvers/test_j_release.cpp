// The J criterion's gradual release (J-Integral->Release Time; include/mupm/solvers/
// solid_solver.hpp): an edge-cracked plate, its top and bottom rows pulled apart by a traction,
// grows its crack by the J criterion, once with the increment's bonds broken at once and once
// released over T. The two runs are the same to the bit up to the first advance. At it:
//  - the release field is the old bond set's force minus the new one's, dF: its forces sum to
//    zero (momentum) and it is not zero;
//  - the accelerations of the released run are the old bond set's: they differ from the
//    instant run's (the new set's) by exactly dF / rho (a wrong sign or factor of the release
//    moves them by dF / rho or more);
//  - over T the solid's energy balance stays closed to round-off, and the release force's work,
//    computed here from the steps' displacements, is what the fracture dissipation gains (the
//    faces open against the force: it is negative), not external work.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "mupm/input/model.hpp"
#include "mupm/solvers/j_integral.hpp"
#include "mupm/solvers/solid_solver.hpp"
#include "mupm/solvers/step_sequence.hpp"
#include "slot.hpp"
#include "test_utils.hpp"

namespace mupm {
namespace {

using test::condition;
using test::sum_owned;

constexpr double kDx = 2e-3;
const MicropolarElastic kSoil = MicropolarElastic::from_bulk_shear(270.83e6, 220.33e6, 100e6, 1e-3);

struct PulledPlate {
  GridSpec<2> g;
  Discretization<2> disc;
  SolidSolver<2> solid;
  Damage<2> damage;
  JIntegral<2> j;
  StepSequence<2> seq;

  static GridSpec<2> grid() {
    auto g = test::box<2>({40, 40}, 2.0, kDx);
    const double L = 40 * kDx;
    Crack c;
    c.a[0] = -1;
    c.b[0] = 0.3 * L + 0.1 * kDx;  // 0.1 dx off the columns where bonds cross (the KGD input's)
    c.a[1] = c.b[1] = 0.5 * L;
    g.cracks = {c};
    g.region_names = {"top", "bottom"};
    g.regions = {test::box2(-1, 1, L - kDx, 1), test::box2(-1, 1, -1, kDx)};
    return g;
  }
  static SolidSettings settings(double release) {
    SolidSettings s;
    s.fracture.criterion = BondBreaking::JIntegral;
    s.fracture.release_time = release;
    return s;
  }
  static JIntegralParams jparams() {
    JIntegralParams jp;
    jp.half = {{8 * kDx, 8 * kDx}};
    jp.criterion = true;
    jp.critical = 2.0;  // J/h [J/m^2], reached as the traction's wave loads the tip
    jp.increment = 0.5 * kDx;
    jp.max_speed = 20;  // the wait Delta a / v = 50 us
    return jp;
  }
  static std::vector<BoundaryCondition> loads() {
    auto up = condition(BoundaryCondition::Traction, "top", 0, 2e5);
    auto down = condition(BoundaryCondition::Traction, "bottom", 1, -2e5);
    up.component = down.component = 1;
    return {up, down};
  }
  explicit PulledPlate(double release)
      : g(grid()),
        disc(discretize(test::world(), g)),
        solid(disc, solid_params(kSoil, g, 0.5), loads(), settings(release), MPI_COMM_WORLD),
        damage(disc, 0.3, MPI_COMM_WORLD),
        j(disc, jparams(), damage, MPI_COMM_WORLD) {
    Kokkos::deep_copy(disc.points.saturation, 0.0);
    Kokkos::deep_copy(disc.points.porosity, 0.2);
    solid.update_density();
    j.attach(solid.state(), solid.params());
    seq.mechanics = &solid;
    seq.damage = &damage;
    seq.j_criterion = &j;
    solid.initialize(0, false);
    damage.update();
  }
};

TEST(JRelease, ForcesContinueAcrossTheBreakAndItsWorkIsFracture) {
  const double release = 5e-5;
  PulledPlate inst(0.0), rel(release);
  const double dt = 0.5 * inst.solid.estimate_stable_dt();
  inst.solid.set_time_step(dt);
  rel.solid.set_time_step(dt);
  const double e0 = rel.solid.energy().balance();
  int n = 0;
  for (; n < 4000 && inst.j.advances() == 0; ++n) {
    inst.seq.step(n, n * dt, dt);
    rel.seq.step(n, n * dt, dt);
  }
  ASSERT_EQ(inst.j.advances(), 1) << "no advance in " << n << " steps";
  ASSERT_EQ(rel.j.advances(), 1) << "the runs differ before the first advance";
  auto& pi = inst.disc.points;
  auto& pr = rel.disc.points;
  const auto& rho = rel.solid.density();
  double momentum[2] = {0, 0}, size = 0, worst = 0, jump = 0;
  for (std::size_t i = 0; i < pr.n_owned; ++i)
    for (int k = 0; k < 2; ++k) {
      const double F = pr.release_force(i, k);
      momentum[k] += F * pr.volume(i);
      size += std::abs(F) * pr.volume(i);
      if (pr.fixed(i) & (1u << k))
        continue;
      jump = std::max(jump, std::abs(F / rho(i)));
      worst = std::max(worst, std::abs(pr.a(i, k) - pi.a(i, k) - F / rho(i)));
    }
  MPI_Allreduce(MPI_IN_PLACE, momentum, 2, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &size, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &worst, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &jump, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  const auto at_break = rel.solid.energy();
  const auto inst_break = inst.solid.energy();
  // Through the release (no other advance can come: the wait is T): the release force's work
  // from the steps' displacement increments, by the trapezoid rule on r(t) (r = 1 - s dt / T
  // s steps after the break).
  const int steps = int(std::floor(release / dt));
  double balance = 0, work = 0;
  // (u, theta) of the step's start: a copy (a host mirror of host memory is the View itself)
  Vectors u0("test::u0", pr.n_owned, 3);
  auto dof = [&](std::size_t i, int k) { return k < 2 ? pr.u(i, k) : pr.theta(i, 0); };
  for (std::size_t i = 0; i < pr.n_owned; ++i)
    for (int k = 0; k < 3; ++k)
      u0(i, k) = dof(i, k);
  for (int s = 0; s < steps; ++s, ++n) {
    rel.seq.step(n, n * dt, dt);
    balance = std::max(balance, std::abs(rel.solid.energy().balance() - e0));
    const double r = 1 - (s + 0.5) * dt / release;
    for (std::size_t i = 0; i < pr.n_owned; ++i)
      for (int k = 0; k < 3; ++k)  // the force on u, the couple on theta
        if (!(pr.fixed(i) & (1u << k))) {
          work += r * pr.release_force(i, k) * (dof(i, k) - u0(i, k)) * pr.volume(i);
          u0(i, k) = dof(i, k);
        }
  }
  MPI_Allreduce(MPI_IN_PLACE, &work, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  ASSERT_EQ(rel.j.advances(), 1);
  const auto end = rel.solid.energy();
  if (test::world()->getRank() == 0)
    std::printf(
        "release: first advance at step %d (dt %.3e s); dF sums to (%.2e, %.2e) of %.3e N; "
        "accelerations off the old set's by %.2e of the jump %.3e m/s^2; fracture dissipation "
        "%.6e J at the break (instant %.6e J), %.6e J after %d steps of the release, whose "
        "force did %.6e J; balance at most %.2e J of %.2e J\n",
        n - steps, dt, momentum[0], momentum[1], size, worst, jump, at_break.fracture,
        inst_break.fracture, end.fracture, steps, work, balance, end.scale());
  EXPECT_GT(size, 0.0);
  EXPECT_LT(std::abs(momentum[0]), 1e-10 * size);
  EXPECT_LT(std::abs(momentum[1]), 1e-10 * size);
  EXPECT_GT(jump, 0.0);
  EXPECT_LT(worst, 1e-9 * jump);
  // At the break itself both runs lose the same strain energy (the same u, the same bond sets);
  // the instant run books the kinetic shift's jump with it too.
  EXPECT_GT(at_break.fracture, 0.0);
  EXPECT_LT(work, 0.0) << "the faces open against the release force";
  EXPECT_NEAR(end.fracture - at_break.fracture, -work, 1e-9 * std::abs(work))
      << "the release force's work is fracture dissipation";
  EXPECT_LT(balance, 1e-10 * end.scale());
}

}  // namespace
}  // namespace mupm
