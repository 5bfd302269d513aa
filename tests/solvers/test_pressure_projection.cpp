// The assembled operators of the semi-implicit pressure step (include/mupm/solvers/
// pressure_system.hpp) against the kernels they stand for, on 1 and 2 ranks: the flow operator
// and the coupling (volumetric strain, pressure force and moment), and their values refilled on
// kept graphs after breakage against a fresh build. The step itself is tested
// against closed forms in tests/solvers/test_fluid_solver.cpp (FluidSolverSemiImplicit,
// FluidSolverLong.TerzaghiSemiImplicit*) and tests/cli/semi_implicit.sh.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>

#include "mupm/input/model.hpp"
#include "mupm/solvers/fluid_solver.hpp"
#include "mupm/solvers/pressure_system.hpp"
#include "projection_matrix.hpp"
#include "solid_body.hpp"
#include "test_utils.hpp"

namespace mupm {
namespace {

using test::field;
using test::ProjectionMatrix;

double global_max(double v) {
  MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return v;
}

template <int Dim>
void fill(const Points<Dim>& p, const Vectors& out, int offset = 0) {
  for (std::size_t i = 0; i < p.size(); ++i) {
    double x[3] = {0, 0, 0};
    for (int d = 0; d < Dim; ++d)
      x[d] = p.x(i, d);
    for (std::size_t c = 0; c < out.extent(1); ++c)
      out(i, c) = field(x, int(c) + offset);
  }
}

// Largest |a - b| over the owned rows, relative to the largest |b| (all ranks).
double relative_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double diff = 0, scale = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    diff = std::max(diff, std::abs(a[k] - b[k]));
    scale = std::max(scale, std::abs(b[k]));
  }
  const double largest = global_max(scale), r = global_max(diff) / largest;
  if (test::world()->getRank() == 0)
    std::printf("[ operator ] largest difference %.2e of the largest value %.3e\n", r, largest);
  return r;
}

// x over the owned points as a vector of the operators' map.
template <int Dim>
TpetraVector owned_vector(const Discretization<Dim>& disc, const Scalars& x) {
  TpetraVector v(disc.dist.owned_map());
  auto w = v.getLocalViewHost(Tpetra::Access::OverwriteAll);
  for (std::size_t i = 0; i < disc.points.n_owned; ++i)
    w(i, 0) = x(i);
  return v;
}

// y = H x against V_i div_i(x) of the fluid's passes (st.flow after fluid_flow of x): the
// relative difference.
template <int Dim>
double against_divergence(const CrsMatrix& H, const Discretization<Dim>& disc,
                          const FluidState<Dim>& st, const TpetraVector& xv, TpetraVector& y) {
  const auto& p = disc.points;
  H.apply(xv, y);
  std::vector<double> got(p.n_owned), want(p.n_owned);
  auto yv = y.getLocalViewHost(Tpetra::Access::ReadOnly);
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    got[i] = yv(i, 0);
    want[i] = p.volume(i) * st.flow(i);
  }
  return relative_difference(got, want);
}

