// Micropolar correspondence kernels: patch tests, zero-energy mode, and conservation of momenta
// and energy in an undamped free body. The closed forms (the Cosserat layer in simple shear, the
// P-wave speed) are in tests/solvers/test_solid_validation.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "mupm/kernels/central_difference.hpp"
#include "mupm/kernels/solid.hpp"
#include "solvers/solid_body.hpp"

namespace mupm {
namespace {
using test::Body;

const MicropolarElastic kLaw =
    MicropolarElastic::from_bulk_shear(270.83e6, 220.33e6, 100e6, 7.5e-3);

// Affine u and uniform theta: eps = A - [theta x] exactly at every point, boundary included
// (eq 50); kappa = 0.
TEST(SolidPatch, AffineStrainExactEverywhere2D) {
  Body<2> body(test::box<2>({12, 9}, 3.015, 2.5e-3), kLaw, 0.5);
  const double A[4] = {1e-3, -2e-3, 3e-4, 5e-4}, th0 = 7e-4;
  body.set([&](const double* x, double* u, double* t) {
    u[0] = A[0] * x[0] + A[1] * x[1] + 1e-4;
    u[1] = A[2] * x[0] + A[3] * x[1] - 2e-4;
    t[0] = th0;
  });
  body.forces();
  auto eps = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.eps);
  auto kap = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.kappa);
  // eps_xy = du_x/dy + theta, eps_yx = du_y/dx - theta (2D, theta counterclockwise).
  const double expected[4] = {A[0], A[1] + th0, A[2] - th0, A[3]};
  for (std::size_t i = 0; i < body.pts().n_owned; ++i) {
    for (int k = 0; k < 4; ++k)
      ASSERT_NEAR(eps(i, k), expected[k], 1e-14) << "point " << i;
    for (int k = 0; k < 2; ++k)
      ASSERT_NEAR(kap(i, k), 0.0, 1e-12);
  }
}

TEST(SolidPatch, AffineStrainExactEverywhere3D) {
  Body<3> body(test::box<3>({6, 5, 7}, 3.015, 2.5e-3), kLaw, 0.5);
  const double A[9] = {1e-3, -2e-3, 3e-4, 5e-4, -1e-4, 2e-4, 4e-4, 1e-4, -3e-4};
  const double t0[3] = {1e-4, -2e-4, 3e-4};
  body.set([&](const double* x, double* u, double* t) {
    for (int a = 0; a < 3; ++a)
      u[a] = A[3 * a] * x[0] + A[3 * a + 1] * x[1] + A[3 * a + 2] * x[2];
    for (int r = 0; r < 3; ++r)
      t[r] = t0[r];
  });
  body.forces();
  auto eps = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.eps);
  // eps_ik = du_i/dx_k - e_ijk theta_j
  double expected[9];
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) {
      double e = A[3 * i + k];
      for (int j = 0; j < 3; ++j) {
        const int perm = (i - j) * (j - k) * (k - i) / 2;  // Levi-Civita e_ijk
        e -= perm * t0[j];
      }
      expected[3 * i + k] = e;
    }
  for (std::size_t i = 0; i < body.pts().n_owned; ++i)
    for (int k = 0; k < 9; ++k)
      ASSERT_NEAR(eps(i, k), expected[k], 1e-14) << "point " << i;
}

