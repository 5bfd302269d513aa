// The step of Algorithm 1, written once: the mechanics (the micropolar solid, or kinematics
// alone) advances u and theta, then bond breakage and damage, then the fluid; with Staggering =
// Fluid First the fluid comes before the mechanics instead (the paper's "dual-direction"
// staggering, Algorithm 1 and eqs 127-149, e.g. fluid first for fluid-driven cracks).
// The fluid advances once every `fluid_every` steps over their combined interval, in `substeps`
// equal steps:
//   Solid First: the solid steps with p held; after the last solid step of an interval the
//     fluid advances over it with the volume change those steps made.
//   Fluid First: at the start of an interval the fluid advances with the volume change of the
//     previous interval; then the solid steps with the new p.
// After each fluid update the mixture density follows the new saturation (eq 1).
// Bond breakage is a step of its own between the mechanics' forces at t + dt and its velocity
// update: the energy criterion (Algorithm 4) on the step's bond energies, then the J criterion
// (include/mupm/solvers/j_integral.hpp, Algorithm 3); the damage and the flow of the new bond
// set follow the mechanics (damage_step), then the crack's aperture (crack_step).
#ifndef MUPM_STEP_SEQUENCE_HPP
#define MUPM_STEP_SEQUENCE_HPP

#include "mupm/solvers/damage.hpp"
#include "mupm/solvers/fluid_solver.hpp"
#include "mupm/solvers/j_integral.hpp"
#include "mupm/solvers/module.hpp"

namespace mupm {

template <int Dim>
struct StepSequence {
  Mechanics* mechanics = nullptr;  // none: the fluid alone (rigid skeleton)
  FluidSolver<Dim>* fluid = nullptr;
  Damage<Dim>* damage = nullptr;  // bond breakage and damage (fracture)
  bool fluid_first = false;
  int fluid_every = 1;
  int substeps = 1;
  long long damage_seen = -1;  // broken bond pairs at the last damage update (bookkeeping)

  // Solver->Pressure Integration = Semi-Implicit: the solid's step split around the pressure
  // solve (include/mupm/solvers/pressure_projection.hpp): move, pressure, the forces, breakage,
  // the velocities and damage, then the fluid's water and energy bookkeeping; every step, no
  // substeps.
  Skeleton* skeleton = nullptr;
  // Fracture->Bond Breakage = J-Integral: Algorithm 3 after the mechanics' forces (header).
  JIntegral<Dim>* j_criterion = nullptr;

  // Step number `step` (0-based, counted from t = 0 so restarts keep the intervals), t -> t + dt.
  void step(long long step, double t, double dt) {
    if (skeleton && fluid && fluid->semi_implicit()) {
      skeleton->move(t, dt);
      fluid->project(t, dt, *skeleton);
      skeleton->finish_forces(t, dt);
      skeleton->complete(t, dt, breakage(t + dt));
      damage_step();
      crack_step();
      fluid->finish_projection(dt);
      mechanics->update_density();
      return;
    }
    const double interval = fluid_every * dt;
    if (fluid && fluid_first && step % fluid_every == 0)
      advance_fluid(t, interval);
    if (mechanics) {
      mechanics->step_to_forces(t, dt);
      mechanics->complete_step(t, dt, breakage(t + dt));
    }
    damage_step();
    crack_step();
    // Without mechanics the interval is this step's [t, t + dt] (fluid_every is 1).
    if (fluid && !fluid_first && (step + 1) % fluid_every == 0)
      advance_fluid(mechanics ? t + dt - interval : t, interval);
  }

 private:
  // The step's bond breakage at its end time t_end: the energy criterion, then the J
  // criterion; the bonds broken on this rank and the energy they released (the energy
  // criterion's; the J criterion's release no bond energy).
  Breakage breakage(double t_end) {
    Breakage b = mechanics->energy_breakage();
    if (j_criterion)
      b.bonds += j_criterion_step(t_end).bonds;
    return b;
  }
  Breakage j_criterion_step(double t_end) { return j_criterion->advance(t_end); }
  // Bonds broke in the mechanics step: the damage changes (the pre-cracks' is computed at the
  // start), and so does the fluid's flow of the current pressure (K^-1 and the families).
  void damage_step() {
    if (damage && mechanics && mechanics->broken_pairs() != damage_seen) {
      damage->update();
      if (fluid && mechanics->broken_pairs() > 0)
        fluid->bonds_changed();
      damage_seen = mechanics->broken_pairs();
    }
  }
  // The crack opens with the displacement: the aperture of the points with broken bonds
  // (pre-cracks included) every step (the solid left u current on the ghosts), which the crack
  // water's storage and flow take (include/mupm/solvers/fracture_flow.hpp).
  void crack_step() {
    if (damage && mechanics)
      damage->update_aperture();
  }
  void advance_fluid(double t, double interval) {
    fluid->advance(t, interval, substeps);
    if (mechanics)
      mechanics->update_density();
  }
};

}  // namespace mupm

#endif