// V H p against V_i div_i(p) of the fluid's passes, unsaturated (k_r and alpha vary).
template <int Dim>
void check_flow_operator() {
  std::array<long long, Dim> counts;
  counts.fill(9);
  counts[0] = 12;
  auto disc = discretize(test::world(), test::box<Dim>(counts, 3.015));
  auto& p = disc.points;
  Kokkos::deep_copy(p.porosity, 0.3);
  auto fp = fluid_params(disc.grid, 1e-9, 0.5);
  fp.retention = VanGenuchten::mualem(2e4, 1.8);
  fill(p, as_vectors(p.p));
  Kokkos::parallel_for(
      range(0, p.size()), KOKKOS_LAMBDA(const std::size_t i) { p.p(i) *= -3e4; });
  FluidState<Dim> st;
  st.allocate(p.size(), p.n_owned);
  fluid_constitutive(p, fp, st);
  Scalars x("x", p.size());
  fill(p, as_vectors(x), 5);
  fluid_flow(disc, fp, st, x, false);
  const auto H = assemble_flow_operator(disc, fp, st.alpha);
  const TpetraVector xv = owned_vector(disc, x);
  TpetraVector y(disc.dist.owned_map());
  EXPECT_LT(against_divergence(*H, disc, st, xv, y), 1e-12);
  // Symmetric: x . H y = y . H x for two fields.
  TpetraVector z(disc.dist.owned_map()), hz(disc.dist.owned_map());
  {
    auto v = z.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t i = 0; i < p.n_owned; ++i) {
      double xi[3] = {0, 0, 0};
      for (int d = 0; d < Dim; ++d)
        xi[d] = p.x(i, d);
      v(i, 0) = field(xi, 9);
    }
  }
  H->apply(z, hz);
  const double xhz = xv.dot(hz), zhx = z.dot(y);
  EXPECT_NEAR(xhz, zhx, 1e-12 * std::abs(xhz));
  EXPECT_GT(xv.dot(y), 0) << "positive semi-definite: x . H x >= 0";
}

bool same_entries(const CrsMatrix& a, const CrsMatrix& b) {
  return test::entry_difference(a, b) == 0;
}

// The kept graphs (include/mupm/solvers/kept_matrix.hpp): the flow operator and the coupling
// built on an intact, nearly saturated body, then refilled after bonds break (every bond across
// x = x0, at both ends) and S_r, k_r and alpha change, equal a fresh build on the new state to
// the bit (what a restart builds), B_0^T kept (KeptTranspose) too, and the refilled flow operator
// is the fluid's divergence over the intact bonds, as the fresh one on an intact body is
// (FlowOperatorIsTheFluidsDivergence).
TEST(PressureProjection, KeptGraphsRefilledAfterBreakageEqualAFreshBuild) {
  auto disc = discretize(test::world(), test::box<2>({12, 9}, 3.015));
  auto& p = disc.points;
  Kokkos::deep_copy(p.porosity, 0.3);
  auto fp = fluid_params(disc.grid, 1e-9, 0.5);
  fp.retention = VanGenuchten::mualem(2e4, 1.8);
  FluidState<2> st;
  st.allocate(p.size(), p.n_owned);
  fill(p, as_vectors(p.p));
  Kokkos::parallel_for(
      range(0, p.size()), KOKKOS_LAMBDA(const std::size_t i) { p.p(i) *= -1e3; });
  fluid_constitutive(p, fp, st);
  FlowOperator<2> h;
  h.build(disc, fp, st.alpha);
  VolumeCoupling<2> b;
  b.build(disc, 0.8);
  KeptTranspose bt;  // B_0^T: its rows are the dofs, those of ghost columns on another rank
  bt.build(b.matrix());
  const auto b_intact = Teuchos::rcp(new CrsMatrix(*b.matrix(), Teuchos::Copy));
  // Break every bond across x0 (a geometric rule: both ends on every rank agree).
  const double x0 = disc.grid.origin[0] + 5.5 * disc.grid.dx;
  long long broken = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i)
    for (BondIndex e = disc.bonds.offsets(i); e < disc.bonds.offsets(i + 1); ++e) {
      const LocalId j = disc.bonds.neighbor(e);
      if ((p.x(i, 0) - x0) * (p.x(j, 0) - x0) < 0) {
        disc.bonds.intact(e) = 0;
        ++broken;
      }
    }
  MPI_Allreduce(MPI_IN_PLACE, &broken, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  ASSERT_GT(broken, 100);
  disc.update_shape();
  // Drier: S_r, k_r and alpha change.
  Kokkos::parallel_for(
      range(0, p.size()), KOKKOS_LAMBDA(const std::size_t i) { p.p(i) *= 30; });
  fluid_constitutive(p, fp, st);
  Scalars x("x", p.size());
  fill(p, as_vectors(x), 5);
  fluid_flow(disc, fp, st, x, false);
  h.fill(disc, fp, st.alpha, true);
  b.fill(disc, 0.8);
  FlowOperator<2> h_fresh;
  h_fresh.build(disc, fp, st.alpha);
  VolumeCoupling<2> b_fresh;
  b_fresh.build(disc, 0.8);
  EXPECT_TRUE(same_entries(*h.matrix(), *h_fresh.matrix()));
  EXPECT_TRUE(same_entries(*b.matrix(), *b_fresh.matrix()));
  bt.fill(*b.matrix());  // the kept transpose: Tpetra's transposer's of the new values
  EXPECT_TRUE(same_entries(*bt.matrix(), *transpose(b_fresh.matrix())));
  EXPECT_FALSE(same_entries(*bt.matrix(), *transpose(b_intact)))
      << "the refill changed B_0^T's values";
  // A refill that leaves the bonds (geometry = false: the kept transpose of the gradient).
  h.fill(disc, fp, st.alpha, false);
  EXPECT_TRUE(same_entries(*h.matrix(), *h_fresh.matrix()));
  TpetraVector y(disc.dist.owned_map());
  EXPECT_LT(against_divergence(*h.matrix(), disc, st, owned_vector(disc, x), y), 1e-12);
}

