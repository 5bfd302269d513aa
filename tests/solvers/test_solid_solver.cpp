// The solid step with boundary conditions: bars under traction and under end displacements
// (static equilibrium against the closed form and exact reaction; constant and mirrored
// layers), a body couple, and the stable-step estimate against the actual
// stability limit of the central-difference scheme.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "../../src/solvers/laws/solid_build.hpp"
#include "mupm/input/input.hpp"
#include "mupm/input/model.hpp"
#include "mupm/solvers/solid_solver.hpp"
#include "test_utils.hpp"

namespace mupm {
namespace {

template <int Dim>
SolidParams params(const MicropolarElastic& law, const GridSpec<Dim>& g) {
  return solid_params(law, g, 0.5);
}

const MicropolarElastic kLaw =
    MicropolarElastic::from_bulk_shear(270.83e6, 220.33e6, 100e6, 7.5e-3);

// A bar loaded through its two end faces (the boundary-layer issue, item 5): free in y, held
// at x = 0 and loaded at x = L as `load` says, run to rest. Returns the owned points' x and u
// (gathered on every rank, sorted by gid) and the reaction of the first condition.
struct BarResult {
  std::vector<double> x, u, y, v;  // x, u_x; y, u_y
  double reaction = 0;
};
template <int Dim>
BarResult bar_to_rest(const GridSpec<Dim>& g, std::vector<BoundaryCondition> bcs, int steps,
                      const MicropolarElastic& law = kLaw) {
  auto disc = discretize(test::world(), g);
  Kokkos::deep_copy(disc.points.saturation, 1.0);
  typename SolidSolver<Dim>::Settings set;
  const double L = g.counts[0] * g.dx;
  const double c_p = std::sqrt((law.lambda + 2 * law.mu) / set.rho_s);
  set.damping = 2 * kPi * c_p / (4 * L) * 2;  // about critical for the first axial mode
  SolidSolver<Dim> solver(disc, params(law, g), bcs, set, MPI_COMM_WORLD);
  solver.initialize(0.0, false);
  const double dt = 0.5 * solver.estimate_stable_dt();
  double time = 0;
  for (int n = 0; n < steps; ++n, time += dt)
    solver.step(time, dt);
  const auto e = solver.energy();
  EXPECT_LT(e.kinetic, 1e-8 * e.internal);  // at rest
  EXPECT_LT(std::abs(e.balance()), 1e-3 * e.external_work);
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.x);
  auto u = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.u);
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.gid);
  const std::size_t total = std::size_t(disc.grid.n_global());
  BarResult r;
  for (auto* v : {&r.x, &r.u, &r.y, &r.v})
    v->assign(total, 0.0);
  for (std::size_t i = 0; i < disc.points.n_owned; ++i) {
    r.x[gid(i)] = x(i, 0);
    r.u[gid(i)] = u(i, 0);
    r.y[gid(i)] = x(i, 1);
    r.v[gid(i)] = u(i, 1);
  }
  for (auto* v : {&r.x, &r.u, &r.y, &r.v})
    MPI_Allreduce(MPI_IN_PLACE, v->data(), int(total), MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  r.reaction = solver.reactions().at(0);
  return r;
}

// The 2D bar of the traction tests: 40 x 8 of spacing dx, a layer of one horizon before x = 0
// (region "left", held by `hold`), the traction t on the last column (region "right", `pull`,
// consistent or on the outer row). Regions `extra` are added after those two.
struct TractionBar {
  GridSpec<2> g;
  BoundaryCondition hold, pull;
};
TractionBar traction_bar(double dx, double factor, double t, bool consistent,
                         std::vector<std::pair<std::string, Box>> extra = {}) {
  TractionBar b;
  b.g = test::box<2>({40, 8}, factor, dx);
  b.g.layers[0] = {b.g.horizon_cells(), 0};
  const double L = 40 * dx;
  Box left, right;
  left.lo[0] = left.lo[1] = right.lo[1] = -1;
  left.hi[0] = -0.25 * dx;
  left.hi[1] = right.hi[1] = 1;
  right.lo[0] = L - dx;
  right.hi[0] = L;
  b.g.region_names = {"left", "right"};
  b.g.regions = {left, right};
  for (const auto& [name, box] : extra) {
    b.g.region_names.push_back(name);
    b.g.regions.push_back(box);
  }
  b.hold.name = "hold";
  b.hold.kind = BoundaryCondition::Displacement;
  b.hold.region_mask = 1u << 0;
  b.pull.name = "pull";
  b.pull.kind = BoundaryCondition::Traction;
  b.pull.region_mask = 1u << 1;
  b.pull.value = t;
  b.pull.consistent = consistent;
  b.pull.face = 1;  // +x
  return b;
}

