// Closed-form checks of the elastic micropolar solid: the Cosserat layer in simple shear
// (closed form in CosseratShear below) and the P-wave speed in a laterally constrained bar.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

#include "solvers/solid_body.hpp"

namespace mupm {
namespace {

using test::Body;

// The closed form of the micropolar layer 0 <= y <= h in simple shear by the traction tau on its
// faces, plane strain, u(0) = 0, theta(0) = theta(h) = 0, couple stress m = B kappa with
// B = mu l^2 / 2 (eq 81), alpha^2 = 4 mu mu_c / ((mu + mu_c) B). Signs as in eq 50 (2D:
// eps_xy = du_x/dy + theta, theta counterclockwise), so theta -> -gamma/2 away from the faces.
struct CosseratShear {
  double mu = 10e6, mu_c = 5e6, l = 0.01, h = 0.1, tau = 10e3, lambda = 10e6;
  double alpha() const { return std::sqrt(4 * mu * mu_c / ((mu + mu_c) * (mu * l * l / 2))); }
  double theta(double y) const {
    const double a = alpha();
    return -(tau / (2 * mu)) * (1 - std::cosh(a * (y - h / 2)) / std::cosh(a * h / 2));
  }
  double u(double y) const {
    const double a = alpha();
    return tau * y / mu - mu_c * tau / (mu * (mu + mu_c) * a) *
                              (std::sinh(a * (y - h / 2)) + std::sinh(a * h / 2)) /
                              std::cosh(a * h / 2);
  }
};

// Dynamic relaxation with mass-proportional damping c until steps are done.
template <int Dim>
void relax(Body<Dim>& body, double dt, double damping, int steps) {
  const Vectors none;
  body.forces();
  for (int n = 0; n < steps; ++n) {
    advance_positions(body.pts(), dt);
    body.forces();
    advance_velocities(body.pts(), body.st.force, body.st.moment, body.rho, body.inertia, none,
                       none, {0, 0, 0}, damping, dt);
  }
}

// Fixes the components of `mask` on the points selected by `where`.
template <int Dim>
void fix(Body<Dim>& body, std::uint32_t mask, std::function<bool(const double*)> where) {
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), body.pts().x);
  auto fixed = Kokkos::create_mirror_view(body.pts().fixed);
  Kokkos::deep_copy(fixed, body.pts().fixed);
  for (std::size_t i = 0; i < body.pts().size(); ++i) {
    double xi[3] = {0, 0, 0};
    for (int d = 0; d < Dim; ++d)
      xi[d] = x(i, d);
    if (where(xi))
      fixed(i) |= mask;
  }
  Kokkos::deep_copy(body.pts().fixed, fixed);
}

