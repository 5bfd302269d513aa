#include "mupm/input/input.hpp"

#include "mupm/data/bonds.hpp"
#include "mupm/data/points.hpp"
#include "mupm/input/options.hpp"
#include "mupm/kernels/j_integral.hpp"

#include <unistd.h>
#include <Teuchos_Array.hpp>
#include <Teuchos_CommHelpers.hpp>
#include <Teuchos_DefaultMpiComm.hpp>
#include <Teuchos_StandardParameterEntryValidators.hpp>
#include <Teuchos_StringInputSource.hpp>
#include <Teuchos_XMLObject.hpp>
#include <Teuchos_XMLParameterListCoreHelpers.hpp>
#include <algorithm>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

namespace mupm {

namespace {

using Teuchos::Array;
using Teuchos::ParameterList;
using Teuchos::RCP;
using Teuchos::rcp;

// Initial Conditions->NAME->Field: the registry's settable fields (include/mupm/data/points.hpp),
// then the hydrostatic pressure, which is not a field value.
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
std::string joined(const std::vector<std::string>& v) {
  std::string out;
  for (std::size_t k = 0; k < v.size(); ++k)
    out += (k == 0 ? "" : k + 1 == v.size() ? " or " : ", ") + v[k];
  return out;
}
const std::vector<std::string> kFaces = {"-x", "+x", "-y", "+y", "-z", "+z"};

template <class T>
RCP<Teuchos::EnhancedNumberValidator<T>> at_least(T lo) {
  return rcp(new Teuchos::EnhancedNumberValidator<T>(lo, std::numeric_limits<T>::max()));
}
RCP<Teuchos::EnhancedNumberValidator<double>> positive() {
  return at_least(std::numeric_limits<double>::min());
}
RCP<Teuchos::StringValidator> one_of(const std::vector<std::string>& v) {
  return rcp(new Teuchos::StringValidator(Array<std::string>(v.begin(), v.end())));
}

void region_template(ParameterList& r) {
  r.set("Min", Array<double>(), "Lower corner of the box [m] (Dim values, closed).");
  r.set("Max", Array<double>(), "Upper corner of the box [m] (Dim values, closed).");
}
void crack_template(ParameterList& c) {
  c.set("Start", Array<double>(), "2D: first end of the crack segment [m].");
  c.set(
      "End", Array<double>(),
      "2D: second end of the crack segment [m]: the tip, from which crack_length measures growth.");
  c.set("Corner", Array<double>(), "3D: a corner of the crack rectangle [m].");
  c.set("Edge 1", Array<double>(),
        "3D: first edge vector of the rectangle from Corner [m]: the direction of growth for "
        "crack_length (the tip is the far edge).");
  c.set("Edge 2", Array<double>(),
        "3D: second edge vector of the rectangle from Corner [m], orthogonal to Edge 1.");
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
  c.set("Type", std::string("Displacement"),
        "Displacement [m], Velocity [m/s] or Micro-Rotation [rad] prescribed on the region's "
        "points (the boundary-layer method: use a boundary layer region), or Traction [Pa] "
        "applied as a body force traction/dx on the region's points (make it the outermost real "
        "row of the face), or Body Force [N/m^3], or Body Couple [N m/m^3] (Component: the "
        "rotation axis). Fluid (Solver->Physics = Pore Fluid or Hydro-Mechanical): Pore "
        "Pressure [Pa] prescribed on the region's points (a drained boundary; boundaries "
        "without one are impervious), or Fluid Source: water injected at Value [m^3/s; in 2D "
        "m^3/s per metre of thickness] spread over the region's points by volume (a point "
        "source: a region holding one point; a line: a one-row region; negative: extraction), "
        "or Fluid Flux: water flowing into the body through a face at Value [m/s] (negative: "
        "out), on a boundary layer region (e.g. 'Layer -y'): its points outside one face take "
        "the pressure that continues the body's with the gradient of that flux (README, "
        "'Boundary layers'). "
        "Fracture (Fracture->Fracture Flow = true): Fracture Pressure [Pa] prescribed on the "
        "region's fracture points, or Fracture Source: water injected into the region's "
        "fracture points at Value [m^3/s; in 2D per metre of thickness] (e.g. at a crack's "
        "mouth; an error if the region has no fracture point). "
        "Component is ignored by the fluid conditions.",
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

// The user-named sublists: validated against their template one by one, not by Teuchos'
// recursion.
const std::vector<std::pair<std::string, void (*)(ParameterList&)>> kNamedSublists = {
    {"Regions", region_template}, {"Pre-Cracks", crack_template}};

}  // namespace

const std::vector<std::string>& output_field_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& s : Points<3>::specs())
      if (s.has(kOutput))
        n.push_back(s.name);
    return n;
  }();
  return names;
}

