// The model an input describes, as the plain structs the lower layers take, built in one place
// (model_from_input) from the validated parameter list; but for a constitutive law's own
// parameters, which its registration's factory reads from Model::materials
// (include/mupm/input/law_registry.hpp). The parameter builders below derive the
// constants that depend on the grid (stabilization modulus, family volume and second moment);
// tests and benchmarks call them too, so every caller gets the same constants.
#ifndef MUPM_MODEL_HPP
#define MUPM_MODEL_HPP

#include <Teuchos_ParameterList.hpp>
#include <string>
#include <vector>

#include "mupm/input/input.hpp"
#include "mupm/input/law_registry.hpp"
#include "mupm/input/options.hpp"
#include "mupm/io/checkpoint.hpp"
#include "mupm/kernels/fluid.hpp"
#include "mupm/kernels/j_integral.hpp"
#include "mupm/kernels/solid.hpp"
#include "mupm/laws/micropolar_elastic.hpp"
#include "mupm/mesh/grid.hpp"
#include "mupm/solvers/linear_solve_settings.hpp"

namespace mupm {

// SolidParams of a law on a grid: G, D (eqs 69-71 by `choice`) and V_H.
template <int Dim>
SolidParams solid_params(const MicropolarElastic& law, const GridSpec<Dim>& g,
                         double stabilization = 0.5,
                         StabilizationModulus choice = StabilizationModulus::Automatic) {
  SolidParams prm;
  prm.law = law;
  prm.stabilization = stabilization;
  prm.stab_modulus = stabilization_modulus<Dim>(law, g.horizon, g.thickness, choice);
  prm.horizon_volume = g.family_volume();
  return prm;
}

// FluidParams with mobility k/mu_w and flow stabilization G on a grid: V_H and k2 from the grid,
// everything else at its default (set the members afterwards).
template <int Dim>
FluidParams fluid_params(const GridSpec<Dim>& g, double mobility, double stabilization = 0.5) {
  FluidParams f;
  f.mobility = mobility;
  f.stabilization = stabilization;
  f.horizon_volume = g.family_volume();
  f.second_moment = family_second_moment<Dim>(g.horizon, g.thickness);
  return f;
}

// Settings of the run (Solver, Output, Diagnostics).
struct RunSettings {
  Physics physics = Physics::MicropolarSolid;
  Staggering staggering = Staggering::SolidFirst;
  int solid_steps_per_fluid_step = 1;
  int fluid_substeps = 1;              // 0: automatic
  bool semi_implicit = false;          // Pressure Integration = Semi-Implicit
  LinearSolveSettings pressure_solve;  // Solver->Pressure Solve
  double time_step = 1e-6;
  bool automatic_time_step = false;
  double safety = 0.5;
  long long n_steps = 0;
  double end_time = 0;  // > 0: run to this time instead of n_steps (last_step)
  double energy_tolerance = 1e-2;
  bool stop_on_energy_violation = false;
  long long energy_check_start = 20;
  std::string restart_from;
  FixedSettings fixed;  // what a restart may not change (fixed_settings)
  // Output.
  std::string folder = "output";
  std::vector<std::string> fields;
  int field_interval = 10, series_interval = 1, checkpoint_interval = 0;
  int second_order_window = 0;  // 0: field_interval
  // The point fields allocated (point_field_groups; model_from_input sets it). The second-order
  // work is computed where its group is.
  unsigned field_groups = kAllGroups;
  bool checkpoint_at_end = true;
  double progress_interval = 5;
  // Diagnostics.
  bool kernel_timers = true, check_finite = true;
};

template <int Dim>
struct Model {
  GridSpec<Dim> grid;
  RunSettings run;
  // Materials->Model's registration (include/mupm/input/law_registry.hpp), and the validated
  // Materials, from which its factory reads the law's own parameters.
  const LawRegistration* law = nullptr;
  Teuchos::ParameterList materials;
  SolidParams solid;
  MicropolarElastic material;   // the 3D law (solid.law is its plane_stress() in plane stress)
  bool plane_stress = false;    // Discretization->Plane = Stress (2D)
  double solid_density = 2000;  // rho_s
  double damping = 0;           // Solver->Damping
  FluidParams fluid;
  FractureParams fracture;
  JIntegralParams j_integral;          // no contours: no J
  double porosity = 0;                 // Materials->Porosity (initial)
  Kokkos::Array<double, 3> gravity{};  // Solver->Gravity
  std::vector<BoundaryCondition> boundary_conditions;
  std::vector<InitialCondition> initial_conditions;
  std::vector<std::string> warnings;  // inputs that run but may mislead, said at the start
};

template <int Dim>
Model<Dim> model_from_input(const Teuchos::ParameterList& input);

// The settings a checkpoint records and a restart may not change (the checkpoint's state cannot
// follow them): Solver->Physics, Discretization->Pre-Cracks, and where they act Materials->Model,
// Fracture->Bond Breakage, Fracture->Fracture Flow and its Minimum Aperture. Others (material
// constants, loads, output) a restart applies as given.
FixedSettings fixed_settings(const Teuchos::ParameterList& input);

}  // namespace mupm

#endif
