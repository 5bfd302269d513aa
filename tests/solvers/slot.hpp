// Shared by the fracture-flow tests (test_fracture_flow.cpp, test_fracture_joining.cpp): a
// plate cut through its width (the slot), fracture conditions, the fracture parameters, and a
// sum over the owned points of all ranks.
#ifndef MUPM_TESTS_SLOT_HPP
#define MUPM_TESTS_SLOT_HPP

#include <mpi.h>

#include <string>

#include "mupm/kernels/boundary_conditions.hpp"
#include "mupm/kernels/damage.hpp"
#include "mupm/kernels/fracture.hpp"
#include "mupm/solvers/damage.hpp"
#include "test_utils.hpp"

namespace mupm::test {

inline constexpr double kDx = 2.5e-3;
inline constexpr int kNx = 48, kNy = 8;

// A 2D plate kNx x kNy cut through its whole width at y = H/2 (a pre-crack between rows 3 and
// 4), delta = 3 dx; regions 0 "left" (x < 3 dx), 1 "right" (x > L - 3 dx), 2 "middle".
struct Slot {
  GridSpec<2> g;
  Discretization<2> disc;
  double L = kNx * kDx, H = kNy * kDx;
  Slot() : g(make()), disc(discretize(world(), g)) {
    Damage<2> damage(disc, 0.3, MPI_COMM_WORLD);
    damage.update();
  }
  static GridSpec<2> make() {
    auto g = box<2>({kNx, kNy}, 3.0, kDx);
    const double L = kNx * kDx, H = kNy * kDx;
    Crack c;
    c.a[0] = -1;
    c.a[1] = 0.5 * H;
    c.b[0] = L + 1;
    c.b[1] = 0.5 * H;
    g.cracks = {c};
    Box left, right, middle;
    for (Box* b : {&left, &right, &middle}) {
      b->lo[0] = b->lo[1] = -1;
      b->hi[0] = b->hi[1] = 1;
    }
    left.hi[0] = 3 * kDx;
    right.lo[0] = L - 3 * kDx;
    middle.lo[0] = 0.25 * L;
    middle.hi[0] = 0.75 * L;
    g.region_names = {"left", "right", "middle"};
    g.regions = {left, right, middle};
    return g;
  }
  // Opens the crack by s: the upper half moves up by s/2, the lower half down (apertures = s).
  void open(double s) {
    auto x = disc.points.x, u = disc.points.u;
    const double h = 0.5 * H;
    Kokkos::parallel_for(
        range(0, disc.points.size()),
        KOKKOS_LAMBDA(const std::size_t i) { u(i, 1) = x(i, 1) > h ? 0.5 * s : -0.5 * s; });
    compute_aperture(disc.bonds, disc.points);
  }
};

inline BoundaryCondition condition(BoundaryCondition::Kind kind, const std::string& name,
                                   int region, double value) {
  BoundaryCondition bc;
  bc.kind = kind;
  bc.name = name;
  bc.region_mask = region < 0 ? 0u : 1u << region;
  bc.value = value;
  return bc;
}

inline FractureParams flow_params() {
  FractureParams f;
  f.flow = true;
  f.viscosity = 1e-3;
  f.min_aperture = 1e-7;
  return f;
}

// Sum over the owned points of f(i), over all ranks.
template <class F>
inline double sum_owned(const Points<2>& p, F&& f) {
  double s = 0;
  for (std::size_t i = 0; i < p.n_owned; ++i)
    s += f(i);
  MPI_Allreduce(MPI_IN_PLACE, &s, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  return s;
}

}  // namespace mupm::test

#endif