RCP<ParameterList> valid_parameters() {
  auto pl = rcp(new ParameterList("mupm"));
  {
    ParameterList& d = pl->sublist("Discretization", false,
                                   "The point grid: a box of cell-centred points of spacing "
                                   "Spacing, boundary layers, pre-cracks and named regions.");
    d.set("Dimension", 2, "2 (plane strain, or plane stress: Plane) or 3.",
          rcp(new Teuchos::EnhancedNumberValidator<int>(2, 3)));
    d.set("Spacing", 1.0, "Point spacing dx [m] (required, > 0).", positive());
    d.set("Counts", Array<int>(),
          "Number of points of the real body along each axis (Dim values >= 1). Give Counts "
          "or Extents.",
          rcp(new Teuchos::ArrayNumberValidator<int>(at_least(1))));
    d.set("Extents", Array<double>(),
          "Size of the real body along each axis [m] (Dim values, each a whole multiple of "
          "Spacing). Give Counts or Extents.");
    d.set("Origin", Array<double>(), "Lower corner of the real body [m] (Dim values; default 0).");
    d.set("Horizon Factor", 3.015,
          "Horizon delta as a multiple of Spacing (used unless Horizon is given).", positive());
    d.set("Horizon", 0.0, "Horizon delta [m]; 0: use Horizon Factor. Give one of the two.",
          at_least(0.0));
    d.set("Thickness", 1.0,
          "Out-of-plane thickness h [m] (2D only): point volumes dx^2 h, so the CSV's energies, "
          "reactions and water masses are those of the thickness h; J is per unit thickness; "
          "Fluid Source and Fracture Source values are per metre of thickness.",
          positive());
    d.set("Plane", std::string("Strain"),
          "2D only. Strain: plane strain (eps_zz = 0). Stress: plane stress (sigma_zz = 0: the "
          "law's in-plane lambda becomes 2 lambda mu / (lambda + 2 mu); derivation in "
          "include/mupm/laws/micropolar_elastic.hpp; with pore water the total sigma_zz = 0: the "
          "pressure's in-plane coefficient becomes 2 mu / (lambda + 2 mu) and the storage gains "
          "1 / (lambda + 2 mu); Drucker-Prager returns to sigma_zz = 0, derivation in "
          "include/mupm/laws/micropolar_drucker_prager.hpp), for Solver->Physics = Micropolar "
          "Solid or Hydro-Mechanical (with Fracture->Fracture Flow the crack water pushes the "
          "faces in the plane, include/mupm/solvers/fracture_flow.hpp; Drucker-Prager with pore "
          "water returns to sigma'_zz = S_r p and gives the water its plastic thickness change; "
          "with Pressure Integration = Semi-Implicit a step late, "
          "include/mupm/solvers/fluid_solver.hpp, lagged_plastic_source).",
          plane_options().validator());
    d.set("Boundary Layer Horizons", 2.0,
          "Thickness of each boundary layer in horizons: floor(value * delta / dx) rows. 2 (the "
          "default) gives the layer points next to the body full families too, which the "
          "correspondence model needs for exact boundary values; the paper's layers are 1. With "
          "Boundary Layers: at least dx / delta (one row), and at most the larger of the body "
          "along the layer's axis and 2 horizons.",
          positive());
    d.set("Boundary Layers", Array<std::string>(),
          "Faces of the body that get a boundary layer of fictitious points outside them (the "
          "paper's boundary-layer method), any of -x +x -y +y -z +z. "
          "Each layer is also a region named 'Layer -y' etc.",
          rcp(new Teuchos::ArrayStringValidator(one_of(kFaces))));
    d.set("Boundary Layer Values", std::string("Constant"),
          "How Pore Pressure and Fracture Pressure conditions set their boundary-layer points, "
          "unless a condition's "
          "own Boundary Layer Values says otherwise. Constant: the prescribed value g (the "
          "paper's method; the face then drains as if it sat about 0.7 delta farther out). "
          "Mirrored: a layer point at distance d outside the face takes 2 g - p(m), p(m) the "
          "pressure of the point m at distance d inside, every fluid substep (the face: the one "
          "the condition's region lies outside of; a Fracture Pressure's points take 2 g - "
          "p_f(m) of the step's start where m is a fracture point no condition holds, else g). "
          "Kinematic conditions stay Constant unless "
          "their own Boundary Layer Values says Mirrored. See "
          "README, 'Boundary layers'.",
          one_of({"Constant", "Mirrored"}));
    ParameterList& r = d.sublist("Regions", false,
                                 "Named boxes for boundary and initial conditions and outputs: "
                                 "one sublist per region, named as you like (at most 24).");
    region_template(r.sublist("NAME"));
    ParameterList& c = d.sublist("Pre-Cracks", false,
                                 "Initial cracks, one sublist each: a segment (Start, End) in 2D, "
                                 "a rectangle (Corner, Edge 1, Edge 2) in 3D. Bonds crossing a "
                                 "crack start broken; points closer than Spacing to it start as "
                                 "fracture points.");
    crack_template(c.sublist("NAME"));
  }
  {
    ParameterList& m =
        pl->sublist("Materials", false, "The solid (Solver->Physics = Micropolar Solid).");
    m.set("Model", std::string("Micropolar Elastic"),
          "Constitutive model: Micropolar Elastic (eqs 80-81), or Micropolar Drucker-Prager "
          "(eqs 82-95: the elastic law plus the Drucker-Prager yield surface and plastic "
          "potential as the paper writes them, non-associative flow, linear softening of the "
          "cohesion down to a residual one; plane strain in 2D).",
          constitutive_model_options().validator());
    m.set("Friction Angle", 30.0,
          "Drucker-Prager friction angle phi [degrees] in [0, 90) (eqs 89-90; Micropolar "
          "Drucker-Prager).",
          rcp(new Teuchos::EnhancedNumberValidator<double>(0.0, 89.999)));
    m.set("Dilation Angle", 0.0,
          "Dilation angle psi [degrees] in [0, 90) of the plastic potential (eqs 88, 91; "
          "Micropolar Drucker-Prager). psi = phi is associative flow.",
          rcp(new Teuchos::EnhancedNumberValidator<double>(0.0, 89.999)));
    m.set("Cohesion", 0.0, "Initial cohesion c_0 [Pa] (eq 92; Micropolar Drucker-Prager: > 0).",
          at_least(0.0));
    m.set("Residual Cohesion", 0.0,
          "Residual cohesion c_r [Pa]: softening stops at c = c_r (Micropolar Drucker-Prager; "
          "<= Cohesion).",
          at_least(0.0));
    m.set("Softening Modulus", 0.0,
          "h [Pa] of c = c_0 + h eps-hat^p (eq 92; Micropolar Drucker-Prager): negative softens, "
          "positive hardens. eps-hat^p is eq 95 with its curvature term weighted by l^2 "
          "(2/3 l^2 dkappa^p : dkappa^p), which makes it the work conjugate of q.");
    m.set("Bulk Modulus", 0.0, "Drained bulk modulus K [Pa] (> 0 for a solid).", at_least(0.0));
    m.set("Shear Modulus", 0.0, "Shear modulus mu [Pa] (> 0 for a solid).", at_least(0.0));
    m.set("Micropolar Shear Modulus", 0.0, "Cosserat coupling modulus mu_c [Pa] (eq 80).",
          at_least(0.0));
    m.set("Length Scale", 0.0,
          "Micropolar length scale l [m] (> 0 for a solid): couple-stress modulus mu l^2/2 "
          "(eq 81) and micro-inertia (pi/2)(1 - phi) rho_s l^2 (eq 13).",
          at_least(0.0));
    m.set("Solid Density", 2000.0, "Density of the solid grains rho_s [kg/m^3].", positive());
    m.set("Porosity", 0.0, "Initial porosity phi (0 <= phi < 1); Initial Conditions may override.",
          rcp(new Teuchos::EnhancedNumberValidator<double>(0.0, 0.999999)));
    m.set("Stabilization", 0.5, "Stabilization parameter G in [0, 1] (eqs 66-67).",
          rcp(new Teuchos::EnhancedNumberValidator<double>(0.0, 1.0)));
    m.set(
        "Stabilization Modulus", std::string("Automatic"),
        "D of eqs 69-71. Eq 71: the paper's 3D D = E(1-4nu)/(4 pi delta^2 (1-nu-2nu^2)), "
        "negative for nu > 1/4, then an error. Bulk Matching: D = 3K/(8 pi delta^2) in 3D, "
        "(lambda+mu)/(6 pi h delta) in 2D (stabilization energy of a uniform expansion equal "
        "to the elastic one; derivation in include/mupm/kernels/solid.hpp). Automatic: Eq 71 in 3D "
        "where it is positive, Bulk Matching otherwise and always in 2D.",
        stabilization_modulus_options().validator());
  }
  {
    ParameterList& f = pl->sublist(
        "Fluid", false,
        "Pore water (Solver->Physics = Pore Fluid or Hydro-Mechanical; Water Density always).");
    f.set("Water Density", 1000.0, "rho_w [kg/m^3], in the mixture density (eq 1).", positive());
    f.set("Fluid Bulk Modulus", 2.2e9,
          "K_w [Pa]: storage C = phi dS_r/dp + phi S_r / K_w. Saturated points store water by "
          "its compressibility alone; the explicit scheme cannot take K_w -> infinity "
          "(incompressible water), and its stable steps shrink as K_w grows (the solid's by "
          "the undrained modulus K + K_w/phi, the fluid's with C); Solver->Pressure "
          "Integration = Semi-Implicit takes any K_w at the drained skeleton's step.",
          positive());
    f.set("Incompressible", false,
          "Incompressible pore water (K_w = infinity, the paper's assumption; Fluid Bulk Modulus "
          "is then not used). Needs Solver->Pressure Integration = Semi-Implicit.");
    f.set("Intrinsic Permeability", 0.0,
          "k [m^2] (with Viscosity). Give either this or Hydraulic Conductivity, not both.",
          at_least(0.0));
    f.set("Viscosity", 1e-3,
          "Dynamic viscosity of water mu_w [Pa s] (with Intrinsic Permeability).", positive());
    f.set("Hydraulic Conductivity", 0.0,
          "K_h [m/s], the paper's 'hydraulic conductivity k_w': converted by k/mu_w = K_h / "
          "(rho_w g_0), g_0 = 9.80665 m/s^2 (whatever Solver->Gravity is). Give either this "
          "or Intrinsic Permeability, not both.",
          at_least(0.0));
    f.set("Retention Model", std::string("Saturated"),
          "Saturated: S_r = 1, k_r = 1 at any pressure. Van Genuchten: S_r = [1 + (-p/s_a)^n]^-m "
          "for p < 0 (eq 12), Mualem k_r = S_r^1/2 [1 - (1 - S_r^(1/m))^m]^2 (eq 56).",
          retention_model_options().validator());
    f.set("Air Entry Pressure", 1e4, "s_a [Pa] of eq 12 (Van Genuchten).", positive());
    f.set("Van Genuchten n", 2.0, "n of eq 12 (> 1).", positive());
    f.set("Van Genuchten m", 0.0, "m of eqs 12 and 56 in (0, 1); 0: Mualem's m = 1 - 1/n.",
          rcp(new Teuchos::EnhancedNumberValidator<double>(0.0, 0.999999)));
    f.set("Flow Stabilization", 0.5,
          "G in [0, 1] of the flow stabilization (eqs 72-78): bond-wise diffusion of the "
          "non-uniform part of p that damps checkerboard pressure modes; G = 1 gives bond "
          "conductances equal to the uniform-weight bond-based model's (derivation in "
          "include/mupm/kernels/fluid.hpp).",
          rcp(new Teuchos::EnhancedNumberValidator<double>(0.0, 1.0)));
    f.set("Gravity In Darcy Flux", true,
          "Darcy's law with gravity, q = -(k_r k / mu_w)(grad p - rho_w g) with g = "
          "Solver->Gravity (eq 54); false: q = -(k_r k / mu_w) grad p.");
  }
  {
    ParameterList& f = pl->sublist("Fracture", false,
                                   "Bond breakage (Solver->Physics = Micropolar Solid or "
                                   "Hydro-Mechanical), damage and fracture points.");
    f.set("Bond Breakage", std::string("None"),
          "None: bonds never break (pre-cracks stay as they are). Energy: a bond breaks once "
          "its energy W (eq 34, accumulated from the force and moment states over the run) "
          "reaches W_cr = 4 G_cr/(pi delta^4) in 3D (eq 36), 3 G_cr/(2 h delta^3) in 2D "
          "(derivation in include/mupm/kernels/fracture.hpp); the energy it holds is booked "
          "as fracture dissipation. J-Integral (2D, Algorithm 3): the first pre-crack advances "
          "by J-Integral->Crack Increment along its direction, at most once a step, whenever J/h "
          "of the first J-Integral contour >= G_cr: the bonds across the increment break.",
          bond_breaking_options().validator());
    f.set("Critical Energy Release Rate", 0.0,
          "G_cr [J/m^2 = N/m] of the Energy and J-Integral criteria (> 0 with them).",
          at_least(0.0));
    f.set("Critical Damage", 0.3,
          "D_cr in (0, 1]: a point with damage D >= D_cr (eq 37) is a fracture point (eq 104; "
          "the paper gives no value). Points next to a pre-crack are fracture points from the "
          "start.",
          rcp(new Teuchos::EnhancedNumberValidator<double>(1e-6, 1.0)));
    f.set("Bond Energy Force State", std::string("Effective"),
          "Force state whose work is the bond energy W (eq 34). Effective: the skeleton's, "
          "sigma-bar K^-1 xi plus stabilization, as the paper's text says (Terzaghi: the "
          "effective stress breaks the skeleton). Total: with the pore-water part "
          "-S_r p K^-1 xi, as eq 34 is printed. The same without a fluid.",
          bond_energy_state_options().validator());
    f.set("Fracture Flow", false,
          "true: water in the cracks (Solver->Physics = Hydro-Mechanical). The fracture "
          "points carry a fracture pressure p_f that flows along the crack by the cubic law "
          "a^3/(12 mu_w) (mu_w = Fluid->Viscosity), exchanges water with the pores (eq 19) and "
          "pushes the crack's faces apart; solved implicitly every fluid step (Semi-Implicit: in "
          "the pore pressure's solve). Conditions: "
          "Fracture Pressure, Fracture Source. Derivations in "
          "include/mupm/kernels/fracture_flow.hpp.");
    f.set("Crack Water Force", std::string("Face Pressure"),
          "How the crack's water pressure p_f acts on the solid (Fracture Flow). Face "
          "Pressure: p_f pushes the crack's faces apart (central pair forces on the broken "
          "bonds, p_f per unit face area), with the undrained p_f* of the opening the solid is "
          "at (Explicit; Semi-Implicit: the p_f of the joint solve). Eq 17 (Explicit only): as the "
          "paper prints it, bonds between two fracture points carry -S_rf p_f "
          "K^-1 xi in place of -S_r p K^-1 xi; those bonds run along the faces, so p_f barely "
          "acts across the crack (and p_f is that of the last fluid step); its force does work "
          "the crack water does not supply, and with injection it blows up at any time step "
          "(inputs/README.md, Example 1). Derivations and why "
          "in include/mupm/kernels/fracture_flow.hpp.",
          crack_water_force_options().validator());
    f.set("Minimum Aperture", 1e-6,
          "a_min [m]: a film of water in the crack (the paper gives none). The conductance "
          "takes max(a, a_min); the storage the crack's volume a + a_min, whose opening stores "
          "water. Explicit: the crack water's stiffness K_w / a_min enters the solid's stable "
          "step, a small a_min (with a stiff water) means a small step (not Semi-Implicit). With "
          "Fracture Flow, below Spacing "
          "(the film fits in a "
          "crack point's cell).",
          positive());
  }
  {
    ParameterList& j = pl->sublist(
        "J-Integral", false,
        "The micropolar J-integral (eqs 30, 125-126) around the tip of the first pre-crack, on "
        "rectangular contours centred on the tip (2D). Time-series columns j_integral, "
        "j_translational, j_rotational (first contour) and j_integral_<k> (contour k >= 2), per "
        "unit thickness [J/m^2 = Pa m]. The tip: with Fracture->Bond Breakage = J-Integral the "
        "pre-crack's End advanced by the crack's increments, otherwise the tracked tip "
        "(crack_tip_x/y). Derivation and discretization in include/mupm/kernels/j_integral.hpp.");
    j.set("Half Widths", Array<double>(),
          "Half width along x of each contour (at most 8; empty: no J-integral), in Units. The "
          "contour's edges are moved to the nearest cell faces.");
    j.set("Half Heights", Array<double>(),
          "Half height along y of each contour, in Units (empty: the Half Widths).");
    j.set("Units", std::string("Spacings"),
          "Units of Half Widths and Half Heights: Spacings (multiples of "
          "Discretization->Spacing) or Metres.",
          contour_units_options().validator());
    j.set("Crack Increment", 0.0,
          "Delta a [m] by which the J criterion (Fracture->Bond Breakage = J-Integral) advances "
          "the crack each time J/h >= Critical Energy Release Rate (0: one Spacing; at most the "
          "smallest contour half size).",
          at_least(0.0));
    j.set("Speed Cap", true,
          "J criterion: after an advance the next waits Delta a / c_R, c_R = c_s (0.862 + "
          "1.14 nu)/(1 + nu) the skeleton's Rayleigh wave speed at the initial density (a "
          "running mode I crack's limit). false: an advance whenever J/h >= G_cr, at most one a "
          "step (the paper's Algorithm 3), which lets the crack run at Delta a / dt while the "
          "contours still show the field of before the last increment.");
  }
  {
    ParameterList& b =
        pl->sublist("Boundary Conditions", false, "One sublist per condition, named as you like.");
    bc_template(b.sublist("NAME"));
  }

  {
    ParameterList& ic = pl->sublist("Initial Conditions", false,
                                    "Initial fields, one sublist per condition, named as you "
                                    "like, applied in the order given.");
    ic_template(ic.sublist("NAME"));
  }
  {
    ParameterList& s = pl->sublist("Solver", false, "Time stepping.");
    s.set("Physics", std::string("Micropolar Solid"),
          "Physics advanced each step. Micropolar Solid: the stabilized micropolar "
          "correspondence solid (Materials), explicit central difference. Kinematics Only: no "
          "internal forces (points move with their velocity); damage from intact bonds (eq 37) "
          "either way. Pore Fluid: unsaturated flow in a rigid skeleton (Fluid), explicit in "
          "p. Hydro-Mechanical: both, staggered (Staggering), coupled by the total stress "
          "sigma-bar - S_r p 1 (eq 46), the mixture density (eq 1) and the volume change rate "
          "(eq 117).",
          physics_options().validator());
    s.set("Staggering", std::string("Solid First"),
          "Order of the staggered step (Hydro-Mechanical). Solid First: the solid steps with "
          "the pressure held, then the fluid with the volume change they made. Fluid First: the "
          "fluid steps with the previous interval's volume change, then the solid with the new "
          "pressure (fluid-driven problems). Both agree as Time Step -> 0.",
          staggering_options().validator());
    s.set("Solid Steps Per Fluid Step", 1,
          "Hydro-Mechanical: the fluid advances once every this many solid steps, over their "
          "combined interval (a larger fluid step when flow is slow).",
          at_least(1));
    s.set("Fluid Substeps", 1,
          "Equal fluid steps per fluid interval (sub-cycling when flow is faster than the "
          "solid); 0: as many as Time Step Safety Factor x the estimated stable fluid step "
          "requires. With Physics = Pore Fluid the interval is Time Step (Automatic Time Step "
          "sets it to the safety factor x the stable fluid step). At most 1e6, the automatic "
          "choice's limit too (2147483647 ran for ever).",
          rcp(new Teuchos::EnhancedNumberValidator<int>(0, 1000000)));
    s.set("Pressure Integration", std::string("Explicit"),
          "Hydro-Mechanical: how the pore pressure is advanced. Explicit: forward Euler in p "
          "with the undrained split (the pore water's stiffness K_w/phi in the solid's stable "
          "step, the fluid's own stable step by substeps). Semi-Implicit: one linear solve per "
          "step (Pressure Solve) for the pressure at the step's end, with the volume change it "
          "gives the skeleton within the step (a pressure projection, include/mupm/solvers/"
          "pressure_projection.hpp): the step is the drained skeleton's, any K_w (Fluid->"
          "Incompressible), no fluid substeps; with Fracture Flow the fracture pressure is in the "
          "same solve (no K_w / a_min limit). Refused for now: Crack Water Force = Eq 17, "
          "Fluid Flux, and "
          "Staggering, Solid Steps Per Fluid Step, Fluid Substeps other than Solid First, 1, 1.",
          pressure_integration_options().validator());
    s.set("Pressure Stabilization", 1.0,
          "Semi-Implicit: G_p >= 0 of the projection's pressure stabilization, the flow "
          "stabilization's bond-wise diffusion (eqs 72-78) on the step's pressure increment "
          "with the mobility G_p S_r^2 dt / rho in place of k_r k / mu_w. It holds the pressure "
          "modes the skeleton does not feel (checkerboards) whatever the permeability; "
          "without it incompressible water in a tight soil stalls the solve "
          "(include/mupm/solvers/pressure_projection.hpp).",
          at_least(0.0));
    {
      ParameterList& ps = s.sublist(
          "Pressure Solve", false,
          "The linear solve of Pressure Integration = Semi-Implicit (Trilinos: Belos' CG, or "
          "GMRES where mirrored pressure layers make the system unsymmetric; Ifpack2), "
          "distributed over the ranks like the points.");
      ps.set("Preconditioner", std::string("ILU"),
             "Ifpack2's preconditioner: ILU (RILUK on each rank's rows; a solve that fails with "
             "it, e.g. at a zero pivot, is repeated with the ILU of the current values if it was "
             "kept from earlier ones, then with Jacobi for that matrix), Jacobi or None.",
             one_of({"ILU", "Jacobi", "None"}));
      ps.set("ILU Fill Level", 0, "Level of fill k of ILU(k).", at_least(0));
      ps.set("Drop Tolerance", 0.02,
             "ILU: the factors are of the matrix without its entries |a_ij| < this x "
             "sqrt(|a_ii a_jj|), each added to the diagonal (the preconditioner stays symmetric "
             "positive definite; the solve is still of the whole matrix). The projection's "
             "matrix is two horizons wide with small far entries: 0.02 keeps about a quarter "
             "of them (an apply 3.6 times cheaper, 40 % more iterations, measured on Example 1 "
             "case 1). 0: the whole matrix.",
             rcp(new Teuchos::EnhancedNumberValidator<double>(0.0, 1.0)));
      ps.set("Preconditioner Refresh Interval", 20,
             "When the matrix's values change (every step with a fracture network or "
             "unsaturated water, at each step that breaks bonds) the preconditioner is computed "
             "again on every this-many-th change and at the step after a checkpoint (so that a "
             "restart continues bit for bit), and kept in between; the solve still reaches "
             "Tolerance on the current matrix, only its iterations depend on it. 1: every "
             "change. A new matrix graph (points joining the network) always computes it.",
             at_least(1));
      ps.set("Tolerance", 1e-11,
             "Residual ||b - A x|| at which the solve stops, relative to the largest right-hand "
             "side ||b|| of the run so far (the water balances of a step): every point's water "
             "balance holds to it (the CSV's fluid_mass_error accumulates it).",
             rcp(new Teuchos::EnhancedNumberValidator<double>(1e-15, 1e-2)));
      ps.set("Maximum Iterations", 1000, "A solve not converged by then stops the run (exit 3).",
             at_least(1));
      ps.set("Recycled Vectors", 0,
             "> 0: CG becomes Belos' recycling CG (RCG): approximate eigenvectors of the "
             "smallest eigenvalues, this many, gathered over the steps and deflated from every "
             "later solve, for this many extra products and preconditioner applies per step. "
             "Pays where a solve takes many iterations (Example 1 case 1 at 100 x 100: 54 "
             "preconditioner applies a step become 28, the solve 1.3 times faster with 10, "
             "perf/README.md). The "
             "space is dropped at each checkpoint, so a restart continues bit for bit. Not "
             "used with GMRES (mirrored pressure layers). 0: CG.",
             at_least(0));
    }
    s.set("Time Step", 1e-6, "Time step dt [s] (> 0).", positive());
    s.set("Automatic Time Step", false,
          "Use Time Step Safety Factor x the estimated stable step instead of Time Step.");
    s.set("Time Step Safety Factor", 0.5,
          "Fraction of the estimated stable step (power iteration on the discrete operator) used "
          "by Automatic Time Step, and the limit above which Time Step draws a warning.",
          rcp(new Teuchos::EnhancedNumberValidator<double>(1e-6, 1.0)));
    s.set("Gravity", Array<double>(),
          "Gravitational acceleration [m/s^2] (Dim values; default 0).");
    s.set("Damping", 0.0,
          "Mass-proportional damping c [1/s] (a = f/rho - c v), for quasi-static runs by dynamic "
          "relaxation; 0: none.",
          at_least(0.0));
    s.set("Energy Tolerance", 1e-2,
          "Largest accepted |E_int + E_kin - dt^2/8 sum m|a|^2 + D - W_ext - W_pore - E_0| "
          "(solid, eqs 137-140, with the central difference's kinetic energy) and "
          "|E_s - E_s0 + W_c + D_f - W_ext,f| (fluid, eqs 147-149) relative to the largest of "
          "their terms; beyond it a warning with the step.",
          at_least(0.0));
    s.set("Stop On Energy Violation", false, "Stop the run when the energy balance is violated.");
    s.set("Energy Check Start", 20,
          "Steps after the start (or a restart) before the energy balances are checked: in the "
          "first steps from rest every term is tiny and the scheme's start-up error (forward "
          "Euler weighs the first fluid step with p = 0; the first solid steps of a ramped load) "
          "is of the same size as the terms.",
          at_least(0));
    s.set("Number of Steps", 100,
          "Number of time steps (>= 0): the last step number (a restart continues up to it). "
          "Not used when End Time > 0.",
          at_least(0));
    s.set("End Time", 0.0,
          "Simulated time to run to [s]; > 0: the run ends on the first step whose time reaches "
          "it (within 1e-6 dt), ceil(End Time / dt) steps with the dt in use (Automatic Time "
          "Step's estimate, or Time Step; a restart may take another), and Number of Steps is "
          "not used; 0: run Number of Steps. More than 1e12 steps is refused.",
          at_least(0.0));
    s.set("Restart From", std::string(""),
          "Checkpoint file (.h5) to continue from; empty: start at t = 0. The run may use a "
          "different number of ranks and threads than the one that wrote it.");
  }
  {
    ParameterList& o = pl->sublist("Output", false, "Files written to Output->Folder.");
    o.set("Folder", std::string("output"), "Output folder (created if missing).");
    o.set("Field Interval", 10,
          "Steps between point-field outputs (HDF5 + XDMF); 0: first and last step only.",
          at_least(0));
    o.set("Fields", Array<std::string>({"displacement", "velocity", "damage", "fracture"}),
          "Point fields written at each field output. Any of: " + joined(output_field_names()) +
              ". Global id and reference position are always written.",
          rcp(new Teuchos::ArrayStringValidator(one_of(output_field_names()))));
    o.set("Time Series Interval", 1, "Steps between rows of time_series.csv (>= 1).", at_least(1));
    o.set("Second-Order Work Window", 0,
          "Steps over which the second-order work (eq 42; field second_order_work, CSV "
          "negative_second_order_work_fraction) takes its changes; 0: Field Interval. "
          "Computed with Materials->Model = Micropolar Drucker-Prager or when Fields lists "
          "second_order_work.",
          at_least(0));
    o.set("Checkpoint Interval", 0, "Steps between checkpoints; 0: none during the run.",
          at_least(0));
    o.set("Checkpoint At End", true, "Write a checkpoint after the last step.");
    o.set("Progress Interval", 5.0,
          "Wall-clock seconds between progress lines (step, time, ETA); 0: every step.",
          at_least(0.0));
  }
  {
    ParameterList& g = pl->sublist("Diagnostics", false, "Checks and reports.");
    g.set("Kernel Timers", true,
          "Print the per-kernel time table (min/max over ranks) at the end of the run.");
    g.set("Check Finite", true,
          "Stop the run when a field holds NaN or Inf, naming the step, global id and position.");
  }
  return pl;
}

