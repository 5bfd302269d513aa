// The J-integral at every crack tip (include/mupm/solvers/j_integral.hpp): the tips of the
// pre-cracks, a centre crack's two tips under the J criterion, and Sneddon's pressurised crack.
//
// Sneddon: a centre crack of length 2a, a uniform pressure p on its faces, no other load. In an
// infinite plate K_I = p sqrt(pi a) and J = K_I^2/E' = pi a p^2/E' (E' = E/(1 - nu^2), plane
// strain). In a strip of width 2b (height 2 x width) by superposition with a remote tension
// sigma = p: K_I = p sqrt(pi a) F(a/b), F = (1 - 0.025 l^2 + 0.06 l^4) sqrt(sec(pi l/2)),
// l = a/b (Tada's handbook, within 0.1 %).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "mupm/solvers/j_integral.hpp"
#include "static_plate.hpp"
#include "test_utils.hpp"

namespace mupm {
namespace {

using test::cell;
using test::crack_water_load;
using test::hold;
using test::kClassical;
using test::static_plate;
using test::StaticPlate;
using test::tension;

// F(a/b) of a centre crack in a strip of width 2b (header).
double centre_factor(double l) {
  return (1 - 0.025 * l * l + 0.06 * std::pow(l, 4)) / std::sqrt(std::cos(M_PI * l / 2));
}

JIntegralParams sized(const std::vector<double>& half_spacings, double dx, bool face) {
  JIntegralParams jp;
  for (double h : half_spacings)
    jp.half.push_back({h * dx, h * dx});
  jp.increment = dx;
  jp.face = face;
  return jp;
}

TEST(JIntegralTips, AreThePreCrackEndsInsideTheBody) {
  Box body;
  body.hi[0] = 0.2;
  body.hi[1] = 0.1;
  Crack centre, edge, through;
  centre.a[0] = 0.08, centre.b[0] = 0.12, centre.a[1] = centre.b[1] = 0.05;
  edge.a[0] = -0.01, edge.b[0] = 0.05, edge.a[1] = edge.b[1] = 0.03;
  through.a[0] = -0.01, through.b[0] = 0.21, through.a[1] = through.b[1] = 0.07;
  const auto t = crack_tips({centre, edge, through}, body);
  ASSERT_EQ(t.size(), 3u);
  // The centre crack's End, then its Start (growing the other way), each with half of it.
  EXPECT_EQ(t[0].x[0], 0.12);
  EXPECT_EQ(t[0].d[0], 1.0);
  EXPECT_EQ(t[1].x[0], 0.08);
  EXPECT_EQ(t[1].d[0], -1.0);
  EXPECT_NEAR(t[0].base, 0.02, 1e-15);
  EXPECT_NEAR(t[1].base, 0.02, 1e-15);
  EXPECT_EQ(t[0].crack, 0u);
  EXPECT_EQ(t[1].crack, 0u);
  // The edge crack's End, with its length inside the body.
  EXPECT_EQ(t[2].crack, 1u);
  EXPECT_EQ(t[2].x[0], 0.05);
  EXPECT_NEAR(t[2].base, 0.05, 1e-15);
}

// A centre crack under remote tension, 60 x 60 points: both tips see the same J, the J criterion
// advances both by its own J, and increments of dx/2 break exactly the bonds one of dx does.
// The crack's ends sit 0.1 dx off the points where bonds cross its line (multiples of dx/4
// here): a bond through an end counts as crossing (bond_crosses, core/geometry.hpp), but which
// side of the end a rounded position falls on differs between the two ends, and J at the tips
// then differed by 5e-4.
TEST(JIntegralTips, CentreCrackGrowsAtBothTips) {
  const int n = 60;
  const double dx = 1e-3, a = 8.1 * dx;
  auto P = static_plate(n, n, dx, 3.0, 0.5 * n * dx + a, kClassical, 0.5 * n * dx - a);
  tension(*P, 1e6);
  ASSERT_GT(P->sp.solve(1e-13), 0);
  Damage<2> damage(P->disc, 0.3, MPI_COMM_WORLD);
  damage.update();
  JIntegralParams jp = sized({4, 6}, dx, false);
  jp.criterion = true;
  jp.increment = 0.5 * dx;
  JIntegral<2> j(P->disc, jp, damage, MPI_COMM_WORLD);
  j.attach(P->st, P->sp.prm);
  ASSERT_EQ(j.tips(), 2u);
  const double J1 = j.evaluate(0)[0].total, J2 = j.evaluate(1)[0].total;
  EXPECT_GT(J1, 0);
  EXPECT_NEAR(J2 / J1, 1.0, 1e-6) << "the tips of a symmetric crack";
  EXPECT_NEAR(j.evaluate(0)[1].total / J1, 1.0, 0.02) << "path independence";
  // Two half increments at each tip ...
  j.attach(P->st, P->sp.prm);
  auto intact_before =
      Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), P->disc.bonds.intact);
  JIntegral<2> low(
      P->disc,
      [&] {
        auto q = jp;
        q.critical = 0.5 * J1;
        q.cut = true;  // as with fracture flow
        return q;
      }(),
      damage, MPI_COMM_WORLD);
  low.attach(P->st, P->sp.prm);
  long long broken = 0;
  for (int s = 0; s < 2; ++s)
    broken += low.advance(double(s)).bonds;
  EXPECT_EQ(low.advances(0), 2);
  EXPECT_EQ(low.advances(1), 2);
  EXPECT_DOUBLE_EQ(low.tip(0)[0], 0.5 * n * dx + a + dx);
  EXPECT_DOUBLE_EQ(low.tip(1)[0], 0.5 * n * dx - a - dx);
  MPI_Allreduce(MPI_IN_PLACE, &broken, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_GT(broken, 0);
  SeriesRow row;
  low.series(row);
  auto column = [&](const std::string& name) {
    const auto& v = row.names();
    const auto it = std::find(v.begin(), v.end(), name);
    EXPECT_NE(it, v.end()) << name;
    return it == v.end() ? -1.0 : row.values()[std::size_t(it - v.begin())];
  };
  EXPECT_NEAR(column("j_crack_length"), 2 * a + 2 * dx, 1e-15);
  EXPECT_NEAR(column("j_crack_length_tip1"), a + dx, 1e-15);
  EXPECT_NEAR(column("j_crack_length_tip2"), a + dx, 1e-15);
  EXPECT_DOUBLE_EQ(column("j_integral_tip2"), low.evaluate(1)[0].total);
  EXPECT_DOUBLE_EQ(column("j_integral_tip2_2"), low.evaluate(1)[1].total);
  GlobalRefs g;
  low.globals(g);
  ASSERT_EQ(g.refs().size(), 4u);
  EXPECT_EQ(g.refs()[2].name, "advances_tip2");
  // The points next to the increments are fracture points at once (kFlagCut): the row on each
  // side of the crack over the grown dx and the cell ahead of each new tip, whose damage is
  // below D_cr.
  auto& pts = P->disc.points;
  damage.update();
  int cut = 0, below = 0;
  for (std::size_t i = 0; i < pts.n_owned; ++i) {
    const double s = std::abs(pts.x(i, 0) - 0.5 * n * dx) / dx, y = pts.x(i, 1) - 0.5 * P->H;
    if (std::abs(std::abs(y) - 0.5 * dx) < 1e-9 &&
        (std::abs(s - 8.5) < 1e-6 || std::abs(s - 9.5) < 1e-6)) {
      ++cut;
      EXPECT_TRUE(pts.fracture(i)) << "x = " << pts.x(i, 0) << ", y = " << pts.x(i, 1);
      below += pts.damage(i) < 0.3;
    }
  }
  MPI_Allreduce(MPI_IN_PLACE, &cut, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &below, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(cut, 8);
  EXPECT_GT(below, 0) << "the flag, not the damage, made them fracture points";
  // A restart: the flags follow from the advances alone.
  auto flags = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pts.flags);
  Kokkos::parallel_for(
      "test::clear_cut", range(0, pts.size()),
      KOKKOS_LAMBDA(const std::size_t i) { pts.flags(i) &= ~std::uint32_t(kFlagCut); });
  JIntegral<2> again(
      P->disc,
      [&] {
        auto q = jp;
        q.cut = true;
        return q;
      }(),
      damage, MPI_COMM_WORLD);
  GlobalRefs h;
  again.globals(h);
  for (std::size_t k = 0; k < h.refs().size(); ++k)
    h.refs()[k].set(g.refs()[k].get());
  again.mark_cuts();
  auto remarked = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pts.flags);
  long long flags_differ = 0;
  for (std::size_t i = 0; i < pts.size(); ++i)
    flags_differ += flags(i) != remarked(i);
  EXPECT_EQ(flags_differ, 0);
  // ... break the bonds one increment of dx breaks at each tip.
  auto after_halves =
      Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), P->disc.bonds.intact);
  Kokkos::deep_copy(P->disc.bonds.intact, intact_before);
  for (double x0 : {0.5 * n * dx + a, 0.5 * n * dx - a - dx}) {
    Crack seg;
    seg.a[0] = x0, seg.b[0] = x0 + dx, seg.a[1] = seg.b[1] = 0.5 * P->H;
    break_crossing<2>(P->disc.points, P->disc.bonds, seg);
  }
  auto after_whole = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), P->disc.bonds.intact);
  long long differ = 0;
  for (std::size_t b = 0; b < after_whole.extent(0); ++b)
    differ += after_whole(b) != after_halves(b);
  EXPECT_EQ(differ, 0);
}

