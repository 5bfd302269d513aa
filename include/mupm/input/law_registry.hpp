// The constitutive laws Materials->Model offers, one registration each. A law's registration
// (src/solvers/laws/<law>.cpp) declares its name and doc, its own parameters in Materials with
// their defaults, docs and validators, its checks and warnings, the point-field groups it needs,
// and its factory, which builds the solid solver for it from the model. The Model validator,
// Materials' parameters and checks, the point fields a run allocates and the driver's solid
// (src/solvers/driver/assembly.hpp) follow from the registrations.
//
// A new law: its header in include/mupm/laws/ with its line in laws.hpp (MUPM_FOR_EACH_LAW: the
// solver's instantiation and this registry's order), and its registration file.
//
// The input layer reads the registry; the registrations, whose factories build solvers, are
// defined in the solvers layer.
#ifndef MUPM_LAW_REGISTRY_HPP
#define MUPM_LAW_REGISTRY_HPP

#include <Teuchos_ParameterList.hpp>
#include <memory>
#include <string>
#include <vector>

#include "mupm/laws/laws.hpp"

namespace mupm {

class Mechanics;
// What a law's factory builds its solid solver from (src/solvers/laws/solid_build.hpp).
template <int Dim>
struct SolidBuild;

struct LawRegistration {
  const char* name;  // Materials->Model
  const char* doc;   // its part of Model's doc string
  // Its own parameters in Materials (every law's elastic constants are Materials' own,
  // src/input/modules/materials.cpp). nullptr: none.
  void (*declare)(Teuchos::ParameterList& materials);
  // Its checks with a solid, after Teuchos' validation; throws InputError naming the parameter's
  // full path. nullptr: none.
  void (*check)(const Teuchos::ParameterList& materials);
  // Inputs that run but may mislead, said at the start of the run. nullptr: none.
  void (*warn)(const Teuchos::ParameterList& materials, std::vector<std::string>& warnings);
  unsigned field_groups;  // FieldGroup bits (include/mupm/data/fields.hpp) it needs
  // Its state is defined on energy-free points, so it runs with slaved boundary layers
  // (src/input/model.cpp, check_mirrored_kinematic).
  bool energy_free_points;
  // The solid solver of the law, in 2D and 3D.
  std::unique_ptr<Mechanics> (*build2)(const SolidBuild<2>& build);
  std::unique_ptr<Mechanics> (*build3)(const SolidBuild<3>& build);

  template <int Dim>
  std::unique_ptr<Mechanics> build(const SolidBuild<Dim>& b) const {
    if constexpr (Dim == 2)
      return build2(b);
    else
      return build3(b);
  }
};

// The registration of each law of MUPM_FOR_EACH_LAW, named by the law's 2D type.
template <class Law>
const LawRegistration& law_registration();
#define MUPM_LAW_REGISTRATION(D, LAW) \
  template <>                         \
  const LawRegistration& law_registration<LAW>();
MUPM_FOR_EACH_LAW(MUPM_LAW_REGISTRATION, 2)
#undef MUPM_LAW_REGISTRATION

// Every law, in MUPM_FOR_EACH_LAW's order; the first is Materials->Model's default.
const std::vector<const LawRegistration*>& law_registry();
// The law Materials->Model names (the validator accepted it).
const LawRegistration& law_named(const std::string& name);

}  // namespace mupm

#endif