namespace {

std::string path_of(const ParameterList& list, const std::string& name) {
  return list.name() + "->" + name;
}

// Teuchos' messages name the (sub)list and the entry and list what is valid; keep them, and
// drop the preamble and the "Throw number" trailer.
std::string clean_teuchos(const std::exception& e) {
  std::string msg = e.what();
  const auto pos = msg.find("Error");
  if (pos != std::string::npos && pos > 0)
    msg = msg.substr(pos);
  const auto tr = msg.find("Throw number");
  if (tr != std::string::npos)
    msg = msg.substr(0, tr);
  while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' '))
    msg.pop_back();
  return msg;
}

// The XML reader names the root "ANONYMOUS"; give every list its full path from "mupm".
void name_lists(ParameterList& list, const std::string& path) {
  list.setName(path);
  for (auto it = list.begin(); it != list.end(); ++it)
    if (list.entry(it).isList())
      name_lists(list.sublist(list.name(it)), path + "->" + list.name(it));
}

void validate_level(ParameterList& list, const ParameterList& valid) {
  // Sublists whose children are user-named are checked entry by entry against "NAME".
  for (auto it = list.begin(); it != list.end(); ++it) {
    const std::string& name = list.name(it);
    const auto* ventry = valid.getEntryPtr(name);
    if (ventry && ventry->isList() && list.entry(it).isList() &&
        Teuchos::getValue<ParameterList>(*ventry).isSublist("NAME")) {
      ParameterList& user = list.sublist(name);
      const ParameterList& tmpl = Teuchos::getValue<ParameterList>(*ventry).sublist("NAME");
      for (auto jt = user.begin(); jt != user.end(); ++jt) {
        const std::string& child = user.name(jt);
        if (!user.entry(jt).isList())
          throw InputError("Error, " + path_of(user, child) +
                           " is a parameter, but here every entry must be a sublist (one per "
                           "named item) with the parameters: " +
                           tmpl.currentParametersString());
        validate_level(user.sublist(child), tmpl);
      }
    }
  }
  // This level: names, types and ranges (Teuchos), then defaults; recursion into the fixed
  // sublists below.
  ParameterList shallow(valid.name());
  for (auto it = valid.begin(); it != valid.end(); ++it) {
    const std::string& name = valid.name(it);
    if (valid.entry(it).isList()) {
      ParameterList& s = shallow.sublist(name);
      if (Teuchos::getValue<ParameterList>(valid.entry(it)).isSublist("NAME"))
        s.disableRecursiveValidation();
    } else {
      shallow.setEntry(name, valid.entry(it));
    }
  }
  // Validators' own messages do not say where the entry is: add its full path.
  for (auto it = list.begin(); it != list.end(); ++it) {
    const auto* ventry = valid.getEntryPtr(list.name(it));
    if (!ventry || ventry->isList() || list.entry(it).isList())
      continue;
    const auto& any = list.entry(it).getAny(false);
    if (any.type() != ventry->getAny(false).type())
      throw InputError("Error, " + path_of(list, list.name(it)) + " has type \"" + any.typeName() +
                       "\" (value \"" + Teuchos::toString(any) + "\"); the expected type is \"" +
                       ventry->getAny(false).typeName() + "\": " + ventry->docString());
    if (ventry->validator().is_null())
      continue;
    try {
      ventry->validator()->validate(list.entry(it), list.name(it), list.name());
    } catch (const std::exception& e) {
      throw InputError("Error, " + path_of(list, list.name(it)) + " = " +
                       Teuchos::toString(list.entry(it).getAny(false)) +
                       " is not valid. Expected: " + ventry->docString() + "\n" + clean_teuchos(e));
    }
  }
  try {
    list.validateParameters(shallow, 0);
  } catch (const std::exception& e) {
    throw InputError(clean_teuchos(e));
  }
  for (auto it = valid.begin(); it != valid.end(); ++it) {
    const std::string& name = valid.name(it);
    if (!valid.entry(it).isList()) {
      // A filled-in default is marked as such (isDefault), without the validator, so the
      // resolved list written back is plain values.
      if (!list.isParameter(name)) {
        Teuchos::ParameterEntry e;
        e.setAnyValue(valid.entry(it).getAny(false), true);
        e.setDocString(valid.entry(it).docString());
        list.setEntry(name, e);
      }
      continue;
    }
    ParameterList& sub = list.sublist(name);
    const ParameterList& vsub = Teuchos::getValue<ParameterList>(valid.entry(it));
    if (vsub.isSublist("NAME"))
      continue;  // children checked above
    validate_level(sub, vsub);
  }
}