TEST(PressureProjection, FlowOperatorIsTheFluidsDivergence2D) {
  check_flow_operator<2>();
}
TEST(PressureProjection, FlowOperatorIsTheFluidsDivergence3D) {
  check_flow_operator<3>();
}

// B~ (u, theta) against V S_r tr(eps) of the solid's pass 1, and B~^T p against V (f, l) of the
// solid's passes with the pore pressure p alone (u = theta = 0, no undrained split).
template <int Dim>
void check_coupling() {
  constexpr int R = kRotDim<Dim>, NC = Dim + R;
  std::array<long long, Dim> counts;
  counts.fill(8);
  counts[0] = 11;
  const auto law = MicropolarElastic::from_bulk_shear(10e6, 6e6, 3e6, 0.01);
  test::Body<Dim> body(test::box<Dim>(counts, 3.015), law, 0.5);
  auto& p = body.pts();
  auto sr = p.saturation;
  Kokkos::parallel_for(
      range(0, p.size()),
      KOKKOS_LAMBDA(const std::size_t i) { sr(i) = 0.6 + 0.001 * double(i % 7); });
  const auto B = assemble_volume_coupling(body.disc);
  const auto dofs = component_map(body.disc, NC, false);
  // Strain: u, theta a rough field on every point (ghosts included).
  fill(p, p.u);
  fill(p, p.theta, 7);
  body.forces();
  TpetraVector uv(dofs), bu(body.disc.dist.owned_map());
  {
    auto v = uv.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t i = 0; i < p.n_owned; ++i) {
      for (int d = 0; d < Dim; ++d)
        v(i * NC + d, 0) = p.u(i, d);
      for (int r = 0; r < R; ++r)
        v(i * NC + Dim + r, 0) = p.theta(i, r);
    }
  }
  B->apply(uv, bu);
  std::vector<double> a(p.n_owned), b(p.n_owned);
  {
    auto v = bu.getLocalViewHost(Tpetra::Access::ReadOnly);
    for (std::size_t i = 0; i < p.n_owned; ++i) {
      double tr = 0;
      for (int d = 0; d < Dim; ++d)
        tr += body.st.eps(i, d * Dim + d);
      a[i] = v(i, 0);
      b[i] = p.volume(i) * p.saturation(i) * tr;
    }
  }
  EXPECT_LT(relative_difference(a, b), 1e-12) << "B~ u is V S_r tr(eps)";
  // Force: p alone.
  Kokkos::deep_copy(p.u, 0.0);
  Kokkos::deep_copy(p.theta, 0.0);
  fill(p, as_vectors(p.p), 3);
  body.forces();
  TpetraVector pv(body.disc.dist.owned_map()), f(dofs);
  {
    auto v = pv.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t i = 0; i < p.n_owned; ++i)
      v(i, 0) = p.p(i);
  }
  B->apply(pv, f, Teuchos::TRANS);
  std::vector<double> fa, fb, la, lb;
  auto v = f.getLocalViewHost(Tpetra::Access::ReadOnly);
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    for (int d = 0; d < Dim; ++d) {
      fa.push_back(v(i * NC + d, 0));
      fb.push_back(p.volume(i) * body.st.force(i, d));
    }
    for (int r = 0; r < R; ++r) {
      la.push_back(v(i * NC + Dim + r, 0));
      lb.push_back(p.volume(i) * body.st.moment(i, r));
    }
  }
  EXPECT_LT(relative_difference(fa, fb), 1e-12) << "B~^T p is the pore water's force";
  EXPECT_LT(relative_difference(la, lb), 1e-10) << "and its moment";
}

