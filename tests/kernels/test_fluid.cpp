// Fluid kernels against closed forms: retention and relative permeability (eqs 12, 56),
// the nonlocal gradient of a linear field, the flow divergence of a linear flux field, gravity
// in Darcy's law, and the sign and size of the flow stabilization on a checkerboard mode.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "mupm/input/model.hpp"
#include "mupm/solvers/fluid_solver.hpp"
#include "test_utils.hpp"

namespace mupm {
namespace {

TEST(FluidRetention, VanGenuchtenMualemValidationNumbers) {
  // Eqs 12 and 56 at s_a = 10 kPa, n = 2, m = 1 - 1/n: the closed forms' values at s = 1, 10 and
  // 50 kPa, to 6 digits (the last k_r to 3).
  const auto vg = VanGenuchten::mualem(10e3, 2.0);
  EXPECT_DOUBLE_EQ(vg.m, 0.5);
  const double s[] = {1e3, 10e3, 50e3};
  const double S[] = {0.995037, 0.707107, 0.196116};
  const double kr[] = {0.808879, 0.072138, 1.67e-4};
  for (int k = 0; k < 3; ++k) {
    const double sr = vg.saturation(-s[k]);
    EXPECT_NEAR(sr, S[k], 1e-6) << "s = " << s[k];
    if (k < 2)
      EXPECT_NEAR(vg.relative_permeability(sr), kr[k], 1e-6) << "s = " << s[k];
    else  // given to 3 digits
      EXPECT_NEAR(vg.relative_permeability(sr) / kr[k], 1.0, 3e-3) << "s = " << s[k];
  }
  // Saturated at p >= 0, and for the Saturated model at any p.
  EXPECT_EQ(vg.saturation(0.0), 1.0);
  EXPECT_EQ(vg.saturation(5e3), 1.0);
  EXPECT_EQ(vg.dsaturation_dp(5e3), 0.0);
  EXPECT_EQ(vg.relative_permeability(1.0), 1.0);
  VanGenuchten sat;
  EXPECT_EQ(sat.saturation(-50e3), 1.0);
  EXPECT_EQ(sat.relative_permeability(0.3), 1.0);
  // dS/dp against a central difference: positive (S falls as the suction grows).
  for (double p : {-1e3, -10e3, -50e3}) {
    const double h = 1e-3 * std::abs(p);
    const double fd = (vg.saturation(p + h) - vg.saturation(p - h)) / (2 * h);
    EXPECT_GT(vg.dsaturation_dp(p), 0.0);
    EXPECT_NEAR(vg.dsaturation_dp(p) / fd, 1.0, 1e-5) << "p = " << p;
  }
  // m overridable: S = [1 + (s/s_a)^n]^-m with m = 0.3 at s = s_a gives 2^-0.3.
  VanGenuchten own = vg;
  own.m = 0.3;
  EXPECT_NEAR(own.saturation(-10e3), std::pow(2.0, -0.3), 1e-14);
}

// A fluid body: discretization, parameters, state, a pressure field set from a function.
template <int Dim>
struct FluidBody {
  Discretization<Dim> disc;
  FluidParams prm;
  FluidState<Dim> st;

  FluidBody(const GridSpec<Dim>& g, double G)
      : disc(discretize(test::world(), g)), prm(fluid_params(g, 2e-9, G)) {
    st.allocate(disc.points.size(), disc.points.n_owned);
    Kokkos::deep_copy(disc.points.porosity, 0.3);
    Kokkos::deep_copy(disc.points.rel_perm, 1.0);
  }
  Points<Dim>& pts() { return disc.points; }
  void set(std::function<double(const double*)> f) {
    auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), pts().x);
    auto p = Kokkos::create_mirror_view(pts().p);
    for (std::size_t i = 0; i < pts().size(); ++i) {
      double xi[3] = {0, 0, 0};
      for (int d = 0; d < Dim; ++d)
        xi[d] = x(i, d);
      p(i) = f(xi);
    }
    Kokkos::deep_copy(pts().p, p);
  }
  void flow() {
    fluid_constitutive(pts(), prm, st);  // p is set on owned and ghost points alike
    fluid_flow(disc, prm, st, pts().p);
    Kokkos::fence();
  }
};

template <int Dim>
GridSpec<Dim> grid() {
  if constexpr (Dim == 2)
    return test::box<2>({24, 20}, 3.015, 0.01);
  else
    return test::box<3>({15, 14, 14}, 3.015, 0.01);
}

