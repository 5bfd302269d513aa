// Second-order work (include/mupm/kernels/shear_bands.hpp): the point field against the bond
// sum of eq 42 evaluated here, and against sigma : eps for a homogeneous deformation; the band
// measurement on synthetic bands of known angle and width.
#include <gtest/gtest.h>

#include <cmath>

#include "mupm/kernels/shear_bands.hpp"
#include "solid_body.hpp"

namespace mupm {
namespace {

const MicropolarElastic kLaw = MicropolarElastic::from_bulk_shear(27.8e6, 20.8e6, 40.6e6, 5e-3);

struct Snapshot {
  Kokkos::View<double**, Kokkos::LayoutRight, HostSpace> u, th, sig, m;
};
// A copy (create_mirror_view would alias a host view).
Kokkos::View<double**, Kokkos::LayoutRight, HostSpace> copy_of(const Vectors& v) {
  auto c = Kokkos::create_mirror(HostSpace(), v);
  Kokkos::deep_copy(c, v);
  return c;
}
Snapshot snapshot(test::Body<2>& b) {
  auto& p = b.pts();
  return {copy_of(p.u), copy_of(p.theta), copy_of(p.stress), copy_of(p.couple_stress)};
}

// Eq 42 at owned point i by its bonds: sum_j (dT_ij . dU^_ij + dM_ij . dOmega_ij) V_j with
// T_ij = sigma_i K_i^-1 xi, M_ij = m_i K_i^-1 xi (the correspondence force states).
std::vector<double> eq42_by_bonds(test::Body<2>& b, const Snapshot& A, const Snapshot& B) {
  auto& p = b.pts();
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), p.x);
  auto vol = Kokkos::create_mirror_view_and_copy(HostSpace(), p.volume);
  auto Kinv = Kokkos::create_mirror_view_and_copy(HostSpace(), b.disc.shape.Kinv);
  auto off = Kokkos::create_mirror_view_and_copy(HostSpace(), b.disc.bonds.offsets);
  auto nb = Kokkos::create_mirror_view_and_copy(HostSpace(), b.disc.bonds.neighbor);
  auto intact = Kokkos::create_mirror_view_and_copy(HostSpace(), b.disc.bonds.intact);
  std::vector<double> out(p.n_owned, 0.0);
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    for (auto k = off(i); k < off(i + 1); ++k) {
      if (!intact(k))
        continue;
      const int j = nb(k);
      const double xi[2] = {x(j, 0) - x(i, 0), x(j, 1) - x(i, 1)};
      double kx[2];  // K^-1 xi
      for (int a = 0; a < 2; ++a)
        kx[a] = Kinv(i, 2 * a) * xi[0] + Kinv(i, 2 * a + 1) * xi[1];
      double dU[2], dT[2];
      for (int a = 0; a < 2; ++a) {
        // U^ = u_j - u_i - Omega-bar x xi, Omega-bar x xi = tb (-xi_y, xi_x)
        auto uh = [&](const Snapshot& s) {
          const double tb = 0.5 * (s.th(i, 0) + s.th(j, 0));
          const double c = a == 0 ? -tb * xi[1] : tb * xi[0];
          return s.u(j, a) - s.u(i, a) - c;
        };
        dU[a] = uh(B) - uh(A);
        dT[a] = 0;
        for (int c = 0; c < 2; ++c)
          dT[a] += (B.sig(i, 2 * a + c) - A.sig(i, 2 * a + c)) * kx[c];
      }
      const double dOm = (B.th(j, 0) - B.th(i, 0)) - (A.th(j, 0) - A.th(i, 0));
      double dM = 0;
      for (int c = 0; c < 2; ++c)
        dM += (B.m(i, c) - A.m(i, c)) * kx[c];
      out[i] += (dT[0] * dU[0] + dT[1] * dU[1] + dM * dOm) * vol(j);
    }
  }
  return out;
}

// A non-affine deformation: the field of eq 40 equals the bond sum of eq 42 at every point.
TEST(ShearBandsSecondOrderWork, PointFieldIsTheBondSumOfEq42) {
  test::Body<2> b(test::box<2>({24, 20}, 3.05, 2e-3), kLaw, 0.1);
  auto& p = b.pts();
  Vectors start("start", p.size(), 2 * (4 + 2));
  Scalars d2("d2", p.size());
  b.set([](const double* x, double* u, double* t) {
    u[0] = 1e-4 * std::sin(40 * x[0] + 10 * x[1]);
    u[1] = 2e-4 * std::cos(30 * x[1]) * x[0];
    t[0] = 3e-3 * std::sin(50 * x[1]);
  });
  b.forces();
  const Snapshot A = snapshot(b);
  second_order_work(p, b.st.eps, b.st.kappa, start, Scalars());
  b.set([](const double* x, double* u, double* t) {
    u[0] = 3e-4 * std::sin(25 * x[0]) * std::cos(20 * x[1]);
    u[1] = -1e-4 * std::sin(60 * x[0] * x[1] + 1);
    t[0] = -2e-3 * std::cos(45 * x[0]);
  });
  b.forces();
  const Snapshot B = snapshot(b);
  second_order_work(p, b.st.eps, b.st.kappa, start, d2);
  auto got = Kokkos::create_mirror_view_and_copy(HostSpace(), d2);
  const auto ref = eq42_by_bonds(b, A, B);
  double scale = 0;
  for (double r : ref)
    scale = std::max(scale, std::fabs(r));
  ASSERT_GT(scale, 0);
  int neg = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    EXPECT_NEAR(got(i), ref[i], 1e-9 * scale) << i;
    neg += got(i) < 0;
  }
  EXPECT_EQ(neg, 0);  // elastic: d2E = d eps : C : d eps + B |d kappa|^2 > 0 everywhere
}

