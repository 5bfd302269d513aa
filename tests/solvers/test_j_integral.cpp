// The micropolar J-integral (eqs 30, 125-126; include/mupm/kernels/j_integral.hpp) and the J
// criterion (Algorithm 3; include/mupm/solvers/j_integral.hpp).
//
// The LEFM K-fields. A plate with a straight crack along y = y_t ending at (x_t, y_t) is given the
// Williams displacement field of a mode I (or mode II) crack of stress-intensity factor K
// (plane strain: kappa = 3 - 4 nu; plane stress: (3 - nu)/(1 + nu)), and theta = its rotation
// (du_y/dx - du_x/dy)/2, so that the micropolar part of the strain vanishes; mu_c and l are
// small (the classical limit). Away from the tip the field is an equilibrium field of the
// material, so J on every contour is the closed form K^2 (1 - nu^2)/E in plane strain and K^2/E
// in plane stress (Discretization->Plane = Stress, the law's MicropolarElastic::plane_stress),
// mode I and II alike. A factor or sign error in either the energy term or
// the bond term moves J by tens of percent (they are of the same size on these contours).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>
#include <tuple>
#include <vector>

#include "mupm/input/model.hpp"
#include "mupm/solvers/j_integral.hpp"
#include "mupm/solvers/solid_solver.hpp"
#include "static_plate.hpp"
#include "test_utils.hpp"

namespace mupm {
namespace {

using test::cell;
using test::crack_water_load;
using test::hold;
using test::kClassical;
using test::KField;
using test::sent_factor;
using test::static_plate;
using test::StaticPlate;
using test::tension;

struct Plate {
  GridSpec<2> g;
  Discretization<2> disc;
  SolidParams prm;
  SolidState<2> st;
};

// n x n points of 1 mm, delta = 3 dx, an edge crack from the left face to the centre.
Plate cracked_plate(int n, const MicropolarElastic& law) {
  Plate p{test::box<2>({n, n}, 3.0, 1e-3), {}, {}, {}};
  const double c = 0.5 * n * p.g.dx;
  Crack crack;
  crack.a[0] = -0.01;
  crack.a[1] = c;
  crack.b[0] = c;
  crack.b[1] = c;
  p.g.cracks = {crack};
  p.disc = discretize(test::world(), p.g);
  p.prm = solid_params(law, p.g, 0.5);
  p.st.allocate(p.disc.points.size(), p.disc.points.n_owned);
  return p;
}

// u and theta of every point (owned and ghosts) from the K-field, then the forces.
void impose(Plate& p, const KField& f) {
  auto& pts = p.disc.points;
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.x);
  auto u = Kokkos::create_mirror_view(pts.u);
  auto th = Kokkos::create_mirror_view(pts.theta);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    double v[2];
    f.u(x(i, 0), x(i, 1), v);
    u(i, 0) = v[0];
    u(i, 1) = v[1];
    th(i, 0) = f.rotation(x(i, 0), x(i, 1));
  }
  Kokkos::deep_copy(pts.u, u);
  Kokkos::deep_copy(pts.theta, th);
  solid_forces(p.disc, p.prm, p.st);
}

JIntegralParams contours(std::vector<double> half_spacings, double dx) {
  JIntegralParams jp;
  for (double h : half_spacings)
    jp.half.push_back({h * dx, h * dx});
  jp.increment = dx;
  return jp;
}

// The K-field of kClassical with its tip at the centre of cracked_plate(80, ...), in plane strain
// or plane stress (nu the 3D Poisson ratio).
KField centre_field(bool mode2, bool plane_stress = false) {
  const double nu = kClassical.poisson();
  KField f;
  f.mode2 = mode2;
  f.mu = kClassical.mu;
  f.kappa = plane_stress ? (3 - nu) / (1 + nu) : 3 - 4 * nu;
  f.xt = f.yt = 0.04;
  return f;
}

// (mode II, plane stress)
class JIntegralKField : public ::testing::TestWithParam<std::tuple<bool, bool>> {};