TEST(PressureProjection, CouplingIsTheVolumetricStrainAndThePressureForce2D) {
  check_coupling<2>();
}
TEST(PressureProjection, CouplingIsTheVolumetricStrainAndThePressureForce3D) {
  check_coupling<3>();
}

// The pressure stabilization (pressure_projection.hpp): a checkerboard pressure exerts no force
// on the skeleton at the points whose neighbours' families are whole (B~^T p = 0: the
// projection cannot see it), and the stabilized flow operator holds it with the closed form of
// the header: with k = 0 and grad p = 0 on the whole families, (V H p)_i = 2 alpha V_i
// sum_j V_j (p_i - p_j) = 4 alpha V_i p_i sum_{j odd} V_j, alpha = G_p S_r^2 dt / (rho k2 w0), k2
// the continuous family's second moment, pi h delta^4 / 4 (2D) or 4 pi delta^5 / 15 (3D).
template <int Dim>
void check_checkerboard() {
  constexpr int R = kRotDim<Dim>, NC = Dim + R;
  std::array<long long, Dim> counts;
  counts.fill(Dim == 2 ? 18 : 15);
  const auto law = MicropolarElastic::from_bulk_shear(10e6, 6e6, 3e6, 0.01);
  const double rho = 1900, dt = 3e-6, Gp = 0.7;
  test::Body<Dim> body(test::box<Dim>(counts, 3.015), law, 0.5, StabilizationModulus::Automatic,
                       rho);
  auto& disc = body.disc;
  auto& p = disc.points;
  const double dx = disc.grid.dx, delta = disc.grid.horizon, L = counts[0] * dx;
  Kokkos::deep_copy(p.saturation, 1.0);
  auto parity = [&](std::size_t i) {
    long long s = 0;
    for (int d = 0; d < Dim; ++d)
      s += (long long)std::floor(p.x(i, d) / dx);
    return s % 2 == 0 ? 1.0 : -1.0;
  };
  auto interior = [&](std::size_t i) {  // at least 2 delta from every face
    for (int d = 0; d < Dim; ++d)
      if (p.x(i, d) < 2 * delta || p.x(i, d) > L - 2 * delta)
        return false;
    return true;
  };
  const auto& owned = disc.dist.owned_map();
  TpetraVector cb(owned), single(owned), out(owned);
  {
    auto v = cb.getLocalViewHost(Tpetra::Access::OverwriteAll);
    auto w = single.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t i = 0; i < p.n_owned; ++i) {
      v(i, 0) = parity(i);
      w(i, 0) = interior(i) ? 1.0 : 0.0;  // unit pressures: the scale of a force
    }
  }
  const auto B = assemble_volume_coupling(disc);
  const auto dofs = component_map(disc, NC, false);
  TpetraVector f(dofs), fs(dofs);
  B->apply(cb, f, Teuchos::TRANS);
  B->apply(single, fs, Teuchos::TRANS);
  // The stabilized operator without flow (k = 0: the flow's own alpha is zero).
  auto fp = fluid_params(disc.grid, 0.0, 0.5);
  fp.projection_stabilization = Gp;
  Scalars alpha("alpha", p.size()), density("rho", p.n_owned);
  Kokkos::deep_copy(density, rho);
  add_pressure_stabilization(disc, fp, dt, density, alpha);
  assemble_flow_operator(disc, fp, alpha)->apply(cb, out);
  const double k2 = Dim == 2 ? kPi * disc.grid.thickness * std::pow(delta, 4) / 4
                             : 4 * kPi * std::pow(delta, 5) / 15;
  const double a = Gp * dt / (rho * k2);
  // w0 = (the family's volume) / V_H, V_H the continuous family's: pi delta^2 h or 4 pi delta^3 / 3
  // (eq 76; the same on every whole family).
  const double vh =
      Dim == 2 ? kPi * delta * delta * disc.grid.thickness : 4 * kPi * std::pow(delta, 3) / 3;
  double force = 0, scale = 0, worst = 0, held = 0;
  long long n = 0;
  auto fv = f.getLocalViewHost(Tpetra::Access::ReadOnly);
  auto sv = fs.getLocalViewHost(Tpetra::Access::ReadOnly);
  auto ov = out.getLocalViewHost(Tpetra::Access::ReadOnly);
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    for (int k = 0; k < Dim; ++k)
      scale = std::max(scale, std::abs(sv(i * NC + k, 0)));
    if (!interior(i))
      continue;
    ++n;
    for (int k = 0; k < NC; ++k)
      force = std::max(force, std::abs(fv(i * NC + k, 0)));
    double odd = 0, family = 0;
    for (BondIndex e = disc.bonds.offsets(i); e < disc.bonds.offsets(i + 1); ++e) {
      family += p.volume(disc.bonds.neighbor(e));
      if (parity(disc.bonds.neighbor(e)) != parity(i))
        odd += p.volume(disc.bonds.neighbor(e));
    }
    const double expected = 4 * a / (family / vh) * p.volume(i) * parity(i) * odd;
    held = std::max(held, std::abs(expected));
    worst = std::max(worst, std::abs(ov(i, 0) - expected));
  }
  force = global_max(force);
  scale = global_max(scale);
  worst = global_max(worst);
  held = global_max(held);
  if (test::world()->getRank() == 0)
    std::printf(
        "[ checkerboard ] %dD: force %.2e of a unit pressure's %.2e; stabilized operator "
        "%.3e, off the closed form by %.2e\n",
        Dim, force, scale, held, worst);
  EXPECT_GT(global_max(double(n)), 0) << "no interior point";
  EXPECT_LT(force, 1e-12 * scale) << "the skeleton feels the checkerboard";
  EXPECT_GT(held, 0);
  EXPECT_LT(worst, 1e-12 * held);
}

