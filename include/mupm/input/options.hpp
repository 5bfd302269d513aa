// Enumerated input options, typed once: each option's strings and enum values are one table,
// from which the input's validator (Teuchos StringToIntegralParameterEntryValidator, so
// --print-defaults lists the choices) and the conversion to the enum both follow. The tables are
// in src/input/model.cpp, but for Boundary Conditions->NAME->Type (the kinds' entries,
// src/input/modules/conditions.cpp). Materials->Model's laws are registrations
// (include/mupm/input/law_registry.hpp). Below the input layer nobody compares option strings.
#ifndef MUPM_OPTIONS_HPP
#define MUPM_OPTIONS_HPP

#include <Teuchos_StandardParameterEntryValidators.hpp>
#include <string>
#include <utility>
#include <vector>

#include "mupm/kernels/boundary_conditions.hpp"
#include "mupm/kernels/fracture.hpp"
#include "mupm/laws/stabilization.hpp"

namespace mupm {

// Solver->Physics.
enum class Physics { MicropolarSolid, KinematicsOnly, PoreFluid, HydroMechanical };
inline bool has_solid(Physics p) {
  return p == Physics::MicropolarSolid || p == Physics::HydroMechanical;
}
inline bool has_fluid(Physics p) {
  return p == Physics::PoreFluid || p == Physics::HydroMechanical;
}
// Solver->Staggering.
enum class Staggering { SolidFirst, FluidFirst };
// Solver->Pressure Integration.
enum class PressureIntegration { Explicit, SemiImplicit };
// Fluid->Retention Model.
enum class RetentionModel { Saturated, VanGenuchten };
// Fracture->Bond Energy Force State.
enum class BondEnergyState { Effective, Total };
// Fracture->Crack Water Force.
enum class CrackWaterForce { FacePressure, Eq17 };
// J-Integral->Units.
enum class ContourUnits { Spacings, Metres };
// Discretization->Plane (2D).
enum class Plane { Strain, Stress };

template <class E>
class Options {
 public:
  using Validator = Teuchos::StringToIntegralParameterEntryValidator<int>;
  Options(const std::string& parameter, std::vector<std::pair<std::string, E>> table)
      : table_(std::move(table)) {
    Teuchos::Array<std::string> names;
    Teuchos::Array<int> values;
    for (const auto& [n, v] : table_) {
      names.push_back(n);
      values.push_back(static_cast<int>(v));
    }
    validator_ = Teuchos::rcp(new Validator(names, values, parameter));
  }
  const Teuchos::RCP<const Validator>& validator() const { return validator_; }
  // The value of a string the validator accepted.
  E operator()(const std::string& s) const {
    return static_cast<E>(validator_->getIntegralValue(s));
  }
  const std::string& name(E e) const {
    for (const auto& [n, v] : table_)
      if (v == e)
        return n;
    return table_.front().first;
  }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& t : table_)
      out.push_back(t.first);
    return out;
  }

 private:
  std::vector<std::pair<std::string, E>> table_;
  Teuchos::RCP<const Validator> validator_;
};

const Options<Physics>& physics_options();
const Options<Staggering>& staggering_options();
const Options<PressureIntegration>& pressure_integration_options();
const Options<StabilizationModulus>& stabilization_modulus_options();
const Options<RetentionModel>& retention_model_options();
const Options<BondBreaking>& bond_breaking_options();
const Options<BondEnergyState>& bond_energy_state_options();
const Options<CrackWaterForce>& crack_water_force_options();
const Options<ContourUnits>& contour_units_options();
const Options<Plane>& plane_options();
const Options<BoundaryCondition::Kind>& boundary_condition_options();
const Options<TimeFunction::Kind>& time_function_options();
// Boundary Conditions->NAME->Component: the axis (x, y, z) as 0, 1, 2.
const Options<int>& component_options();

}  // namespace mupm

#endif
