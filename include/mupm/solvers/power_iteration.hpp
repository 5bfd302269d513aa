// The largest eigenvalue of M^-1 A for the stable-step estimates of the solid (A the stiffness,
// M the masses: dt = 2 / sqrt(lambda)) and of the fluid (A the flow operator, M the storage:
// dt = 2 / lambda), by power iteration with the M-weighted Rayleigh quotient
// lambda = x.A x / x.M x, which approaches lambda_max from below.
//
// Op (copied into the kernels) gives, for owned point i and component c < ncomp:
//   double& x(i, c)        the iterate (a field the operator reads; ghosts refreshed by apply)
//   double ax(i, c)        (A x)_ic after apply()
//   double mass(i, c)      M_ic
//   bool held(i, c)        a held component (prescribed: not part of the operator)
//   double start(i, c, s)  the start vector for the point of global id s
// and `apply` (host) evaluates A x for the current iterate.
#ifndef MUPM_POWER_ITERATION_HPP
#define MUPM_POWER_ITERATION_HPP

#include <mpi.h>

#include <cmath>

#include "mupm/core/types.hpp"

namespace mupm {

template <class Op, class Apply>
double largest_eigenvalue(const Op& op, int ncomp, std::size_t n_owned, const GlobalIds& gid,
                          const Scalars& volume, Apply&& apply, MPI_Comm comm, int iterations) {
  Kokkos::parallel_for(
      "mupm::StableStep::start", range(0, n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        const double s = double(gid(i));
        for (int c = 0; c < ncomp; ++c)
          op.x(i, c) = op.start(i, c, s);
      });
  double lambda = 0;
  for (int it = 0; it < iterations; ++it) {
    apply();
    double s[3] = {0, 0, 0};  // x.Ax, x.Mx, |M^-1 A x|_M^2
    Kokkos::parallel_reduce(
        "mupm::StableStep::rayleigh", range(0, n_owned),
        KOKKOS_LAMBDA(const std::size_t i, double& xax, double& xmx, double& yy) {
          for (int c = 0; c < ncomp; ++c) {
            if (op.held(i, c))
              continue;
            const double ax = op.ax(i, c), m = op.mass(i, c), xi = op.x(i, c);
            xax += xi * ax * volume(i);
            xmx += m * xi * xi * volume(i);
            yy += ax * ax / m * volume(i);
          }
        },
        s[0], s[1], s[2]);
    MPI_Allreduce(MPI_IN_PLACE, s, 3, MPI_DOUBLE, MPI_SUM, comm);
    lambda = s[1] > 0 ? s[0] / s[1] : 0.0;
    const double norm = s[2] > 0 ? 1.0 / std::sqrt(s[2]) : 0.0;
    Kokkos::parallel_for(
        "mupm::StableStep::next", range(0, n_owned), KOKKOS_LAMBDA(const std::size_t i) {
          for (int c = 0; c < ncomp; ++c)
            op.x(i, c) = op.held(i, c) ? 0.0 : op.ax(i, c) / op.mass(i, c) * norm;
        });
  }
  return lambda;
}

}  // namespace mupm

#endif