// The layer of CosseratShear: 0 <= y <= h, u_x = u(y), theta = theta(y), shear traction tau.
// The boundary layers (3 rows outside every face) hold the closed form itself, so the interior
// must relax to it: a layer infinite in x, loaded on its faces.
TEST(SolidValidationLong, CosseratLayerSimpleShear) {
  const CosseratShear cs;
  const double mu = cs.mu, mu_c = cs.mu_c, l = cs.l, h = cs.h, lambda = cs.lambda;
  ASSERT_NEAR(cs.alpha(), 163.299, 1e-3);  // the closed form's value for these constants
  auto theta_exact = [&](double y) { return cs.theta(y); };
  auto u_exact = [&](double y) { return cs.u(y); };
  EXPECT_NEAR(theta_exact(h / 2), -4.9972e-4, 1e-8);
  EXPECT_NEAR(u_exact(h), 9.5918e-5, 1e-9);

  // h/dx = 80: the rotation's boundary layer is 1/alpha = 6.1 mm thick, less than delta at
  // h/dx = 40 (alpha delta = 1.23), where the first row's theta is 8.5 % off (u: 0.09 %);
  // at h/dx = 80 (alpha delta = 0.61) theta is within 1.7 % and u within 0.01 %.
  const double dx = h / 80;
  auto g = test::box<2>({2, std::lround(h / dx)}, 3.015, dx);
  // Layers of 2 delta: the neighbours of the real points must have full families too, or a
  // correspondence model sees their truncated shape tensors (with delta-thick layers the
  // columns next to the x-layers were 11 % off in theta).
  g.layers = {{{6, 6}, {6, 6}}};
  Body<2> body(g, MicropolarElastic{lambda, mu, mu_c, l}, 0.5);
  auto outside = [&](const double* x) { return x[0] < 0 || x[0] > 2 * dx || x[1] < 0 || x[1] > h; };
  body.set([&](const double* x, double* u, double* t) {
    u[0] = outside(x) ? u_exact(x[1]) : 0.0;
    u[1] = 0;
    t[0] = outside(x) ? theta_exact(x[1]) : 0.0;
  });
  fix(body, 0b111, outside);
  fix(body, 0b010, [](const double*) { return true; });  // u_y = 0, as in the closed form
  // rho = 2000: c_p = 122 m/s, dt well below dx/c_p; damping near critical for the slowest
  // mode; 5000 steps = 12.5 ms, ~14 decay times of that mode (the result no longer changes).
  const double c_s = std::sqrt(mu / 2000.0);
  relax(body, 2.5e-6, 2 * kPi * c_s / (2 * h), 5000);

  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), body.pts().x);
  auto u = Kokkos::create_mirror_view_and_copy(HostSpace(), body.pts().u);
  auto th = Kokkos::create_mirror_view_and_copy(HostSpace(), body.pts().theta);
  double err_u = 0, err_t = 0;
  for (std::size_t i = 0; i < body.pts().n_owned; ++i) {
    if (outside(&x(i, 0)))
      continue;
    err_u = std::max(err_u, std::abs(u(i, 0) - u_exact(x(i, 1))));
    err_t = std::max(err_t, std::abs(th(i, 0) - theta_exact(x(i, 1))));
  }
  MPI_Allreduce(MPI_IN_PLACE, &err_u, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &err_t, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  RecordProperty("max_u_error_rel", std::to_string(err_u / u_exact(h)));
  RecordProperty("max_theta_error_rel", std::to_string(err_t / std::abs(theta_exact(h / 2))));
  EXPECT_LT(err_u, 0.03 * u_exact(h)) << err_u / u_exact(h);
  EXPECT_LT(err_t, 0.03 * std::abs(theta_exact(h / 2))) << err_t / std::abs(theta_exact(h / 2));
}

