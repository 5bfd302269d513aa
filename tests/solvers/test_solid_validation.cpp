// Closed-form checks of the elastic micropolar solid: the Cosserat layer in simple shear
// (VALIDATION.md section 3) and the P-wave speed in a laterally constrained bar.
#include <gtest/gtest.h>

#include <cmath>

#include "solvers/solid_body.hpp"

namespace mupm {
namespace {

using test::Body;

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

// VALIDATION.md section 3: layer 0 <= y <= h, u_x = u(y), theta = theta(y), shear traction tau.
// The boundary layers (3 rows outside every face) hold the closed form itself, so the interior
// must relax to it: a layer infinite in x, loaded on its faces.
TEST(SolidValidation, CosseratLayerSimpleShear) {
  const double mu = 10e6, mu_c = 5e6, l = 0.01, h = 0.1, tau = 10e3, lambda = 10e6;
  const double B = mu * l * l / 2;
  const double alpha = std::sqrt(4 * mu * mu_c / ((mu + mu_c) * B));
  ASSERT_NEAR(alpha, 163.299, 1e-3);  // the reference number of VALIDATION.md
  auto theta_exact = [&](double y) {
    return -(tau / (2 * mu)) * (1 - std::cosh(alpha * (y - h / 2)) / std::cosh(alpha * h / 2));
  };
  auto u_exact = [&](double y) {
    return tau * y / mu - mu_c * tau / (mu * (mu + mu_c) * alpha) *
                              (std::sinh(alpha * (y - h / 2)) + std::sinh(alpha * h / 2)) /
                              std::cosh(alpha * h / 2);
  };
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

// A Gaussian pulse of u_x in a bar with u_y = 0 and theta = 0 (uniaxial strain) splits into two
// halves that travel at c_p = sqrt((lambda + 2 mu)/rho).
TEST(SolidValidation, PWaveSpeed) {
  const double dx = 1e-3, rho = 2000;
  const auto law = MicropolarElastic::from_bulk_shear(270.83e6, 220.33e6, 100e6, 7.5e-3);
  Body<2> body(test::box<2>({300, 5}, 3.015, dx), law, 0.5);
  const double x0 = 100 * dx, s = 8 * dx;
  body.set([&](const double* x, double* u, double* t) {
    u[0] = 1e-6 * std::exp(-(x[0] - x0) * (x[0] - x0) / (2 * s * s));
    u[1] = 0;
    t[0] = 0;
  });
  fix(body, 0b110, [](const double*) { return true; });
  const double c_p = std::sqrt((law.lambda + 2 * law.mu) / rho);
  const double dt = 2e-7, travel = 100 * dx;
  const int steps = int(std::lround(travel / c_p / dt));
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
  const double c = (peak - x0) / (steps * dt);
  RecordProperty("c_over_cp", std::to_string(c / c_p));
  EXPECT_NEAR(c / c_p, 1.0, 0.03) << "c = " << c << " m/s, c_p = " << c_p << " m/s";
  EXPECT_NEAR(y1, 0.5e-6, 0.1e-6);  // half the pulse went each way
}

}  // namespace
}  // namespace mupm