TEST_P(JIntegralKField, MatchesLefmOnEveryContour) {
  const auto [mode2, plane_stress] = GetParam();
  Plate p = cracked_plate(80, plane_stress ? kClassical.plane_stress() : kClassical);
  const double E = kClassical.young(), nu = kClassical.poisson();
  const KField f = centre_field(mode2, plane_stress);
  impose(p, f);
  Damage<2> damage(p.disc, 0.3, MPI_COMM_WORLD);
  damage.update();
  JIntegral<2> j(p.disc, contours({10, 15, 20}, p.g.dx), damage, MPI_COMM_WORLD);
  j.attach(p.st, p.prm);
  const auto tip = j.tip();
  EXPECT_DOUBLE_EQ(tip[0], 0.04);
  EXPECT_DOUBLE_EQ(tip[1], 0.04);
  const double exact = f.K * f.K * (plane_stress ? 1.0 : 1 - nu * nu) / E;
  const auto v = j.evaluate();
  double lo = 1e300, hi = -1e300;
  for (std::size_t c = 0; c < v.size(); ++c) {
    std::printf(
        "mode %s, plane %s, contour %zu: J = %.5g (translational %.5g, rotational %.5g), "
        "closed form %.5g, error %.2f %%\n",
        mode2 ? "II" : "I", plane_stress ? "stress" : "strain", c + 1, v[c].total,
        v[c].translational, v[c].rotational, exact, 100 * (v[c].total / exact - 1));
    EXPECT_NEAR(v[c].total / exact, 1.0, 0.01) << "contour " << c + 1;
    // The classical limit: the micro-rotational part is small (measured 0.04 % of J).
    EXPECT_LT(std::abs(v[c].rotational), 0.005 * exact) << "contour " << c + 1;
    lo = std::min(lo, v[c].total);
    hi = std::max(hi, v[c].total);
  }
  EXPECT_LT((hi - lo) / exact, 0.005) << "path independence";
}

INSTANTIATE_TEST_SUITE_P(ModesPlanes, JIntegralKField,
                         ::testing::Combine(::testing::Bool(), ::testing::Bool()));

// Intact bonds (over all ranks) that cross the horizontal segment y = yc, x in [x0, x1]: the
// test's own geometry.
long long crossing_bonds(const Discretization<2>& disc, double x0, double x1, double yc) {
  const auto& p = disc.points;
  long long n = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i)
    for (BondIndex b = disc.bonds.offsets(i); b < disc.bonds.offsets(i + 1); ++b) {
      const int j = disc.bonds.neighbor(b);
      const double yi = p.x(i, 1) - yc, yj = p.x(j, 1) - yc;
      if (!disc.bonds.intact(b) || !(yi * yj < 0))
        continue;
      const double xc = p.x(i, 0) + (p.x(j, 0) - p.x(i, 0)) * yi / (yi - yj);
      n += xc >= x0 && xc <= x1 ? 1 : 0;
    }
  MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  return n;
}

