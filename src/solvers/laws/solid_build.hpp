// What a law's factory (include/mupm/input/law_registry.hpp) builds its solid solver from, and the
// solver built for a law. Private to the laws' registrations (src/solvers/laws/) and the driver.
#ifndef MUPM_SRC_SOLID_BUILD_HPP
#define MUPM_SRC_SOLID_BUILD_HPP

#include <mpi.h>

#include <memory>

#include "mupm/input/law_registry.hpp"
#include "mupm/input/model.hpp"
#include "mupm/solvers/j_integral.hpp"
#include "mupm/solvers/solid_solver.hpp"

namespace mupm {

template <int Dim>
struct SolidBuild {
  const Model<Dim>& model;  // model.materials holds the law's own parameters
  Discretization<Dim>& disc;
  const SolidSettings& settings;
  MPI_Comm comm;
  JIntegral<Dim>* j_integral;  // J-Integral->Half Widths given: J integrates the solid's state
};

// The solid solver with `law`, its state attached to the J-integral's contours if any.
template <int Dim, class Law>
std::unique_ptr<Mechanics> solid_module(const SolidBuild<Dim>& b, const Law& law) {
  auto solid = std::make_unique<SolidSolver<Dim, Law>>(
      b.disc, b.model.solid, b.model.boundary_conditions, b.settings, b.comm, law);
  if (b.j_integral) {
    b.j_integral->attach(solid->state(), solid->params());
    solid->keep_pore_part();
  }
  return solid;
}

}  // namespace mupm

#endif
