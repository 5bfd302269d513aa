#include "../input_module.hpp"

#include "mupm/data/points.hpp"
#include "mupm/input/options.hpp"

namespace mupm {

using Teuchos::Array;
using Teuchos::ParameterList;
using Teuchos::rcp;

namespace {

// The kinds of Boundary Conditions->NAME->Type. Each declares its name, its part of Type's doc
// string and what it takes: a rotation axis as Component, a Traction Distribution, which
// Boundary Layer Values. The Type validator (boundary_condition_options), its doc and the checks
// below follow; what a kind needs of the physics is BoundaryCondition::fluid() and
// fracture_fluid() (include/mupm/kernels/boundary_conditions.hpp), where the kind acts. A new
// kind: its enum value and kernel there, its entry here, where it acts in the solvers.
enum class LayerValues {
  Held,        // its layer points hold the prescribed value (Default or Constant)
  Mirrorable,  // Boundary Layer Values = Mirrored accepted
  FromFlux,    // its layer points take the flux's continuation of the body's pressure (Default)
};
struct ConditionKind {
  const char* name;
  BoundaryCondition::Kind kind;
  const char* doc;
  bool rotation = false;     // Component is a rotation axis (z in 2D)
  bool distributed = false;  // Traction Distribution = Consistent accepted
  LayerValues layer = LayerValues::Held;
};

const std::vector<ConditionKind>& condition_kinds() {
  using B = BoundaryCondition;
  constexpr LayerValues M = LayerValues::Mirrorable;
  static const std::vector<ConditionKind> k = {
      {"Displacement", B::Displacement,
       "[m] prescribed on the region's points (the boundary-layer method: use a boundary layer "
       "region)",
       false, false, M},
      {"Velocity", B::Velocity, "[m/s] prescribed on the region's points", false, false, M},
      {"Micro-Rotation", B::MicroRotation,
       "[rad] prescribed on the region's points (Component: the rotation axis)", true, false, M},
      {"Traction", B::Traction,
       "[Pa] applied as a body force traction/dx on the region's points (make it the outermost "
       "real row of the face), or as Traction Distribution says",
       false, true},
      {"Body Force", B::BodyForce, "[N/m^3]"},
      {"Body Couple", B::BodyCouple, "[N m/m^3] (Component: the rotation axis)", true},
      {"Pore Pressure", B::PorePressure,
       "[Pa] prescribed on the region's points (a drained boundary; boundaries without one are "
       "impervious; Solver->Physics = Pore Fluid or Hydro-Mechanical, as for every fluid "
       "condition)",
       false, false, M},
      {"Fluid Source", B::FluidSource,
       "[m^3/s; in 2D m^3/s per metre of thickness]: water injected at Value spread over the "
       "region's points by volume (a point source: a region holding one point; a line: a "
       "one-row region; negative: extraction)"},
      {"Fluid Flux", B::FluidFlux,
       "[m/s]: water flowing into the body through a face at Value (negative: out), on a "
       "boundary layer region (e.g. 'Layer -y'): its points outside one face take the pressure "
       "that continues the body's with the gradient of that flux (README, 'Boundary layers')",
       false, false, LayerValues::FromFlux},
      {"Fracture Pressure", B::FracturePressure,
       "[Pa] prescribed on the region's fracture points (Fracture->Fracture Flow = true, as for "
       "Fracture Source)",
       false, false, M},
      {"Fracture Source", B::FractureSource,
       "[m^3/s; in 2D per metre of thickness]: water injected into the region's fracture points "
       "at Value (e.g. at a crack's mouth; an error if the region has no fracture point)"}};
  return k;
}

const ConditionKind& condition_kind(const std::string& name) {
  for (const ConditionKind& k : condition_kinds())
    if (name == k.name)
      return k;
  throw std::logic_error("unknown boundary-condition kind " + name);  // validated before
}

const char* const kHydrostatic = kHydrostaticPorePressure;
std::vector<std::string> ic_fields() {
  std::vector<std::string> out;
  for (const auto& s : Points<3>::specs())
    if (s.initial_condition)
      out.push_back(s.initial_condition);
  out.push_back(kHydrostatic);
  return out;
}
// Components of a settable field in a `dim`-dimensional body (0: not settable).
int ic_components(const std::string& field, int dim) {
  if (field == kHydrostatic)
    return dim;
  const auto specs = dim == 2 ? Points<2>::specs() : Points<3>::specs();
  for (const auto& s : specs)
    if (s.initial_condition && field == s.initial_condition)
      return s.ncomp;
  return 0;
}
void ic_template(ParameterList& c) {
  c.set(
      "Field", std::string("Velocity"),
      "Field to set: " + joined(ic_fields()) +
          ". Value holds one entry per component: Displacement, Velocity: Dim; Micro-Rotation, "
          "Micro-Rotation Rate: 1 in 2D, 3 in 3D; Pore Pressure [Pa], "
          "Porosity, Saturation: 1 (with a fluid physics S_r follows from the pressure "
          "instead). The crack water takes none: a point joins the fracture network with "
          "its pore pressure (a pre-crack's points at the first step), so a Pore Pressure on "
          "the crack's region sets it. Hydrostatic Pore Pressure: p = rho_w g . (x - x_0) with g = "
          "Solver->Gravity and Value = x_0, a point of the water table (Dim values).",
      one_of(ic_fields()));
  c.set("Region", std::string("All"),
        "Name of a region of Discretization->Regions, or All. Later conditions overwrite "
        "earlier ones where they overlap.");
  c.set("Value", Array<double>(), "The value (number of entries as Field says).");
}

void bc_template(ParameterList& c) {
  std::string doc = "The condition's kind, one of: ";
  for (const ConditionKind& k : condition_kinds())
    doc += std::string(&k == &condition_kinds().front() ? "" : "; ") + k.name + " " + k.doc;
  c.set("Type", std::string(condition_kinds().front().name),
        doc + ". Component is ignored by the fluid conditions.",
        boundary_condition_options().validator());
  c.set("Region", std::string("All"), "Region name (Discretization->Regions, 'Layer -y', All).");
  c.set("Component", std::string("x"),
        "x, y or z: the displacement/velocity/traction/force component, or the rotation axis "
        "(2D micro-rotation: z).",
        component_options().validator());
  c.set("Value", 0.0, "The value, times the time function.");
  c.set("Time Function", std::string("Constant"),
        "Constant: Value. Ramp: Value * min(t / Ramp Time, 1). Rate: Value * t. Table: Value * "
        "the piecewise-linear table (Times, Values), held constant outside it.",
        time_function_options().validator());
  c.set("Ramp Time", 0.0, "Ramp duration [s] (Time Function = Ramp).", at_least(0.0));
  c.set("Times", Array<double>(), "Table times [s], increasing (Time Function = Table).");
  c.set("Values", Array<double>(), "Table values (Time Function = Table), as many as Times.");
  c.set("Boundary Layer Values", std::string("Default"),
        "Values on boundary-layer points. Pore Pressure: Constant (the prescribed value g, the "
        "paper's method) or Mirrored (2 g - p of the body point mirrored about the face, so that "
        "p passes through g at the face); Default: Discretization->Boundary Layer Values. "
        "Fracture Pressure: the same, with 2 g - p_f(m) of the step's start on its fracture "
        "points whose mirror m is a fracture point that no condition holds (g on the others). "
        "Displacement, Velocity and Micro-Rotation (Physics = Micropolar Solid): Mirrored (this "
        "parameter only; the region must lie outside one face). A mirrored Displacement of the "
        "face's "
        "normal that is the only kinematic condition of its layer makes the layer the mirror "
        "image of the body about a symmetry plane at u_n = g (u_n = 2 g - u_n, u_t and theta "
        "reflected: a roller with zero tangential micro-rotation). Any other mirrored "
        "kinematic condition (e.g. a clamp: x, y and the rotation, each Mirrored, on "
        "one layer) slaves its layer: the layer's points carry no strain energy and each "
        "prescribed component takes 2 g - v(m) of the mirror point m (for Velocity, g is the "
        "displacement it has prescribed), so the field passes through g at the face; components "
        "without a condition stay free; every kinematic "
        "condition on the layer must then be Mirrored with the same Region (Micropolar Elastic, "
        "no bond breakage). Default and Constant hold g. Points of the region that are not "
        "outside its face only (corners, body points) hold g either way (README, 'Boundary "
        "layers').",
        one_of({"Default", "Constant", "Mirrored"}));
  c.set("Traction Distribution", std::string("Outer Row"),
        "How a Traction is spread over the points. Outer Row: traction / dx on the region's "
        "points (the region: the outermost real row of the face; the paper's method). "
        "Consistent: the region is a box holding the outermost real row of exactly one face "
        "(and not the next row); the traction loads the strip of points within 2 delta + dx of "
        "that face (and its boundary layer) inside the box's other coordinates, with the force "
        "and couple densities that balance the uniform stress carrying the traction (so a "
        "uniform field is in equilibrium up to the face; README, 'Boundary layers').",
        one_of({"Outer Row", "Consistent"}));
}

void check_region(const ParameterList& c, const ParameterList& regions,
                  const Array<std::string>& faces) {
  const std::string region = c.get<std::string>("Region");
  bool known = region == "All" || regions.isSublist(region);
  for (const auto& f : faces)
    known = known || region == "Layer " + f;
  if (!known)
    throw InputError("Error, " + path_of(c, "Region") + " = '" + region +
                     "' names no region; expected All, a sublist of " + regions.name() +
                     " or a boundary layer such as 'Layer -y'.");
}

void declare_boundary_conditions(ParameterList& b) {
  bc_template(b.sublist("NAME"));
}
void declare_initial_conditions(ParameterList& ic) {
  ic_template(ic.sublist("NAME"));
}

// Each condition's region exists; components, distribution, layer values and time function fit
// its type and the dimension; fluid conditions have a fluid, crack-water ones Fracture Flow.
void check_boundary_conditions(ParameterList& input) {
  ParameterList& d = input.sublist("Discretization");
  const int dim = d.get<int>("Dimension");
  const Array<std::string> faces = d.get<Array<std::string>>("Boundary Layers");
  ParameterList& regions = d.sublist("Regions");
  ParameterList& bcs = input.sublist("Boundary Conditions");
  for (auto it = bcs.begin(); it != bcs.end(); ++it) {
    ParameterList& c = bcs.sublist(bcs.name(it));
    check_region(c, regions, faces);
    const ConditionKind& kind = condition_kind(c.get<std::string>("Type"));
    const std::string comp = c.get<std::string>("Component");
    const int axis = component_options()(comp);
    const bool rotation = kind.rotation;
    if (rotation && dim == 2 && axis != 2)
      throw InputError("Error, " + path_of(c, "Component") + " = " + comp +
                       ": in 2D the micro-rotation is about z; write z.");
    if (!rotation && axis >= dim)
      throw InputError("Error, " + path_of(c, "Component") + " = " + comp + ": a " +
                       std::to_string(dim) + "D body has components x" +
                       (dim == 3 ? ", y and z." : " and y."));
    if (!kind.distributed && c.get<std::string>("Traction Distribution") != "Outer Row")
      throw InputError("Error, " + path_of(c, "Traction Distribution") + " = " +
                       c.get<std::string>("Traction Distribution") +
                       ": only a Traction is distributed; a " + c.get<std::string>("Type") +
                       " condition takes Outer Row (the default).");
    // Fluid Flux sets its layer one way only (the flux's continuation of the body's pressure).
    if (kind.layer == LayerValues::FromFlux &&
        c.get<std::string>("Boundary Layer Values") != "Default")
      throw InputError("Error, " + path_of(c, "Boundary Layer Values") + " = " +
                       c.get<std::string>("Boundary Layer Values") +
                       ": a Fluid Flux condition sets its boundary-layer points by the flux (the "
                       "body's pressure continued with the flux's gradient); leave it Default.");
    // An odd reflection of the held components of layers that keep their energy was built and
    // measured unstable (not an invariant subspace of the vector operator: Terzaghi's column grew
    // without bound at H = 40 dx). Kinematic conditions mirror by the reflection R (a symmetry
    // plane) or by slaving energy-free layers (input/model.cpp, kernels/boundary_conditions.hpp).
    if (c.get<std::string>("Boundary Layer Values") == "Mirrored" &&
        kind.layer != LayerValues::Mirrorable) {
      std::vector<std::string> mirrorable;
      for (const bool pressure : {true, false})  // the pressures, then the kinematic kinds
        for (const ConditionKind& k : condition_kinds()) {
          BoundaryCondition b;
          b.kind = k.kind;
          if (k.layer == LayerValues::Mirrorable && b.fluid() == pressure)
            mirrorable.push_back(k.name);
        }
      throw InputError("Error, " + path_of(c, "Boundary Layer Values") + " = Mirrored: only " +
                       joined(mirrorable, " and ") +
                       " conditions mirror their boundary-layer values; " +
                       c.get<std::string>("Type") +
                       " conditions hold the prescribed value (write Constant or Default).");
    }
    const auto tf = time_function_options()(c.get<std::string>("Time Function"));
    if (tf == TimeFunction::Ramp && !(c.get<double>("Ramp Time") > 0))
      throw InputError("Error, " + path_of(c, "Ramp Time") + " must be > 0 for a Ramp.");
    if (tf == TimeFunction::Table) {
      const auto t = c.get<Array<double>>("Times"), v = c.get<Array<double>>("Values");
      bool increasing = t.size() >= 2;
      for (Teuchos::Ordinal k = 1; k < t.size(); ++k)
        increasing = increasing && t[k] > t[k - 1];
      if (!increasing || v.size() != t.size())
        throw InputError("Error, " + c.name() +
                         ": a Table needs at least 2 increasing Times and as many Values.");
    }
  }
  const std::string physics = input.sublist("Solver").get<std::string>("Physics");
  const bool fluid = has_fluid(physics_options()(physics));
  for (auto it = bcs.begin(); it != bcs.end(); ++it) {
    const ParameterList& c = bcs.sublist(bcs.name(it));
    const std::string type = c.get<std::string>("Type");
    BoundaryCondition bc;
    bc.kind = boundary_condition_options()(type);
    if (!fluid && bc.fluid())
      throw InputError("Error, " + path_of(c, "Type") + " = " + type +
                       " needs Solver->Physics = Pore Fluid or Hydro-Mechanical (it is " + physics +
                       ").");
    if (bc.fracture_fluid() && !input.sublist("Fracture").get<bool>("Fracture Flow"))
      throw InputError("Error, " + path_of(c, "Type") + " = " + type +
                       " needs mupm->Fracture->Fracture Flow = true.");
  }
}

// Each condition's field is settable, with one value per component, on a region that exists.
void check_initial_conditions(ParameterList& input) {
  ParameterList& d = input.sublist("Discretization");
  const int dim = d.get<int>("Dimension");
  const Array<std::string> faces = d.get<Array<std::string>>("Boundary Layers");
  ParameterList& regions = d.sublist("Regions");
  ParameterList& ics = input.sublist("Initial Conditions");
  for (auto it = ics.begin(); it != ics.end(); ++it) {
    ParameterList& c = ics.sublist(ics.name(it));
    const std::string field = c.get<std::string>("Field");
    get_array<double>(c, "Value", std::size_t(ic_components(field, dim)), field);
    check_region(c, regions, faces);
  }
}

}  // namespace

const Options<BoundaryCondition::Kind>& boundary_condition_options() {
  static const Options<BoundaryCondition::Kind> o("Type", [] {
    std::vector<std::pair<std::string, BoundaryCondition::Kind>> table;
    for (const ConditionKind& k : condition_kinds())
      table.emplace_back(k.name, k.kind);
    return table;
  }());
  return o;
}

InputModule boundary_conditions_input() {
  return {"Boundary Conditions", "One sublist per condition, named as you like.",
          declare_boundary_conditions, check_boundary_conditions, nullptr};
}

InputModule initial_conditions_input() {
  return {"Initial Conditions",
          "Initial fields, one sublist per condition, named as you like, applied in the order "
          "given.",
          declare_initial_conditions, check_initial_conditions, nullptr};
}

namespace {

// The bit of a condition's Region among names (region_names); All: none.
std::uint32_t region_mask(const std::vector<std::string>& names, const std::string& region) {
  for (std::size_t r = 0; r < names.size(); ++r)
    if (names[r] == region)
      return 1u << r;
  return 0;  // All
}

}  // namespace

// The conditions of the input (include/mupm/input/input.hpp).
std::vector<InitialCondition> initial_conditions_from_input(const ParameterList& input) {
  const auto names = region_names(input.sublist("Discretization"));
  std::vector<InitialCondition> out;
  const ParameterList& ics = input.sublist("Initial Conditions");
  for (auto it = ics.begin(); it != ics.end(); ++it) {
    const ParameterList& c = ics.sublist(ics.name(it));
    InitialCondition ic;
    ic.name = ics.name(it);
    ic.field = c.get<std::string>("Field");
    ic.region_mask = region_mask(names, c.get<std::string>("Region"));
    const auto v = c.get<Array<double>>("Value");
    ic.value.assign(v.begin(), v.end());
    out.push_back(ic);
  }
  return out;
}

std::vector<BoundaryCondition> boundary_conditions_from_input(const ParameterList& input) {
  const auto names = region_names(input.sublist("Discretization"));
  const int dim = input_dimension(input);
  std::vector<BoundaryCondition> out;
  const ParameterList& bcs = input.sublist("Boundary Conditions");
  for (auto it = bcs.begin(); it != bcs.end(); ++it) {
    const ParameterList& c = bcs.sublist(bcs.name(it));
    BoundaryCondition bc;
    bc.name = bcs.name(it);
    bc.kind = boundary_condition_options()(c.get<std::string>("Type"));
    bc.region_mask = region_mask(names, c.get<std::string>("Region"));
    bc.component = component_options()(c.get<std::string>("Component"));
    // In 2D the only rotation component, about z, is theta's component 0.
    if ((bc.kind == BoundaryCondition::MicroRotation || bc.kind == BoundaryCondition::BodyCouple) &&
        dim == 2)
      bc.component = 0;
    bc.value = c.get<double>("Value");
    bc.time.kind = time_function_options()(c.get<std::string>("Time Function"));
    bc.time.ramp_time = c.get<double>("Ramp Time");
    const auto t = c.get<Array<double>>("Times"), v = c.get<Array<double>>("Values");
    bc.time.times.assign(t.begin(), t.end());
    bc.time.values.assign(v.begin(), v.end());
    std::string values = c.get<std::string>("Boundary Layer Values");
    if (values == "Default")
      values = input.sublist("Discretization").get<std::string>("Boundary Layer Values");
    // The Discretization's default reaches Pore Pressure only; a Displacement or Micro-Rotation
    // condition mirrors when it says so itself (input/model.cpp, check_mirrored_kinematic).
    bc.mirrored = bc.kind == BoundaryCondition::FluidFlux ||
                  ((bc.kind == BoundaryCondition::PorePressure ||
                    bc.kind == BoundaryCondition::FracturePressure) &&
                   values == "Mirrored") ||
                  (bc.kinematic() && c.get<std::string>("Boundary Layer Values") == "Mirrored");
    bc.consistent = bc.kind == BoundaryCondition::Traction &&
                    c.get<std::string>("Traction Distribution") == "Consistent";
    out.push_back(bc);
  }
  return out;
}

}  // namespace mupm
