// The staggered solid/fluid step of Algorithm 1 in either order (FORMULATION "Time
// integration"): the fluid advances once every `fluid_every` solid steps over their combined
// interval, in `substeps` equal steps.
//   Solid First: the solid steps with p held; after the last solid step of an interval the
//     fluid advances over it with the volume change those steps made.
//   Fluid First: at the start of an interval the fluid advances with the volume change of the
//     previous interval; then the solid steps with the new p.
// After each fluid update the mixture density follows the new saturation (eq 1).
#ifndef MUPM_STAGGERED_HPP
#define MUPM_STAGGERED_HPP

#include "mupm/fluid_solver.hpp"
#include "mupm/solid_solver.hpp"

namespace mupm {

template <int Dim>
struct Staggered {
  SolidSolver<Dim>* solid = nullptr;
  FluidSolver<Dim>* fluid = nullptr;
  bool fluid_first = false;
  int fluid_every = 1;
  int substeps = 1;

  // Step number `step` (0-based, counted from t = 0 so restarts keep the intervals), t -> t + dt.
  void step(long long step, double t, double dt) {
    const double interval = fluid_every * dt;
    if (fluid_first && step % fluid_every == 0)
      advance_fluid(t, interval);
    solid->step(t, dt);
    if (!fluid_first && (step + 1) % fluid_every == 0)
      advance_fluid(t + dt - interval, interval);
  }

 private:
  void advance_fluid(double t, double interval) {
    fluid->advance(t, interval, substeps);
    solid->update_density();
  }
};

}  // namespace mupm

#endif