// Mean u_x of the lattice column at x (all rows of the body and its layers).
double column_u(const BarResult& r, double x, double dx) {
  double sum = 0;
  int n = 0;
  for (std::size_t k = 0; k < r.x.size(); ++k)
    if (std::abs(r.x[k] - x) < 0.1 * dx) {
      sum += r.u[k];
      ++n;
    }
  EXPECT_GT(n, 0) << "no column at " << x;
  return sum / std::max(n, 1);
}

// The loaded column's (at xe) displacement beyond the straight line through the columns at xa and
// xb, as a length (the face acts as if it sat that much farther out); `strain`: the line's slope.
double loaded_face_excess(const BarResult& r, double dx, double xa, double xb, double xe,
                          double& strain) {
  const double ua = column_u(r, xa, dx), ub = column_u(r, xb, dx), ue = column_u(r, xe, dx);
  strain = (ub - ua) / (xb - xa);
  return (ue - (ub + strain * (xe - xb))) / strain;
}

// A bar under a consistent traction whose loaded face has a slaved layer beyond it (theta = 0
// Mirrored on it, u free there: the traction-loaded face of the Cosserat layer in
// test_solid_validation.cpp, through the solver): the uniform tension (theta = 0) continues into
// the layer, so the loaded column stays on the interior's line. Built before the layer's points
// were marked energy-free, the load would balance stresses those points do not carry.
TEST(SolidSolver, ConsistentTractionWithSlavedLayer) {
  const double dx = 2.5e-3, t = 1e5, L = 40 * dx;
  Box beyond;
  beyond.lo[0] = L + 0.25 * dx;
  beyond.lo[1] = -1;
  beyond.hi[0] = beyond.hi[1] = 1;
  auto b = traction_bar(dx, 3.015, t, true, {{"beyond", beyond}});
  b.g.layers[0][1] = 2 * b.g.horizon_cells();
  b.g.mirrored_layers = true;
  BoundaryCondition spin;
  spin.name = "spin";
  spin.kind = BoundaryCondition::MicroRotation;
  spin.region_mask = 1u << 2;
  spin.mirrored = spin.slaved = true;
  const auto r = bar_to_rest(b.g, {b.hold, b.pull, spin}, 6000);
  const double strain = t * (1 - kLaw.poisson() * kLaw.poisson()) / kLaw.young();
  double measured = 0;
  const double excess = loaded_face_excess(r, dx, 10.5 * dx, 30.5 * dx, L - 0.5 * dx, measured);
  std::printf("consistent with a slaved layer: strain ratio %.6f, loaded face's excess %.4f dx\n",
              measured / strain, excess / dx);
  EXPECT_NEAR(measured / strain, 1.0, 0.005);
  EXPECT_NEAR(r.reaction, -t * 8 * dx * b.g.thickness, 1e-4 * t * 8 * dx) << "reaction";
  EXPECT_LT(std::abs(excess), 1e-3 * dx) << excess / dx;
}

// Traction on the outer column (item 5 of the boundary-layer issue): the interior strain and
// the reaction are exact; what the truncated families at the loaded face cost shows as the
// loaded column's displacement beyond the interior's straight line, as a length: the face
// acts as if it sat `surface_length` farther out.
// With Traction Distribution = Consistent (kernels/boundary_conditions.hpp,
// consistent_traction_load) the uniform stress is in equilibrium up to the loaded face, so the
// loaded column continues the interior's straight line: no excess beyond round-off and the
// iteration's rest (asserted below 1e-3 dx; the outer row's excess is 0.1-0.2 dx).
TEST(SolidSolverLong, BarUnderTraction) {
  const double dx = 2.5e-3, t = 1e5, L = 40 * dx, H = 8 * dx;
  for (const bool consistent : {false, true}) {
    for (const double factor : {3.015, 4.015}) {
      const auto b = traction_bar(dx, factor, t, consistent);
      const auto r = bar_to_rest(b.g, {b.hold, b.pull}, 6000);
      const double strain = t * (1 - kLaw.poisson() * kLaw.poisson()) / kLaw.young();
      double measured = 0;
      const double surface_length =
          loaded_face_excess(r, dx, 10.5 * dx, 30.5 * dx, L - 0.5 * dx, measured);
      const std::string tag = std::string(consistent ? "_consistent" : "_outer_row") + "_delta" +
                              std::to_string(int(factor));
      RecordProperty("strain_ratio" + tag, std::to_string(measured / strain));
      RecordProperty("surface_length_over_dx" + tag, std::to_string(surface_length / dx));
      std::printf(
          "%s, delta %.3f dx: strain ratio %.6f, loaded face's excess %.4f dx (%.3f %% of L)\n",
          consistent ? "consistent" : "outer row", factor, measured / strain, surface_length / dx,
          100 * surface_length / L);
      EXPECT_NEAR(measured / strain, 1.0, 0.005) << measured << " vs " << strain;
      EXPECT_NEAR(r.reaction, -t * H * b.g.thickness, 1e-4 * t * H) << "reaction";
      if (consistent) {
        EXPECT_LT(std::abs(surface_length), 1e-3 * dx) << surface_length / dx;
      }
    }
  }
}