template <class T>
Array<T> get_array(const ParameterList& l, const std::string& name, std::size_t n,
                   const std::string& what) {
  Array<T> a = l.get<Array<T>>(name);
  if (static_cast<std::size_t>(a.size()) != n) {
    std::ostringstream s;
    s << "Error, " << path_of(l, name) << " must hold " << n << " values (" << what << "), not "
      << a.size() << ".";
    throw InputError(s.str());
  }
  return a;
}

// J-Integral: 2D, a solid, a pre-crack, matching contour sizes that fit the body at the start.
void check_j_integral(ParameterList& input, int dim, Physics phys) {
  ParameterList& j = input.sublist("J-Integral");
  const ParameterList& fr = input.sublist("Fracture");
  const bool criterion =
      bond_breaking_options()(fr.get<std::string>("Bond Breakage")) == BondBreaking::JIntegral;
  const auto w = j.get<Array<double>>("Half Widths");
  auto h = j.get<Array<double>>("Half Heights");
  if (w.empty() && !h.empty())
    throw InputError("Error, " + path_of(j, "Half Heights") + " is given without " +
                     path_of(j, "Half Widths") + ".");
  if (w.empty()) {
    if (criterion)
      throw InputError("Error, " + path_of(fr, "Bond Breakage") + " = J-Integral needs " +
                       path_of(j, "Half Widths") + ": at least one contour around the tip.");
    return;
  }
  const std::string what = path_of(j, "Half Widths");
  if (dim != 2)
    throw InputError("Error, " + what + ": the J-integral is 2D (Discretization->Dimension = 2).");
  if (!has_solid(phys))
    throw InputError("Error, " + what +
                     ": the J-integral needs Solver->Physics = Micropolar Solid or "
                     "Hydro-Mechanical.");
  const ParameterList& d = input.sublist("Discretization");
  if (d.sublist("Pre-Cracks").numParams() == 0)
    throw InputError("Error, " + what +
                     ": the J-integral's contours surround the tip of the first "
                     "Discretization->Pre-Cracks entry; there is none.");
  if (w.size() > kMaxContours)
    throw InputError("Error, " + what + " lists " + std::to_string(w.size()) +
                     " contours; at most " + std::to_string(kMaxContours) + " are supported.");
  if (!h.empty() && h.size() != w.size())
    throw InputError("Error, " + path_of(j, "Half Heights") + " has " + std::to_string(h.size()) +
                     " values and " + what + " " + std::to_string(w.size()) +
                     ": give one per contour, or none.");
  if (h.empty())
    h = w;
  const double dx = d.get<double>("Spacing");
  const double unit =
      contour_units_options()(j.get<std::string>("Units")) == ContourUnits::Metres ? 1.0 : dx;
  for (Teuchos::Ordinal k = 0; k < w.size(); ++k)
    for (double v : {w[k], h[k]})
      if (!(v * unit >= dx))
        throw InputError("Error, " + what + " / Half Heights: contour " + std::to_string(k + 1) +
                         " has a half size of " + std::to_string(v * unit) +
                         " m, below one Spacing (" + std::to_string(dx) +
                         " m): a contour must hold the tip and the points around it.");
  // The contours at the start, centred on the first pre-crack's End, inside the real body (their
  // edges go to the nearest cell faces, at most dx/2 away): a contour beyond it runs through no
  // material, and J came out 0.012 for 0.93 with a half width past the body's faces.
  const ParameterList& cracks = d.sublist("Pre-Cracks");
  const auto tip = cracks.sublist(cracks.name(cracks.begin())).get<Array<double>>("End");
  const auto counts = d.get<Array<int>>("Counts");
  const auto ext = d.get<Array<double>>("Extents");
  const auto origin = d.get<Array<double>>("Origin");
  for (Teuchos::Ordinal k = 0; k < w.size(); ++k)
    for (int a = 0; a < 2; ++a) {
      const double o = origin.empty() ? 0.0 : origin[a];
      const double n = counts.empty() ? std::round(ext[a] / dx) : double(counts[a]);
      const double half = (a == 0 ? w[k] : h[k]) * unit;
      if (tip[a] - half < o - 0.5 * dx || tip[a] + half > o + n * dx + 0.5 * dx) {
        std::ostringstream m;
        m << "Error, " << (a == 0 ? what : path_of(j, "Half Heights")) << ": contour " << k + 1
          << " spans " << (a == 0 ? 'x' : 'y') << " = " << tip[a] - half << " to " << tip[a] + half
          << " m around the first pre-crack's End, beyond the body (" << o << " to " << o + n * dx
          << " m): the contour must run through the material. Give a smaller half size.";
        throw InputError(m.str());
      }
    }
  const double inc = j.get<double>("Crack Increment");
  for (Teuchos::Ordinal k = 0; k < w.size(); ++k)
    if (criterion && std::min(w[k], h[k]) * unit < inc)
      throw InputError("Error, " + path_of(j, "Crack Increment") + " = " + std::to_string(inc) +
                       " m exceeds the half size of contour " + std::to_string(k + 1) + " (" +
                       std::to_string(std::min(w[k], h[k]) * unit) +
                       " m): an increment must stay inside the contours (it is in metres).");
}

