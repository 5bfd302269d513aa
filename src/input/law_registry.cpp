#include "mupm/input/law_registry.hpp"

#include <stdexcept>

namespace mupm {

const std::vector<const LawRegistration*>& law_registry() {
#define MUPM_LAW_ENTRY(D, LAW) &law_registration<LAW>(),
  static const std::vector<const LawRegistration*> r = {MUPM_FOR_EACH_LAW(MUPM_LAW_ENTRY, 2)};
#undef MUPM_LAW_ENTRY
  return r;
}

const LawRegistration& law_named(const std::string& name) {
  for (const LawRegistration* l : law_registry())
    if (l->name == name)
      return *l;
  throw std::logic_error("no constitutive law named '" + name + "' (Materials->Model's validator)");
}

}  // namespace mupm