// Plane stress (Discretization->Plane = Stress, MicropolarElastic::plane_stress): a thin
// plate's uniaxial stress sigma_xx = t has eps_xx = t/E, eps_yy = -nu t/E (E, nu the 3D
// constants). Given that affine field, every point's law gives sigma_yy = 0 and sigma_xx = t, and
// pass 1 books the energy density t^2/(2E) (the stabilization's is zero for an affine field).
// Plane strain's lambda would give sigma_yy = 0.43 t here (Example 2's skeleton, nu = 0.30).
TEST(SolidPatch, PlaneStressUniaxialStress) {
  const auto solid = MicropolarElastic::from_bulk_shear(60e9, 27.7e9, 14e9, 4e-3);
  const auto law = solid.plane_stress();
  const double E = solid.young(), nu = solid.poisson(), t = 1e6, dx = 1e-3;
  double eps[4] = {t / E, 0, 0, -nu * t / E}, kappa[2] = {0, 0}, sigma[4], m[2];
  law.stress<2>(eps, kappa, sigma, m);
  EXPECT_NEAR(sigma[0], t, 1e-12 * t);
  EXPECT_NEAR(sigma[3], 0.0, 1e-12 * t);
  EXPECT_NEAR(sigma[1], 0.0, 1e-12 * t);
  EXPECT_NEAR(sigma[2], 0.0, 1e-12 * t);
  Body<2> body(test::box<2>({12, 9}, 3.015, dx), law, 0.5);
  body.set([&](const double* x, double* u, double* th) {
    u[0] = eps[0] * x[0];
    u[1] = eps[3] * x[1];
    th[0] = 0;
  });
  body.forces();
  auto en = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.energy);
  const double w = t * t / (2 * E), volume = dx * dx;  // thickness 1 m
  for (std::size_t i = 0; i < body.pts().n_owned; ++i)
    ASSERT_NEAR(en(i) / volume, w, 1e-9 * w) << "point " << i;
}

// Linear theta: kappa = grad theta at every point (eq 51); eps exact where the family is
// symmetric (the mean rotation of a bond adds a term odd in xi, zero only over a full family).
TEST(SolidPatch, LinearRotationGivesExactWryness) {
  Body<2> body(test::box<2>({12, 12}, 3.015, 2.5e-3), kLaw, 0.5);
  const double g[2] = {0.3, -0.2};
  body.set([&](const double* x, double* u, double* t) {
    u[0] = u[1] = 0;
    t[0] = 1e-3 + g[0] * x[0] + g[1] * x[1];
  });
  body.forces();
  auto kap = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.kappa);
  auto eps = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.eps);
  auto th = Kokkos::create_mirror_view_and_copy(HostSpace(), body.pts().theta);
  const auto in = body.interior(3);
  for (std::size_t i = 0; i < body.pts().n_owned; ++i) {
    ASSERT_NEAR(kap(i, 0), g[0], 1e-12);
    ASSERT_NEAR(kap(i, 1), g[1], 1e-12);
    if (in[i]) {
      ASSERT_NEAR(eps(i, 1), th(i, 0), 1e-14);
      ASSERT_NEAR(eps(i, 2), -th(i, 0), 1e-14);
    }
  }
}

// A rigid rotation u = theta0 e_z x x with theta = theta0 has zero strain and no forces.
TEST(SolidPatch, RigidRotationIsStrainFree) {
  Body<2> body(test::box<2>({10, 10}, 3.015, 2.5e-3), kLaw, 0.5);
  const double t0 = 2e-3;
  body.set([&](const double* x, double* u, double* t) {
    u[0] = -t0 * x[1];
    u[1] = t0 * x[0];
    t[0] = t0;
  });
  body.forces();
  auto eps = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.eps);
  auto f = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.force);
  auto l = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.moment);
  const double fscale = kLaw.mu * t0 / (2.5e-3);  // force density of a strain t0 over dx
  for (std::size_t i = 0; i < body.pts().n_owned; ++i) {
    for (int k = 0; k < 4; ++k)
      ASSERT_NEAR(eps(i, k), 0.0, 1e-15);
    for (int k = 0; k < 2; ++k)
      ASSERT_NEAR(f(i, k), 0.0, 1e-10 * fscale);
    ASSERT_NEAR(l(i, 0), 0.0, 1e-10 * fscale * 2.5e-3);
  }
  EXPECT_NEAR(body.energy(), 0.0, 1e-20);
}

