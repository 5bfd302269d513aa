#include "mupm/input/model.hpp"

#include "input_module.hpp"

#include "mupm/kernels/fracture_flow.hpp"

#include <Teuchos_Array.hpp>
#include <algorithm>
#include <limits>
#include <sstream>

namespace mupm {

using Teuchos::Array;
using Teuchos::ParameterList;

namespace {

// A value as text that tells any two values apart.
std::string exact_text(const Teuchos::ParameterEntry& e) {
  std::ostringstream s;
  if (e.isType<double>()) {
    s << exact(Teuchos::getValue<double>(e));
  } else if (e.isType<Array<double>>()) {
    const auto a = Teuchos::getValue<Array<double>>(e);
    s << "{";
    for (Teuchos::Ordinal k = 0; k < a.size(); ++k)
      s << (k ? ", " : "") << exact(a[k]);
    s << "}";
  } else if (e.isType<bool>()) {
    s << (Teuchos::getValue<bool>(e) ? "true" : "false");
  } else {
    e.getAny(false).print(s);
  }
  return s.str();
}

// The pre-cracks as text: each sublist's name and its non-empty geometry, in input order.
std::string cracks_text(const ParameterList& cracks) {
  std::string s;
  for (auto it = cracks.begin(); it != cracks.end(); ++it) {
    const ParameterList& c = cracks.sublist(cracks.name(it));
    s += (s.empty() ? "" : "; ") + cracks.name(it) + ":";
    for (const char* k : {"Start", "End", "Corner", "Edge 1", "Edge 2"})
      if (!c.get<Array<double>>(k).empty())
        s += std::string(" ") + k + " = " + exact_text(c.getEntry(k));
  }
  return s.empty() ? "none" : s;
}

}  // namespace

const Options<Physics>& physics_options() {
  static const Options<Physics> o("Physics", {{"Micropolar Solid", Physics::MicropolarSolid},
                                              {"Kinematics Only", Physics::KinematicsOnly},
                                              {"Pore Fluid", Physics::PoreFluid},
                                              {"Hydro-Mechanical", Physics::HydroMechanical}});
  return o;
}
const Options<Staggering>& staggering_options() {
  static const Options<Staggering> o("Staggering", {{"Solid First", Staggering::SolidFirst},
                                                    {"Fluid First", Staggering::FluidFirst}});
  return o;
}
const Options<PressureIntegration>& pressure_integration_options() {
  static const Options<PressureIntegration> o(
      "Pressure Integration", {{"Explicit", PressureIntegration::Explicit},
                               {"Semi-Implicit", PressureIntegration::SemiImplicit}});
  return o;
}
const Options<StabilizationModulus>& stabilization_modulus_options() {
  static const Options<StabilizationModulus> o(
      "Stabilization Modulus", {{"Automatic", StabilizationModulus::Automatic},
                                {"Eq 71", StabilizationModulus::Eq71},
                                {"Bulk Matching", StabilizationModulus::BulkMatching}});
  return o;
}
const Options<RetentionModel>& retention_model_options() {
  static const Options<RetentionModel> o(
      "Retention Model",
      {{"Saturated", RetentionModel::Saturated}, {"Van Genuchten", RetentionModel::VanGenuchten}});
  return o;
}
const Options<ContourUnits>& contour_units_options() {
  static const Options<ContourUnits> o(
      "Units", {{"Spacings", ContourUnits::Spacings}, {"Metres", ContourUnits::Metres}});
  return o;
}
const Options<Plane>& plane_options() {
  static const Options<Plane> o("Plane", {{"Strain", Plane::Strain}, {"Stress", Plane::Stress}});
  return o;
}
const Options<BondBreaking>& bond_breaking_options() {
  static const Options<BondBreaking> o("Bond Breakage", {{"None", BondBreaking::None},
                                                         {"Energy", BondBreaking::Energy},
                                                         {"J-Integral", BondBreaking::JIntegral}});
  return o;
}
const Options<CrackWaterForce>& crack_water_force_options() {
  static const Options<CrackWaterForce> o(
      "Crack Water Force",
      {{"Face Pressure", CrackWaterForce::FacePressure}, {"Eq 17", CrackWaterForce::Eq17}});
  return o;
}
const Options<BondEnergyState>& bond_energy_state_options() {
  static const Options<BondEnergyState> o(
      "Bond Energy Force State",
      {{"Effective", BondEnergyState::Effective}, {"Total", BondEnergyState::Total}});
  return o;
}
const Options<TimeFunction::Kind>& time_function_options() {
  static const Options<TimeFunction::Kind> o("Time Function", {{"Constant", TimeFunction::Constant},
                                                               {"Ramp", TimeFunction::Ramp},
                                                               {"Rate", TimeFunction::Rate},
                                                               {"Table", TimeFunction::Table}});
  return o;
}
const Options<int>& component_options() {
  static const Options<int> o("Component", {{"x", 0}, {"y", 1}, {"z", 2}});
  return o;
}

// Mirrored kinematic conditions (kernels/boundary_conditions.hpp). A mirrored Displacement of
// the normal of its face that is the only kinematic condition reaching its layer points makes
// the layer the body's mirror image (mirror_kinematic: a symmetry plane). Any other mirrored
// kinematic condition (a tangential Displacement, a Velocity, a Micro-Rotation, or several on one
// layer, such as a clamp) slaves the layer (slave_layer): its points carry no strain energy, so
// every kinematic condition that reaches them must be mirrored too and share their region. Sets
// BoundaryCondition::slaved. Thrown on every rank (all read the same input).
inline std::string kind_name(const BoundaryCondition& bc) {
  return bc.kind == BoundaryCondition::Displacement ? "Displacement"
         : bc.kind == BoundaryCondition::Velocity   ? "Velocity"
                                                    : "Micro-Rotation";
}
template <int Dim>
void check_mirrored_kinematic(const GridSpec<Dim>& g, std::vector<BoundaryCondition>& bcs,
                              const std::string& root, Physics physics, const LawRegistration& law,
                              BondBreaking breaking, bool j_contours) {
  const char* axes = "xyz";
  // Whether region mask b reaches the points of region mask a (outside face `axis`) that lie
  // outside that face only: a's box clipped to the body along the other axes. Points sit at
  // cell centres, so boxes that only touch share none.
  auto overlap = [&](std::uint32_t a, int axis, std::uint32_t b) {
    if (b == 0)
      return true;
    for (std::size_t r = 0; r < g.regions.size(); ++r)
      for (std::size_t q = 0; q < g.regions.size(); ++q) {
        if (!(a & (1u << r)) || !(b & (1u << q)))
          continue;
        bool meet = true;
        for (int d = 0; d < Dim; ++d) {
          double lo = g.regions[r].lo[d], hi = g.regions[r].hi[d];
          if (d != axis) {
            lo = std::max(lo, g.origin[d]);
            hi = std::min(hi, g.origin[d] + g.counts[d] * g.dx);
          }
          meet = meet && lo < g.regions[q].hi[d] && g.regions[q].lo[d] < hi;
        }
        if (meet)
          return true;
      }
    return false;
  };
  for (auto& bc : bcs) {
    if (!(bc.kinematic() && bc.mirrored))
      continue;
    const std::string path = root + "->Boundary Conditions->" + bc.name + "->";
    // Measured: Terzaghi's column (tests/solvers/test_fluid_solver.cpp) with mirrored walls grew
    // without bound by T_v = 0.2, with constant or mirrored drained layers. The layer's pore
    // pressure is its own unknown, not the mirror image of the body's, so the coupled operator
    // is not symmetric; refused until the layer's water is mirrored too.
    if (physics != Physics::MicropolarSolid)
      throw InputError("Error, " + path + "Boundary Layer Values = Mirrored: mirrored " +
                       kind_name(bc) + " layers need " + root +
                       "->Solver->Physics = Micropolar Solid (with pore water they were measured "
                       "unstable; write Constant).");
    const int axis = face_axis(g, bc.region_mask);
    if (axis < 0)
      throw InputError("Error, " + path +
                       "Region: a mirrored condition (Boundary Layer Values = Mirrored) needs a "
                       "region that lies outside exactly one face of the body (a boundary layer "
                       "such as 'Layer -x').");
    bool alone = true;
    for (const auto& other : bcs)
      if (&other != &bc && other.kinematic() && overlap(bc.region_mask, axis, other.region_mask))
        alone = false;
    bc.slaved = !(alone && bc.kind == BoundaryCondition::Displacement && bc.component == axis);
    if (!bc.slaved)
      continue;
    // Slaved layers are built and measured for the elastic solid whose bonds stay intact:
    // breakage accumulates bond energies from the increments, which the slaving rewrites
    // (slaved_increment), and the plastic law's state on energy-free points is not defined.
    // The J-integral's contours may reach into the layers, whose states are zero.
    const std::string what = "Boundary Layer Values = Mirrored on a " + kind_name(bc) +
                             (bc.kind == BoundaryCondition::MicroRotation
                                  ? std::string()
                                  : std::string(" of component ") + axes[bc.component]) +
                             " slaves its layer (energy-free points)";
    if (!law.energy_free_points || breaking != BondBreaking::None) {
      std::vector<std::string> laws;  // those that run with slaved layers
      for (const LawRegistration* l : law_registry())
        if (l->energy_free_points)
          laws.push_back(l->name);
      throw InputError("Error, " + path + what + ", which is implemented for " + root +
                       "->Materials->Model = " + joined(laws) + " with " + root +
                       "->Fracture->Bond Breakage = None only; write Constant, or mirror the "
                       "normal Displacement alone (a symmetry plane).");
    }
    if (j_contours)
      throw InputError("Error, " + path + what + ", and the J-integral's contours (" + root +
                       "->J-Integral->Half Widths) may reach into them, where the states are "
                       "zero; write Constant, or give no contours.");
    // Each body point must be the mirror of one layer point per face (the fold's one writer).
    const int side = face_index(g, bc.region_mask) % 2;
    if (g.counts[axis] < g.layers[axis][side])
      throw InputError("Error, " + path + "Region: " + what + ", which is " +
                       std::to_string(g.layers[axis][side]) + " rows thick, but the body is " +
                       std::to_string(g.counts[axis]) + " rows along " + axes[axis] +
                       ": a slaved layer needs a body at least as thick as the layer (each body "
                       "point the mirror of one layer point).");
    for (const auto& other : bcs) {
      if (&other == &bc || !other.kinematic() || !overlap(bc.region_mask, axis, other.region_mask))
        continue;
      const bool rotation = other.kind == BoundaryCondition::MicroRotation;
      if (other.mirrored && other.region_mask == bc.region_mask &&
          rotation == (bc.kind == BoundaryCondition::MicroRotation) &&
          other.component == bc.component)
        throw InputError("Error, " + path + "Component: " + root + "->Boundary Conditions->" +
                         other.name +
                         " prescribes the same component of the same layer; give "
                         "each component one condition.");
      if (!other.mirrored || other.region_mask != bc.region_mask)
        throw InputError("Error, " + path +
                         "Boundary Layer Values = Mirrored slaves the points of its layer (they "
                         "carry no strain energy and follow their mirrors), but " +
                         root + "->Boundary Conditions->" + other.name +
                         (other.mirrored ? " reaches some of them with another Region; give "
                                           "both the same Region."
                                         : " also prescribes some of them with constant "
                                           "values; write Boundary Layer Values = Mirrored "
                                           "there too, or Constant here."));
    }
  }
}

// A Fluid Flux condition continues the body's pressure across one face (FluidSolver): its
// region must lie outside exactly one face.
template <int Dim>
void check_fluid_flux(const GridSpec<Dim>& g, const std::vector<BoundaryCondition>& bcs,
                      const std::string& root) {
  for (const auto& bc : bcs)
    if (bc.kind == BoundaryCondition::FluidFlux && face_axis(g, bc.region_mask) < 0)
      throw InputError("Error, " + root + "->Boundary Conditions->" + bc.name +
                       "->Region: a Fluid Flux condition needs a region that lies outside "
                       "exactly one face of the body (a boundary layer such as 'Layer -y'): the "
                       "flux enters through that face.");
}

// Traction Distribution = Consistent (kernels/boundary_conditions.hpp, consistent_traction_load):
// the region must be one box that holds the outermost real row of exactly one face of the body
// and not the row next to it; sets the condition's face.
template <int Dim>
void check_consistent_traction(const GridSpec<Dim>& g, std::vector<BoundaryCondition>& bcs,
                               const std::string& root) {
  for (auto& bc : bcs) {
    if (!bc.consistent)
      continue;
    const std::string path = root + "->Boundary Conditions->" + bc.name + "->";
    const std::uint32_t mask = bc.region_mask;
    int r = 0;
    while (mask != 0 && !(mask & (1u << r)))
      ++r;
    if (mask == 0 || (mask & (mask - 1)) != 0 || r >= int(g.regions.size()) ||
        face_axis(g, mask) >= 0)
      throw InputError("Error, " + path +
                       "Region: Traction Distribution = Consistent needs a region of "
                       "Discretization->Regions (a box on one face), not All or a layer.");
    const Box& b = g.regions[std::size_t(r)];
    int faces = 0;
    for (int a = 0; a < Dim; ++a)
      for (int side = 0; side < 2; ++side) {
        const double n = side ? 1.0 : -1.0;
        const double plane = g.origin[a] + (side ? g.counts[a] * g.dx : 0.0);
        const double outer = plane - n * 0.5 * g.dx, next = plane - n * 1.5 * g.dx;
        const bool holds_outer = b.lo[a] <= outer && outer <= b.hi[a];
        const bool holds_next = b.lo[a] <= next && next <= b.hi[a];
        if (holds_outer && !holds_next) {
          bc.face = 2 * a + side;
          ++faces;
        }
      }
    // The strip (2 delta + dx deep) must not reach the surface forces of the opposite face
    // (within 2 delta of it), which it would load with the opposite sign.
    const int a = bc.face / 2;
    if (faces == 1 && g.counts[a] * g.dx < 4 * g.horizon + g.dx)
      throw InputError("Error, " + path + "Traction Distribution = Consistent: the body is " +
                       std::to_string(g.counts[a] * g.dx) +
                       " m across the loaded face, less than "
                       "4 delta + dx = " +
                       std::to_string(4 * g.horizon + g.dx) +
                       " m, so the loaded strip would reach the opposite face; use Outer Row.");
    if (faces != 1)
      throw InputError(
          "Error, " + path + "Region: Traction Distribution = Consistent needs a box that holds " +
          "the outermost real row of exactly one face of the body (its coordinate across that " +
          "face within half a spacing of the face) and not the next row; this one holds " +
          (faces == 0 ? "none." : "the outer row of " + std::to_string(faces) + " faces."));
  }
}

template <int Dim>
Model<Dim> model_from_input(const ParameterList& input) {
  Model<Dim> m;
  m.grid = grid_from_input<Dim>(input);
  const ParameterList& solver = input.sublist("Solver");
  const ParameterList& output = input.sublist("Output");
  const ParameterList& diag = input.sublist("Diagnostics");
  const ParameterList& materials = input.sublist("Materials");
  const ParameterList& fluid = input.sublist("Fluid");

  RunSettings& r = m.run;
  r.physics = physics_options()(solver.get<std::string>("Physics"));
  r.staggering = staggering_options()(solver.get<std::string>("Staggering"));
  r.solid_steps_per_fluid_step = solver.get<int>("Solid Steps Per Fluid Step");
  r.fluid_substeps = solver.get<int>("Fluid Substeps");
  r.semi_implicit =
      pressure_integration_options()(solver.get<std::string>("Pressure Integration")) ==
      PressureIntegration::SemiImplicit;
  {
    const ParameterList& ps = solver.sublist("Pressure Solve");
    r.pressure_solve.preconditioner = ps.get<std::string>("Preconditioner");
    r.pressure_solve.fill_level = ps.get<int>("ILU Fill Level");
    r.pressure_solve.refresh_interval = ps.get<int>("Preconditioner Refresh Interval");
    r.pressure_solve.drop_tolerance = ps.get<double>("Drop Tolerance");
    r.pressure_solve.tolerance = ps.get<double>("Tolerance");
    r.pressure_solve.max_iterations = ps.get<int>("Maximum Iterations");
    r.pressure_solve.recycle = ps.get<int>("Recycled Vectors");
    r.pressure_solve.refresh_growth = ps.get<double>("Refresh Iteration Growth");
    r.pressure_solve.amg_strong_threshold = ps.get<double>("AMG Strong Threshold");
    r.pressure_solve.amg_interpolation_entries = ps.get<int>("AMG Interpolation Entries");
    r.pressure_solve.amg_aggressive_levels = ps.get<int>("AMG Aggressive Levels");
    r.pressure_solve.amg_fallback = ps.get<bool>("AMG Fallback");
    r.pressure_solve.amg_drop_tolerance = ps.get<double>("AMG Drop Tolerance");
    const int write = input.sublist("Diagnostics").get<int>("Write Pressure System");
    if (write > 0) {
      r.pressure_solve.write_at = write;
      r.pressure_solve.write_prefix = input.sublist("Output").get<std::string>("Folder") + "/";
    }
  }
  r.time_step = solver.get<double>("Time Step");
  r.automatic_time_step = solver.get<bool>("Automatic Time Step");
  r.safety = solver.get<double>("Time Step Safety Factor");
  r.n_steps = solver.get<int>("Number of Steps");
  r.end_time = solver.get<double>("End Time");
  r.energy_tolerance = solver.get<double>("Energy Tolerance");
  r.stop_on_energy_violation = solver.get<bool>("Stop On Energy Violation");
  r.energy_check_start = solver.get<int>("Energy Check Start");
  r.restart_from = solver.get<std::string>("Restart From");
  r.folder = output.get<std::string>("Folder");
  const auto fields = output.get<Array<std::string>>("Fields");
  r.fields.assign(fields.begin(), fields.end());
  r.field_interval = output.get<int>("Field Interval");
  r.second_order_window = output.get<int>("Second-Order Work Window");
  r.field_groups = point_field_groups(input);
  r.series_interval = output.get<int>("Time Series Interval");
  r.checkpoint_interval = output.get<int>("Checkpoint Interval");
  r.checkpoint_at_end = output.get<bool>("Checkpoint At End");
  r.progress_interval = output.get<double>("Progress Interval");
  r.kernel_timers = diag.get<bool>("Kernel Timers");
  r.check_finite = diag.get<bool>("Check Finite");

  const auto g = solver.get<Array<double>>("Gravity");
  for (Teuchos::Ordinal k = 0; k < g.size() && k < 3; ++k)
    m.gravity[k] = g[k];
  m.damping = solver.get<double>("Damping");

  m.law = &law_named(materials.get<std::string>("Model"));
  m.materials = materials;
  if (m.law->warn)
    m.law->warn(materials, m.warnings);
  auto law = MicropolarElastic::from_bulk_shear(
      materials.get<double>("Bulk Modulus"), materials.get<double>("Shear Modulus"),
      materials.get<double>("Micropolar Shear Modulus"), materials.get<double>("Length Scale"));
  const bool plane_stress =
      Dim == 2 &&
      plane_options()(input.sublist("Discretization").get<std::string>("Plane")) == Plane::Stress;
  m.material = law;
  m.plane_stress = plane_stress;
  if (plane_stress)
    law = law.plane_stress();
  m.solid = solid_params<Dim>(
      law, m.grid, materials.get<double>("Stabilization"),
      stabilization_modulus_options()(materials.get<std::string>("Stabilization Modulus")));
  if (plane_stress)
    m.solid.pore = m.material.plane_stress_coupling();
  m.solid_density = materials.get<double>("Solid Density");
  m.porosity = materials.get<double>("Porosity");

  const double rho_w = fluid.get<double>("Water Density");
  const double k = fluid.get<double>("Intrinsic Permeability");
  m.fluid = fluid_params<Dim>(
      m.grid,
      k > 0 ? k / fluid.get<double>("Viscosity")
            : fluid.get<double>("Hydraulic Conductivity") / (rho_w * kStandardGravity),
      fluid.get<double>("Flow Stabilization"));
  m.fluid.water_density = rho_w;
  m.fluid.pore = m.solid.pore;
  m.fluid.bulk_modulus = fluid.get<bool>("Incompressible")
                             ? std::numeric_limits<double>::infinity()
                             : fluid.get<double>("Fluid Bulk Modulus");
  m.fluid.semi_implicit = r.semi_implicit;
  m.fluid.projection_stabilization = solver.get<double>("Pressure Stabilization");
  if (retention_model_options()(fluid.get<std::string>("Retention Model")) ==
      RetentionModel::VanGenuchten) {
    m.fluid.retention = VanGenuchten::mualem(fluid.get<double>("Air Entry Pressure"),
                                             fluid.get<double>("Van Genuchten n"));
    const double vm = fluid.get<double>("Van Genuchten m");
    if (vm > 0)
      m.fluid.retention.m = vm;
  }
  if (fluid.get<bool>("Gravity In Darcy Flux"))
    m.fluid.gravity = m.gravity;

  const ParameterList& fracture = input.sublist("Fracture");
  m.fracture.criterion = bond_breaking_options()(fracture.get<std::string>("Bond Breakage"));
  m.fracture.critical_energy = critical_bond_energy<Dim>(
      fracture.get<double>("Critical Energy Release Rate"), m.grid.horizon, m.grid.thickness);
  m.fracture.critical_damage = fracture.get<double>("Critical Damage");
  m.fracture.effective_state =
      bond_energy_state_options()(fracture.get<std::string>("Bond Energy Force State")) ==
      BondEnergyState::Effective;
  m.fracture.flow = fracture.get<bool>("Fracture Flow");
  m.fracture.viscosity = fluid.get<double>("Viscosity");
  m.fracture.min_aperture = fracture.get<double>("Minimum Aperture");
  m.fracture.water_modulus = m.fluid.bulk_modulus;
  m.fracture.face_pressure =
      crack_water_force_options()(fracture.get<std::string>("Crack Water Force")) ==
      CrackWaterForce::FacePressure;

  const ParameterList& j = input.sublist("J-Integral");
  const auto widths = j.get<Teuchos::Array<double>>("Half Widths");
  auto heights = j.get<Teuchos::Array<double>>("Half Heights");
  if (heights.empty())
    heights = widths;
  const double unit = contour_units_options()(j.get<std::string>("Units")) == ContourUnits::Metres
                          ? 1.0
                          : m.grid.dx;
  for (Teuchos::Ordinal k = 0; k < widths.size() && k < heights.size(); ++k)
    m.j_integral.half.push_back({widths[k] * unit, heights[k] * unit});
  m.j_integral.criterion = m.fracture.criterion == BondBreaking::JIntegral;
  m.j_integral.face = m.fracture.flow && m.fracture.face_pressure;
  m.j_integral.cut = m.j_integral.criterion && m.fracture.flow;
  m.j_integral.critical = fracture.get<double>("Critical Energy Release Rate");
  const double inc = j.get<double>("Crack Increment");
  m.j_integral.increment = inc > 0 ? inc : m.grid.dx;
  // The tip's speed cap (include/mupm/solvers/j_integral.hpp): the Rayleigh wave speed of the
  // skeleton, c_R = c_s (0.862 + 1.14 nu)/(1 + nu) (Viktorov's fit), c_s = sqrt(mu / rho) with
  // the initial mixture density of saturated pores (the heaviest: the lowest speed).
  const double rho = mixture_density(m.porosity, m.solid_density, 1.0, m.fluid.water_density);
  const double nu = m.solid.law.poisson();
  if (j.get<bool>("Speed Cap")) {
    const double v = j.get<double>("Maximum Crack Speed");  // 0: c_R
    m.j_integral.max_speed =
        v > 0 ? v : std::sqrt(m.solid.law.mu / rho) * (0.862 + 1.14 * nu) / (1 + nu);
  }
  m.fracture.release_time = j.get<double>("Release Time");  // needs the cap (modules/fracture)
  const double wait = m.j_integral.increment / m.j_integral.max_speed;
  if (m.fracture.release_time > wait * (1 + 1e-9))
    throw InputError("Error, " + input.name() +
                     "->J-Integral->Release Time = " + std::to_string(m.fracture.release_time) +
                     " s exceeds the speed cap's wait " + "Delta a / v = " + std::to_string(wait) +
                     " s (Crack Increment / Maximum Crack Speed, or / c_R): the next J decision "
                     "would see a field still under release.");

  m.boundary_conditions = boundary_conditions_from_input(input);
  for (const auto& bc : m.boundary_conditions)
    m.grid.mirrored_layers = m.grid.mirrored_layers || bc.mirrored;
  check_mirrored_kinematic(m.grid, m.boundary_conditions, input.name(), r.physics, *m.law,
                           m.fracture.criterion, !m.j_integral.half.empty());
  check_fluid_flux(m.grid, m.boundary_conditions, input.name());
  check_consistent_traction(m.grid, m.boundary_conditions, input.name());
  m.initial_conditions = initial_conditions_from_input(input);
  r.fixed = fixed_settings(input);
  return m;
}

FixedSettings fixed_settings(const ParameterList& input) {
  const ParameterList& solver = input.sublist("Solver");
  const ParameterList& fracture = input.sublist("Fracture");
  const Physics physics = physics_options()(solver.get<std::string>("Physics"));
  FixedSettings f;
  auto fix = [&](const char* list, const std::string& name, const std::string& why) {
    f.push_back(
        {std::string(list) + "->" + name, exact_text(input.sublist(list).getEntry(name)), why});
  };
  fix("Solver", "Physics", "the checkpoint's state holds that physics' fields and balances only");
  if (physics == Physics::HydroMechanical)
    fix("Solver", "Pressure Integration",
        "the checkpoint's forces were applied with that scheme's pressure (the undrained split's "
        "p* or p itself) and its energy ledger (the projection's work)");
  if (has_solid(physics)) {
    fix("Materials", "Model",
        "a Drucker-Prager state (plastic strains, softened cohesion, plastic dissipation) can "
        "neither be dropped nor made up without a jump in the stored energy");
    fix("Fracture", "Bond Breakage",
        "each criterion keeps its own state (bond energies, the crack's tip), which the other "
        "has not accumulated");
    fix("Discretization", "Plane",
        "the checkpoint's stresses, plastic strains and water content are that plane's (plane "
        "stress: sigma_zz = 0 with eps_zz free); the other plane would start from them with a "
        "jump in the stored energy");
  }
  const ParameterList& d = input.sublist("Discretization");
  f.push_back({"Discretization->Pre-Cracks", cracks_text(d.sublist("Pre-Cracks")),
               "the broken bonds and fracture points come from the checkpoint; a pre-crack "
               "added or moved would break loaded bonds without their energy being booked"});
  if (physics == Physics::HydroMechanical) {
    fix("Fracture", "Fracture Flow",
        "the crack water (its pressure and mass) would appear or vanish, breaking the water "
        "balance");
    if (fracture.get<bool>("Fracture Flow"))
      fix("Fracture", "Minimum Aperture",
          "the crack's stored water (a + a_min) and its stiffness, from which the run's stable "
          "step was estimated, are the checkpoint's");
  }
  return f;
}

template Model<2> model_from_input<2>(const ParameterList&);
template Model<3> model_from_input<3>(const ParameterList&);

}  // namespace mupm
