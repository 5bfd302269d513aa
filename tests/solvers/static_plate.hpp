// Shared by the J-integral tests (test_j_integral.cpp): an edge-cracked strip solved for its
// static equilibrium (static_solve.hpp), its loads, and the LEFM geometry factor of a single
// edge crack in tension.
#ifndef MUPM_TESTS_STATIC_PLATE_HPP
#define MUPM_TESTS_STATIC_PLATE_HPP

#include <mpi.h>

#include <array>
#include <cmath>
#include <memory>

#include "mupm/input/model.hpp"
#include "mupm/solvers/crack_face_force.hpp"
#include "mupm/solvers/damage.hpp"
#include "static_solve.hpp"
#include "test_utils.hpp"

namespace mupm::test {

// A single edge crack of length a in a strip of width W, remote tension: the LEFM geometry
// factor F(a/W) of K_I = sigma sqrt(pi a) F; reference values F(0.1, 0.3, 0.5) below.
inline double sent_factor(double aw) {
  const double t = M_PI * aw / 2;
  return std::sqrt(std::tan(t) / t) * (0.752 + 2.02 * aw + 0.37 * std::pow(1 - std::sin(t), 3)) /
         std::cos(t);
}

// Example 2's skeleton (nu = 0.30, E = 72 GPa) with mu_c and l small.
inline const MicropolarElastic kClassical =
    MicropolarElastic::from_bulk_shear(60e9, 27.7e9, 27.7e9 * 1e-4, 1e-5);

// The LEFM near-tip (Williams) displacement field of a mode I or II crack along -x from (xt, yt)
// (test_j_integral.cpp's header), and its rotation.
struct KField {
  double K = 1e6;  // stress-intensity factor [Pa m^0.5]
  bool mode2 = false;
  double mu = 0, kappa = 0;  // shear modulus, Kolosov's constant
  double xt = 0, yt = 0;     // tip
  void u(double x, double y, double* out) const {
    const double dx = x - xt, dy = y - yt;
    const double r = std::sqrt(dx * dx + dy * dy), t = std::atan2(dy, dx);
    const double a = K / (2 * mu) * std::sqrt(r / (2 * M_PI));
    const double s = std::sin(t / 2), c = std::cos(t / 2);
    if (!mode2) {
      out[0] = a * c * (kappa - 1 + 2 * s * s);
      out[1] = a * s * (kappa + 1 - 2 * c * c);
    } else {
      out[0] = a * s * (kappa + 1 + 2 * c * c);
      out[1] = -a * c * (kappa - 1 - 2 * s * s);
    }
  }
  // (du_y/dx - du_x/dy)/2 by central differences of the closed form.
  double rotation(double x, double y) const {
    const double h = 1e-8;
    double a[2], b[2], c[2], d[2];
    u(x + h, y, a);
    u(x - h, y, b);
    u(x, y + h, c);
    u(x, y - h, d);
    return 0.5 * ((a[1] - b[1]) - (c[0] - d[0])) / (2 * h);
  }
};

// An edge-cracked plate solved for its static equilibrium (tests/solvers/static_solve.hpp):
// nx x ny points of spacing dx, horizon factor m, the crack from the left face (or from x =
// start: a centre crack) to x = a along y = H/2 (a cell face).
struct StaticPlate {
  GridSpec<2> g;
  Discretization<2> disc;
  SolidState<2> st;
  StaticProblem<2> sp;
  double W = 0, H = 0;
};

inline std::unique_ptr<StaticPlate> static_plate(int nx, int ny, double dx, double m, double a,
                                                 const MicropolarElastic& law,
                                                 double start = -0.01) {
  auto P = std::make_unique<StaticPlate>();
  P->g = box<2>({nx, ny}, m, dx);
  P->W = nx * dx;
  P->H = ny * dx;
  Crack crack;
  crack.a[0] = start;
  crack.a[1] = 0.5 * P->H;
  crack.b[0] = a;
  crack.b[1] = 0.5 * P->H;
  P->g.cracks = {crack};
  P->disc = discretize(world(), P->g);
  P->st.allocate(P->disc.points.size(), P->disc.points.n_owned);
  auto& sp = P->sp;
  sp.disc = &P->disc;
  sp.prm = solid_params(law, P->g, 0.5);
  sp.st = &P->st;
  const std::size_t n = P->disc.points.n_owned;
  sp.load.assign(n * 3, 0.0);
  sp.held.assign(n * 3, 0);
  // The probe: an interior point far from the crack (row ny/4, column nx/2).
  sp.probe = GlobalId(ny / 4) * nx + nx / 2;
  return P;
}

// Row and column of an owned point.
inline std::array<long long, 2> cell(const StaticPlate& P, std::size_t i) {
  return {std::llround(P.disc.points.x(i, 0) / P.g.dx - 0.5),
          std::llround(P.disc.points.x(i, 1) / P.g.dx - 0.5)};
}

// The rigid motions held at two points of the right face (u_x, u_y at mid-height, u_x at the
// top).
inline void hold(StaticPlate& P) {
  const auto nx = P.g.counts[0], ny = P.g.counts[1];
  for (std::size_t i = 0; i < P.disc.points.n_owned; ++i) {
    const auto c = cell(P, i);
    if (c[0] == nx - 1 && c[1] == ny / 2)
      P.sp.held[i * 3 + 0] = P.sp.held[i * 3 + 1] = 1;
    if (c[0] == nx - 1 && c[1] == ny - 1)
      P.sp.held[i * 3 + 0] = 1;
  }
}

// Remote tension sigma on the top and bottom rows (sigma / dx per unit volume of the row).
inline void tension(StaticPlate& P, double sigma) {
  const auto ny = P.g.counts[1];
  for (std::size_t i = 0; i < P.disc.points.n_owned; ++i) {
    const auto c = cell(P, i);
    if (c[1] == ny - 1)
      P.sp.load[i * 3 + 1] = sigma / P.g.dx;
    if (c[1] == 0)
      P.sp.load[i * 3 + 1] = -sigma / P.g.dx;
  }
  hold(P);
}

// The crack water's force (CrackFaceForce, through the broken bonds) of a uniform p_f on the
// fracture points of P's crack, S_rf = 1, with the face-area shares A_i = V_i / (n_i dx) that
// the network step writes (kernels/fracture_flow.hpp): P's load, and the caller's
// Points::applied_crack_force.
inline void crack_water_load(StaticPlate& P, double p) {
  auto& pts = P.disc.points;
  const std::size_t n = pts.size();
  Damage<2> damage(P.disc, 0.3, MPI_COMM_WORLD);
  damage.update();
  pts.pf = Scalars("pf", n);
  pts.pf_saturation = Scalars("pf_saturation", n);
  pts.pf_aperture = Scalars("pf_aperture", n);
  pts.pf_modulus = Scalars("pf_modulus", n);
  pts.pf_area = Scalars("pf_area", n);
  Vectors fracture("fracture", n, 1);  // the flags, onto the ghosts
  for (std::size_t i = 0; i < pts.n_owned; ++i)
    fracture(i, 0) = pts.fracture(i);
  P.disc.dist.refresh({fracture});
  for (std::size_t i = 0; i < pts.n_owned; ++i) {
    if (!pts.fracture(i))
      continue;
    int rows = 1;  // n_i: i and the fracture points on its line across the crack
    for (BondIndex b = P.disc.bonds.offsets(i); b < P.disc.bonds.offsets(i + 1); ++b) {
      const int j = P.disc.bonds.neighbor(b);
      rows += fracture(j, 0) > 0 && std::abs(pts.x(j, 0) - pts.x(i, 0)) < 0.5 * P.g.dx;
    }
    pts.pf(i) = p;
    pts.pf_saturation(i) = 1;
    pts.pf_area(i) = pts.volume(i) / (rows * P.g.dx);
  }
  CrackFaceForce<2> water(P.disc);
  water.evaluate();
  for (std::size_t i = 0; i < pts.n_owned; ++i)
    for (int d = 0; d < 2; ++d)
      P.sp.load[i * 3 + d] = pts.applied_crack_force(i, d) = water.force()(i, d);
}

}  // namespace mupm::test

#endif