TEST(PressureProjection, CheckerboardIsHeldByThePressureStabilization2D) {
  check_checkerboard<2>();
}
TEST(PressureProjection, CheckerboardIsHeldByThePressureStabilization3D) {
  check_checkerboard<3>();
}

// The pressure solve's preconditioner (include/mupm/solvers/linear_solve.hpp) on the semi-
// implicit step's matrix for incompressible water in a tight soil (pressure_projection.hpp),
// A = dt^2 B~ M^-1 B~^T + dt V H (k = 0: the pressure stabilization alone) + V C (C a small
// storage), 2D, delta = 3.015 dx: two horizons wide, on 1 and 2 ranks:
//  - Drop Tolerance: the ILU's matrix P keeps under half of A's entries, and P - A is positive
//    semi-definite (each dropped |a_ij| on the diagonal: x^T (P - A) x = sum |a_ij| (x_i -+
//    x_j)^2 >= 0; leaving the dropped entries out, or adding them signed, makes it indefinite);
//    CG with ILU(0) of P solves A x = b to the tolerance, checked with ||b - A x|| computed here;
//  - Preconditioner Refresh Interval = 3: refresh() computes the factors on every third call,
//    and at once after renew(); with factors of earlier values the solve still reaches the
//    tolerance on the current matrix.
// The matrix: test::ProjectionMatrix (projection_matrix.hpp), 24 x 24 points.
TEST(PressureProjectionSolve, SparsifiedAndKeptPreconditionerSolveTheWholeMatrix) {
  ProjectionMatrix m;
  const auto& p = m.body.disc.points;
  const auto& a = m.a;
  const auto& owned = m.owned;
  LinearSolveSettings set;
  set.method = "CG";
  set.preconditioner = "ILU";
  set.tolerance = 1e-10;
  set.drop_tolerance = 0.02;
  set.refresh_interval = 3;
  LinearSolve solve(set);
  solve.set_matrix(a);
  const auto pm = solve.preconditioner_matrix();
  ASSERT_FALSE(pm.is_null());
  const double kept = double(pm->getGlobalNumEntries()) / double(a->getGlobalNumEntries());
  EXPECT_LT(kept, 0.5);
  // x^T (P - A) x >= 0 for fields of every roughness (the same on any rank count).
  double worst = 0, scale = 0;
  for (int k = 0; k < 12; ++k) {
    TpetraVector x(owned), ax(owned), px(owned);
    {
      auto v = x.getLocalViewHost(Tpetra::Access::OverwriteAll);
      for (std::size_t i = 0; i < p.n_owned; ++i) {
        const double g = double(p.gid(i));
        v(i, 0) = std::sin((k + 1) * 0.37 * g + k) + (k % 3 == 0 ? std::cos(2.9 * g) : 0.0);
      }
    }
    a->apply(x, ax);
    pm->apply(x, px);
    const double xa = x.dot(ax), xp = x.dot(px);
    scale = std::max(scale, xa);
    worst = std::min(worst, xp - xa);
  }
  if (test::world()->getRank() == 0)
    std::printf(
        "[ drop 0.02 ] the ILU's matrix keeps %.3f of the entries; min x^T (P - A) x = "
        "%.2e of x^T A x up to %.2e\n",
        kept, worst, scale);
  EXPECT_GE(worst, -1e-12 * scale);
  // Solves against x = the smooth field, b = A x, computed here.
  auto check_solve = [&](const char* what) {
    TpetraVector exact(owned), b(owned), x(owned);
    m.problem(0, 1.0, exact, b);
    x.putScalar(0.0);
    double sc = 0;
    const auto res = solve.solve(b, x, sc);
    const double rel = m.residual(b, x);
    if (test::world()->getRank() == 0)
      std::printf("[ %s ] %d CG iterations, ||b - A x|| / ||b|| = %.2e\n", what, res.iterations,
                  rel);
    EXPECT_TRUE(res.converged) << what;
    EXPECT_LT(rel, 2e-10) << what;
  };
  check_solve("ILU(0) of the sparsified matrix");
  // Refreshes: the factors on every third call, and at once after renew().
  const long long s0 = solve.setups();
  std::vector<long long> computed;
  for (int call = 1; call <= 7; ++call) {
    m.add_to_diagonal(0.3 * m.mean_diagonal());
    if (call == 5)
      solve.renew();
    solve.refresh();
    computed.push_back(solve.setups() - s0);
    if (call == 2)
      check_solve("factors of values two refreshes old");
  }
  // calls 1, 2 kept; 3 computes; 4 kept; 5 renewed; 6 kept; 7 kept (the count restarts at 5)
  EXPECT_EQ(computed, (std::vector<long long>{0, 0, 1, 1, 2, 2, 2}));
  check_solve("after the refreshes");
}