// Plane stress (Discretization->Plane = Stress: the law's plane_stress()): the bar of
// BarUnderTraction (consistent traction, delta = 3.015 dx) relaxes to uniaxial stress, axial strain
// t / E and lateral strain -nu t / E with the 3D E and nu, measured between the columns at 10.5
// and 30.5 dx and between the top and bottom rows there. Plane strain would give t (1 - nu^2) / E
// and -nu (1 + nu) t / E: 3.2 % and 18 % away (nu = 0.18).
TEST(SolidSolver, BarUnderTractionPlaneStress) {
  const double dx = 2.5e-3, t = 1e5, L = 40 * dx, H = 8 * dx;
  const auto b = traction_bar(dx, 3.015, t, true);
  const auto r = bar_to_rest(b.g, {b.hold, b.pull}, 6000, kLaw.plane_stress());
  const double E = kLaw.young(), nu = kLaw.poisson();  // 3D
  double axial = 0;
  loaded_face_excess(r, dx, 10.5 * dx, 30.5 * dx, L - 0.5 * dx, axial);
  // u_y of the top row less the bottom row's, over the body's columns 10.5 .. 30.5 dx.
  double top = 0, bottom = 0;
  int n_top = 0, n_bottom = 0;
  for (std::size_t k = 0; k < r.x.size(); ++k) {
    if (r.x[k] < 10 * dx || r.x[k] > 31 * dx)
      continue;
    if (std::abs(r.y[k] - (H - 0.5 * dx)) < 0.1 * dx) {
      top += r.v[k];
      ++n_top;
    } else if (std::abs(r.y[k] - 0.5 * dx) < 0.1 * dx) {
      bottom += r.v[k];
      ++n_bottom;
    }
  }
  ASSERT_GT(n_top, 0);
  ASSERT_GT(n_bottom, 0);
  const double lateral = (top / n_top - bottom / n_bottom) / (H - dx);
  std::printf(
      "[ plane stress bar ] axial strain / (t/E) = %.5f, lateral strain / (-nu t/E) = %.5f "
      "(plane strain would give %.5f and %.5f)\n",
      axial / (t / E), lateral / (-nu * t / E), 1 - nu * nu, 1 + nu);
  EXPECT_NEAR(axial / (t / E), 1.0, 0.005);
  EXPECT_NEAR(lateral / (-nu * t / E), 1.0, 0.005);
  EXPECT_NEAR(r.reaction, -t * H * b.g.thickness, 1e-4 * t * H) << "reaction";
}

// The same in 3D (a 16 x 3 x 3 bar, uniaxial stress: strain t / E): the consistent
// distribution leaves the loaded column on the interior's straight line; the outer row's excess
// is printed for the record.
TEST(SolidSolver, BarUnderTraction3D) {
  const double dx = 2.5e-3, t = 1e5;
  for (const bool consistent : {false, true}) {
    auto g = test::box<3>({16, 3, 3}, 3.015, dx);
    g.layers[0] = {g.horizon_cells(), 0};
    const double L = 16 * dx;
    Box left, right;
    for (int d = 1; d < 3; ++d) {
      left.lo[d] = right.lo[d] = -1;
      left.hi[d] = right.hi[d] = 1;
    }
    left.lo[0] = -1;
    left.hi[0] = -0.25 * dx;
    right.lo[0] = L - dx;
    right.hi[0] = L;
    g.region_names = {"left", "right"};
    g.regions = {left, right};
    BoundaryCondition hold, pull;
    hold.name = "hold";
    hold.kind = BoundaryCondition::Displacement;
    hold.region_mask = 1u << 0;
    pull.name = "pull";
    pull.kind = BoundaryCondition::Traction;
    pull.region_mask = 1u << 1;
    pull.value = t;
    pull.consistent = consistent;
    pull.face = 1;  // +x
    const auto r = bar_to_rest(g, {hold, pull}, 4000);
    const double strain = t / kLaw.young();
    double measured = 0;
    const double surface_length =
        loaded_face_excess(r, dx, 7.5 * dx, 12.5 * dx, L - 0.5 * dx, measured);
    std::printf("3D %s: strain ratio %.6f, loaded face's excess %.4f dx\n",
                consistent ? "consistent" : "outer row", measured / strain, surface_length / dx);
    RecordProperty(std::string("surface_length_over_dx_3d_") + (consistent ? "consistent" : "row"),
                   std::to_string(surface_length / dx));
    EXPECT_NEAR(r.reaction, -t * 9 * dx * dx, 1e-4 * t * 9 * dx * dx) << "reaction";
    if (consistent) {
      EXPECT_NEAR(measured / strain, 1.0, 0.005) << measured << " vs " << strain;
      EXPECT_LT(std::abs(surface_length), 1e-3 * dx) << surface_length / dx;
    }
  }
}