// Plane stress with pore water (PoreCoupling, include/mupm/laws/micropolar_elastic.hpp), an
// unsaturated field from p = -50 kPa to +20 kPa: the storage of fluid_constitutive is
//   C = phi (dS/dp + S / K_w) + S (S + p dS/dp) / (lambda + 2 mu)
// and the undrained modulus 2 mu / (lambda + 2 mu) S / C, with the 3D lambda, mu; and the stored
// energy's thickness part (S p)^2 / (2 (lambda + 2 mu)) has the thickness part of C times p as
// its derivative: storage and energy are the same term.
TEST(FluidStorage, PlaneStressStorageAndStoredEnergy) {
  const auto law = MicropolarElastic::from_bulk_shear(10e6, 6e6, 3e6, 0.01);
  const double lam = law.lambda, mu = law.mu, phi = 0.3, Kw = 2.2e9;
  FluidBody<2> body(grid<2>(), 0.5);
  body.prm.retention = VanGenuchten::mualem(10e3, 2.0);
  body.prm.bulk_modulus = Kw;
  body.prm.pore = law.plane_stress_coupling();
  body.set([](const double* x) { return -50e3 + 70e3 * x[0] / 0.24; });
  fluid_constitutive(body.pts(), body.prm, body.st);
  Kokkos::fence();
  const VanGenuchten vg = body.prm.retention;
  const double cz = body.prm.pore.lateral_compliance;
  int checked = 0;
  for (std::size_t i = 0; i < body.pts().n_owned; ++i) {
    const double p = body.pts().p(i), S = vg.saturation(p), dS = vg.dsaturation_dp(p);
    const double C = phi * (dS + S / Kw) + S * (S + p * dS) / (lam + 2 * mu);
    EXPECT_NEAR(body.st.storage(i), C, 1e-12 * C) << "p = " << p;
    EXPECT_NEAR(body.pts().undrained_modulus(i), 2 * mu / (lam + 2 * mu) * S / C, 1e-12 * S / C);
    if (std::abs(p) < 100)
      continue;
    // The thickness's part of the stored energy (with c_z less without), whose derivative is
    // the thickness's part of C p (the capillary part is a quadrature, good to ~1e-4 only).
    const double h = 1e-4 * std::abs(p);
    auto thickness = [&](double q) {
      return stored_energy_density(vg, phi, 1 / Kw, q, cz) -
             stored_energy_density(vg, phi, 1 / Kw, q, 0.0);
    };
    const double fd = (thickness(p + h) - thickness(p - h)) / (2 * h);
    const double exact = S * (S + p * dS) / (lam + 2 * mu) * p;
    EXPECT_NEAR(fd, exact, 1e-6 * std::abs(exact)) << "p = " << p;
    ++checked;
  }
  EXPECT_GT(checked, 0);
}

template <class T>
class FluidKernels : public ::testing::Test {};
using Dims = ::testing::Types<std::integral_constant<int, 2>, std::integral_constant<int, 3>>;
TYPED_TEST_SUITE(FluidKernels, Dims);

// A linear field p = p0 + b.x: grad p = b at every point, boundary points included (K is the
// same discrete sum), q = -(k/mu) b; no flow divergence at interior points; the stabilization
// sees R = 0.
TYPED_TEST(FluidKernels, LinearPressureGradientIsExact) {
  constexpr int Dim = TypeParam::value;
  FluidBody<Dim> body(grid<Dim>(), 0.5);
  const double b[3] = {2.0e5, -1.3e5, 0.7e5};
  body.set([&](const double* x) {
    double s = 3e4;
    for (int d = 0; d < Dim; ++d)
      s += b[d] * x[d];
    return s;
  });
  body.flow();
  auto grad = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.grad);
  auto q = Kokkos::create_mirror_view_and_copy(HostSpace(), body.pts().darcy_flux);
  auto flow = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.flow);
  const auto in = test::interior_points(body.disc, 6);
  int n_in = 0;
  for (std::size_t i = 0; i < body.pts().n_owned; ++i) {
    for (int d = 0; d < Dim; ++d) {
      EXPECT_NEAR(grad(i, d), b[d], 1e-9 * 2e5);
      EXPECT_NEAR(q(i, d), -body.prm.mobility * b[d], 1e-9 * body.prm.mobility * 2e5);
    }
    if (in[i]) {
      ++n_in;
      // Scale: |q| / dx.
      EXPECT_NEAR(flow(i), 0.0, 1e-9 * body.prm.mobility * 2e5 / 0.01);
    }
  }
  EXPECT_GT(n_in, 0);
}

// A quadratic field p = 1/2 x.H x with uniform mobility: q = -(k/mu) H x is a linear flux
// field and the flow divergence must equal div q = -(k/mu) tr H at interior points, whatever
// G is (the stabilization's two terms cancel for a quadratic field).
TYPED_TEST(FluidKernels, LinearFluxDivergenceIsExact) {
  constexpr int Dim = TypeParam::value;
  for (double G : {0.0, 0.5, 1.0}) {
    FluidBody<Dim> body(grid<Dim>(), G);
    const double H[3][3] = {{3e6, 1e6, -0.5e6}, {1e6, -1e6, 0.8e6}, {-0.5e6, 0.8e6, 2e6}};
    body.set([&](const double* x) {
      double s = 0;
      for (int a = 0; a < Dim; ++a)
        for (int c = 0; c < Dim; ++c)
          s += 0.5 * x[a] * H[a][c] * x[c];
      return s;
    });
    body.flow();
    double trH = 0;
    for (int d = 0; d < Dim; ++d)
      trH += H[d][d];
    const double expected = -body.prm.mobility * trH;
    auto flow = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.flow);
    const auto in = test::interior_points(body.disc, 6);
    int n_in = 0;
    for (std::size_t i = 0; i < body.pts().n_owned; ++i)
      if (in[i]) {
        ++n_in;
        EXPECT_NEAR(flow(i), expected, 1e-9 * std::abs(expected)) << "G = " << G;
      }
    EXPECT_GT(n_in, 0);
  }
}

