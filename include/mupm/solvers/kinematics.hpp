// Solver->Physics = Kinematics Only: no internal forces; u and theta move with their
// velocities by the central difference (include/mupm/kernels/central_difference.hpp) with zero
// force and no gravity.
#ifndef MUPM_KINEMATICS_HPP
#define MUPM_KINEMATICS_HPP

#include "mupm/kernels/central_difference.hpp"
#include "mupm/mesh/discretization.hpp"
#include "mupm/solvers/module.hpp"

namespace mupm {

template <int Dim>
class Kinematics : public Mechanics {
 public:
  explicit Kinematics(Discretization<Dim>& disc) : disc_(disc) {
    const std::size_t n = disc.points.n_owned;
    force_ = Vectors("mupm::zero_force", n, Dim);
    moment_ = Vectors("mupm::zero_moment", n, kRotDim<Dim>);
    unit_ = Scalars("mupm::unit_density", n);
    Kokkos::deep_copy(unit_, 1.0);
  }
  const char* name() const override { return "kinematics"; }
  void initialize(double, bool) override {}
  void step(double, double dt) override {
    auto& p = disc_.points;
    advance_positions(p, dt);
    advance_velocities(p, force_, moment_, unit_, unit_, Vectors(), Vectors(), {}, 0.0, dt);
    disc_.dist.refresh(p.double_fields(kGhosted));
  }

 private:
  Discretization<Dim>& disc_;
  Vectors force_, moment_;
  Scalars unit_;
};

}  // namespace mupm

#endif