// Interior points of a homogeneous deformation carry no net force, with or without
// stabilization; the moment density is the Cosserat coupling -4 mu_c (theta - omega_macro)
// (from sigma_xy - sigma_yx = 2 mu_c (eps_xy - eps_yx), eq 80): zero when theta follows the
// macro-rotation, restoring otherwise.
TEST(SolidPatch, HomogeneousInteriorForceAndMoment) {
  for (double G : {0.0, 0.5, 1.0}) {
    Body<2> body(test::box<2>({20, 20}, 3.015, 2.5e-3), kLaw, G);
    const double A[4] = {1e-3, -2e-3, 3e-4, 5e-4};
    const double macro = 0.5 * (A[2] - A[1]);  // (du_y/dx - du_x/dy)/2
    for (double offset : {0.0, 4e-4}) {
      body.set([&](const double* x, double* u, double* t) {
        u[0] = A[0] * x[0] + A[1] * x[1];
        u[1] = A[2] * x[0] + A[3] * x[1];
        t[0] = macro + offset;
      });
      body.forces();
      auto f = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.force);
      auto l = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.moment);
      const auto in = body.interior(6);
      const double fscale = kLaw.mu * 1e-3 / 2.5e-3;
      const double l_expected = -4 * kLaw.mu_c * offset;
      int n = 0;
      for (std::size_t i = 0; i < body.pts().n_owned; ++i) {
        if (!in[i])
          continue;
        ++n;
        for (int k = 0; k < 2; ++k)
          ASSERT_NEAR(f(i, k), 0.0, 1e-9 * fscale) << "G " << G;
        ASSERT_NEAR(l(i, 0), l_expected, 1e-9 * 4 * kLaw.mu_c * 1e-3) << "G " << G;
      }
      int total = 0;
      MPI_Allreduce(&n, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
      EXPECT_GT(total, 0);
    }
  }
}

// The checkerboard u_x = c (-1)^(i+j) has eps = 0 at every interior point: a zero-energy mode
// of the plain correspondence model. Stabilization gives it energy and a restoring force.
template <int Dim>
void checkerboard(const MicropolarElastic& law) {
  const double dx = 2.5e-3, c = 1e-6;
  std::array<long long, Dim> counts;
  counts.fill(Dim == 2 ? 20 : 13);
  for (double G : {0.0, 0.5}) {
    Body<Dim> body(test::box<Dim>(counts, 3.015, dx), law, G);
    body.set([&](const double* x, double* u, double* t) {
      long long parity = 0;
      for (int d = 0; d < Dim; ++d)
        parity += std::llround(x[d] / dx - 0.5);
      for (int d = 0; d < Dim; ++d)
        u[d] = 0;
      u[0] = parity % 2 ? c : -c;
      for (int r = 0; r < kRotDim<Dim>; ++r)
        t[r] = 0;
    });
    body.forces();
    auto f = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.force);
    auto u = Kokkos::create_mirror_view_and_copy(HostSpace(), body.pts().u);
    auto en = Kokkos::create_mirror_view_and_copy(HostSpace(), body.st.energy);
    const auto in = body.interior(6);
    const double fscale = law.mu * c / (dx * dx);
    double e_in = 0;
    for (std::size_t i = 0; i < body.pts().n_owned; ++i) {
      if (!in[i])
        continue;
      e_in += en(i);
      if (G == 0) {
        ASSERT_NEAR(f(i, 0), 0.0, 1e-9 * fscale);
      } else {
        ASSERT_LT(f(i, 0) * u(i, 0), -1e-3 * fscale * c);  // restoring, of the scale mu c/dx^2
      }
    }
    MPI_Allreduce(MPI_IN_PLACE, &e_in, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    if (G == 0) {
      EXPECT_NEAR(e_in, 0.0, 1e-25);
    } else {
      EXPECT_GT(e_in, 0.0);
    }
  }
}

TEST(SolidStabilization, CheckerboardResisted2D) {
  checkerboard<2>(kLaw);
}

TEST(SolidStabilization, CheckerboardResisted3DAtNu03) {
  // nu = 0.3: eq 71 gives D < 0; the automatic choice takes the bulk-matched modulus.
  const auto law = MicropolarElastic::from_bulk_shear(1e9 / (3 * 0.4), 1e9 / 2.6, 2e8,
                                                      5e-3);  // E = 1 GPa, nu = 0.3
  EXPECT_NEAR(law.poisson(), 0.3, 1e-12);
  EXPECT_LT(stabilization_modulus<3>(law, 7.5e-3, 1.0, StabilizationModulus::Eq71), 0.0);
  EXPECT_GT(stabilization_modulus<3>(law, 7.5e-3, 1.0, StabilizationModulus::Automatic), 0.0);
  checkerboard<3>(law);
}