void check_region(const ParameterList& c, const ParameterList& regions,
                  const Array<std::string>& faces);

// The horizon delta [m] of Discretization: Horizon, or Horizon Factor times Spacing.
double horizon_of(const ParameterList& d) {
  const double h = d.get<double>("Horizon");
  return h > 0 ? h : d.get<double>("Horizon Factor") * d.get<double>("Spacing");
}
// Rows of a boundary layer `horizons` horizons thick: floor(horizons delta / dx) (grid_from_input).
double layer_rows(const ParameterList& d, double horizons) {
  return std::floor(horizons * horizon_of(d) / d.get<double>("Spacing") * (1 + 1e-10));
}

// Boundary Layer Horizons gives floor(value delta / dx) rows per layer (grid_from_input). A value
// that gives no row leaves the layers and their conditions empty; a layer thicker than both the
// default 2 horizons and the body it bounds is no boundary layer any more (it is a larger body;
// points farther than 2 horizons from the face reach neither a body point's family nor those of
// its neighbours), and a huge value overflows the grid's row counts.
void check_layer_rows(const ParameterList& d, const Array<std::string>& faces) {
  const double dx = d.get<double>("Spacing"), horizon = horizon_of(d);
  const double value = d.get<double>("Boundary Layer Horizons");
  const double rows = layer_rows(d, value);
  if (rows < 1) {
    std::ostringstream s;
    s << "Error, " << path_of(d, "Boundary Layer Horizons") << " = " << value
      << " gives layers of no row (floor(value * delta / dx) = 0 with delta = " << horizon
      << " m, dx = " << dx << " m): the boundary layers " << path_of(d, "Boundary Layers")
      << " asks for and their conditions would be empty. The minimum is dx / delta = "
      << dx / horizon << " (one row); 2 is usual.";
    throw InputError(s.str());
  }
  const auto counts = d.get<Array<int>>("Counts");
  const auto ext = d.get<Array<double>>("Extents");
  const double default_rows = layer_rows(d, 2);
  for (const auto& f : faces) {
    const int k = f[1] - 'x';
    const double body = counts.empty() ? std::round(ext[k] / dx) : double(counts[k]);
    const double most = std::max(default_rows, body);
    if (rows > most) {
      std::ostringstream s;
      s << "Error, " << path_of(d, "Boundary Layer Horizons") << " = " << value
        << " gives layers of " << rows << " rows, thicker than the body along " << f[1] << " ("
        << body << " rows) and than the default 2 horizons (" << default_rows
        << " rows): a boundary layer's points farther than 2 horizons from the face act on no "
           "point of the body. The maximum here is "
        << most * dx / horizon << " (2 is usual).";
      throw InputError(s.str());
    }
  }
}

