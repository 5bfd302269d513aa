// Materials->Model = Micropolar Drucker-Prager (include/mupm/laws/micropolar_drucker_prager.hpp):
// its parameters in Materials, their checks, its point fields and its solver.
#include "../../input/input_module.hpp"
#include "mupm/core/types.hpp"
#include "mupm/data/fields.hpp"
#include "solid_build.hpp"

namespace mupm {
namespace {

using Teuchos::ParameterList;
using Teuchos::rcp;

void declare(ParameterList& m) {
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

void check(const ParameterList& m) {
  const double c0 = m.get<double>("Cohesion"), cr = m.get<double>("Residual Cohesion");
  if (!(c0 > 0))
    throw InputError("Error, " + path_of(m, "Cohesion") +
                     " must be > 0 for Materials->Model = Micropolar Drucker-Prager.");
  if (cr > c0)
    throw InputError("Error, " + path_of(m, "Residual Cohesion") + " = " + std::to_string(cr) +
                     " Pa exceeds " + path_of(m, "Cohesion") + " = " + std::to_string(c0) +
                     " Pa: softening ends at the residual cohesion.");
}

DruckerPragerParams params(const ParameterList& m) {
  const double deg = kPi / 180;
  DruckerPragerParams d;
  d.friction = m.get<double>("Friction Angle") * deg;
  d.dilation = m.get<double>("Dilation Angle") * deg;
  d.cohesion = m.get<double>("Cohesion");
  d.residual = m.get<double>("Residual Cohesion");
  d.softening = m.get<double>("Softening Modulus");
  return d;
}

// psi > phi: the plastic dissipation per d lambda, q + sqrt3 a3 p-bar = k c + sqrt3 (a3 - a1)
// p-bar on the yield surface (the law's header), turns negative under a mean compression -p-bar
// beyond k c / (sqrt3 (a3 - a1)).
void warn(const ParameterList& m, std::vector<std::string>& warnings) {
  const double phi = m.get<double>("Friction Angle"), psi = m.get<double>("Dilation Angle");
  const DruckerPragerParams d = params(m);
  if (d.dilation > d.friction)
    warnings.push_back("mupm->Materials->Dilation Angle = " + exact(psi) +
                       " exceeds Friction Angle = " + exact(phi) +
                       " degrees: the plastic dissipation turns negative (energy made by plastic "
                       "flow) under a mean compressive stress beyond k c / (sqrt3 (a3 - a1)) "
                       "(eqs 87-91); soils have psi <= phi");
}

// The return is 3D in plane stress too: the 3D law (model.material), not solid.law.
template <int Dim>
std::unique_ptr<Mechanics> build(const SolidBuild<Dim>& b) {
  return solid_module(
      b, MicropolarDruckerPrager<Dim>(b.model.material, params(b.model.materials), b.disc.points,
                                      b.model.plane_stress, b.settings.fluid));
}

}  // namespace

template <>
const LawRegistration& law_registration<MicropolarDruckerPrager<2>>() {
  // The plastic state, and the second-order work (eq 42) that detects its shear bands.
  static const LawRegistration r{
      "Micropolar Drucker-Prager",
      "Micropolar Drucker-Prager (eqs 82-95: the elastic law plus the Drucker-Prager yield "
      "surface and plastic potential as the paper writes them, non-associative flow, linear "
      "softening of the cohesion down to a residual one; plane strain in 2D)",
      declare,
      check,
      warn,
      kGroupPlastic | kGroupSecondOrderWork,
      false,  // the plastic state on energy-free points is not defined
      build<2>,
      build<3>};
  return r;
}

}  // namespace mupm