// A bar stretched by its end layers (u_x = 0 before x = 0, u_x = U beyond x = L, ramped; free in
// y): eps = U / L, sigma_xx = E' eps (plane strain, free sides), reaction -sigma_xx H. Constant
// layers make the body act longer (the kink at each face); mirrored layers (the body's mirror
// image about u_x = g, mirror_kinematic) reproduce the uniform stretch, which is symmetric about
// both faces, exactly when the layers are 2 delta thick (`horizons` = 2): then every layer point
// that bonds to the body has a whole family, and its force state is the body's.
// The 40 x 8 bar of spacing dx with layers `horizons` horizons thick at both ends (regions
// "left" and "right": the layer points beyond x = 0 and x = L).
GridSpec<2> end_layer_bar(double dx, int horizons, bool mirrored) {
  auto g = test::box<2>({40, 8}, 3.015, dx);
  g.layers[0] = {horizons * g.horizon_cells(), horizons * g.horizon_cells()};
  g.mirrored_layers = mirrored;
  const double L = 40 * dx;
  Box left, right;
  left.lo[0] = left.lo[1] = right.lo[1] = -1;
  left.hi[0] = -0.25 * dx;
  left.hi[1] = right.hi[1] = right.hi[0] = 1;
  right.lo[0] = L + 0.25 * dx;
  g.region_names = {"left", "right"};
  g.regions = {left, right};
  return g;
}

double end_displacement_bar(bool mirrored, int horizons, double& reaction_ratio) {
  const double dx = 2.5e-3, U = 1e-5;
  const auto g = end_layer_bar(dx, horizons, mirrored);
  const double L = 40 * dx, H = 8 * dx;
  BoundaryCondition hold, pull;
  hold.name = "hold";
  hold.kind = pull.kind = BoundaryCondition::Displacement;
  hold.region_mask = 1u << 0;
  pull.name = "pull";
  pull.region_mask = 1u << 1;
  pull.value = U;
  pull.time.kind = TimeFunction::Ramp;
  pull.time.ramp_time = 1e-3;  // about 1000 of the 6000 steps
  hold.mirrored = pull.mirrored = mirrored;
  const auto r = bar_to_rest(g, {hold, pull}, 6000);
  const double E = kLaw.young(), nu = kLaw.poisson();
  const double strain = U / L, stress = E / (1 - nu * nu) * strain;
  const double xa = 10.5 * dx, xb = 30.5 * dx;
  const double measured = (column_u(r, xb, dx) - column_u(r, xa, dx)) / (xb - xa);
  reaction_ratio = -r.reaction / (stress * H * g.thickness);
  return measured / strain;
}

TEST(SolidSolverLong, BarUnderEndDisplacement) {
  // Measured once with one-horizon mirrored layers (L = 60 dx): 1.0053, the layer's outer
  // points' truncated families (README); not rerun here.
  double reaction_constant = 0, reaction_mirrored = 0;
  const double constant = end_displacement_bar(false, 1, reaction_constant);
  const double mirrored = end_displacement_bar(true, 2, reaction_mirrored);
  RecordProperty("strain_ratio_constant", std::to_string(constant));
  RecordProperty("strain_ratio_mirrored", std::to_string(mirrored));
  std::printf(
      "end displacement: strain ratio %.6f constant, %.6f mirrored (2 horizons); "
      "reaction ratio %.6f, %.6f\n",
      constant, mirrored, reaction_constant, reaction_mirrored);
  EXPECT_NEAR(mirrored, 1.0, 0.005);
  EXPECT_NEAR(reaction_mirrored, 1.0, 0.005);
  // Constant layers: the body acts longer than L by about 0.7 dx per face (measured 2.3 % at
  // L = 60 dx, 3.4 % expected at 40 dx); the test pins that they are the worse.
  EXPECT_LT(constant, mirrored);
  EXPECT_NEAR(reaction_constant, constant, 1e-3);  // reaction and strain agree either way
}

// A bar between two slaved clamps (Boundary Layer Values = Mirrored on u_x, u_y and theta of
// each end layer: kernels/boundary_conditions.hpp, slave_layer), the right one pulled to
// u_x = U (ramped), free sides. With nu = 0 (lambda = 0) the clamps restrain no contraction and
// the closed form is the uniform stretch eps = U / L, sigma_xx = 2 mu eps, reaction -sigma_xx H,
// which the odd reflection reproduces in the layers exactly (a linear field): the strain and the
// reaction (dPsi/dg = -2 sum f V over the layer) within 0.5 %. The layers are one horizon thick:
// their points carry no energy, so their truncated families do not matter. Against the paper's
// constant clamps (which act as if the faces sat ~0.7 delta farther out) and the energy balance
// with the slaved work 2 dg (bar_to_rest: 1e-3 of W_ext).
// x, y and the rotation held on the layers of regions 0 and 1 (`first`_x ... `second`_r), mirrored
// and slaved or constant, all zero.
std::vector<BoundaryCondition> clamps(const std::string& first, const std::string& second,
                                      bool slaved) {
  std::vector<BoundaryCondition> bcs;
  for (int end = 0; end < 2; ++end)
    for (int c = 0; c < 3; ++c) {
      BoundaryCondition bc;
      bc.name = (end ? second : first) + "_" + "xyr"[c];
      bc.kind = c < 2 ? BoundaryCondition::Displacement : BoundaryCondition::MicroRotation;
      bc.component = c < 2 ? c : 0;
      bc.region_mask = 1u << end;
      bc.mirrored = bc.slaved = slaved;
      bcs.push_back(bc);
    }
  return bcs;
}