// The Cosserat layer of CosseratShear with boundary layers that hold the conditions
// themselves, no exact data in them (the boundary-layer issue): the base clamped (u = theta = 0),
// and either
// - `driven`: the top clamped at u = U = u_exact(h), theta = 0; the displacement-driven problem
//   has the traction problem's solution, so the top clamp's reaction over the width must be
//   tau; or
// - the test: theta = 0 held on the top (u free there) and the shear traction tau on the
//   top row of real points (a body force tau / dx), or, `consistent`, distributed as Traction
//   Distribution = Consistent does (kernels/boundary_conditions.hpp, consistent_traction_load:
//   the strip within 2 delta + dx of the top face, the slaved layer's free u included, balancing
//   the uniform shear stress tau that the discrete operator with its fold makes of it).
// `slaved`: Boundary Layer Values = Mirrored (kernels/boundary_conditions.hpp, slave_layer: the
// layers carry no strain energy and follow their mirrors oddly, their forces folded back), else
// Constant (the paper's: the layers hold g and keep their energy). Infinite in x by periodic
// images: the columns outside the body (6 = 2 delta each side, energy-free, as the slaved
// layers) copy the column W to the left or right, and their forces are folded onto those (the
// same chain rule as the slaved layers' fold), before the slaved layers' fold. The images need
// the whole body on each rank: run on one rank (a test harness of the solver's kernels; the
// solver's own rank independence is tested with the quick start in tests/cli/restart.sh).
struct ClampedLayer {
  double tau_error = 0;    // driven: reaction / W / tau - 1
  double u_row_error = 0;  // u of the top row against the closed form there
  double u_top_error = 0;  // traction: u(h) (extrapolated from the top rows) / u_exact(h) - 1
  double theta_mid_error = 0, u_mid_error = 0;  // at the row next below h / 2
  double stiffness_ratio = 0;  // G_eff / mu = tau h / (mu u(h)): driven from the reaction
};
ClampedLayer cosserat_layer_between_layers(bool slaved, bool driven, int per_h,
                                           bool consistent = false) {
  const CosseratShear cs;
  const double mu = cs.mu, mu_c = cs.mu_c, l = cs.l, h = cs.h, tau = cs.tau, lambda = cs.lambda;
  auto theta_exact = [&](double y) { return cs.theta(y); };
  auto u_exact = [&](double y) { return cs.u(y); };
  const double U = u_exact(h), dx = h / per_h;
  const int cols = 2;
  const double W = cols * dx;
  auto g = test::box<2>({cols, per_h}, 3.015, dx);
  g.layers = {{{6, 6}, {6, 6}}};
  g.mirrored_layers = true;
  Box bottom, top;  // the y-layers' points inside the x-range (the images are the others)
  bottom.lo[0] = top.lo[0] = 0;
  bottom.hi[0] = top.hi[0] = W;
  bottom.lo[1] = -1;
  bottom.hi[1] = -0.25 * dx;
  top.lo[1] = h + 0.25 * dx;
  top.hi[1] = 1;
  g.region_names = {"bottom", "top"};
  g.regions = {bottom, top};
  Body<2> body(g, MicropolarElastic{lambda, mu, mu_c, l}, 0.5);
  auto& p = body.pts();
  // The conditions: x and the rotation on both layers (top x only when driven); u_y = 0 is held
  // everywhere, as in the closed form.
  std::vector<BoundaryCondition> bcs;
  auto add = [&](BoundaryCondition::Kind kind, std::uint32_t mask, double value) {
    BoundaryCondition bc;
    bc.kind = kind;
    bc.region_mask = mask;
    bc.value = value;
    bc.mirrored = bc.slaved = slaved;
    bcs.push_back(bc);
  };
  add(BoundaryCondition::Displacement, 1u << 0, 0.0);
  add(BoundaryCondition::MicroRotation, 1u << 0, 0.0);
  add(BoundaryCondition::MicroRotation, 1u << 1, 0.0);
  if (driven)
    add(BoundaryCondition::Displacement, 1u << 1, U);
  auto xh = Kokkos::create_mirror_view_and_copy(HostSpace(), p.x);
  auto key = [&](double x, double y) {
    return std::make_pair(std::lround(x / dx * 2), std::lround(y / dx * 2));
  };
  std::map<std::pair<long, long>, int> at;
  for (std::size_t i = 0; i < p.size(); ++i)
    at[key(xh(i, 0), xh(i, 1))] = int(i);
  std::vector<int> image, source;
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const double x = xh(i, 0), y = xh(i, 1);
    if (x < 0 || x > W) {
      double xc = std::fmod(x, W);
      if (xc < 0)
        xc += W;
      image.push_back(int(i));
      source.push_back(at.at(key(xc, y)));
    }
  }
  auto to_device = [](const std::vector<int>& v) {
    Kokkos::View<int*> d("index", v.size());
    auto hd = Kokkos::create_mirror_view(d);
    for (std::size_t k = 0; k < v.size(); ++k)
      hd(k) = v[k];
    Kokkos::deep_copy(d, hd);
    return d;
  };
  auto img = to_device(image), src = to_device(source);
  body.set([&](const double* x, double* u, double* t) {
    u[0] = x[1] < 0 ? 0.0 : (x[1] > h ? (driven ? U : tau * h / mu) : tau * x[1] / mu);
    u[1] = 0;
    t[0] = 0;
  });
  auto outside = [&](const double* x) { return x[0] < 0 || x[0] > W; };
  fix(body, 0b010, [](const double*) { return true; });
  fix(body, 0b111, outside);
  fix(body, kFixedNoEnergy, outside);
  mark_fixed(bcs, p);
  if (slaved)
    mark_mirrored_layers(bcs, p, body.disc.mirror);
  auto set_layers = [&] {
    if (slaved)
      for (const auto& bc : bcs)
        slave_layer(bc, p, body.disc.mirror, bc.value, 0.0);  // constant g
    else
      apply_kinematic(bcs, p, 0.0, 0.0);
    auto u = p.u, th = p.theta, v = p.v;
    Kokkos::parallel_for(
        range(0, image.size()), KOKKOS_LAMBDA(const std::size_t k) {
          const int i = img(k), m = src(k);
          u(i, 0) = u(m, 0);
          v(i, 0) = v(m, 0);
          th(i, 0) = th(m, 0);
        });
  };
  const FaceSlots slots{-1, -1, 0, 1, -1, -1};  // the -y and +y faces
  Vectors fold("fold", p.size(), 2 * 3);
  auto forces = [&] {
    body.forces();
    auto f = body.st.force, mo = body.st.moment;
    Kokkos::parallel_for(  // in order: an image's source may be an image's source too
        range(0, 1), KOKKOS_LAMBDA(const std::size_t) {
          for (std::size_t k = 0; k < img.extent(0); ++k) {
            const int i = img(k), m = src(k);
            for (int d = 0; d < 2; ++d) {
              f(m, d) += f(i, d);
              f(i, d) = 0;
            }
            mo(m, 0) += mo(i, 0);
            mo(i, 0) = 0;
          }
        });
    fold_layer_forces(body.disc, slots, f, mo, fold);
  };
  Vectors load("load", p.n_owned, 2), none, couple("couple", p.n_owned, 1);
  if (!driven) {
    auto b = Kokkos::create_mirror_view(load);
    Kokkos::deep_copy(b, 0.0);
    if (!consistent) {
      for (std::size_t i = 0; i < p.n_owned; ++i)
        if (!outside(&xh(i, 0)) && xh(i, 1) < h && xh(i, 1) > h - dx)
          b(i, 0) = tau / dx;
    } else {
      SolidState<2> tmp;
      tmp.allocate(p.size(), p.n_owned);
      uniform_stress_forces(body.disc, body.prm, unit_traction_stress(2, 3, 0), tmp);
      auto f = tmp.force, mo = tmp.moment;
      Kokkos::parallel_for(
          range(0, 1), KOKKOS_LAMBDA(const std::size_t) {
            for (std::size_t k = 0; k < img.extent(0); ++k) {
              const int i = img(k), m = src(k);
              f(m, 0) += f(i, 0);
              f(i, 0) = 0;
              mo(m, 0) += mo(i, 0);
              mo(i, 0) = 0;
            }
          });
      fold_layer_forces(body.disc, slots, f, mo, fold);
      Vectors unit("unit_load", p.n_owned, 3);
      consistent_traction_load(p, 3, 0, 2 * g.horizon + dx, {0, -1, 0}, {W, 1, 0}, h, f, mo, unit);
      auto uh = Kokkos::create_mirror_view_and_copy(HostSpace(), unit);
      auto c = Kokkos::create_mirror_view(couple);
      auto vol = Kokkos::create_mirror_view_and_copy(HostSpace(), p.volume);
      double total = 0;
      for (std::size_t i = 0; i < p.n_owned; ++i) {
        b(i, 0) = tau * uh(i, 0);
        c(i, 0) = tau * uh(i, 2);
        total += b(i, 0) * vol(i);
      }
      // The discrete divergence theorem: the strip carries the traction times the face's area.
      EXPECT_NEAR(total, tau * W * g.thickness, 1e-12 * tau * W * g.thickness);
      Kokkos::deep_copy(couple, c);
    }
    Kokkos::deep_copy(load, b);
  }
  const double c_s = std::sqrt(mu / 2000.0), damping = 2 * kPi * c_s / (2 * h);
  const double dt = 2.5e-6 * 80 / per_h;
  const int steps = 6000 * per_h / 80;
  set_layers();
  forces();
  for (int n = 0; n < steps; ++n) {
    advance_positions(p, dt);
    set_layers();
    forces();
    advance_velocities(p, body.st.force, body.st.moment, body.rho, body.inertia, load, couple,
                       {0, 0, 0}, damping, dt);
  }
  auto u = Kokkos::create_mirror_view_and_copy(HostSpace(), p.u);
  auto th = Kokkos::create_mirror_view_and_copy(HostSpace(), p.theta);
  auto f = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.force);
  auto vol = Kokkos::create_mirror_view_and_copy(HostSpace(), p.volume);
  auto regions = Kokkos::create_mirror_view_and_copy(HostSpace(), p.regions);
  ClampedLayer r;
  double reaction = 0, u1 = 0, u2 = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const double x = xh(i, 0), y = xh(i, 1);
    if (regions(i) & (1u << 1))
      reaction -= (slaved ? 2 : 1) * f(i, 0) * vol(i);  // dPsi/dU (SolidSolver::reactions)
    if (x < 0 || x > W || y < 0 || y > h || x > dx)
      continue;
    if (std::abs(y - (h / 2 - dx / 2)) < 0.1 * dx) {
      r.u_mid_error = u(i, 0) / u_exact(y) - 1;
      r.theta_mid_error = th(i, 0) / theta_exact(y) - 1;
    }
    if (std::abs(y - (h - dx / 2)) < 0.1 * dx)
      u1 = u(i, 0);
    if (std::abs(y - (h - 1.5 * dx)) < 0.1 * dx)
      u2 = u(i, 0);
  }
  if (driven) {
    r.tau_error = reaction / (W * g.thickness) / tau - 1;
    r.stiffness_ratio = reaction / (W * g.thickness) * h / (mu * U);
  } else {
    const double u_top = 1.5 * u1 - 0.5 * u2;  // u(h), half a spacing above the top row
    r.u_top_error = u_top / U - 1;
    r.u_row_error = u1 / u_exact(h - dx / 2) - 1;
    r.stiffness_ratio = tau * h / (mu * u_top);
  }
  return r;
}

