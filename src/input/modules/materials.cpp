#include "../input_module.hpp"

#include "mupm/input/law_registry.hpp"
#include "mupm/input/options.hpp"

namespace mupm {

using Teuchos::Array;
using Teuchos::ParameterList;
using Teuchos::rcp;

namespace {

// Materials->Model: the registered laws (include/mupm/input/law_registry.hpp).
const Options<int>& model_options() {
  static const Options<int> o("Model", [] {
    std::vector<std::pair<std::string, int>> table;
    for (const LawRegistration* l : law_registry())
      table.emplace_back(l->name, int(table.size()));
    return table;
  }());
  return o;
}

void declare_materials(ParameterList& m) {
  std::string doc = "Constitutive model: ";
  for (const LawRegistration* l : law_registry())
    doc += (l == law_registry().front() ? "" : ", or ") + std::string(l->doc);
  m.set("Model", std::string(law_registry().front()->name), doc + ".", model_options().validator());
  for (const LawRegistration* l : law_registry())
    if (l->declare)
      l->declare(m);
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
    const LawRegistration& law = law_named(m.get<std::string>("Model"));
    if (law.check)
      law.check(m);
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
  return law_named(input.sublist("Materials").get<std::string>("Model")).field_groups;
}

}  // namespace

InputModule materials_input() {
  return {"Materials", "The solid (Solver->Physics = Micropolar Solid).", declare_materials,
          check_materials, materials_field_groups};
}

}  // namespace mupm