double clamped_bar(bool slaved, double& reaction_ratio) {
  const double dx = 2.5e-3, U = 1e-5;
  const MicropolarElastic law{0.0, 220.33e6, 100e6, 7.5e-3};
  const auto g = end_layer_bar(dx, 1, slaved);
  const double L = 40 * dx, H = 8 * dx;
  auto bcs = clamps("left", "right", slaved);
  bcs[3].value = U;  // right_x
  bcs[3].time.kind = TimeFunction::Ramp;
  bcs[3].time.ramp_time = 1e-3;
  const auto r = bar_to_rest(g, bcs, 6000, law);
  const double strain = U / L, stress = 2 * law.mu * strain;  // E' = 2 mu at nu = 0
  const double xa = 10.5 * dx, xb = 30.5 * dx;
  const double measured = (column_u(r, xb, dx) - column_u(r, xa, dx)) / (xb - xa);
  reaction_ratio = -r.reaction / (stress * H * g.thickness);  // left_x's: the held end's
  return measured / strain;
}

TEST(SolidSolverLong, BarBetweenSlavedClamps) {
  double reaction_constant = 0, reaction_slaved = 0;
  const double constant = clamped_bar(false, reaction_constant);
  const double slaved = clamped_bar(true, reaction_slaved);
  RecordProperty("strain_ratio_constant", std::to_string(constant));
  RecordProperty("strain_ratio_slaved", std::to_string(slaved));
  std::printf(
      "clamped bar (nu = 0): strain ratio %.6f constant, %.6f slaved; reaction ratio %.6f, "
      "%.6f\n",
      constant, slaved, reaction_constant, reaction_slaved);
  EXPECT_NEAR(slaved, 1.0, 1e-5);  // a linear field: the slaving continues it exactly
  EXPECT_NEAR(reaction_slaved, 1.0, 1e-5);
  EXPECT_LT(constant, slaved);
}