// The targets at h = 80 dx with plain (slaved) layers: u(h) within 1 % and theta(h/2)
// within 2 % (the traction-loaded layer), the size effect G_eff / mu = 1.0426 within 0.5 %, from
// the reaction of the clamp-driven layer and from u(h) of the traction-loaded one. The traction
// on the top row (traction / dx, the paper's) leaves the loaded face acting ~0.55 dx above h
// (G_eff -0.55 %, measured and reported, not asserted); the consistent distribution is asserted.
// Constant layers (the paper's method) are measured for the record and must be the worse. The
// closed form's stiffness ratio is computed here, not copied.
TEST(SolidValidationLong, CosseratLayerBetweenSlavedClamps) {
  int ranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  if (ranks > 1)
    GTEST_SKIP() << "periodic images need the whole layer on one rank";
  const CosseratShear cs;
  const double stiffness = cs.tau * cs.h / (cs.mu * cs.u(cs.h));
  EXPECT_NEAR(stiffness, 1.0426, 1e-4);  // classical u(h) 1e-4 m over the closed form's 9.5918e-5
  for (const bool driven : {true, false}) {
    // constant, slaved; traction only: slaved and constant with the consistent traction
    ClampedLayer r[4];
    const char* names[4] = {"_constant", "_slaved", "_slaved_consistent", "_constant_consistent"};
    for (int k = 0; k < (driven ? 2 : 4); ++k) {
      r[k] = cosserat_layer_between_layers(k == 1 || k == 2, driven, 80, k >= 2);
      const std::string tag = std::string(driven ? "driven" : "traction") + names[k];
      std::printf(
          "%s: tau %+.3f %%, u(h) %+.3f %%, top row %+.3f %%, u(h/2) %+.3f %%, "
          "theta(h/2) %+.3f %%, G_eff/mu %.5f (closed form %.5f)\n",
          tag.c_str(), 100 * r[k].tau_error, 100 * r[k].u_top_error, 100 * r[k].u_row_error,
          100 * r[k].u_mid_error, 100 * r[k].theta_mid_error, r[k].stiffness_ratio, stiffness);
      RecordProperty(tag + "_stiffness_ratio", std::to_string(r[k].stiffness_ratio));
      RecordProperty(tag + "_theta_mid_error", std::to_string(r[k].theta_mid_error));
    }
    const std::string tag = driven ? "driven" : "traction";
    EXPECT_LT(std::abs(r[1].theta_mid_error), 0.02) << tag;
    EXPECT_LT(std::abs(r[1].u_mid_error), 0.01) << tag;
    if (driven) {
      EXPECT_LT(std::abs(r[1].stiffness_ratio / stiffness - 1), 0.005);
      EXPECT_LT(std::abs(r[1].tau_error), std::abs(r[0].tau_error));
    } else {
      EXPECT_LT(std::abs(r[1].u_top_error), 0.01);
      EXPECT_LT(std::abs(r[1].u_top_error), std::abs(r[0].u_top_error));
      EXPECT_LT(std::abs(r[2].theta_mid_error), 0.02);
      EXPECT_LT(std::abs(r[2].u_top_error), 0.01);
      EXPECT_LT(std::abs(r[2].stiffness_ratio / stiffness - 1), 0.005);
      EXPECT_LT(std::abs(r[2].u_top_error), std::abs(r[1].u_top_error));
    }
  }
}

