// Tests' static solver: the equilibrium of the linear elastic micropolar solid under body forces
// (tractions on the outer rows), by preconditioned conjugate gradients on the force operator.
// The forces are -dPsi/d(u, theta) of a quadratic energy (include/mupm/kernels/solid.hpp), so
// the operator A x = -(f, l)(x) is symmetric in the volume-weighted inner product and positive
// definite once the rigid motions are held; one CG iteration is one force evaluation. The
// preconditioner is the operator's diagonal at an interior point (one value for the
// displacement components, one for the rotation), probed once.
#ifndef MUPM_TEST_STATIC_SOLVE_HPP
#define MUPM_TEST_STATIC_SOLVE_HPP

#include <mpi.h>

#include <cmath>
#include <vector>

#include "mupm/solvers/solid_solver.hpp"

namespace mupm::test {

template <int Dim>
struct StaticProblem {
  static constexpr int C = Dim + kRotDim<Dim>;
  Discretization<Dim>* disc = nullptr;
  SolidParams prm;
  SolidState<Dim>* st = nullptr;
  std::vector<double> load;         // body force and couple densities [n_owned * C]
  std::vector<unsigned char> held;  // 1: the component is held at 0 [n_owned * C]
  GlobalId probe = 0;               // an interior point for the preconditioner

  std::size_t n() const { return disc->points.n_owned; }

  // y = A x (held components 0); leaves u, theta = x and the forces of x in the state.
  void apply(const std::vector<double>& x, std::vector<double>& y) const {
    auto& p = disc->points;
    for (std::size_t i = 0; i < n(); ++i) {
      for (int k = 0; k < Dim; ++k)
        p.u(i, k) = x[i * C + k];
      for (int r = 0; r < C - Dim; ++r)
        p.theta(i, r) = x[i * C + Dim + r];
    }
    disc->dist.refresh({p.u, p.theta});
    solid_forces(*disc, prm, *st);
    Kokkos::fence();
    y.assign(n() * C, 0.0);
    for (std::size_t i = 0; i < n(); ++i) {
      for (int k = 0; k < Dim; ++k)
        y[i * C + k] = held[i * C + k] ? 0.0 : -st->force(i, k);
      for (int r = 0; r < C - Dim; ++r)
        y[i * C + Dim + r] = held[i * C + Dim + r] ? 0.0 : -st->moment(i, r);
    }
  }
  // sum_i V_i a_i . b_i over all ranks.
  double dot(const std::vector<double>& a, const std::vector<double>& b) const {
    double s = 0;
    for (std::size_t i = 0; i < n(); ++i)
      for (int c = 0; c < C; ++c)
        s += disc->points.volume(i) * a[i * C + c] * b[i * C + c];
    MPI_Allreduce(MPI_IN_PLACE, &s, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    return s;
  }

  // Solves A x = load to a relative residual `tol`; returns the iterations taken (-1: not
  // converged within max_iterations). The state holds u, theta and the forces of x.
  int solve(double tol = 1e-9, int max_iterations = 20000) {
    const std::size_t N = n() * C;
    // Preconditioner: the diagonal at the probe point.
    double diag[2] = {0, 0};
    std::vector<double> e(N, 0.0), Ae;
    std::size_t at = N;
    for (std::size_t i = 0; i < n(); ++i)
      if (disc->points.gid(i) == probe)
        at = i;
    for (int which = 0; which < 2; ++which) {
      std::fill(e.begin(), e.end(), 0.0);
      if (at < N)
        e[at * C + (which == 0 ? 0 : Dim)] = 1.0;
      apply(e, Ae);
      double d = at < N ? Ae[at * C + (which == 0 ? 0 : Dim)] : 0.0;
      MPI_Allreduce(MPI_IN_PLACE, &d, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
      diag[which] = d;
    }
    auto precondition = [&](const std::vector<double>& r, std::vector<double>& z) {
      z.resize(N);
      for (std::size_t i = 0; i < n(); ++i)
        for (int c = 0; c < C; ++c)
          z[i * C + c] = r[i * C + c] / diag[c < Dim ? 0 : 1];
    };
    std::vector<double> x(N, 0.0), r(N), z, p, q;
    for (std::size_t k = 0; k < N; ++k)
      r[k] = held[k] ? 0.0 : load[k];
    precondition(r, z);
    p = z;
    double rz = dot(r, z);
    const double r0 = std::sqrt(dot(r, r));
    int it = 0;
    for (; it < max_iterations; ++it) {
      if (std::sqrt(dot(r, r)) <= tol * r0)
        break;
      apply(p, q);
      const double alpha = rz / dot(p, q);
      for (std::size_t k = 0; k < N; ++k) {
        x[k] += alpha * p[k];
        r[k] -= alpha * q[k];
      }
      precondition(r, z);
      const double rz_new = dot(r, z);
      const double beta = rz_new / rz;
      rz = rz_new;
      for (std::size_t k = 0; k < N; ++k)
        p[k] = z[k] + beta * p[k];
    }
    apply(x, q);  // the state of the solution
    return it < max_iterations ? it : -1;
  }

  // Potential energy Psi - sum V load.x of the state (after solve).
  double potential() const {
    const auto& p = disc->points;
    double s = 0;
    for (std::size_t i = 0; i < n(); ++i) {
      s += st->energy(i);
      for (int k = 0; k < Dim; ++k)
        s -= p.volume(i) * load[i * C + k] * p.u(i, k);
      for (int r = 0; r < C - Dim; ++r)
        s -= p.volume(i) * load[i * C + Dim + r] * p.theta(i, r);
    }
    MPI_Allreduce(MPI_IN_PLACE, &s, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    return s;
  }
};

}  // namespace mupm::test

#endif