// Slaved layers fold their forces onto mirrors that may live on another rank
// (Distribution::add_to_owners). A block 6 dx wide and 4 dx high between slaved clamps, the top
// one sheared and lifted (ramped): its lattice (with 3-row layers) is 10 rows high, so 2 ranks
// split it across the middle and the bottom layer's outer row has its mirrors on the other rank.
// The same run on this rank alone (MPI_COMM_SELF) must give the same bits of u and theta, and
// the reactions and energies (sums over ranks) to round-off.
struct SlavedRun {
  std::vector<double> state;  // u, theta by global id (`fields` entries), reactions, energies
  std::size_t fields = 0;
  int cross_rank_mirrors = 0;
  double balance_error = 0, work = 0;  // |E_int + E_kin - W_ext - E_0|, W_ext at the end
};
// `refine`: steps of dt / refine, refine times as many (the same end time). `shear`: the top's
// x also moves at 0.05 m/s, by a Velocity condition (`velocity`) or a Displacement at that Rate.
SlavedRun slaved_block(const Teuchos::RCP<const Comm>& comm, MPI_Comm mpi, int refine = 1,
                       bool shear = false, bool velocity = false) {
  const double dx = 2.5e-3;
  auto g = test::box<2>({6, 4}, 3.015, dx);
  g.layers[1] = {g.horizon_cells(), g.horizon_cells()};
  g.mirrored_layers = true;
  Box bottom, top;
  bottom.lo[0] = bottom.lo[1] = top.lo[0] = -1;
  bottom.hi[0] = top.hi[0] = top.hi[1] = 1;
  bottom.hi[1] = -0.25 * dx;
  top.lo[1] = 4 * dx + 0.25 * dx;
  g.region_names = {"bottom", "top"};
  g.regions = {bottom, top};
  auto bcs = clamps("bottom", "top", true);
  for (int c = 0; c < 2; ++c) {  // top_x, top_y: ramped
    bcs[3 + c].value = c == 0 ? 2e-6 : 1e-6;
    bcs[3 + c].time.kind = TimeFunction::Ramp;
    bcs[3 + c].time.ramp_time = 2e-5;
  }
  if (shear) {  // top_x at 0.05 m/s
    bcs[3].kind = velocity ? BoundaryCondition::Velocity : BoundaryCondition::Displacement;
    bcs[3].value = 0.05;
    bcs[3].time.kind = velocity ? TimeFunction::Constant : TimeFunction::Rate;
  }
  auto disc = discretize(comm, g);
  Kokkos::deep_copy(disc.points.saturation, 1.0);
  SolidSettings set;
  SolidSolver<2> solver(disc, params(kLaw, g), bcs, set, mpi);
  solver.initialize(0.0, false);
  // A fixed step (the estimate's power iteration sums over ranks: not the same bits), about a
  // third of the stable one.
  const double dt = 0.1 * dx / std::sqrt((kLaw.lambda + 2 * kLaw.mu) / set.rho_s) / refine;
  for (int n = 0; n < 200 * refine; ++n)
    solver.step(n * dt, dt);
  auto& p = disc.points;
  auto u = Kokkos::create_mirror_view_and_copy(HostSpace(), p.u);
  auto th = Kokkos::create_mirror_view_and_copy(HostSpace(), p.theta);
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), p.gid);
  auto mirror = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.mirror);
  const std::size_t total = std::size_t(disc.grid.n_global());
  SlavedRun r;
  r.state.assign(3 * total, 0.0);
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    r.state[3 * gid(i)] = u(i, 0);
    r.state[3 * gid(i) + 1] = u(i, 1);
    r.state[3 * gid(i) + 2] = th(i, 0);
    if (mirror(i, 2) >= LocalId(p.n_owned))
      ++r.cross_rank_mirrors;
  }
  MPI_Allreduce(MPI_IN_PLACE, r.state.data(), int(r.state.size()), MPI_DOUBLE, MPI_SUM, mpi);
  MPI_Allreduce(MPI_IN_PLACE, &r.cross_rank_mirrors, 1, MPI_INT, MPI_SUM, mpi);
  r.fields = r.state.size();
  for (double f : solver.reactions())
    r.state.push_back(f);
  const auto e = solver.energy();
  r.balance_error = solver.energy_balances().at(0).error;
  r.work = e.external_work;
  r.state.push_back(e.internal);
  r.state.push_back(e.kinetic);
  r.state.push_back(e.external_work);
  return r;
}

TEST(SolidSolver, SlavedLayersIndependentOfRanks) {
  int ranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  const SlavedRun all = slaved_block(test::world(), MPI_COMM_WORLD);
  const SlavedRun alone = slaved_block(test::self(), MPI_COMM_SELF);
  if (ranks == 2) {
    EXPECT_GT(all.cross_rank_mirrors, 0) << "the partition did not put mirrors on the other rank";
  }
  EXPECT_EQ(alone.cross_rank_mirrors, 0);
  ASSERT_EQ(all.state.size(), alone.state.size());
  ASSERT_GT(all.state.size(), all.fields);
  double moved = 0;
  for (std::size_t k = 0; k < all.fields; ++k) {  // the points' state: the same bits
    EXPECT_EQ(std::memcmp(&all.state[k], &alone.state[k], sizeof(double)), 0)
        << "entry " << k << ": " << all.state[k] << " vs " << alone.state[k];
    moved = std::max(moved, std::abs(all.state[k]));
  }
  EXPECT_GT(moved, 0);
  // Reactions and energies are sums over ranks: equal to round-off.
  for (std::size_t k = all.fields; k < all.state.size(); ++k)
    EXPECT_NEAR(all.state[k], alone.state[k], 1e-12 * std::abs(alone.state[k])) << "entry " << k;
  std::printf("slaved block: %d points with a mirror on another rank, compared with one rank\n",
              all.cross_rank_mirrors);
}

// The work done through slaved layers enters W_ext as dPsi/dg on 2 dg (slaved_increment): the
// undamped energy balance of the slaved block then closes to round-off, with the central
// difference's kinetic energy (SolidSolver::Energy::kinetic_shift; with E_kin alone it was its
// O(dt^2) error, 4.3e-4 of W_ext). Booking the layer points' own increments instead, or leaving
// the factor 2 out, leaves an O(1) share of the work unbalanced at any step.
TEST(SolidSolver, SlavedLayersEnergyBalance) {
  const SlavedRun coarse = slaved_block(test::world(), MPI_COMM_WORLD, 1);
  const SlavedRun fine = slaved_block(test::world(), MPI_COMM_WORLD, 2);
  std::printf("slaved block, undamped: energy error %.3e and %.3e of W_ext = %.4e J (dt, dt/2)\n",
              coarse.balance_error / coarse.work, fine.balance_error / fine.work, coarse.work);
  ASSERT_GT(coarse.work, 0);
  EXPECT_LT(coarse.balance_error, 1e-12 * coarse.work);
  EXPECT_LT(fine.balance_error, 1e-12 * fine.work);
}