// The J criterion (Algorithm 3) on the mode I K-field: with G_cr just below J the crack advances
// one increment (the tip moves by Delta a, exactly the bonds across the increment break, both
// copies); with G_cr just above J nothing happens.
TEST(JIntegral, CriterionAdvancesOneIncrementAtGcr) {
  Plate p = cracked_plate(80, kClassical);
  impose(p, centre_field(false));
  Damage<2> damage(p.disc, 0.3, MPI_COMM_WORLD);
  damage.update();
  JIntegralParams jp = contours({10, 15}, p.g.dx);
  jp.criterion = true;
  JIntegral<2> probe(p.disc, jp, damage, MPI_COMM_WORLD);
  probe.attach(p.st, p.prm);
  const double J = probe.evaluate()[0].total;
  const double dx = p.g.dx;

  jp.critical = 1.001 * J;  // above J: no advance
  JIntegral<2> high(p.disc, jp, damage, MPI_COMM_WORLD);
  high.attach(p.st, p.prm);
  const long long before = crossing_bonds(p.disc, 0.04, 0.04 + dx, 0.04);
  ASSERT_GT(before, 0);
  long long n = high.advance(0.0).bonds;
  MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(n, 0);
  EXPECT_EQ(high.advances(), 0);
  EXPECT_EQ(crossing_bonds(p.disc, 0.04, 0.04 + dx, 0.04), before);

  jp.critical = 0.999 * J;  // below J: one increment
  jp.max_speed = 1000;      // m/s: the next advance no earlier than dx / 1000 m/s = 1 us later
  JIntegral<2> low(p.disc, jp, damage, MPI_COMM_WORLD);
  low.attach(p.st, p.prm);
  n = low.advance(0.0).bonds;
  MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(n, before);  // every directed bond across the increment, i.e. both copies
  EXPECT_EQ(before % 2, 0);
  EXPECT_EQ(crossing_bonds(p.disc, 0.04, 0.04 + dx, 0.04), 0);
  EXPECT_GT(crossing_bonds(p.disc, 0.04 + dx, 0.04 + 2 * dx, 0.04), 0);  // the next one intact
  EXPECT_EQ(low.advances(), 1);
  EXPECT_DOUBLE_EQ(low.tip()[0], 0.04 + dx);
  EXPECT_DOUBLE_EQ(low.tip()[1], 0.04);
  // The speed cap: J at the new tip (the old field) is still above G_cr, but the next increment
  // waits dx / c_R.
  ASSERT_GE(low.evaluate()[0].total, jp.critical);
  n = low.advance(0.9e-6).bonds;
  MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(n, 0);
  EXPECT_EQ(low.advances(), 1);
  n = low.advance(1.0e-6).bonds;
  MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_GT(n, 0);
  EXPECT_EQ(low.advances(), 2);
}

// A homogeneous strain without a crack's opening stores energy but releases none: J = 0 on a
// closed contour (the W terms of opposite edges and the bond terms cancel).
TEST(JIntegral, HomogeneousFieldReleasesNothing) {
  Plate p = cracked_plate(60, kClassical);
  auto& pts = p.disc.points;
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.x);
  auto u = Kokkos::create_mirror_view(pts.u);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    u(i, 0) = 1e-4 * x(i, 0) + 3e-5 * x(i, 1);
    u(i, 1) = -2e-5 * x(i, 0) + 2e-4 * x(i, 1);
  }
  Kokkos::deep_copy(pts.u, u);
  Kokkos::deep_copy(pts.theta, 0.0);
  solid_forces(p.disc, p.prm, p.st);
  Damage<2> damage(p.disc, 0.3, MPI_COMM_WORLD);
  // A contour clear of the crack and of the plate's faces (families complete): centre 45 mm.
  JIntegral<2> j(p.disc, contours({5}, p.g.dx), damage, MPI_COMM_WORLD);
  j.attach(p.st, p.prm);
  JContours jc = j.contours({0.045, 0.045});
  const auto v = j.evaluate(jc);
  // The scale: W times the contour's height.
  const double W = 0.5 * 2e-4 * 2e-4 * 60e9 * 10 * p.g.dx;
  EXPECT_LT(std::abs(v[0].total), 1e-10 * W);
  EXPECT_LT(std::abs(v[0].translational), 1e-10 * W);
}

TEST(JIntegral, SentFactorIsValidations) {
  EXPECT_NEAR(sent_factor(0.1), 1.1957, 1e-4);
  EXPECT_NEAR(sent_factor(0.3), 1.6551, 1e-4);
  EXPECT_NEAR(sent_factor(0.5), 2.8266, 1e-4);
}

// J with the crack water's face term of Points::applied_crack_force when `face`.
std::vector<JIntegral<2>::Value> j_of(StaticPlate& P, const std::vector<double>& halves,
                                      bool face = false) {
  Damage<2> damage(P.disc, 0.3, MPI_COMM_WORLD);
  damage.update();
  auto jp = contours(halves, P.g.dx);
  jp.face = face;
  JIntegral<2> j(P.disc, jp, damage, MPI_COMM_WORLD);
  j.attach(P.st, P.sp.prm);
  return j.evaluate();
}

// The LEFM check of the issue: a single-edge-cracked strip (height 3W) in tension, mu_c and l
// small: J against K_I^2 (1 - nu^2)/E with K_I = sigma sqrt(pi a) F(a/W), at a/W = 0.3 and 0.5,
// on four contours.
class JIntegralSentLong : public ::testing::TestWithParam<double> {};