// Patch test of the slaved layers (kernels/boundary_conditions.hpp), 2D and 3D: a linear field
// u = (eps x, gamma x, 0), theta_z = gamma / 2 (no relative rotation: a uniform symmetric stress,
// no couple stress) between slaved x-layers whose every component is prescribed at the field's
// value on the face. The odd reflection of a linear field about its face value is the field
// itself, so the layers must continue it exactly, and the folded forces must vanish at every
// point whose neighbours' families stay clear of the free faces (more than 2 delta from them),
// the points next to the slaved faces included. A wrong sign of the fold, a missing fold, an even
// reflection or layers that kept their energy leave forces there of the order E eps / dx.
// The moments vanish in a stretch (gamma = 0). Under shear they do not within delta of a slaved
// face: the bond's rotation term 1/2 xi x T couples theta to the bond geometry, which the odd
// reflection of u (both components) does not mirror: a sketch of the fold's sums gives a
// residual proportional to sigma_xy sum_L (xi_n^2 - xi_t^2) V_L over the layer neighbours L (not
// checked term by term); measured: 559 N m/m^3 (2D) and 500 (3D) at the face's neighbours, with
// sigma_xy = 2 kPa, and 0 beyond delta. The clamp's theta then departs from the uniform
// field in a strip one horizon wide, which the Cosserat layer's convergence at second order
// (CosseratLayerBetweenSlavedClamps) measures in the result. Asserted: 0 beyond delta.
template <int Dim>
void slaved_patch_test(double gamma) {
  constexpr int R = kRotDim<Dim>;
  const double dx = 0.01, eps = 1e-4;
  std::array<long long, Dim> counts;
  counts[0] = 8;
  for (int d = 1; d < Dim; ++d)
    counts[d] = 17;
  auto g = test::box<Dim>(counts, 3.015, dx);
  g.layers[0] = {3, 3};
  g.mirrored_layers = true;
  const double L = 8 * dx;
  Box left, right;
  for (int d = 0; d < 3; ++d) {
    left.lo[d] = right.lo[d] = -1;
    left.hi[d] = right.hi[d] = 1;
  }
  left.hi[0] = -0.25 * dx;
  right.lo[0] = L + 0.25 * dx;
  g.region_names = {"left", "right"};
  g.regions = {left, right};
  Body<Dim> body(g, MicropolarElastic{10e6, 10e6, 5e6, 0.01}, 0.5);
  auto& p = body.pts();
  auto field = [&](const double* x, double* u, double* t) {
    u[0] = eps * x[0];
    u[1] = gamma * x[0];
    if (Dim == 3)
      u[2] = 0;
    for (int r = 0; r < R; ++r)
      t[r] = r == R - 1 ? gamma / 2 : 0.0;  // theta_z
  };
  std::vector<BoundaryCondition> bcs;
  for (int end = 0; end < 2; ++end)
    for (int c = 0; c < Dim + R; ++c) {
      const double xf[3] = {end ? L : 0.0, 0, 0};
      double uf[3] = {0, 0, 0}, tf[3] = {0, 0, 0};
      field(xf, uf, tf);
      BoundaryCondition bc;
      bc.kind = c < Dim ? BoundaryCondition::Displacement : BoundaryCondition::MicroRotation;
      bc.component = c < Dim ? c : c - Dim;
      bc.region_mask = 1u << end;
      bc.value = c < Dim ? uf[c] : tf[c - Dim];
      bc.mirrored = bc.slaved = true;
      bcs.push_back(bc);
    }
  mark_fixed(bcs, p);
  mark_mirrored_layers(bcs, p, body.disc.mirror);
  // The real points (owned and ghosts) hold the field; the layers get it from the slaving only.
  body.set([&](const double* x, double* u, double* t) {
    if (x[0] > 0 && x[0] < L)
      field(x, u, t);
  });
  for (const auto& bc : bcs)
    slave_layer(bc, p, body.disc.mirror, bc.value, 0.0);  // constant g
  body.forces();
  const FaceSlots slots{0, 1, -1, -1, -1, -1};
  Vectors fold("fold", p.size(), 2 * (Dim + R));
  fold_layer_forces(body.disc, slots, body.st.force, body.st.moment, fold);
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), p.x);
  auto u = Kokkos::create_mirror_view_and_copy(HostSpace(), p.u);
  auto th = Kokkos::create_mirror_view_and_copy(HostSpace(), p.theta);
  auto f = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.force);
  auto m = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.moment);
  double layer_error = 0, force = 0, moment = 0, moment_near = 0;
  int checked = 0, layer_points = 0;
  const double clear = 2 * g.horizon + 0.5 * dx;  // from the free faces
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    double ue[3] = {0, 0, 0}, te[3] = {0, 0, 0};
    field(&x(i, 0), ue, te);
    if (x(i, 0) < 0 || x(i, 0) > L) {
      ++layer_points;
      for (int d = 0; d < Dim; ++d)
        layer_error = std::max(layer_error, std::abs(u(i, d) - ue[d]));
      for (int r = 0; r < R; ++r)
        layer_error = std::max(layer_error, std::abs(th(i, r) - te[r]) * dx);
      continue;
    }
    bool inner = true;
    for (int d = 1; d < Dim; ++d)
      inner = inner && x(i, d) > clear && x(i, d) < 17 * dx - clear;
    if (!inner)
      continue;
    ++checked;
    const bool near = x(i, 0) < g.horizon || x(i, 0) > L - g.horizon;  // of a slaved face
    for (int d = 0; d < Dim; ++d)
      force = std::max(force, std::abs(f(i, d)));
    for (int r = 0; r < R; ++r)
      (near ? moment_near : moment) = std::max(near ? moment_near : moment, std::abs(m(i, r)));
  }
  MPI_Allreduce(MPI_IN_PLACE, &layer_error, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &force, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &moment, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &moment_near, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &checked, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &layer_points, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  const double scale = 30e6 * eps / dx;  // E eps / dx, the force density of a kink
  std::printf(
      "%dD slaved patch, gamma %g: %d layer points off the field by %.2e m, max |f| %.2e "
      "of E eps / dx, max |l| %.2e N m/m^3 beyond delta of the slaved faces, %.2e "
      "within (%d points)\n",
      Dim, gamma, layer_points, layer_error, force / scale, moment, moment_near, checked);
  EXPECT_GT(layer_points, 0);
  EXPECT_GE(checked, 3 * 8);  // 3 rows (2D) of the 8 columns: the slaved faces' neighbours too
  EXPECT_LT(layer_error, 1e-12 * eps * L);
  EXPECT_LT(force, 1e-9 * scale);
  EXPECT_LT(moment, 1e-9 * scale * dx);
  if (gamma == 0) {
    EXPECT_LT(moment_near, 1e-9 * scale * dx);
  } else {  // a fraction of the shear stress sigma_xy = mu gamma (the sketch's coefficient)
    EXPECT_LT(moment_near, 0.5 * 10e6 * gamma);
    EXPECT_GT(moment_near, 1e-3 * 10e6 * gamma);  // the residual is there: the README says so
  }
}