// A slaved Velocity layer reflects about the displacement it has prescribed (integrated by the
// midpoint rule, as apply_kinematic moves a constant layer): the same motion as a Displacement
// at that Rate, to round-off, and the same energy balance.
TEST(SolidSolver, SlavedVelocityLayerMovesAsDisplacement) {
  const SlavedRun by_velocity = slaved_block(test::world(), MPI_COMM_WORLD, 1, true, true);
  const SlavedRun by_rate = slaved_block(test::world(), MPI_COMM_WORLD, 1, true, false);
  ASSERT_EQ(by_velocity.state.size(), by_rate.state.size());
  double scale = 0, diff = 0;
  for (std::size_t k = 0; k < by_rate.fields; ++k) {
    scale = std::max(scale, std::abs(by_rate.state[k]));
    diff = std::max(diff, std::abs(by_velocity.state[k] - by_rate.state[k]));
  }
  std::printf(
      "slaved Velocity against Displacement (Rate): max |difference| %.2e of %.2e; "
      "energy error %.2e and %.2e of W_ext\n",
      diff, scale, by_velocity.balance_error / by_velocity.work,
      by_rate.balance_error / by_rate.work);
  EXPECT_GT(scale, 1e-6);  // the shear moved the block (the top: 200 steps at 0.05 m/s)
  EXPECT_LT(diff, 1e-10 * scale);
  EXPECT_NEAR(by_velocity.work, by_rate.work, 1e-9 * by_rate.work);
  EXPECT_LT(by_velocity.balance_error, 1e-3 * by_velocity.work);
}

// Displacements held at 0 along x and y on the regions of `mask` (0: every point).
std::vector<BoundaryCondition> held(std::uint32_t mask) {
  BoundaryCondition hold_x, hold_y;
  hold_x.kind = hold_y.kind = BoundaryCondition::Displacement;
  hold_x.name = "hx";
  hold_y.name = "hy";
  hold_x.region_mask = hold_y.region_mask = mask;
  hold_y.component = 1;
  return {hold_x, hold_y};
}