// Free body, undamped: total linear momentum sum rho V v and angular momentum
// sum (X x rho V v + J V omega) are conserved to round-off; the energy error of central
// difference shrinks about 4x when dt halves.
struct FreeRun {
  double p0[2], p1[2], h0, h1, max_energy_error, e0;
};

FreeRun free_run(double dt, int steps) {
  Body<2> body(test::box<2>({14, 11}, 3.015, 2.5e-3), kLaw, 0.5);
  auto& pts = body.pts();
  {
    auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.x);
    auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.gid);
    auto v = Kokkos::create_mirror_view(pts.v);
    auto om = Kokkos::create_mirror_view(pts.omega);
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const double s = double(gid(i));
      v(i, 0) = 0.01 * std::sin(1.7 * s) + 0.02;
      v(i, 1) = 0.01 * std::cos(2.3 * s) - 0.01;
      om(i, 0) = 0.5 * std::sin(0.9 * s);
    }
    Kokkos::deep_copy(pts.v, v);
    Kokkos::deep_copy(pts.omega, om);
  }
  const Vectors none;
  auto momenta = [&](double* p, double& h, double& ke) {
    auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.x);
    auto v = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.v);
    auto om = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.omega);
    auto vol = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.volume);
    auto rho = Kokkos::create_mirror_view_and_copy(HostSpace(), body.rho);
    auto J = Kokkos::create_mirror_view_and_copy(HostSpace(), body.inertia);
    double s[4] = {0, 0, 0, 0};
    for (std::size_t i = 0; i < pts.n_owned; ++i) {
      const double m = rho(i) * vol(i);
      s[0] += m * v(i, 0);
      s[1] += m * v(i, 1);
      s[2] += x(i, 0) * m * v(i, 1) - x(i, 1) * m * v(i, 0) + J(i) * vol(i) * om(i, 0);
      s[3] += 0.5 * m * (v(i, 0) * v(i, 0) + v(i, 1) * v(i, 1)) +
              0.5 * J(i) * vol(i) * om(i, 0) * om(i, 0);
    }
    MPI_Allreduce(MPI_IN_PLACE, s, 4, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    p[0] = s[0];
    p[1] = s[1];
    h = s[2];
    ke = s[3];
  };
  FreeRun r{};
  double ke;
  body.forces();
  advance_velocities(pts, body.st.force, body.st.moment, body.rho, body.inertia, none, none,
                     {0, 0, 0}, 0.0, 0.0);  // a(0) from the initial forces (dt = 0: v unchanged)
  momenta(r.p0, r.h0, ke);
  r.e0 = body.energy() + ke;
  for (int n = 0; n < steps; ++n) {
    advance_positions(pts, dt);
    body.forces();
    advance_velocities(pts, body.st.force, body.st.moment, body.rho, body.inertia, none, none,
                       {0, 0, 0}, 0.0, dt);
    double p[2], h;
    momenta(p, h, ke);
    r.max_energy_error = std::max(r.max_energy_error, std::abs(body.energy() + ke - r.e0));
  }
  momenta(r.p1, r.h1, ke);
  return r;
}

TEST(SolidConservation, MomentaAndEnergy) {
  const double dt = 2e-7;  // about a fifth of the stable step here
  const auto a = free_run(dt, 400);
  const auto b = free_run(dt / 2, 800);
  const double pscale = std::abs(a.p0[0]) + std::abs(a.p0[1]);
  EXPECT_NEAR(a.p1[0], a.p0[0], 1e-12 * pscale);
  EXPECT_NEAR(a.p1[1], a.p0[1], 1e-12 * pscale);
  EXPECT_NEAR(a.h1, a.h0, 1e-11 * (std::abs(a.h0) + 1e-12));
  ASSERT_GT(a.max_energy_error, 0.0);
  const double ratio = a.max_energy_error / b.max_energy_error;
  EXPECT_GT(ratio, 3.0) << a.max_energy_error << " " << b.max_energy_error;
  EXPECT_LT(ratio, 5.0) << a.max_energy_error << " " << b.max_energy_error;
  EXPECT_LT(a.max_energy_error, 1e-3 * a.e0);
}

}  // namespace
}  // namespace mupm