TEST_P(JIntegralSentLong, MatchesLefm) {
  const double aw = GetParam(), dx = 1e-3, sigma = 1e6;
  const int nx = 60;
  auto P = static_plate(nx, 3 * nx, dx, 3.0, aw * nx * dx, kClassical);
  tension(*P, sigma);
  const int its = P->sp.solve();
  ASSERT_GT(its, 0) << "static solve did not converge";
  // The fourth contour reaches past the left face at a/W = 0.3 (it runs along the free face
  // there: the W term of the face, include/mupm/kernels/j_integral.hpp).
  const auto v = j_of(*P, {8, 11, 14, 22});
  const double a = aw * P->W;
  const double K = sigma * std::sqrt(M_PI * a) * sent_factor(aw);
  const double nu = kClassical.poisson();
  const double exact = K * K * (1 - nu * nu) / kClassical.young();
  double lo = 1e300, hi = -1e300;
  for (std::size_t c = 0; c < v.size(); ++c) {
    std::printf(
        "SENT a/W = %.1f (%d CG iterations), contour %zu: J = %.5g (rotational %.3g), "
        "LEFM %.5g, error %.2f %%\n",
        aw, its, c + 1, v[c].total, v[c].rotational, exact, 100 * (v[c].total / exact - 1));
    EXPECT_NEAR(v[c].total / exact, 1.0, 0.10) << "contour " << c + 1;
    lo = std::min(lo, v[c].total);
    hi = std::max(hi, v[c].total);
  }
  EXPECT_LT((hi - lo) / exact, 0.05) << "path independence";
}

INSTANTIATE_TEST_SUITE_P(JStatic, JIntegralSentLong, ::testing::Values(0.3, 0.5));

// The crack water's face term (include/mupm/kernels/j_integral.hpp): the strip above with a
// uniform pressure p on the faces of its edge crack and no remote load, given to J as a step
// gives it, through Points::applied_crack_force: the force density p/dx on the row on each side
// of the crack (as tension() loads the outer rows), or the crack water's own force
// (crack_water_load). The contour term alone misses the faces' work inside the contour, a part
// that grows with the length of crack the contour holds (the continuum's p w(s_Gamma)), so it
// changes from contour to contour; with the face term J is the same on every contour, and
// within 5 % of LEFM (K_I = p sqrt(pi a) F(a/W) by superposition with a remote tension
// sigma = p): measured 1.026-1.029 with the row load, 1.012-1.015 with the crack water's force.
class JIntegralFacePressureLong : public ::testing::TestWithParam<bool> {};