void check_dimension_arrays(ParameterList& input) {
  ParameterList& d = input.sublist("Discretization");
  const int dim = d.get<int>("Dimension");
  const bool has_counts = !d.get<Array<int>>("Counts").empty();
  const bool has_extents = !d.get<Array<double>>("Extents").empty();
  if (has_counts == has_extents)
    throw InputError("Error, " + d.name() +
                     " needs exactly one of Counts (points per axis) and Extents (body size "
                     "in m), each with " +
                     std::to_string(dim) + " values.");
  if (has_counts)
    get_array<int>(d, "Counts", dim, "points per axis");
  if (has_extents) {
    const auto ext = get_array<double>(d, "Extents", dim, "body size per axis in m");
    const double dx = d.get<double>("Spacing");
    for (double e : ext) {
      const double n = e / dx;
      if (!(n >= 1) || std::abs(n - std::round(n)) > 1e-6 * n)
        throw InputError("Error, " + path_of(d, "Extents") + " = " + std::to_string(e) +
                         " is not a positive whole multiple of Spacing = " + std::to_string(dx) +
                         ".");
    }
  }
  if (!d.get<Array<double>>("Origin").empty())
    get_array<double>(d, "Origin", dim, "m");
  if (d.get<double>("Horizon") > 0 && d.isParameter("Horizon Factor") &&
      !d.getEntry("Horizon Factor").isDefault())
    throw InputError("Error, " + d.name() +
                     " gives both Horizon and Horizon Factor: give one of the two.");
  // Lattice neighbours are one spacing apart: a smaller horizon leaves every point without a
  // bond (and a stable step of 0).
  {
    const double dx = d.get<double>("Spacing"), h = d.get<double>("Horizon");
    const bool given = h > 0;
    const double horizon = horizon_of(d);
    if (horizon < dx * (1 - 1e-9)) {
      std::ostringstream s;
      s << "Error, " << path_of(d, given ? "Horizon" : "Horizon Factor") << " = "
        << (given ? h : d.get<double>("Horizon Factor")) << " gives a horizon of " << horizon
        << " m, below the spacing " << dx
        << " m: no point would have a bond. The horizon must be at least one spacing (3.015 "
           "spacings is usual).";
      throw InputError(s.str());
    }
  }
  const Array<std::string> faces = d.get<Array<std::string>>("Boundary Layers");
  for (const auto& f : faces)
    if (f.size() == 2 && (f[1] - 'x') >= dim)
      throw InputError("Error, " + path_of(d, "Boundary Layers") + " names face " + f +
                       ", which a " + std::to_string(dim) + "D body does not have.");
  if (!faces.empty())
    check_layer_rows(d, faces);
  ParameterList& regions = d.sublist("Regions");
  int n_regions = 0;
  for (auto it = regions.begin(); it != regions.end(); ++it, ++n_regions) {
    ParameterList& r = regions.sublist(regions.name(it));
    const auto lo = get_array<double>(r, "Min", dim, "lower corner in m");
    const auto hi = get_array<double>(r, "Max", dim, "upper corner in m");
    for (int k = 0; k < dim; ++k)
      if (hi[k] < lo[k])
        throw InputError("Error, " + r.name() + ": Max must not be below Min on any axis.");
  }
  if (n_regions + 2 * dim > 32)
    throw InputError("Error, " + regions.name() + " holds " + std::to_string(n_regions) +
                     " regions; at most " + std::to_string(32 - 2 * dim) + " are supported.");
  ParameterList& cracks = d.sublist("Pre-Cracks");
  for (auto it = cracks.begin(); it != cracks.end(); ++it) {
    ParameterList& c = cracks.sublist(cracks.name(it));
    if (dim == 2) {
      const auto a = get_array<double>(c, "Start", 2, "2D crack segment start in m");
      const auto b = get_array<double>(c, "End", 2, "2D crack segment end in m");
      if (a[0] == b[0] && a[1] == b[1])
        throw InputError("Error, " + c.name() +
                         ": Start and End are the same point; a pre-crack needs a length.");
      for (const char* k : {"Corner", "Edge 1", "Edge 2"})
        if (!c.get<Array<double>>(k).empty())
          throw InputError("Error, " + path_of(c, k) + " is for 3D cracks; use Start and End.");
    } else {
      get_array<double>(c, "Corner", 3, "3D crack rectangle corner in m");
      const auto e1 = get_array<double>(c, "Edge 1", 3, "edge vector in m");
      const auto e2 = get_array<double>(c, "Edge 2", 3, "edge vector in m");
      const double dot = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
      const double n1 = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
      const double n2 = std::sqrt(e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]);
      if (n1 == 0 || n2 == 0 || std::abs(dot) > 1e-9 * n1 * n2)
        throw InputError("Error, " + c.name() +
                         ": Edge 1 and Edge 2 must be non-zero and orthogonal.");
      for (const char* k : {"Start", "End"})
        if (!c.get<Array<double>>(k).empty())
          throw InputError("Error, " + path_of(c, k) +
                           " is for 2D cracks; use Corner, Edge 1 and Edge 2.");
    }
  }
  ParameterList& ics = input.sublist("Initial Conditions");
  for (auto it = ics.begin(); it != ics.end(); ++it) {
    ParameterList& c = ics.sublist(ics.name(it));
    const std::string field = c.get<std::string>("Field");
    get_array<double>(c, "Value", std::size_t(ic_components(field, dim)), field);
    check_region(c, regions, faces);
  }
  ParameterList& bcs = input.sublist("Boundary Conditions");
  for (auto it = bcs.begin(); it != bcs.end(); ++it) {
    ParameterList& c = bcs.sublist(bcs.name(it));
    check_region(c, regions, faces);
    const auto type = boundary_condition_options()(c.get<std::string>("Type"));
    const std::string comp = c.get<std::string>("Component");
    const int axis = component_options()(comp);
    const bool rotation =
        type == BoundaryCondition::MicroRotation || type == BoundaryCondition::BodyCouple;
    if (rotation && dim == 2 && axis != 2)
      throw InputError("Error, " + path_of(c, "Component") + " = " + comp +
                       ": in 2D the micro-rotation is about z; write z.");
    if (!rotation && axis >= dim)
      throw InputError("Error, " + path_of(c, "Component") + " = " + comp + ": a " +
                       std::to_string(dim) + "D body has components x" +
                       (dim == 3 ? ", y and z." : " and y."));
    if (type != BoundaryCondition::Traction &&
        c.get<std::string>("Traction Distribution") != "Outer Row")
      throw InputError("Error, " + path_of(c, "Traction Distribution") + " = " +
                       c.get<std::string>("Traction Distribution") +
                       ": only a Traction is distributed; a " + c.get<std::string>("Type") +
                       " condition takes Outer Row (the default).");
    // Fluid Flux sets its layer one way only (the flux's continuation of the body's pressure).
    if (type == BoundaryCondition::FluidFlux &&
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
        type != BoundaryCondition::PorePressure && type != BoundaryCondition::FracturePressure &&
        type != BoundaryCondition::Displacement && type != BoundaryCondition::Velocity &&
        type != BoundaryCondition::MicroRotation)
      throw InputError("Error, " + path_of(c, "Boundary Layer Values") +
                       " = Mirrored: only Pore Pressure, Fracture Pressure, Displacement, Velocity "
                       "and Micro-Rotation conditions mirror their boundary-layer values; " +
                       c.get<std::string>("Type") +
                       " conditions hold the prescribed value (write Constant or Default).");
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
  const ParameterList& solver = input.sublist("Solver");
  if (!solver.get<Array<double>>("Gravity").empty())
    get_array<double>(solver, "Gravity", dim, "m/s^2");
  // With Automatic Time Step the run checks it once dt is known (check_run_end).
  if (!solver.get<bool>("Automatic Time Step")) {
    const std::string why =
        end_time_steps_error(solver.get<double>("End Time"), 0, solver.get<double>("Time Step"),
                             "mupm->Solver->Time Step");
    if (!why.empty())
      throw InputError(why);
  }
  const std::string physics = solver.get<std::string>("Physics");
  const Physics phys = physics_options()(physics);
  const bool fluid = has_fluid(phys);
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
  if (fluid) {
    const ParameterList& f = input.sublist("Fluid");
    const double k = f.get<double>("Intrinsic Permeability"),
                 kh = f.get<double>("Hydraulic Conductivity");
    if ((k > 0) == (kh > 0))
      throw InputError("Error, " + path_of(f, "Intrinsic Permeability") + " [m^2] or " +
                       path_of(f, "Hydraulic Conductivity") + " [m/s]: give exactly one of them " +
                       "> 0 for Solver->Physics = " + physics + " (" +
                       (k > 0 ? "both are set" : "neither is set") + ").");
    if (retention_model_options()(f.get<std::string>("Retention Model")) ==
            RetentionModel::VanGenuchten &&
        !(f.get<double>("Van Genuchten n") > 1))
      throw InputError("Error, " + path_of(f, "Van Genuchten n") + " must be > 1.");
    if (!(input.sublist("Materials").get<double>("Porosity") > 0))
      throw InputError("Error, " + path_of(input.sublist("Materials"), "Porosity") +
                       " must be > 0 for Solver->Physics = " + physics +
                       " (the pores hold the water).");
  }
  const ParameterList& disc = input.sublist("Discretization");
  if (plane_options()(disc.get<std::string>("Plane")) == Plane::Stress) {
    if (dim != 2)
      throw InputError("Error, " + path_of(disc, "Plane") + " = Stress is for Dimension = 2.");
    if (!has_solid(phys))
      throw InputError("Error, " + path_of(disc, "Plane") +
                       " = Stress needs a skeleton (Solver->Physics = " + physics +
                       " has none): use Plane = Strain.");
  }
  if (has_solid(phys)) {
    const ParameterList& m = input.sublist("Materials");
    for (const char* k : {"Bulk Modulus", "Shear Modulus", "Length Scale"})
      if (!(m.get<double>(k) > 0))
        throw InputError("Error, " + path_of(m, k) +
                         " must be > 0 for Solver->Physics = " + physics + ".");
    const auto sm = stabilization_modulus_options()(m.get<std::string>("Stabilization Modulus"));
    const double K = m.get<double>("Bulk Modulus"), mu = m.get<double>("Shear Modulus");
    if (constitutive_model_options()(m.get<std::string>("Model")) ==
        ConstitutiveModel::MicropolarDruckerPrager) {
      const double c0 = m.get<double>("Cohesion"), cr = m.get<double>("Residual Cohesion");
      if (!(c0 > 0))
        throw InputError("Error, " + path_of(m, "Cohesion") +
                         " must be > 0 for Materials->Model = Micropolar Drucker-Prager.");
      if (cr > c0)
        throw InputError("Error, " + path_of(m, "Residual Cohesion") + " = " + std::to_string(cr) +
                         " Pa exceeds " + path_of(m, "Cohesion") + " = " + std::to_string(c0) +
                         " Pa: softening ends at the residual cohesion.");
    }
    if (sm == StabilizationModulus::Eq71 && (dim == 2 || mu - (K - 2 * mu / 3) <= 0))
      throw InputError("Error, " + path_of(m, "Stabilization Modulus") + " = Eq 71 " +
                       (dim == 2 ? std::string("is a 3D formula")
                                 : std::string("gives D <= 0 (Poisson's ratio >= 1/4)")) +
                       ": use Automatic or Bulk Matching.");
  }
  const ParameterList& fr = input.sublist("Fracture");
  // a_min is a film of water in a crack point's cell, whose width is Spacing: its porosity
  // (a + a_min) / (rows dx) reaches 1 at a_min = dx (one row), beyond which the crack would hold
  // more water than its cell; the film's stiffness K_w / a_min in the stable step then is
  // meaningless too (1e308 overflowed to a non-finite aperture, 1e50 ran with nothing moving).
  // Only the crack water uses it.
  if (fr.get<bool>("Fracture Flow")) {
    const double amin = fr.get<double>("Minimum Aperture");
    const double dx = input.sublist("Discretization").get<double>("Spacing");
    if (!(amin < dx)) {
      std::ostringstream s;
      s << "Error, " << path_of(fr, "Minimum Aperture") << " = " << amin
        << " m is not below the point spacing " << dx
        << " m (mupm->Discretization->Spacing): the film of water it stands for must fit in a "
           "crack point's cell (1e-6 m is the default).";
      throw InputError(s.str());
    }
  }
  if (fr.get<bool>("Fracture Flow") && phys != Physics::HydroMechanical)
    throw InputError("Error, " + path_of(fr, "Fracture Flow") +
                     " = true needs Solver->Physics = Hydro-Mechanical (it is " + physics +
                     "): the crack's water lives between the solid's crack faces.");
  if (bond_breaking_options()(fr.get<std::string>("Bond Breakage")) != BondBreaking::None) {
    if (!has_solid(phys))
      throw InputError("Error, " + path_of(fr, "Bond Breakage") + " = " +
                       fr.get<std::string>("Bond Breakage") +
                       " needs Solver->Physics = Micropolar Solid or Hydro-Mechanical (it is " +
                       physics + "): bonds break by the work of the solid's force states.");
    if (!(fr.get<double>("Critical Energy Release Rate") > 0))
      throw InputError("Error, " + path_of(fr, "Critical Energy Release Rate") +
                       " must be > 0 for " + path_of(fr, "Bond Breakage") + " = " +
                       fr.get<std::string>("Bond Breakage") + ".");
  }
  check_j_integral(input, dim, phys);
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

// Teuchos reads numbers with operator>>, which turns "abc" or "1e-3x" in an Array(double) into
// 0 without a word. Check every numeric value's text strictly before Teuchos converts it.
bool strict_number(const std::string& token, bool integer) {
  std::size_t b = token.find_first_not_of(" \t\n"), e = token.find_last_not_of(" \t\n");
  if (b == std::string::npos)
    return false;
  const std::string t = token.substr(b, e - b + 1);
  char* end = nullptr;
  errno = 0;
  if (integer) {
    const long long v = std::strtoll(t.c_str(), &end, 10);
    if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
      return false;
  } else {
    const double v = std::strtod(t.c_str(), &end);
    if (!std::isfinite(v))
      return false;
  }
  return errno == 0 && end == t.c_str() + t.size();
}

void check_numbers(const Teuchos::XMLObject& node, const std::string& path) {
  std::set<std::string> seen;
  for (int k = 0; k < node.numChildren(); ++k) {
    const Teuchos::XMLObject& c = node.getChild(k);
    if (!c.hasAttribute("name"))
      continue;
    const std::string name = c.getAttribute("name");
    // Teuchos keeps the last of two entries of one name without a word.
    if (!seen.insert(name).second)
      throw InputError("Error, " + path + "->" + name +
                       " is given twice; give each parameter and sublist once.");
    if (c.getTag() == "ParameterList") {
      check_numbers(c, path + "->" + name);
      continue;
    }
    if (c.getTag() != "Parameter" || !c.hasAttribute("type") || !c.hasAttribute("value"))
      continue;
    const std::string type = c.getAttribute("type"), value = c.getAttribute("value");
    const bool is_int = type == "int" || type == "Array(int)";
    const bool is_double = type == "double" || type == "Array(double)";
    if (!is_int && !is_double)
      continue;
    std::vector<std::string> tokens;
    if (type.rfind("Array", 0) == 0) {
      std::size_t b = value.find('{'), e = value.rfind('}');
      if (b == std::string::npos || e == std::string::npos || e < b)
        throw InputError("Error, " + path + "->" + name + " = \"" + value +
                         "\" is not an array: write {a, b, ...}.");
      const std::string inner = value.substr(b + 1, e - b - 1);
      if (inner.find_first_not_of(" \t\n") != std::string::npos) {
        std::stringstream ss(inner);
        for (std::string tok; std::getline(ss, tok, ',');)
          tokens.push_back(tok);
      }
    } else {
      tokens.push_back(value);
    }
    for (const auto& tok : tokens)
      if (!strict_number(tok, is_int))
        throw InputError("Error, " + path + "->" + name + " = \"" + value + "\": \"" + tok +
                         "\" is not a finite " + (is_int ? "int" : "double") + " number.");
  }
}

}  // namespace