// A uniform body couple m on a body whose displacements are held: at rest the Cosserat
// coupling balances it, -4 mu_c theta + m = 0 (from sigma_xy - sigma_yx = 4 mu_c theta, eq 80),
// so theta = m / (4 mu_c) (uniform: no couple stress, and free faces need d theta/dn = 0).
// The truncated families at the faces perturb theta there (17 % at the face, still 0.6 % at
// 6 dx inside); the centre of this body, 18 dx inside, is checked to 1e-3.
TEST(SolidSolverLong, BodyCoupleAgainstCosseratCoupling) {
  const double dx = 2.5e-3;
  auto g = test::box<2>({40, 40}, 3.015, dx);
  auto disc = discretize(test::world(), g);
  Kokkos::deep_copy(disc.points.saturation, 1.0);
  BoundaryCondition couple;
  couple.kind = BoundaryCondition::BodyCouple;
  couple.name = "m";
  couple.value = 4e4;  // N m / m^3
  typename SolidSolver<2>::Settings set;
  set.damping = 5e4;  // near critical for the rotation: omega = sqrt(4 mu_c / J) = 4.7e4 /s
  auto bcs = held(0);
  bcs.push_back(couple);
  SolidSolver<2> solver(disc, params(kLaw, g), bcs, set, MPI_COMM_WORLD);
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

// A load switched on at once (a body force on a block held at one end, undamped, at 0.9 of the
// stable step) rings the fastest modes. With the central difference's kinetic energy
// 1/2 m v^{n-1/2}.v^{n+1/2} = E_kin - dt^2/8 m|a|^2 (SolidSolver::Energy::kinetic_shift) the
// balance of a linear operator with the trapezoid's work closes to round-off at every step;
// with E_kin alone it is off by the shift, which this load makes a few percent of the largest
// term (asserted too, so that the test shows what the shift does).
TEST(SolidSolver, SuddenLoadBalanceClosesWithTheCentralDifferenceEnergy) {
  const double dx = 2.5e-3;
  auto g = test::box<2>({12, 10}, 3.015, dx);
  g.region_names = {"left"};
  g.regions = {test::box2(-1, 1.5 * dx, -1, 1)};
  auto disc = discretize(test::world(), g);
  Kokkos::deep_copy(disc.points.saturation, 1.0);
  BoundaryCondition push;
  push.kind = BoundaryCondition::BodyForce;
  push.name = "push";
  push.value = 1e6;  // N/m^3 along x, from t = 0
  typename SolidSolver<2>::Settings set;
  auto bcs = held(1u);
  bcs.push_back(push);
  SolidSolver<2> solver(disc, params(kLaw, g), bcs, set, MPI_COMM_WORLD);
  solver.initialize(0.0, false);
  const double dt = 0.9 * solver.estimate_stable_dt();
  solver.set_time_step(dt);
  const double b0 = solver.energy().balance();
  double worst = 0, shift = 0;
  double time = 0;
  for (int n = 0; n < 200; ++n, time += dt) {
    solver.step(time, dt);
    const auto e = solver.energy();
    worst = std::max(worst, std::abs(e.balance() - b0) / e.scale());
    shift = std::max(shift, std::abs(e.kinetic_shift) / e.scale());
  }
  if (test::world()->getRank() == 0)
    std::printf("[ sudden ] balance error / largest term %.2e, largest shift %.2e\n", worst, shift);
  EXPECT_LT(worst, 1e-12);
  EXPECT_GT(shift, 1e-2);  // E_kin alone would have failed the driver's 1 %
  EXPECT_GT(solver.energy().external_work, 0.0);
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

// Each law's registration (include/mupm/input/law_registry.hpp) builds the solid solver of its
// law from the model, with the law's own parameters of Materials: Drucker-Prager's angles in
// radians, its cohesions and softening modulus, the 3D elastic law; the elastic law is the
// model's.
template <int Dim>
void check_law_factories() {
  const std::string counts = Dim == 2 ? "{8, 6}" : "{6, 5, 4}";
  auto input = [&](const std::string& law) {
    return "<ParameterList name=\"mupm\"><ParameterList name=\"Discretization\">"
           "<Parameter name=\"Dimension\" type=\"int\" value=\"" +
           std::to_string(Dim) +
           "\"/><Parameter name=\"Spacing\" type=\"double\" value=\"0.01\"/>"
           "<Parameter name=\"Counts\" type=\"Array(int)\" value=\"" +
           counts +
           "\"/></ParameterList><ParameterList name=\"Materials\">"
           "<Parameter name=\"Model\" type=\"string\" value=\"" +
           law +
           "\"/><Parameter name=\"Bulk Modulus\" type=\"double\" value=\"1e8\"/>"
           "<Parameter name=\"Shear Modulus\" type=\"double\" value=\"5e7\"/>"
           "<Parameter name=\"Length Scale\" type=\"double\" value=\"1e-3\"/>"
           "<Parameter name=\"Friction Angle\" type=\"double\" value=\"30\"/>"
           "<Parameter name=\"Dilation Angle\" type=\"double\" value=\"12\"/>"
           "<Parameter name=\"Cohesion\" type=\"double\" value=\"2e4\"/>"
           "<Parameter name=\"Residual Cohesion\" type=\"double\" value=\"5e3\"/>"
           "<Parameter name=\"Softening Modulus\" type=\"double\" value=\"-3e5\"/>"
           "</ParameterList></ParameterList>";
  };
  auto build = [](const Model<Dim>& m, Discretization<Dim>& disc) {
    SolidSettings settings;
    return m.law->build(SolidBuild<Dim>{m, disc, settings, MPI_COMM_WORLD, nullptr});
  };
  {
    auto pl = parse_input(input("Micropolar Elastic"));
    validate_input(*pl);
    const Model<Dim> m = model_from_input<Dim>(*pl);
    auto disc = discretize(test::world(), m.grid, m.run.field_groups);
    auto solid = build(m, disc);
    auto* el = dynamic_cast<SolidSolver<Dim, MicropolarElastic>*>(solid.get());
    ASSERT_NE(el, nullptr);
    EXPECT_EQ(el->law().lambda, m.solid.law.lambda);
    EXPECT_EQ(el->law().mu, m.solid.law.mu);
  }
  auto pl = parse_input(input("Micropolar Drucker-Prager"));
  validate_input(*pl);
  const Model<Dim> m = model_from_input<Dim>(*pl);
  auto disc = discretize(test::world(), m.grid, m.run.field_groups);
  auto solid = build(m, disc);
  using Elastic = SolidSolver<Dim, MicropolarElastic>;
  EXPECT_EQ(dynamic_cast<Elastic*>(solid.get()), nullptr);
  auto* dp = dynamic_cast<SolidSolver<Dim, MicropolarDruckerPrager<Dim>>*>(solid.get());
  ASSERT_NE(dp, nullptr);
  const DruckerPragerParams& d = dp->law().dp;
  EXPECT_DOUBLE_EQ(d.friction, kPi / 6);
  EXPECT_DOUBLE_EQ(d.dilation, 12 * kPi / 180);
  EXPECT_EQ(d.cohesion, 2e4);
  EXPECT_EQ(d.residual, 5e3);
  EXPECT_EQ(d.softening, -3e5);
  EXPECT_EQ(dp->law().elastic.mu, m.material.mu);
  EXPECT_EQ(dp->law().elastic.lambda, m.material.lambda);
  EXPECT_FALSE(dp->law().plane_stress);
}
TEST(SolidSolver, LawFactories) {
  check_law_factories<2>();
  check_law_factories<3>();
}

}  // namespace
}  // namespace mupm