TEST_P(JIntegralFacePressureLong, IsPathIndependent) {
  const bool water = GetParam();
  const double aw = 0.3, dx = 1e-3, p = 1e6;
  const int nx = 60;
  auto P = static_plate(nx, 3 * nx, dx, 3.0, aw * nx * dx, kClassical);
  const auto ny = P->g.counts[1];
  const double a = aw * P->W;
  auto& pts = P->disc.points;
  pts.applied_crack_force = Vectors("applied_crack_force", pts.size(), 2);
  if (water) {
    crack_water_load(*P, p);
  } else {
    for (std::size_t i = 0; i < pts.n_owned; ++i) {
      const auto c = cell(*P, i);
      if (pts.x(i, 0) < a && (c[1] == ny / 2 || c[1] == ny / 2 - 1)) {
        const double b = (c[1] == ny / 2 ? 1 : -1) * p / dx;  // pushes the faces apart
        P->sp.load[i * 3 + 1] = b;
        pts.applied_crack_force(i, 1) = b;
      }
    }
  }
  // Either load pushes each face with p over the crack's length (and its tip's point).
  double up = 0;
  for (std::size_t i = 0; i < pts.n_owned; ++i)
    up += pts.x(i, 1) > 0.5 * P->H ? P->sp.load[i * 3 + 1] * pts.volume(i) : 0.0;
  MPI_Allreduce(MPI_IN_PLACE, &up, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_GT(up, p * a * (1 - 1e-12));
  EXPECT_LT(up, p * (a + dx) * (1 + 1e-12));
  hold(*P);
  const int its = P->sp.solve();
  ASSERT_GT(its, 0) << "static solve did not converge";
  const std::vector<double> halves = {8, 11, 14};
  const auto v = j_of(*P, halves, true);
  const auto contour_only = j_of(*P, halves, false);
  const double K = p * std::sqrt(M_PI * a) * sent_factor(aw);
  const double nu = kClassical.poisson();
  const double lefm = K * K * (1 - nu * nu) / kClassical.young();
  double lo = 1e300, hi = -1e300, lo0 = 1e300, hi0 = -1e300;
  for (std::size_t c = 0; c < v.size(); ++c) {
    std::printf(
        "face pressure (%s), a/W = %.1f (%d CG iterations), contour %zu (%.0f dx behind the tip): "
        "J = %.5g (face term %.5g, rotational %.3g), without the face term %.5g; LEFM %.5g "
        "(J / LEFM %.3f)\n",
        water ? "crack water's force" : "row", aw, its, c + 1, halves[c], v[c].total, v[c].face,
        v[c].rotational, contour_only[c].total, lefm, v[c].total / lefm);
    // The face term is the whole difference.
    EXPECT_NEAR(v[c].total - v[c].face, contour_only[c].total, 1e-12 * std::abs(v[c].total))
        << "contour " << c + 1;
    EXPECT_EQ(contour_only[c].face, 0.0);
    lo = std::min(lo, v[c].total);
    hi = std::max(hi, v[c].total);
    lo0 = std::min(lo0, contour_only[c].total);
    hi0 = std::max(hi0, contour_only[c].total);
  }
  for (const auto& c : v)
    EXPECT_NEAR(c.total / lefm, 1.0, 0.05) << "J / LEFM";
  // Measured: 0.3 % of J with the face term, 23 % without.
  EXPECT_LT((hi - lo) / hi, 0.01) << "path independence with the face term";
  EXPECT_GT((hi0 - lo0) / hi, 0.10) << "the contour term alone depends on the contour";
}

INSTANTIATE_TEST_SUITE_P(JStatic, JIntegralFacePressureLong, ::testing::Bool());

// J is the energy released per unit crack advance, micro-rotational part included: under fixed
// loads, G = -(Pi(a + da) - Pi(a))/da of the static solutions for the crack lengths a and
// a + da (the bonds across the increment broken) against the mean of J at both. Mode I
// (tension) and mode II (the top row pushed sideways, the bottom row held), with Example 2's
// mu_c = 14 GPa and l = delta = 4 mm, and in mode II with l = 30 mm, where the micro-rotational
// part is 9-13 % of J (measured) and differs between the contours by 4 % of J: a wrong factor or
// sign on it would break the path independence and the energy release.
struct Release {
  bool mode2;
  double l;
};
class JIntegralReleasedEnergyLong : public ::testing::TestWithParam<Release> {};

TEST_P(JIntegralReleasedEnergyLong, EqualsJ) {
  const bool mode2 = GetParam().mode2;
  const double dx = 1e-3, load = 1e6;
  const int n = 60;
  const double a = 0.5 * n * dx;
  auto P = static_plate(n, n, dx, 4.0, a,
                        MicropolarElastic::from_bulk_shear(60e9, 27.7e9, 14e9, GetParam().l));
  if (!mode2) {
    tension(*P, load);
  } else {
    for (std::size_t i = 0; i < P->disc.points.n_owned; ++i) {
      const auto c = cell(*P, i);
      if (c[1] == n - 1)
        P->sp.load[i * 3 + 0] = load / dx;
      if (c[1] == 0)
        P->sp.held[i * 3 + 0] = P->sp.held[i * 3 + 1] = 1;
    }
  }
  Damage<2> damage(P->disc, 0.3, MPI_COMM_WORLD);
  JIntegral<2> j(P->disc, contours({10, 14}, dx), damage, MPI_COMM_WORLD);
  j.attach(P->st, P->sp.prm);
  ASSERT_GT(P->sp.solve(1e-11), 0);
  const double pi0 = P->sp.potential();
  const auto j0 = j.evaluate(j.contours({a, 0.5 * P->H}));
  Crack inc;
  inc.a[0] = a;
  inc.b[0] = a + dx;
  inc.a[1] = inc.b[1] = 0.5 * P->H;
  long long broken = break_crossing<2>(P->disc.points, P->disc.bonds, inc);
  MPI_Allreduce(MPI_IN_PLACE, &broken, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_GT(broken, 0);
  P->disc.update_shape();
  ASSERT_GT(P->sp.solve(1e-11), 0);
  const double pi1 = P->sp.potential();
  const auto j1 = j.evaluate(j.contours({a + dx, 0.5 * P->H}));
  const double G = -(pi1 - pi0) / (dx * P->g.thickness);
  EXPECT_NEAR(j0[1].total / j0[0].total, 1.0, 0.005) << "path independence at a";
  EXPECT_NEAR(j1[1].total / j1[0].total, 1.0, 0.005) << "path independence at a + dx";
  if (GetParam().l > 0.01) {
    EXPECT_GT(j0[0].rotational, 0.05 * j0[0].total) << "the micro-rotational part is exercised";
  }
  for (std::size_t c = 0; c < j0.size(); ++c) {
    const double J = 0.5 * (j0[c].total + j1[c].total);
    const double rot = 0.5 * (j0[c].rotational + j1[c].rotational);
    std::printf(
        "mode %s, l = %g m, contour %zu: J(a) = %.5g, J(a + dx) = %.5g, mean %.5g "
        "(micro-rotational "
        "%.3g, %.1f %%); -dPi/da = %.5g; difference %.2f %%\n",
        mode2 ? "II" : "I", GetParam().l, c + 1, j0[c].total, j1[c].total, J, rot, 100 * rot / J, G,
        100 * (J / G - 1));
    EXPECT_NEAR(J / G, 1.0, 0.03) << "contour " << c + 1;
  }
}

INSTANTIATE_TEST_SUITE_P(JStatic, JIntegralReleasedEnergyLong,
                         ::testing::Values(Release{false, 4e-3}, Release{true, 4e-3},
                                           Release{true, 30e-3}));

// Example 2 at reduced size (60 x 60 points of 1 mm, crack 30 mm, static): J falls as the
// micropolar length l = delta grows, in mode I (tension 1 MPa) and mode II (shear 1 MPa on the
// top row, bottom row held), as in the paper's Tables 1 and 3.
class JIntegralExample2Long : public ::testing::TestWithParam<bool> {};

TEST_P(JIntegralExample2Long, JFallsAsLengthScaleGrows) {
  const bool mode2 = GetParam();
  const double dx = 1e-3;
  const int n = 60;
  std::vector<double> J;
  for (double l : {3e-3, 5e-3}) {
    auto P = static_plate(n, n, dx, l / dx, 0.5 * n * dx,
                          MicropolarElastic::from_bulk_shear(60e9, 27.7e9, 14e9, l));
    if (!mode2) {
      tension(*P, 1e6);
    } else {
      for (std::size_t i = 0; i < P->disc.points.n_owned; ++i) {
        const auto c = cell(*P, i);
        if (c[1] == n - 1)
          P->sp.load[i * 3 + 0] = 1e6 / dx;
        if (c[1] == 0)
          P->sp.held[i * 3 + 0] = P->sp.held[i * 3 + 1] = 1;
      }
    }
    ASSERT_GT(P->sp.solve(), 0);
    const auto v = j_of(*P, {12, 16});
    std::printf(
        "Example 2 reduced, mode %s, l = delta = %g mm: J = %.5g, %.5g (contours 1, 2; "
        "micro-rotational %.3g)\n",
        mode2 ? "II" : "I", l * 1e3, v[0].total, v[1].total, v[0].rotational);
    EXPECT_NEAR(v[1].total / v[0].total, 1.0, 0.005);
    J.push_back(v[0].total);
  }
  EXPECT_LT(J[1], J[0]);
}

INSTANTIATE_TEST_SUITE_P(JStatic, JIntegralExample2Long, ::testing::Values(false, true));

}  // namespace
}  // namespace mupm