// Pressure Solve -> Recycled Vectors (LinearSolveSettings::recycle): Belos' recycling CG on a
// sequence of systems with the matrix above, the storage changing from one to the next (as the
// projection's matrix does when bonds break or saturation changes), right-hand sides of the
// smooth field at growing amplitudes, each solve from 0, on 1 and 2 ranks:
//  - every solve reaches the tolerance, ||b - A x|| computed here;
//  - from the third system on, RCG takes under 0.8 of CG's iterations on the same system
//    (measured 0.70-0.73 on 2 ranks; with the space dropped before each solve it takes exactly
//    as many as CG, as on the first system);
//    no preconditioner, so that each solve is longer than RCG's cycle of 25 iterations, at
//    whose end the space is gathered;
//  - renew() drops the space: the next solve equals, bit for bit, that of a fresh LinearSolve
//    given the same matrix (a restart from the checkpoint where renew() is called).
TEST(PressureProjectionSolve, RecyclingCgDeflatesLaterSolvesAndRenewsLikeARestart) {
  ProjectionMatrix m;
  const auto& owned = m.owned;
  LinearSolveSettings set;
  set.method = "CG";
  set.tolerance = 1e-10;
  // No preconditioner, so that a solve takes more than the 25 iterations of an RCG cycle, at
  // whose end the space is gathered (with ILU(0) this small matrix takes about 20).
  set.preconditioner = "None";
  LinearSolveSettings recycling = set;
  recycling.recycle = 8;
  LinearSolve cg(set), rcg(recycling);
  ASSERT_EQ(cg.method(), "CG");
  ASSERT_EQ(rcg.method(), "RCG");
  cg.set_matrix(m.a);
  rcg.set_matrix(m.a);
  const int systems = 6;
  for (int k = 0; k < systems; ++k) {
    if (k > 0) {
      m.add_to_diagonal(0.01 * m.mean_diagonal());
      cg.refresh();
      rcg.refresh();
    }
    TpetraVector exact(owned), b(owned), x(owned), y(owned);
    m.problem(0, 1.0 + 0.25 * k, exact, b);
    x.putScalar(0.0);
    y.putScalar(0.0);
    double sc = 0, sr = 0;
    const auto a = cg.solve(b, x, sc), r = rcg.solve(b, y, sr);
    const double ra = m.residual(b, x), rr = m.residual(b, y);
    if (test::world()->getRank() == 0)
      std::printf("[ system %d ] CG %d iterations, RCG %d; ||b - A x|| / ||b|| = %.2e and %.2e\n",
                  k, a.iterations, r.iterations, ra, rr);
    EXPECT_TRUE(a.converged && r.converged) << k;
    EXPECT_LT(ra, 2e-10) << k;
    EXPECT_LT(rr, 2e-10) << k;
    if (k >= 2) {
      EXPECT_LT(r.iterations, 0.8 * a.iterations) << k;
    }
  }
  // A restart: a fresh solve of the same matrix, and the renewed one.
  m.add_to_diagonal(0.01 * m.mean_diagonal());
  rcg.renew();
  rcg.refresh();
  LinearSolve fresh(recycling);
  fresh.set_matrix(m.a);
  TpetraVector exact(owned), b(owned), x(owned), y(owned);
  m.problem(0, 3.0, exact, b);
  x.putScalar(0.0);
  y.putScalar(0.0);
  double sx = 0, sy = 0;
  const auto f = fresh.solve(b, x, sx), r = rcg.solve(b, y, sy);
  EXPECT_EQ(f.iterations, r.iterations);
  EXPECT_EQ(test::differing(x, y), 0u) << "renewed RCG and a fresh one";
}

