// The physics modules of a run built from its model (assemble), and the set-up around them: the
// discretization's report, the initial fields, the conditions' regions.
// A part of the driver (src/solvers/simulation.cpp), which alone includes it.
#ifndef MUPM_DRIVER_ASSEMBLY_HPP
#define MUPM_DRIVER_ASSEMBLY_HPP

#include <mpi.h>

#include <algorithm>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "../laws/solid_build.hpp"
#include "mupm/input/model.hpp"
#include "mupm/io/point_rows.hpp"
#include "mupm/solvers/initial_conditions.hpp"
#include "mupm/solvers/j_integral.hpp"
#include "mupm/solvers/kinematics.hpp"
#include "mupm/solvers/solid_solver.hpp"
#include "mupm/solvers/step_sequence.hpp"

namespace mupm::driver {

// The physics modules of a run and the step sequence over them (Algorithm 1).
template <int Dim>
struct Assembly {
  std::unique_ptr<FluidSolver<Dim>> fluid;
  std::unique_ptr<Mechanics> mechanics;  // the micropolar solid, kinematics, or none
  std::unique_ptr<Damage<Dim>> damage;
  std::unique_ptr<JIntegral<Dim>> j_integral;  // J-Integral->Half Widths given
  StepSequence<Dim> sequence;
  double spacing = 0;  // dx, for messages
  // The stable-step watch's state (StableStepWatch), kept across a restart so that a restarted
  // run re-estimates at the same steps and keeps the fluid substeps of the straight run.
  struct Watch {
    long long pairs_at = 0;  // broken pairs at the last estimate
    double storage_at = 0;   // smallest storage C at the last estimate [1/Pa]
    long long substeps = 0;  // fluid substeps in use (0: not set yet)
    double time_step = 0;    // the run's dt [s] (choose_time_step; 0: not set yet)
  } watch;
  // Time series, restart globals and energy balances, in the time series' column order.
  std::vector<Module*> modules() const {
    std::vector<Module*> m{damage.get()};
    if (mechanics)
      m.push_back(mechanics.get());
    if (fluid)
      m.push_back(fluid.get());
    if (j_integral)
      m.push_back(j_integral.get());
    return m;
  }
  // Module set-up in the order the coupling needs: the fluid (S_r, C, flow of the state), then
  // the mechanics, whose tr(eps) of the initial state is the fluid's reference.
  void initialize(double time, bool restarted) {
    if (fluid)
      fluid->initialize(time, restarted);
    if (mechanics) {
      mechanics->initialize(time, restarted);
      if (fluid && !restarted)
        fluid->reset_strain_reference();
    }
  }
  NamedGlobals globals() {
    NamedGlobals out;
    for (Module* m : modules()) {
      GlobalRefs g;
      m->globals(g);
      for (GlobalRef r : g.refs()) {
        r.name = std::string(m->name()) + "/" + r.name;
        out.push_back(r);
      }
    }
    GlobalRefs w;
    w("stable_steps/broken_pairs_at_estimate", watch.pairs_at);
    w("stable_steps/min_storage_at_estimate", watch.storage_at);
    w("stable_steps/fluid_substeps", watch.substeps);
    w("stable_steps/time_step", watch.time_step);
    out.insert(out.end(), w.refs().begin(), w.refs().end());
    return out;
  }
};

template <int Dim>
Assembly<Dim> assemble(const Model<Dim>& model, Discretization<Dim>& disc, MPI_Comm mpi) {
  Assembly<Dim> ph;
  const Physics physics = model.run.physics;
  if (has_fluid(physics))
    ph.fluid =
        std::make_unique<FluidSolver<Dim>>(disc, model.fluid, model.boundary_conditions, mpi);
  ph.damage = std::make_unique<Damage<Dim>>(disc, model.fracture.critical_damage, mpi);
  if (!model.j_integral.half.empty())
    ph.j_integral = std::make_unique<JIntegral<Dim>>(disc, model.j_integral, *ph.damage, mpi);
  if (has_solid(physics)) {
    SolidSettings settings;
    settings.rho_s = model.solid_density;
    settings.rho_w = model.fluid.water_density;
    settings.gravity = model.gravity;
    settings.damping = model.damping;
    settings.fracture = model.fracture;
    settings.semi_implicit = model.run.semi_implicit;
    settings.fluid = has_fluid(physics);
    if (model.run.field_groups & kGroupSecondOrderWork)  // point_field_groups
      settings.second_order_window = model.run.second_order_window > 0
                                         ? model.run.second_order_window
                                         : model.run.field_interval;
    if (!model.law)
      throw std::logic_error("a solid without its law (Model::law)");
    ph.mechanics =
        model.law->build(SolidBuild<Dim>{model, disc, settings, mpi, ph.j_integral.get()});
  } else if (physics == Physics::KinematicsOnly) {
    ph.mechanics = std::make_unique<Kinematics<Dim>>(disc);
  }
  if (ph.fluid && model.fracture.flow)
    ph.fluid->enable_fracture_flow(model.fracture);
  if (ph.fluid && model.run.semi_implicit) {  // Hydro-Mechanical (src/input/modules/solver.cpp)
    ph.fluid->enable_semi_implicit(model.run.pressure_solve);
    ph.sequence.skeleton = dynamic_cast<Skeleton*>(ph.mechanics.get());
    if (!ph.sequence.skeleton)
      throw std::logic_error("Pressure Integration = Semi-Implicit without a solid skeleton");
  }
  ph.spacing = disc.grid.dx;
  ph.sequence.mechanics = ph.mechanics.get();
  ph.sequence.fluid = ph.fluid.get();
  ph.sequence.damage = ph.damage.get();
  if (model.j_integral.criterion && has_solid(physics))  // J integrates the solid's state
    ph.sequence.j_criterion = ph.j_integral.get();
  ph.sequence.fluid_first = model.run.staggering == Staggering::FluidFirst;
  ph.sequence.fluid_every = ph.mechanics ? model.run.solid_steps_per_fluid_step : 1;
  return ph;
}

// Prints the size of the discretization; returns the global number of bonds.
template <int Dim>
long long report_discretization(const Discretization<Dim>& disc, const Teuchos::Comm<int>& comm,
                                int pair_width, std::ostream& out) {
  long long counts[2] = {static_cast<long long>(disc.bonds.size()),
                         static_cast<long long>(disc.points.n_ghost)};
  MPI_Allreduce(MPI_IN_PLACE, counts, 2, MPI_LONG_LONG, MPI_SUM, io::raw(comm));
  const auto& g = disc.grid;
  if (comm.getRank() == 0)
    out << "mupm: " << Dim << "D, " << disc.dist.n_global() << " points (" << counts[1]
        << " ghost copies), " << counts[0] << " bonds, dx = " << g.dx
        << " m, horizon = " << g.horizon << " m (" << g.horizon / g.dx << " dx)\n"
        << "mupm: " << comm.getSize() << " rank(s) x " << ExecSpace().concurrency() << " "
        << ExecSpace::name() << " thread(s); " << Points<Dim>::bytes_per_point(disc.points.groups)
        << " bytes per point, " << Bonds::bytes_per_bond(pair_width) << " bytes per bond\n";
  return counts[0];
}

// The initial fields: Materials->Porosity, saturated, then the initial conditions in order.
template <int Dim>
void initial_state(const Model<Dim>& model, Points<Dim>& pts) {
  Kokkos::deep_copy(pts.porosity, model.porosity);
  Kokkos::deep_copy(pts.saturation, 1.0);
  Kokkos::Array<double, 3> rho_w_g{};
  for (int k = 0; k < 3; ++k)
    rho_w_g[k] = model.fluid.water_density * model.gravity[k];
  apply_initial_conditions(model.initial_conditions, pts, rho_w_g);
}

// Every boundary and initial condition acts on some point: a region that holds none makes the
// condition a silent no-op.
template <int Dim>
void check_regions(const Model<Dim>& model, const Discretization<Dim>& disc, MPI_Comm mpi) {
  const auto regions = io::owned_rows(disc.points.regions, disc.points.n_owned);
  std::vector<long long> counts(model.grid.region_names.size(), 0);
  for (std::uint32_t bits : regions)
    for (std::size_t r = 0; r < counts.size(); ++r)
      counts[r] += (bits >> r) & 1u;
  MPI_Allreduce(MPI_IN_PLACE, counts.data(), int(counts.size()), MPI_LONG_LONG, MPI_SUM, mpi);
  auto check = [&](const std::string& list, const std::string& name, std::uint32_t mask) {
    for (std::size_t r = 0; r < counts.size(); ++r)
      if (mask == (1u << r) && counts[r] == 0)
        throw InputError("Error, mupm->" + list + "->" + name + "->Region = '" +
                         model.grid.region_names[r] +
                         "' holds no point: the condition would do nothing. Check the region's "
                         "Min and Max against the body (points sit at cell centres) or its "
                         "boundary layers.");
  };
  for (const auto& bc : model.boundary_conditions)
    check("Boundary Conditions", bc.name, bc.region_mask);
  for (const auto& ic : model.initial_conditions)
    check("Initial Conditions", ic.name, ic.region_mask);
}

}  // namespace mupm::driver

#endif