TEST(SolidValidation, SlavedLayersPatchTest2D) {
  slaved_patch_test<2>(0.0);
  slaved_patch_test<2>(2e-4);
}
TEST(SolidValidation, SlavedLayersPatchTest3D) {
  slaved_patch_test<3>(0.0);
  slaved_patch_test<3>(2e-4);
}

// A Gaussian pulse of u_x in a bar with u_y = 0 and theta = 0 (uniaxial strain) splits into two
// halves that travel at c_p = sqrt((lambda + 2 mu)/rho): the speed measured after the pulse has
// travelled 100 dx at c_expected in steps of dt, and the right-going half's peak (half the
// pulse's 1e-6 m).
struct Pulse {
  double speed = 0, peak = 0;
};
Pulse pulse_speed(const MicropolarElastic& law, double rho, double c_expected, double dt) {
  const double dx = 1e-3;
  Body<2> body(test::box<2>({300, 5}, 3.015, dx), law, 0.5, StabilizationModulus::Automatic, rho);
  const double x0 = 100 * dx, s = 8 * dx;
  body.set([&](const double* x, double* u, double* t) {
    u[0] = 1e-6 * std::exp(-(x[0] - x0) * (x[0] - x0) / (2 * s * s));
    u[1] = 0;
    t[0] = 0;
  });
  fix(body, 0b110, [](const double*) { return true; });
  const double travel = 100 * dx;
  const int steps = int(std::lround(travel / c_expected / dt));
  relax(body, dt, 0.0, steps);
  // Peak of the right-going half in the middle row, by a parabola through the three largest.
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), body.pts().x);
  auto u = Kokkos::create_mirror_view_and_copy(HostSpace(), body.pts().u);
  std::vector<double> row(300, -1e300);
  for (std::size_t i = 0; i < body.pts().n_owned; ++i)
    if (std::abs(x(i, 1) - 2.5 * dx) < 0.1 * dx)
      row[std::size_t(std::lround(x(i, 0) / dx - 0.5))] = u(i, 0);
  MPI_Allreduce(MPI_IN_PLACE, row.data(), 300, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  std::size_t k = 150;
  for (std::size_t m = 150; m < 290; ++m)
    if (row[m] > row[k])
      k = m;
  const double y0 = row[k - 1], y1 = row[k], y2 = row[k + 1];
  const double peak = (double(k) + 0.5 + 0.5 * (y0 - y2) / (y0 - 2 * y1 + y2)) * dx;
  return {(peak - x0) / (steps * dt), y1};
}