// An ILU(0) breakdown of the pressure solve (include/mupm/solvers/linear_solve.hpp): blocks
// [[1,1,0],[1,1,1],[0,1,1]], nonsingular with a unit diagonal, whose factorization without
// pivoting meets a zero pivot in its second row (1 - 1 * 1), one block per rank on 2 ranks. The
// solve falls back to Jacobi and reaches x = (1, 2, 3) per block, computed here; without the
// fallback it does not converge (KokkosKernels' factorization puts 1e-6 in the zero pivot's
// place; Ifpack2's serial one threw, and its residual was NaN).
TEST(PressureProjectionSolve, IluBreakdownFallsBackToJacobi) {
  const GlobalId n = 6;
  auto map = Teuchos::rcp(new Map(Tpetra::global_size_t(n), 0, test::world()));
  auto a = Teuchos::rcp(new CrsMatrix(map, 3));
  TpetraVector b(map), x(map);
  const double block[3][3] = {{1, 1, 0}, {1, 1, 1}, {0, 1, 1}}, exact[3] = {1, 2, 3};
  {
    auto bv = b.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t l = 0; l < map->getNodeNumElements(); ++l) {
      const GlobalId row = map->getGlobalElement(LocalId(l));
      const int r = int(row % 3);
      std::vector<GlobalId> cols;
      std::vector<double> vals;
      double sum = 0;
      for (int c = 0; c < 3; ++c)
        if (block[r][c] != 0) {
          cols.push_back(row - r + c);
          vals.push_back(block[r][c]);
          sum += block[r][c] * exact[c];
        }
      a->insertGlobalValues(row, Teuchos::ArrayView<const GlobalId>(cols),
                            Teuchos::ArrayView<const double>(vals));
      bv(l, 0) = sum;
    }
  }
  a->fillComplete();
  LinearSolveSettings set;
  set.preconditioner = "ILU";
  set.tolerance = 1e-12;
  LinearSolve solve(set);
  solve.set_matrix(a);
  double scale = 0;
  const LinearSolveResult r = solve.solve(b, x, scale);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(solve.fallbacks(), 1);
  auto xv = x.getLocalViewHost(Tpetra::Access::ReadOnly);
  for (std::size_t l = 0; l < map->getNodeNumElements(); ++l)
    EXPECT_NEAR(xv(l, 0), exact[map->getGlobalElement(LocalId(l)) % 3], 1e-10);
}

