#include "../input_module.hpp"

#include "mupm/input/options.hpp"

namespace mupm {

using Teuchos::Array;
using Teuchos::ParameterList;
using Teuchos::rcp;

namespace {

// The constitutive laws of Materials->Model. Each declares its name, its part of the Model's doc
// string, the parameters it adds to Materials, its checks (with a solid) and the point-field
// groups it needs; the elastic law's constants below (Bulk Modulus to Length Scale) are every
// law's. A new law adds its entry here; its solver is instantiated from
// include/mupm/laws/laws.hpp, built by the driver (src/solvers/driver/assembly.hpp, assemble) and
// given its constants by model_from_input (src/input/model.cpp).
struct LawInput {
  const char* name;
  ConstitutiveModel model;
  const char* doc;
  void (*declare)(ParameterList& materials);  // its own parameters; nullptr: none
  void (*check)(const ParameterList& materials);
  unsigned field_groups;
};

void declare_drucker_prager(ParameterList& m) {
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
}

void check_drucker_prager(const ParameterList& m) {
  const double c0 = m.get<double>("Cohesion"), cr = m.get<double>("Residual Cohesion");
  if (!(c0 > 0))
    throw InputError("Error, " + path_of(m, "Cohesion") +
                     " must be > 0 for Materials->Model = Micropolar Drucker-Prager.");
  if (cr > c0)
    throw InputError("Error, " + path_of(m, "Residual Cohesion") + " = " + std::to_string(cr) +
                     " Pa exceeds " + path_of(m, "Cohesion") + " = " + std::to_string(c0) +
                     " Pa: softening ends at the residual cohesion.");
}

const std::vector<LawInput>& laws() {
  static const std::vector<LawInput> l = {
      {"Micropolar Elastic", ConstitutiveModel::MicropolarElastic, "Micropolar Elastic (eqs 80-81)",
       nullptr, nullptr, 0},
      // The plastic state, and the second-order work (eq 42) that detects its shear bands.
      {"Micropolar Drucker-Prager", ConstitutiveModel::MicropolarDruckerPrager,
       "Micropolar Drucker-Prager (eqs 82-95: the elastic law plus the Drucker-Prager yield "
       "surface and plastic potential as the paper writes them, non-associative flow, linear "
       "softening of the cohesion down to a residual one; plane strain in 2D)",
       declare_drucker_prager, check_drucker_prager, kGroupPlastic | kGroupSecondOrderWork}};
  return l;
}

void declare_materials(ParameterList& m) {
  std::string doc = "Constitutive model: ";
  for (const LawInput& l : laws())
    doc += (&l == &laws().front() ? "" : ", or ") + std::string(l.doc);
  m.set("Model", std::string(laws().front().name), doc + ".",
        constitutive_model_options().validator());
  for (const LawInput& l : laws())
    if (l.declare)
      l.declare(m);
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
  m.set("Stabilization Modulus", std::string("Automatic"),
        "D of eqs 69-71. Eq 71: the paper's 3D D = E(1-4nu)/(4 pi delta^2 (1-nu-2nu^2)), "
        "negative for nu > 1/4, then an error. Bulk Matching: D = 3K/(8 pi delta^2) in 3D, "
        "(lambda+mu)/(6 pi h delta) in 2D (stabilization energy of a uniform expansion equal "
        "to the elastic one; derivation in include/mupm/kernels/solid.hpp). Automatic: Eq 71 in 3D "
        "where it is positive, Bulk Matching otherwise and always in 2D.",
        stabilization_modulus_options().validator());
}

// With a solid: its constants, the law's own checks and the stabilization modulus.
void check_materials(ParameterList& input) {
  const int dim = input.sublist("Discretization").get<int>("Dimension");
  const std::string physics = input.sublist("Solver").get<std::string>("Physics");
  const Physics phys = physics_options()(physics);
  if (has_solid(phys)) {
    const ParameterList& m = input.sublist("Materials");
    for (const char* k : {"Bulk Modulus", "Shear Modulus", "Length Scale"})
      if (!(m.get<double>(k) > 0))
        throw InputError("Error, " + path_of(m, k) +
                         " must be > 0 for Solver->Physics = " + physics + ".");
    const auto sm = stabilization_modulus_options()(m.get<std::string>("Stabilization Modulus"));
    const double K = m.get<double>("Bulk Modulus"), mu = m.get<double>("Shear Modulus");
    for (const LawInput& l : laws())
      if (l.check && l.name == m.get<std::string>("Model"))
        l.check(m);
    if (sm == StabilizationModulus::Eq71 && (dim == 2 || mu - (K - 2 * mu / 3) <= 0))
      throw InputError("Error, " + path_of(m, "Stabilization Modulus") + " = Eq 71 " +
                       (dim == 2 ? std::string("is a 3D formula")
                                 : std::string("gives D <= 0 (Poisson's ratio >= 1/4)")) +
                       ": use Automatic or Bulk Matching.");
  }
}

// The fields of the law a solid uses.
unsigned materials_field_groups(const ParameterList& input) {
  const Physics physics = physics_options()(input.sublist("Solver").get<std::string>("Physics"));
  if (!has_solid(physics))
    return 0;
  const std::string model = input.sublist("Materials").get<std::string>("Model");
  for (const LawInput& l : laws())
    if (l.name == model)
      return l.field_groups;
  return 0;
}

}  // namespace

const Options<ConstitutiveModel>& constitutive_model_options() {
  static const Options<ConstitutiveModel> o("Model", [] {
    std::vector<std::pair<std::string, ConstitutiveModel>> table;
    for (const LawInput& l : laws())
      table.emplace_back(l.name, l.model);
    return table;
  }());
  return o;
}

InputModule materials_input() {
  return {"Materials", "The solid (Solver->Physics = Micropolar Solid).", declare_materials,
          check_materials, materials_field_groups};
}

}  // namespace mupm
