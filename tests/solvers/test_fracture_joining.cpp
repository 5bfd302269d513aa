// Points that join the crack's network (include/mupm/solvers/fracture_flow.hpp, header): they
// start at the network's pressure around them, and the water that fills their share of the
// crack's volume at joining is booked (FractureFlow::joined), so that water stays conserved.
//
// A closed slot in an impervious bulk (pore pressure 0) is held at p_f = p1 from its left end
// until it is at rest at p1; then the second row of points above the crack becomes fracture
// points (kFlagCut, as the J criterion's increments do). They join at p1, the network
// pressure in their families: the step needs no water from the held end (joining at their
// bulk p_w = 0 it would have to raise their fill by p1/K_w, a volume the test computes), and
// the joined water is rho_w V (s + a_min)/(3 dx) each (their aperture s, three fracture points
// on their line across the crack: the header's n_i).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "mupm/input/model.hpp"
#include "mupm/solvers/fluid_solver.hpp"
#include "mupm/solvers/fracture_flow.hpp"
#include "slot.hpp"
#include "test_utils.hpp"

namespace mupm {
namespace {

using test::condition;
using test::flow_params;
using test::kDx;
using test::Slot;
using test::sum_owned;

TEST(FractureJoining, AtTheNetworkPressureWithItsWaterBooked) {
  const double p1 = 1e6, s0 = 1e-4, dt = 1e-3;
  Slot s;
  s.open(s0);
  auto prm = fluid_params(s.g, 0.0, 0.5);  // impervious bulk: no exchange
  auto& p = s.disc.points;
  FluidSolver<2> fluid(s.disc, prm, {condition(BoundaryCondition::FracturePressure, "left", 0, p1)},
                       MPI_COMM_WORLD);
  const FractureParams fp = flow_params();
  fluid.enable_fracture_flow(fp);
  fluid.initialize(0.0, false);
  const auto* ff = fluid.fracture_flow();
  const double mass0 = fluid.fluid_mass() + ff->mass();
  int n = 0;
  for (; n < 40; ++n)  // each step far beyond the slot's diffusion time
    fluid.advance(n * dt, dt, 1);
  auto on = [&](std::size_t i) { return p.pf_saturation(i) > 0; };
  const double rest = sum_owned(p, [&](std::size_t i) { return on(i) ? 0.0 : 1.0; });
  const double worst0 =
      sum_owned(p, [&](std::size_t i) { return on(i) ? std::abs(p.pf(i) - p1) / p1 : 0.0; });
  ASSERT_LT(worst0, 1e-9) << "the slot is at rest at p1";
  // The second row above the crack: kFlagCut, then the damage's fracture points.
  Crack row;
  row.a[0] = -1;
  row.b[0] = s.L + 1;
  row.a[1] = row.b[1] = 0.5 * s.H + kDx;
  mark_cut<2>(p, row, kDx);
  Damage<2>(s.disc, 0.3, MPI_COMM_WORLD).update();
  auto fresh = [&](std::size_t i) { return p.fracture(i) && !on(i); };
  const double joining = sum_owned(p, [&](std::size_t i) { return fresh(i) ? 1.0 : 0.0; });
  EXPECT_EQ(joining, double(test::kNx));
  const double rho = prm.water_density, amin = fp.min_aperture;
  const double fill = sum_owned(p, [&](std::size_t i) {
    return fresh(i) ? p.volume(i) * (p.aperture(i) + amin) / (3 * kDx) : 0.0;
  });
  const double joined0 = ff->joined(), supplied0 = ff->inflows()[0];
  fluid.advance(n * dt, dt, 1);
  ++n;
  const double joined = ff->joined() - joined0, supplied = ff->inflows()[0] - supplied0;
  // Joining at p_w = 0 the new points' fill would need rho V phi_f p1/K_w from the held end.
  const double would = rho * fill * p1 / prm.bulk_modulus;
  const double worst =
      sum_owned(p, [&](std::size_t i) { return on(i) ? std::abs(p.pf(i) - p1) / p1 : 0.0; });
  const double water = fluid.fluid_mass() + ff->mass() - mass0 - ff->inflows()[0] - ff->joined();
  if (test::world()->getRank() == 0)
    std::printf(
        "joining: %g points, joined %.9e kg (closed form %.9e), the held end supplied "
        "%.3e kg in the step (%.3e kg joining at p_w); p_f off p1 by %.2e; water %.2e kg\n",
        joining, joined, rho * fill, supplied, would, worst, water);
  EXPECT_NEAR(joined, rho * fill, 1e-12 * rho * fill);
  EXPECT_LT(std::abs(supplied), 1e-6 * would);
  EXPECT_LT(worst, 1e-9);
  EXPECT_LT(std::abs(water), 1e-12 * mass0 + 1e-9 * joined);
  EXPECT_GT(rest, 0.0);  // the row joined was off the network before
}

}  // namespace
}  // namespace mupm