RCP<ParameterList> parse_input(const std::string& xml) {
  try {
    const auto root = Teuchos::StringInputSource(xml).getObject();
    if (root.getTag() == "ParameterList" &&
        (!root.hasAttribute("name") || root.getAttribute("name") != "mupm"))
      throw InputError("Error, the input's root list is named '" +
                       (root.hasAttribute("name") ? root.getAttribute("name") : std::string()) +
                       "'; a mupm input is <ParameterList name=\"mupm\">.");
    check_numbers(root, "mupm");
  } catch (const InputError&) {
    throw;
  } catch (const std::exception&) {
    // Malformed XML: reported below by the parameter-list reader with its line number.
  }
  try {
    auto pl = Teuchos::getParametersFromXmlString(xml);
    name_lists(*pl, "mupm");
    return pl;
  } catch (const std::exception& e) {
    // Keep the parser's own sentence ("XML parse error at line N: ..."), not its source location.
    std::string msg = e.what();
    const auto pos = msg.find("XML parse error");
    if (pos != std::string::npos)
      msg = msg.substr(pos);
    throw InputError("Error, the input is not a valid Teuchos XML parameter list: " + msg);
  }
}

RCP<ParameterList> read_input(const Teuchos::Comm<int>& comm, const std::string& path) {
  std::string text;
  int ok = 1;
  if (comm.getRank() == 0) {
    std::ifstream f(path);
    std::error_code ec;
    if (!f || std::filesystem::is_directory(path, ec)) {
      ok = 0;
    } else {
      std::ostringstream s;
      s << f.rdbuf();
      text = s.str();
    }
  }
  Teuchos::broadcast(comm, 0, &ok);
  if (!ok)
    throw InputError("Error, cannot read the input file '" + path + "'.");
  long long n = static_cast<long long>(text.size());
  Teuchos::broadcast(comm, 0, &n);
  text.resize(static_cast<std::size_t>(n));
  if (n > 0)
    Teuchos::broadcast(comm, 0, static_cast<int>(n), &text[0]);
  return parse_input(text);
}

// Solver->Pressure Integration = Semi-Implicit (include/mupm/solvers/pressure_projection.hpp):
// what it takes and what it does not have yet; Fluid->Incompressible needs it.
static void check_pressure_integration(const ParameterList& input) {
  const ParameterList& solver = input.sublist("Solver");
  const std::string root = input.name();
  const bool si = pressure_integration_options()(solver.get<std::string>("Pressure Integration")) ==
                  PressureIntegration::SemiImplicit;
  const std::string path = root + "->Solver->Pressure Integration";
  if (input.sublist("Fluid").get<bool>("Incompressible") && !si)
    throw InputError("Error, " + root + "->Fluid->Incompressible = true needs " + path +
                     " = Semi-Implicit: the explicit scheme's stable steps (the solid's with "
                     "the undrained modulus K + K_w/phi, the fluid's with the storage phi/K_w) "
                     "shrink to zero as K_w grows.");
  if (!si)
    return;
  const std::string have = path + " = Semi-Implicit ";
  if (physics_options()(solver.get<std::string>("Physics")) != Physics::HydroMechanical)
    throw InputError("Error, " + have + "couples the pore pressure with the skeleton: it needs " +
                     root + "->Solver->Physics = Hydro-Mechanical.");
  // The crack water's force enters the joint solve as the transpose of the crack volume's
  // Jacobian (pressure_projection.hpp); eq 17's force on the fracture bonds has no such pair.
  const ParameterList& fracture = input.sublist("Fracture");
  if (fracture.get<bool>("Fracture Flow") &&
      crack_water_force_options()(fracture.get<std::string>("Crack Water Force")) !=
          CrackWaterForce::FacePressure)
    throw InputError("Error, " + have +
                     "solves the crack water's pressure with the face force "
                     "it does work through: " +
                     root +
                     "->Fracture->Crack Water Force must be Face Pressure (or use Explicit).");
  // Fluid Flux (an even image of the body's pressure in the layer): measured unstable with
  // incompressible water (inputs/consolidation.xml, mirrored layers, K_h / 100, the top drain a
  // Fluid Flux of 1e-6 m/s: the solid diverged at step 2130). Mirrored Pore Pressure layers
  // (odd images) run since the pressure stabilization (pressure_projection.hpp): the same input
  // with drains, K_h / 10 and / 100, closes its balances (solid 1e-6 J, water 5e-13 kg), and
  // Terzaghi's mirrored column is within 1 % (tests/solvers/test_fluid_solver.cpp).
  if (input.isSublist("Boundary Conditions")) {  // validated: every entry a sublist with a Type
    const ParameterList& bcs = input.sublist("Boundary Conditions");
    for (auto it = bcs.begin(); it != bcs.end(); ++it)
      if (bcs.sublist(bcs.name(it)).get<std::string>("Type") == "Fluid Flux")
        throw InputError("Error, " + have + "does not take " + root + "->Boundary Conditions->" +
                         bcs.name(it) +
                         "->Type = Fluid Flux yet: its layer's pressures, images of the body's, "
                         "were measured unstable with incompressible water. Use a Pore Pressure, "
                         "or Explicit.");
  }
  if (staggering_options()(solver.get<std::string>("Staggering")) != Staggering::SolidFirst ||
      solver.get<int>("Solid Steps Per Fluid Step") != 1 || solver.get<int>("Fluid Substeps") != 1)
    throw InputError("Error, " + have +
                     "solves the pressure once in every step, inside the "
                     "skeleton's step: " +
                     root +
                     "->Solver->Staggering, Solid Steps Per Fluid "
                     "Step and Fluid Substeps are for Explicit (leave them at Solid First, 1, 1).");
}

void validate_input(ParameterList& input) {
  if (input.isSublist("Discretization") && !input.sublist("Discretization").isParameter("Spacing"))
    throw InputError("Error, the required parameter " + input.name() +
                     "->Discretization->Spacing (point spacing in m, a double > 0) is missing.");
  if (!input.isSublist("Discretization"))
    throw InputError("Error, the required sublist " + input.name() +
                     "->Discretization is missing.");
  validate_level(input, *valid_parameters());
  check_dimension_arrays(input);
  check_pressure_integration(input);
}

namespace {

template <int Dim>
MemoryNeed memory_need_of(const ParameterList& input, int ranks) {
  const GridSpec<Dim> g = grid_from_input<Dim>(input);
  MemoryNeed m;
  m.points = double(g.n_global());
  // Bonds per point: the lattice offsets within the horizon.
  const int r = int(g.horizon / g.dx);
  long long family = 0;
  for (int i = -r; i <= r; ++i)
    for (int j = -r; j <= r; ++j)
      for (int k = (Dim == 3 ? -r : 0); k <= (Dim == 3 ? r : 0); ++k) {
        const double d2 = double(i * i + j * j + k * k) * g.dx * g.dx;
        family += (d2 > 0 && d2 <= g.horizon * g.horizon * (1 + 1e-12)) ? 1 : 0;
      }
  m.bonds_per_point = double(family);
  // A rank's part: a box of n points with a halo of r rows of ghosts.
  const double n = std::ceil(m.points / ranks);
  const double side = std::pow(n, 1.0 / Dim);
  const double ghosts = std::min(std::pow(side + 2 * r, Dim) - n, m.points - n);
  // Per point: the registry's fields, plus solver state, shape tensors and ghost-exchange buffers
  // (SolidState, FluidState, solver arrays, two MultiVectors of the widest refresh): 512 B in 2D,
  // 1 KiB in 3D. Per bond: the bond registry (with the pair force states of bond breakage),
  // plus the sort keys of the neighbour build.
  const double per_point = double(Points<Dim>::bytes_per_point()) + (Dim == 2 ? 512 : 1024);
  const bool breaks =
      bond_breaking_options()(input.sublist("Fracture").get<std::string>("Bond Breakage")) ==
      BondBreaking::Energy;
  const double per_bond =
      double(Bonds::bytes_per_bond(breaks ? Dim + kRotDim<Dim> : 0)) + sizeof(GlobalId);
  m.bytes_per_rank = (n + ghosts) * per_point + n * m.bonds_per_point * per_bond;
  return m;
}

double mem_available_bytes() {
  std::ifstream f("/proc/meminfo");
  std::string key;
  double kb = 0;
  while (f >> key >> kb) {
    if (key == "MemAvailable:")
      return kb * 1024;
    f.ignore(256, '\n');
  }
  return 0;  // unknown
}

}  // namespace

