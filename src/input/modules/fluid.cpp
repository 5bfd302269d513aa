#include "../input_module.hpp"

#include "mupm/input/options.hpp"

namespace mupm {

using Teuchos::Array;
using Teuchos::ParameterList;
using Teuchos::rcp;

namespace {

void declare_fluid(ParameterList& f) {
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
  f.set("Viscosity", 1e-3, "Dynamic viscosity of water mu_w [Pa s] (with Intrinsic Permeability).",
        positive());
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

// With a fluid: one permeability, a valid retention curve, pores.
void check_fluid(ParameterList& input) {
  const std::string physics = input.sublist("Solver").get<std::string>("Physics");
  const bool fluid = has_fluid(physics_options()(physics));
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
}

unsigned fluid_field_groups(const ParameterList& input) {
  const Physics physics = physics_options()(input.sublist("Solver").get<std::string>("Physics"));
  return has_fluid(physics) ? unsigned(kGroupPoreWater) : 0u;
}

}  // namespace

InputModule fluid_input() {
  return {"Fluid",
          "Pore water (Solver->Physics = Pore Fluid or Hydro-Mechanical; Water Density "
          "always).",
          declare_fluid, check_fluid, fluid_field_groups};
}

}  // namespace mupm