// A right-hand side with a NaN (a run gone unstable before its solve) is reported as such, on
// every rank (the norm is global), not as a solve that stopped at a relative residual of 0
// after 0 iterations; a finite one on the same matrix solves.
TEST(PressureProjectionSolve, NonFiniteRightHandSideIsReported) {
  const GlobalId n = 4;
  auto map = Teuchos::rcp(new Map(Tpetra::global_size_t(n), 0, test::world()));
  auto a = Teuchos::rcp(new CrsMatrix(map, 1));
  for (std::size_t l = 0; l < map->getNodeNumElements(); ++l) {
    const GlobalId row = map->getGlobalElement(LocalId(l));
    const GlobalId col[1] = {row};
    const double val[1] = {2.0};
    a->insertGlobalValues(row, Teuchos::ArrayView<const GlobalId>(col, 1),
                          Teuchos::ArrayView<const double>(val, 1));
  }
  a->fillComplete();
  LinearSolve solve(LinearSolveSettings{});
  solve.set_matrix(a);
  TpetraVector b(map), x(map);
  b.putScalar(1.0);
  double scale = 0;
  EXPECT_TRUE(solve.solve(b, x, scale).finite_rhs);
  if (map->getGlobalElement(0) == 0) {  // the rank holding row 0
    auto bv = b.getLocalViewHost(Tpetra::Access::ReadWrite);
    bv(0, 0) = std::numeric_limits<double>::quiet_NaN();
  }
  const LinearSolveResult r = solve.solve(b, x, scale);
  EXPECT_FALSE(r.finite_rhs);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.iterations, 0);
}

}  // namespace
}  // namespace mupm