MemoryNeed memory_need(const Teuchos::Comm<int>& comm, const ParameterList& input) {
  MemoryNeed m = input_dimension(input) == 2 ? memory_need_of<2>(input, comm.getSize())
                                             : memory_need_of<3>(input, comm.getSize());
  MPI_Comm raw = MPI_COMM_SELF;
  if (const auto* mc = dynamic_cast<const Teuchos::MpiComm<int>*>(&comm))
    raw = (*mc->getRawMpiComm())();
  MPI_Comm node;
  MPI_Comm_split_type(raw, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
  int on_node = 1;
  MPI_Comm_size(node, &on_node);
  MPI_Comm_free(&node);
  double avail = mem_available_bytes() / on_node;
  MPI_Allreduce(MPI_IN_PLACE, &avail, 1, MPI_DOUBLE, MPI_MIN, raw);
  m.available_per_rank = avail;
  return m;
}

MemoryNeed check_memory(const Teuchos::Comm<int>& comm, const ParameterList& input) {
  const MemoryNeed m = memory_need(comm, input);
  if (m.available_per_rank > 0 && m.bytes_per_rank > m.available_per_rank) {
    std::ostringstream s;
    s.precision(3);
    s << "Error, the discretization (mupm->Discretization->Counts or Extents, Spacing, Horizon) "
         "needs about "
      << m.bytes_per_rank / (1 << 30) << " GiB per rank (" << m.points << " points, "
      << m.bonds_per_point << " bonds each, " << comm.getSize() << " rank(s)): more than the "
      << m.available_per_rank / (1 << 30)
      << " GiB available per rank (MemAvailable over the ranks of a node). Use more nodes or a "
         "coarser Spacing.";
    throw InputError(s.str());
  }
  return m;
}

void check_files(const Teuchos::Comm<int>& comm, const ParameterList& input) {
  std::string why;
  if (comm.getRank() == 0) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const std::string restart = input.sublist("Solver").get<std::string>("Restart From");
    if (!restart.empty()) {
      std::ifstream f(restart, std::ios::binary);
      char sig[8] = {};
      const char hdf5[8] = {'\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};
      if (fs::is_directory(restart, ec))
        why = "Error, mupm->Solver->Restart From = '" + restart +
              "' is a directory; give the checkpoint file, e.g. '" + restart + "/checkpoint.h5'.";
      else if (!f)
        why = "Error, mupm->Solver->Restart From = '" + restart +
              "': no such file (or it cannot be read).";
      else if (!f.read(sig, 8) || !std::equal(sig, sig + 8, hdf5))
        why = "Error, mupm->Solver->Restart From = '" + restart +
              "' is not an HDF5 file; give a checkpoint.h5 a mupm run wrote.";
    }
    // The output folder, or the nearest existing folder above it, must be writable.
    const std::string folder = input.sublist("Output").get<std::string>("Folder");
    fs::path p = fs::absolute(folder, ec);
    while (!p.empty() && !fs::exists(p, ec) && p != p.parent_path())
      p = p.parent_path();
    if (why.empty() && fs::exists(folder, ec) && !fs::is_directory(folder, ec))
      why = "Error, mupm->Output->Folder = '" + folder + "' is a file, not a folder.";
    else if (why.empty() && !p.empty() && fs::exists(p, ec) && !fs::is_directory(p, ec))
      // A component of the path is a file: no folder can be made below it.
      why = "Error, mupm->Output->Folder = '" + folder + "': '" + p.string() +
            "' is a file, not a folder.";
    else if (why.empty() && access(p.c_str(), W_OK | X_OK) != 0)
      why = "Error, mupm->Output->Folder = '" + folder + "': '" + p.string() +
            "' is not writable (" + std::strerror(errno) + ").";
  }
  long long n = static_cast<long long>(why.size());
  Teuchos::broadcast(comm, 0, &n);
  why.resize(static_cast<std::size_t>(n));
  if (n > 0) {
    Teuchos::broadcast(comm, 0, static_cast<int>(n), &why[0]);
    throw InputError(why);
  }
}

std::string end_time_steps_error(double end_time, double time, double dt,
                                 const std::string& dt_source) {
  const double steps = (end_time - time) / dt;
  if (!(end_time > 0) || !(dt > 0) || steps <= kMaxEndTimeSteps)
    return "";
  std::ostringstream s;
  s << "Error, mupm->Solver->End Time = " << end_time << " s takes " << steps
    << " steps of dt = " << dt << " s (" << dt_source << ")";
  if (time > 0)
    s << " from the checkpoint's time " << time << " s";
  s << ": more than " << kMaxEndTimeSteps
    << ", which no run reaches (the step counter and the time series are exact below it). "
       "Check End Time and the time step.";
  return s.str();
}

int input_dimension(const ParameterList& input) {
  return input.sublist("Discretization").get<int>("Dimension");
}

template <int Dim>
GridSpec<Dim> grid_from_input(const ParameterList& input) {
  const ParameterList& d = input.sublist("Discretization");
  GridSpec<Dim> g;
  g.dx = d.get<double>("Spacing");
  g.horizon = horizon_of(d);
  g.thickness = Dim == 2 ? d.get<double>("Thickness") : 1.0;
  const auto counts = d.get<Array<int>>("Counts");
  const auto ext = d.get<Array<double>>("Extents");
  const auto origin = d.get<Array<double>>("Origin");
  for (int k = 0; k < Dim; ++k) {
    g.counts[k] = counts.empty() ? std::llround(ext[k] / g.dx) : counts[k];
    g.origin[k] = origin.empty() ? 0.0 : origin[k];
  }
  // check_layer_rows has bounded it.
  const int rows = static_cast<int>(layer_rows(d, d.get<double>("Boundary Layer Horizons")));
  for (const auto& f : d.get<Array<std::string>>("Boundary Layers"))
    g.layers[f[1] - 'x'][f[0] == '-' ? 0 : 1] = rows;
  const ParameterList& regions = d.sublist("Regions");
  for (auto it = regions.begin(); it != regions.end(); ++it) {
    const ParameterList& r = regions.sublist(regions.name(it));
    Box b;
    const auto lo = r.get<Array<double>>("Min"), hi = r.get<Array<double>>("Max");
    for (int k = 0; k < Dim; ++k) {
      b.lo[k] = lo[k];
      b.hi[k] = hi[k];
    }
    g.region_names.push_back(regions.name(it));
    g.regions.push_back(b);
  }
  // Boundary layers as regions: the rows outside the face, across the whole lattice.
  for (int k = 0; k < Dim; ++k)
    for (int side = 0; side < 2; ++side) {
      if (g.layers[k][side] == 0)
        continue;
      Box b;
      for (int j = 0; j < Dim; ++j) {
        b.lo[j] = g.origin[j] - (g.layers[j][0] + 1) * g.dx;
        b.hi[j] = g.origin[j] + (g.counts[j] + g.layers[j][1] + 1) * g.dx;
      }
      const double lo_face = g.origin[k], hi_face = g.origin[k] + g.counts[k] * g.dx;
      if (side == 0)
        b.hi[k] = lo_face - 0.25 * g.dx;
      else
        b.lo[k] = hi_face + 0.25 * g.dx;
      g.region_names.push_back(std::string("Layer ") + (side ? '+' : '-') + char('x' + k));
      g.regions.push_back(b);
    }
  const ParameterList& cracks = d.sublist("Pre-Cracks");
  for (auto it = cracks.begin(); it != cracks.end(); ++it) {
    const ParameterList& c = cracks.sublist(cracks.name(it));
    Crack cr;
    if (Dim == 2) {
      const auto a = c.get<Array<double>>("Start"), b = c.get<Array<double>>("End");
      for (int k = 0; k < 2; ++k) {
        cr.a[k] = a[k];
        cr.b[k] = b[k];
      }
    } else {
      const auto a = c.get<Array<double>>("Corner"), e1 = c.get<Array<double>>("Edge 1"),
                 e2 = c.get<Array<double>>("Edge 2");
      for (int k = 0; k < 3; ++k) {
        cr.a[k] = a[k];
        cr.b[k] = e1[k];
        cr.c[k] = e2[k];
      }
    }
    // A crack that misses the body breaks no bond and would measure no length.
    const CrackPart part = crack_inside<Dim>(cr, g.body());
    if (!(part.s1 > part.s0))
      throw InputError("Error, " + c.name() +
                       " lies outside the body (or touches it in a point or along its surface "
                       "only): it would cut no bond. Check its coordinates against the body, "
                       "which spans Origin to Origin + Counts x Spacing.");
    g.cracks.push_back(cr);
  }
  return g;
}

template GridSpec<2> grid_from_input<2>(const ParameterList&);
template GridSpec<3> grid_from_input<3>(const ParameterList&);

namespace {

// Region names in bit order: the user's regions, then the boundary layers (as grid_from_input).
std::vector<std::string> region_names(const ParameterList& input) {
  const ParameterList& d = input.sublist("Discretization");
  std::vector<std::string> names;
  const ParameterList& regions = d.sublist("Regions");
  for (auto it = regions.begin(); it != regions.end(); ++it)
    names.push_back(regions.name(it));
  const int dim = d.get<int>("Dimension");
  const auto faces = d.get<Array<std::string>>("Boundary Layers");
  for (int k = 0; k < dim; ++k)
    for (int side = 0; side < 2; ++side) {
      const std::string f = std::string(side ? "+" : "-") + char('x' + k);
      for (const auto& g : faces)
        if (g == f) {
          names.push_back("Layer " + f);
          break;
        }
    }
  return names;
}

std::uint32_t region_mask(const std::vector<std::string>& names, const std::string& region) {
  for (std::size_t r = 0; r < names.size(); ++r)
    if (names[r] == region)
      return 1u << r;
  return 0;  // All
}

}  // namespace

std::vector<InitialCondition> initial_conditions_from_input(const ParameterList& input) {
  const auto names = region_names(input);
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
  const auto names = region_names(input);
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
