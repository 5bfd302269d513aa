// A small elastic micropolar body for the solid tests: discretization, parameters, state.
#ifndef MUPM_TEST_SOLID_BODY_HPP
#define MUPM_TEST_SOLID_BODY_HPP

#include <cmath>
#include <functional>

#include "mupm/input/model.hpp"
#include "mupm/kernels/central_difference.hpp"
#include "mupm/solvers/solid_solver.hpp"
#include "test_utils.hpp"

namespace mupm::test {

template <int Dim>
struct Body {
  Discretization<Dim> disc;
  SolidParams prm;
  SolidState<Dim> st;
  Scalars rho, inertia;

  Body(const GridSpec<Dim>& g, const MicropolarElastic& law, double G,
       StabilizationModulus choice = StabilizationModulus::Automatic, double density = 2000)
      : disc(discretize(world(), g)), prm(solid_params(law, g, G, choice)) {
    st.allocate(disc.points.size(), disc.points.n_owned);
    rho = Scalars("rho", disc.points.n_owned);
    inertia = Scalars("J", disc.points.n_owned);
    Kokkos::deep_copy(rho, density);
    Kokkos::deep_copy(inertia, micro_inertia(0.0, density, law.length));
  }
  Points<Dim>& pts() { return disc.points; }

  // Sets u and theta on owned and ghost points from functions of the reference position.
  void set(std::function<void(const double*, double*, double*)> field) {
    auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), pts().x);
    auto u = Kokkos::create_mirror_view(pts().u);
    auto th = Kokkos::create_mirror_view(pts().theta);
    for (std::size_t i = 0; i < pts().size(); ++i) {
      double xi[3] = {0, 0, 0}, ui[3] = {0, 0, 0}, ti[3] = {0, 0, 0};
      for (int d = 0; d < Dim; ++d)
        xi[d] = x(i, d);
      field(xi, ui, ti);
      for (int d = 0; d < Dim; ++d)
        u(i, d) = ui[d];
      for (int r = 0; r < kRotDim<Dim>; ++r)
        th(i, r) = ti[r];
    }
    Kokkos::deep_copy(pts().u, u);
    Kokkos::deep_copy(pts().theta, th);
  }
  void forces() {
    disc.dist.refresh({pts().u, pts().theta});
    solid_forces(disc, prm, st);
    Kokkos::fence();
  }
  double energy() {
    double e = 0;
    auto en = st.energy;
    Kokkos::parallel_reduce(
        range(0, pts().n_owned), KOKKOS_LAMBDA(const std::size_t i, double& s) { s += en(i); }, e);
    MPI_Allreduce(MPI_IN_PLACE, &e, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    return e;
  }
  std::vector<bool> interior(int rows) { return interior_points(disc, rows); }
};

}  // namespace mupm::test

#endif