// Sneddon (header) at a = 16 spacings (and 32 with the crack water's force), delta = 3 dx, l = a/b
// = 0.4, the pressure as the row load p/dx on each side of the crack (`water` false) or as the
// crack water's own force (crack_water_load, the force the step applies, S_rf = 1). Checked: the
// two tips agree, J with the face term is within 3 % of LEFM and the same on three contours (2 %),
// J without it is not (its missing p w(s_Gamma) grows with the contour), and J is the lattice's own
// energy release rate: under the fixed pressure, G = d(work)/da / 4 (Pi = -work/2, two tips) from
// the solves at a and a + dx, against the mean of J at both. The same crack under remote tension is
// printed beside it (inputs/README.md, "Sneddon's crack").
struct Sneddon {
  double ratio = 0, spread = 0, spread0 = 0, tips = 0;
  double j = 0, work = 0;  // J of tip 1's first contour; the load's work sum f.u V
  double lefm = 0;         // pi a p^2 F^2 / E'
};

// The skeleton and horizon factor of sneddon(), and the pore water's undrained modulus M (0: no
// water; else saturated pores whose pressure is the undrained split's p* = -M tr(eps), the
// model's own coupling, kernels/solid.hpp).
struct SneddonMaterial {
  MicropolarElastic law = kClassical;
  double m = 3.0;
  double undrained = 0;
};