// Hydrostatic pressure p = rho_w g.x: Darcy's flux with gravity (eq 54) vanishes everywhere.
TYPED_TEST(FluidKernels, HydrostaticPressureHasNoFlux) {
  constexpr int Dim = TypeParam::value;
  FluidBody<Dim> body(grid<Dim>(), 0.5);
  body.prm.gravity[Dim - 1] = -9.81;
  body.set([&](const double* x) { return 1000 * -9.81 * (x[Dim - 1] - 0.5); });
  body.flow();
  auto q = Kokkos::create_mirror_view_and_copy(HostSpace(), body.pts().darcy_flux);
  auto flow = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.flow);
  const double scale = body.prm.mobility * 1000 * 9.81;
  for (std::size_t i = 0; i < body.pts().n_owned; ++i) {
    for (int d = 0; d < Dim; ++d)
      EXPECT_NEAR(q(i, d), 0.0, 1e-9 * scale);
    EXPECT_NEAR(flow(i), 0.0, 1e-9 * scale / 0.01);
  }
  // Without gravity in Darcy's law the same field (higher pressure below) drives a flux
  // k/mu rho_w |g| upwards.
  body.prm.gravity[Dim - 1] = 0;
  body.flow();
  q = Kokkos::create_mirror_view_and_copy(HostSpace(), body.pts().darcy_flux);
  EXPECT_NEAR(q(0, Dim - 1), scale, 1e-9 * scale);
}

// Checkerboard pressure (-1)^(sum of lattice indices): the correspondence gradient is zero at
// interior points (a zero-energy mode), so without stabilization nothing flows; with it the
// flow divergence is the bond-wise diffusion sum_j (alpha_i + alpha_j)(p_i - p_j) V_j with
// alpha = G (k/mu) / (k2 w0): it has the sign of p_i, so C dp/dt = -div pulls p back to zero.
TYPED_TEST(FluidKernels, CheckerboardIsDampedByStabilization) {
  constexpr int Dim = TypeParam::value;
  const auto g = grid<Dim>();
  const double amp = 1e4;
  auto checker = [&](const double* x) {
    long long s = 0;
    for (int d = 0; d < Dim; ++d)
      s += std::llround(std::floor((x[d] - g.origin[d]) / g.dx));
    return (s % 2 == 0 ? 1.0 : -1.0) * amp;
  };
  for (double G : {0.0, 0.5}) {
    FluidBody<Dim> body(g, G);
    body.set(checker);
    body.flow();
    auto flow = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.flow);
    auto grad = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.grad);
    auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), body.pts().x);
    auto p = Kokkos::create_mirror_view_and_copy(HostSpace(), body.pts().p);
    auto off = Kokkos::create_mirror_view_and_copy(HostSpace(), body.disc.bonds.offsets);
    auto nb = Kokkos::create_mirror_view_and_copy(HostSpace(), body.disc.bonds.neighbor);
    auto vol = Kokkos::create_mirror_view_and_copy(HostSpace(), body.pts().volume);
    const auto in = test::interior_points(body.disc, 6);
    int n_in = 0;
    for (std::size_t i = 0; i < body.pts().n_owned; ++i) {
      if (!in[i])
        continue;
      ++n_in;
      for (int d = 0; d < Dim; ++d)
        EXPECT_NEAR(grad(i, d), 0.0, 1e-9 * amp / g.dx);
      // Expected: 2 alpha sum_j (p_i - p_j) V_j with the family's own volume in w0.
      double wsum = 0, diff = 0;
      for (auto b = off(i); b < off(i + 1); ++b) {
        wsum += vol(nb(b));
        diff += (p(i) - p(nb(b))) * vol(nb(b));
      }
      const double alpha =
          G * body.prm.mobility / body.prm.second_moment * body.prm.horizon_volume / wsum;
      const double expected = 2 * alpha * diff;
      if (G == 0) {
        EXPECT_NEAR(flow(i), 0.0, 1e-9 * body.prm.mobility * amp / (g.dx * g.dx));
      } else {
        EXPECT_NEAR(flow(i), expected, 1e-9 * std::abs(expected));
        EXPECT_GT(flow(i) * p(i), 0.0);  // dissipative: dp/dt opposes p
      }
    }
    EXPECT_GT(n_in, 0);
  }
}

}  // namespace
}  // namespace mupm
