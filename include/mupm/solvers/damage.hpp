// The damage module: the damage of every point from its intact bonds (eq 37) after the
// mechanics step, and its time-series columns. The fracture issue adds bond breakage here
// (Algorithm 4: after the solid step, before the fluid step).
#ifndef MUPM_SOLVERS_DAMAGE_HPP
#define MUPM_SOLVERS_DAMAGE_HPP

#include <mpi.h>

#include "mupm/kernels/damage.hpp"
#include "mupm/mesh/discretization.hpp"
#include "mupm/solvers/module.hpp"

namespace mupm {

template <int Dim>
class Damage : public Module {
 public:
  Damage(Discretization<Dim>& disc, MPI_Comm comm) : disc_(disc), comm_(comm) {}

  const char* name() const override { return "damage"; }

  void update() { compute_damage(disc_.bonds, disc_.points); }

  // Volume-weighted mean damage and the number of broken bonds (each bond is listed by both
  // its ends). Sums over ranks in a fixed order would be needed for bit-equal sums; these are
  // reports.
  void series(SeriesRow& row) const override {
    const auto& p = disc_.points;
    auto damage = p.damage;
    auto volume = p.volume;
    double sums[2] = {0, 0};
    Kokkos::parallel_reduce(
        "mupm::Diagnostics::damage", range(0, p.n_owned),
        KOKKOS_LAMBDA(const std::size_t i, double& d, double& v) {
          d += damage(i) * volume(i);
          v += volume(i);
        },
        sums[0], sums[1]);
    long long broken = 0;
    auto intact = disc_.bonds.intact;
    Kokkos::parallel_reduce(
        "mupm::Diagnostics::broken_bonds", range(0, disc_.bonds.size()),
        KOKKOS_LAMBDA(const std::size_t b, long long& c) { c += intact(b) ? 0 : 1; }, broken);
    MPI_Allreduce(MPI_IN_PLACE, sums, 2, MPI_DOUBLE, MPI_SUM, comm_);
    MPI_Allreduce(MPI_IN_PLACE, &broken, 1, MPI_LONG_LONG, MPI_SUM, comm_);
    row("mean_damage", sums[1] > 0 ? sums[0] / sums[1] : 0.0);
    row("broken_bonds", double(broken) / 2);
  }

 private:
  Discretization<Dim>& disc_;
  MPI_Comm comm_;
};

}  // namespace mupm

#endif