Sneddon sneddon(double na, bool water, bool remote, int nx = 0, const SneddonMaterial& mat = {}) {
  const double dx = 1e-3, l = 0.4, p = 1e6;
  if (nx == 0)
    nx = 2 * int(std::lround(na / l));
  const int ny = 2 * nx;
  const double W = nx * dx, a = na * dx;
  auto P = static_plate(nx, ny, dx, mat.m, 0.5 * W + a, mat.law, 0.5 * W - a);
  auto& pts = P->disc.points;
  pts.applied_crack_force = Vectors("applied_crack_force", pts.size(), 2);
  if (mat.undrained > 0) {
    Kokkos::deep_copy(pts.saturation, 1.0);
    Kokkos::deep_copy(pts.undrained_modulus, mat.undrained);
  }
  if (remote) {
    tension(*P, p);
  } else if (water) {
    crack_water_load(*P, p);
  } else {
    for (std::size_t i = 0; i < pts.n_owned; ++i) {
      const auto c = cell(*P, i);
      if (std::abs(pts.x(i, 0) - 0.5 * W) < a && (c[1] == ny / 2 || c[1] == ny / 2 - 1)) {
        const double f = (c[1] == ny / 2 ? 1 : -1) * p / dx;  // pushes the faces apart
        P->sp.load[i * 3 + 1] = f;
        pts.applied_crack_force(i, 1) = f;
      }
    }
  }
  hold(*P);
  const int its = P->sp.solve();
  EXPECT_GT(its, 0) << "static solve did not converge";
  Sneddon s;
  for (std::size_t i = 0; i < pts.n_owned; ++i)
    for (int d = 0; d < 2; ++d)
      s.work += P->sp.load[i * 3 + d] * pts.u(i, d) * pts.volume(i);
  MPI_Allreduce(MPI_IN_PLACE, &s.work, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  Damage<2> damage(P->disc, 0.3, MPI_COMM_WORLD);
  damage.update();
  const std::vector<double> halves = {0.25 * na, 0.4 * na, 0.55 * na};
  JIntegral<2> j(P->disc, sized(halves, dx, !remote), damage, MPI_COMM_WORLD);
  j.attach(P->st, P->sp.prm);
  JIntegral<2> j0(P->disc, sized(halves, dx, false), damage, MPI_COMM_WORLD);
  j0.attach(P->st, P->sp.prm);
  EXPECT_EQ(j.tips(), 2u);
  // The undrained skeleton: lambda + M (J takes the total force state, kernels/j_integral.hpp).
  MicropolarElastic un = mat.law;
  un.lambda += mat.undrained;
  const double nu = un.poisson(), E1 = un.young() / (1 - nu * nu);
  const double F = centre_factor(a / (0.5 * W)), lefm = M_PI * a * p * p * F * F / E1;
  const auto v1 = j.evaluate(0), v2 = j.evaluate(1), c1 = j0.evaluate(0);
  double lo = 1e300, hi = -1e300, lo0 = 1e300, hi0 = -1e300;
  for (std::size_t c = 0; c < v1.size(); ++c) {
    if (test::world()->getRank() == 0)
      std::printf(
          "Sneddon (%s), a = %.1f dx, delta = %.0f dx (%d CG iterations), contour %zu (half %.1f "
          "dx): J = %.5g at tip 1, %.5g at tip 2 (face term %.4g), without the face term %.5g; "
          "LEFM %.5g: J/LEFM %.4f (without %.4f); onset of a pressure ramp / LEFM's %.4f\n",
          remote  ? "remote tension"
          : water ? "crack water's force"
                  : "row load",
          na, mat.m, its, c + 1, halves[c], v1[c].total, v2[c].total, v1[c].face, c1[c].total, lefm,
          v1[c].total / lefm, c1[c].total / lefm, 1 / std::sqrt(v1[c].total / lefm));
    lo = std::min(lo, v1[c].total);
    hi = std::max(hi, v1[c].total);
    lo0 = std::min(lo0, c1[c].total);
    hi0 = std::max(hi0, c1[c].total);
    s.tips = std::max(s.tips, std::abs(v2[c].total / v1[c].total - 1));
  }
  s.j = v1[0].total;
  s.lefm = lefm;
  s.ratio = v1[0].total / lefm;
  s.spread = (hi - lo) / hi;
  s.spread0 = (hi0 - lo0) / hi;
  return s;
}

class JIntegralTipsLong : public ::testing::TestWithParam<bool> {};

TEST_P(JIntegralTipsLong, SneddonMatchesLefm) {
  const bool water = GetParam();
  // a = 32 dx with the crack water's force only (the row load's is the same to 0.1 %: 1.012).
  std::vector<Sneddon> runs = {sneddon(16, water, false)};
  if (water)
    runs.push_back(sneddon(32, water, false));
  const Sneddon& coarse = runs.front();
  const int nx16 = 2 * int(std::lround(16 / 0.4));  // coarse's plate, kept for a = 16.5, 17
  // Measured 1.018 (a = 16 dx) and 1.011 (32 dx); remote tension 1.021 at a = 16 dx.
  for (const Sneddon& s : runs) {
    EXPECT_LT(s.tips, 1e-4) << "the two tips";
    EXPECT_NEAR(s.ratio, 1.0, 0.03) << "J / LEFM";
    EXPECT_LT(s.spread, 0.02) << "path independence with the face term";
    EXPECT_GT(s.spread0, 0.10) << "the contour term alone depends on the contour";
  }
  // Ends at cell centres (as after an odd number of increments of dx/2): the contours of both
  // tips on the cell face ahead of them.
  const Sneddon centred = sneddon(16.5, water, false, nx16);
  EXPECT_LT(centred.tips, 1e-3) << "the two tips, ends at cell centres";
  EXPECT_NEAR(centred.ratio, 1.0, 0.03) << "J / LEFM, ends at cell centres";
  // The lattice's energy release rate from the solves at a and a + dx (the plate's width
  // kept): measured within 0.4 % of the mean J of the two.
  const Sneddon longer = sneddon(17, water, false, nx16);
  const double released = (longer.work - coarse.work) / 1e-3 / 4;
  EXPECT_NEAR(0.5 * (coarse.j + longer.j) / released, 1.0, 0.01) << "J against compliance";
  if (test::world()->getRank() == 0)
    std::printf("Sneddon, a = 16 dx: compliance G %.5g, mean J at a and a + dx %.5g\n", released,
                0.5 * (coarse.j + longer.j));
  if (!water)  // the reference: the same crack under remote tension (no face term)
    sneddon(16, false, true);
}

INSTANTIATE_TEST_SUITE_P(JStatic, JIntegralTipsLong, ::testing::Bool());

// Sneddon's crack in the KGD input's undrained matrix (inputs/kgd_hydraulic_fracture.xml: K =
// 270.83 MPa, mu = 220.33 MPa, water M = K_w / phi = 11 GPa, nu_u = 0.49, delta = 2 dx), the
// crack water's force, a = 8.1 dx, l = a/b = 0.14: J of the total force state against LEFM with
// the undrained E' and against the lattice's compliance G (the solves at a and a + dx). Measured:
// G / LEFM 0.997; J / G 1.036 on the contour of half 2 dx, 1.011 on 4.5 dx. J's W is the
// skeleton's energy alone (solid pass 1): the water's p*^2 / (2 M) is left out, the likely
// source of J's 2.2 % spread over the contours (0.1 % in the dry crack). With the drained E' LEFM
// would be 1.61 times larger: the check fails if the water's coupling is lost. (A skeleton with
// lambda + M in place of the water is not the same lattice: its stabilization modulus takes lambda
// + mu, and J and G came out 0.76-0.79 of LEFM.)
TEST(JIntegralTipsUndrainedLong, SneddonMatchesUndrainedLefm) {
  SneddonMaterial mat;
  mat.law = MicropolarElastic::from_bulk_shear(270.83e6, 220.33e6, 100e6, 0.4e-3);
  mat.m = 2.0;
  mat.undrained = 2.2e9 / 0.2;
  const int nx = 2 * int(std::lround(8.1 / 0.14));
  const Sneddon s = sneddon(8.1, true, false, nx, mat), longer = sneddon(9.1, true, false, nx, mat);
  const double released = (longer.work - s.work) / 1e-3 / 4;
  const double lefm = 0.5 * (s.lefm + longer.lefm), j = 0.5 * (s.j + longer.j);
  if (test::world()->getRank() == 0)
    std::printf("Undrained Sneddon, a = 8.1 dx: compliance G %.5g, LEFM %.5g, mean J %.5g\n",
                released, lefm, j);
  EXPECT_LT(s.tips, 1e-4) << "the two tips";
  EXPECT_NEAR(released / lefm, 1.0, 0.02) << "the lattice's G against LEFM, undrained E'";
  EXPECT_NEAR(j / released, 1.0, 0.05) << "J against compliance";
  EXPECT_LT(s.spread, 0.03) << "path independence";
}

// A crack grown by the J criterion's increments is the pre-crack of its length: the KGD's
// matrix and plate (square, 120 x 120 spacings, delta = 2 dx, the undrained water), a centre
// crack grown at both tips from a = 8.1 dx by eight increments of dx/2 (G_cr = 0: every call
// advances both), the cut points fracture points, then loaded by the crack water's force; the
// same plate with a pre-crack of 12.1 dx. The bond sets and the fracture points must be the
// same, and J then the same to the static solves' tolerance (measured: equal to 6 digits; J/LEFM
// with the strip's F 1.076 here: the square plate's own compliance, inputs/README.md, "KGD").
TEST(JIntegralTipsUndrainedLong, GrownCrackIsThePreCrackOfItsLength) {
  const int n = 120;
  const double dx = 1e-3, W = n * dx, p = 1e6;
  const auto law = MicropolarElastic::from_bulk_shear(270.83e6, 220.33e6, 100e6, 0.4e-3);
  auto solve = [&](double a, int increments) {
    auto P = static_plate(n, n, dx, 2.0, 0.5 * W + a, law, 0.5 * W - a);
    auto& pts = P->disc.points;
    pts.applied_crack_force = Vectors("applied_crack_force", pts.size(), 2);
    Kokkos::deep_copy(pts.saturation, 1.0);
    Kokkos::deep_copy(pts.undrained_modulus, 2.2e9 / 0.2);
    Damage<2> damage(P->disc, 0.3, MPI_COMM_WORLD);
    damage.update();
    JIntegralParams jp = sized({4, 6}, dx, true);
    jp.criterion = true;
    jp.increment = 0.5 * dx;
    jp.critical = 0;  // J = 0 of the unloaded plate advances both tips
    jp.cut = true;
    JIntegral<2> j(P->disc, jp, damage, MPI_COMM_WORLD);
    j.attach(P->st, P->sp.prm);
    for (int s = 0; s < increments; ++s)
      j.advance(double(s));
    EXPECT_EQ(j.advances(0), increments);
    EXPECT_EQ(j.advances(1), increments);
    P->disc.update_shape();  // the families the breaks left (as after a step's breakage)
    crack_water_load(*P, p);
    hold(*P);
    EXPECT_GT(P->sp.solve(), 0) << "static solve did not converge";
    damage.update();
    j.attach(P->st, P->sp.prm);
    return std::make_tuple(
        j.evaluate(0)[0].total,
        Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), P->disc.bonds.intact),
        Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pts.fracture));
  };
  const auto [grown, grown_bonds, grown_fracture] = solve(8.1 * dx, 8);
  const auto [pre, pre_bonds, pre_fracture] = solve(12.1 * dx, 0);
  ASSERT_EQ(grown_bonds.extent(0), pre_bonds.extent(0));
  long long bonds = 0, points = 0;
  for (std::size_t b = 0; b < pre_bonds.extent(0); ++b)
    bonds += grown_bonds(b) != pre_bonds(b);
  for (std::size_t i = 0; i < pre_fracture.extent(0); ++i)
    points += grown_fracture(i) != pre_fracture(i);
  EXPECT_EQ(bonds, 0) << "bonds the increments broke against the pre-crack's";
  EXPECT_EQ(points, 0) << "fracture points";
  if (test::world()->getRank() == 0)
    std::printf("grown crack (8.1 -> 12.1 dx): J %.6g; pre-crack of 12.1 dx: J %.6g\n", grown, pre);
  EXPECT_NEAR(grown / pre, 1.0, 1e-6);
}

}  // namespace
}  // namespace mupm