// Homogeneous deformation from rest: d2E = sigma : eps (+ m : kappa = 0) with eps of the
// affine field (eps_xy = du_x/dy + theta, eps_yx = du_y/dx - theta) and sigma of eq 80, at every
// point (an affine field is reproduced exactly, boundary points too).
TEST(ShearBandsSecondOrderWork, HomogeneousDeformationGivesSigmaColonEps) {
  test::Body<2> b(test::box<2>({16, 16}, 3.05, 2e-3), kLaw, 0.1);
  auto& p = b.pts();
  Vectors start("start", p.size(), 12);
  Scalars d2("d2", p.size());
  b.forces();  // at rest
  second_order_work(p, b.st.eps, b.st.kappa, start, Scalars());
  const double A[4] = {1e-3, -4e-4, 7e-4, -2e-3}, th = 3e-4;
  b.set([&](const double* x, double* u, double* t) {
    u[0] = A[0] * x[0] + A[1] * x[1];
    u[1] = A[2] * x[0] + A[3] * x[1];
    t[0] = th;
  });
  b.forces();
  second_order_work(p, b.st.eps, b.st.kappa, start, d2);
  const double e[4] = {A[0], A[1] + th, A[2] - th, A[3]};
  const double tr = e[0] + e[3];
  double w = kLaw.lambda * tr * tr;
  for (int a = 0; a < 2; ++a)
    for (int c = 0; c < 2; ++c)
      w += (kLaw.mu + kLaw.mu_c) * e[2 * a + c] * e[2 * a + c] +
           (kLaw.mu - kLaw.mu_c) * e[2 * a + c] * e[2 * c + a];
  ASSERT_GT(w, 0);
  auto got = Kokkos::create_mirror_view_and_copy(HostSpace(), d2);
  for (std::size_t i = 0; i < p.n_owned; ++i)
    EXPECT_NEAR(got(i), w, 1e-8 * w) << i;
}

// Band measurement on synthetic conjugate bands crossing off the body's centre: points within
// w/2 of the lines through (cx, cy) at +-beta from the horizontal get eps-hat = 1, the others
// 0.1: band_angle = beta and band_width = w to a spacing.
TEST(ShearBands, SyntheticConjugateBands) {
  const double dx = 1e-3, beta = 57.5 * kPi / 180, w = 6e-3;
  Discretization<2> disc = discretize(test::world(), test::box<2>({100, 200}, 3.05, dx));
  auto& p = disc.points;
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), p.x);
  auto e = Kokkos::create_mirror_view(p.equivalent_plastic_strain);
  const double cx = 0.05, cy = 0.115;  // the body's centre is (0.05, 0.1)
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double dxp = x(i, 0) - cx, dyp = x(i, 1) - cy;
    const double d1 = std::fabs(-std::sin(beta) * dxp + std::cos(beta) * dyp);
    const double d2 = std::fabs(std::sin(beta) * dxp + std::cos(beta) * dyp);
    e(i) = (std::min(d1, d2) < w / 2 && std::fabs(dyp) < 0.07) ? 1.0 : 0.1;
  }
  Kokkos::deep_copy(p.equivalent_plastic_strain, e);
  auto sum = [](double* d, int n) {
    MPI_Allreduce(MPI_IN_PLACE, d, n, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  };
  auto max = [](double* d, int n) {
    MPI_Allreduce(MPI_IN_PLACE, d, n, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  };
  double angle, width;
  measure_bands(p, 0.05, 0.1, sum, max, angle, width);
  EXPECT_NEAR(angle, 57.5, 1.0);
  EXPECT_NEAR(width, w, dx);
  // Uniform yielding (nothing localized), and no yielding: 0.
  for (double v : {1.0, 0.0}) {
    Kokkos::deep_copy(p.equivalent_plastic_strain, v);
    measure_bands(p, 0.05, 0.1, sum, max, angle, width);
    EXPECT_EQ(angle, 0.0);
    EXPECT_EQ(width, 0.0);
  }
}

}  // namespace
}  // namespace mupm