TEST(SolidValidation, PWaveSpeed) {
  const double rho = 2000;
  const auto law = MicropolarElastic::from_bulk_shear(270.83e6, 220.33e6, 100e6, 7.5e-3);
  const double c_p = std::sqrt((law.lambda + 2 * law.mu) / rho);
  const Pulse p = pulse_speed(law, rho, c_p, 2e-7);
  RecordProperty("c_over_cp", std::to_string(p.speed / c_p));
  EXPECT_NEAR(p.speed / c_p, 1.0, 0.03) << "c = " << p.speed << " m/s, c_p = " << c_p << " m/s";
  EXPECT_NEAR(p.peak, 0.5e-6, 0.1e-6);  // half the pulse went each way
}

// Plane stress (Discretization->Plane = Stress, MicropolarElastic::plane_stress): the same pulse
// travels at sqrt(E / (rho (1 - nu^2))), E and nu the 3D constants. Example 2's skeleton
// (nu = 0.30): plane strain's sqrt((lambda + 2 mu)/rho) is 10.7 % faster. Both are measured on
// the same grid and pulse, whose dispersion (the pulse's width is 2.7 horizons) slows both
// alike: their ratio is asserted to 0.5 %, each speed to 3 %.
TEST(SolidValidation, PWaveSpeedPlaneStress) {
  const double rho = 2000, dx = 1e-3;
  const auto solid = MicropolarElastic::from_bulk_shear(60e9, 27.7e9, 14e9, 4e-3);
  const double E = solid.young(), nu = solid.poisson();
  const double c = std::sqrt(E / (rho * (1 - nu * nu)));
  const double c_strain = std::sqrt((solid.lambda + 2 * solid.mu) / rho);
  const Pulse stress = pulse_speed(solid.plane_stress(), rho, c, 0.1 * dx / c);
  const Pulse strain = pulse_speed(solid, rho, c_strain, 0.1 * dx / c_strain);
  std::printf(
      "plane stress: c = %.2f m/s, closed form %.2f (ratio %.4f); plane strain: %.2f, "
      "closed form %.2f (ratio %.4f); stress/strain %.4f, closed form %.4f\n",
      stress.speed, c, stress.speed / c, strain.speed, c_strain, strain.speed / c_strain,
      stress.speed / strain.speed, c / c_strain);
  EXPECT_NEAR(stress.speed / c, 1.0, 0.03);
  EXPECT_NEAR(strain.speed / c_strain, 1.0, 0.03);
  EXPECT_NEAR((stress.speed / strain.speed) / (c / c_strain), 1.0, 0.005);
  EXPECT_NEAR(stress.peak, 0.5e-6, 0.1e-6);
}

}  // namespace
}  // namespace mupm
