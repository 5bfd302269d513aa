// Materials->Model = Micropolar Elastic (include/mupm/laws/micropolar_elastic.hpp): the
// elastic constants every law takes are Materials' own (src/input/modules/materials.cpp).
#include "solid_build.hpp"

namespace mupm {
namespace {

template <int Dim>
std::unique_ptr<Mechanics> build(const SolidBuild<Dim>& b) {
  return solid_module(b, b.model.solid.law);  // in plane stress, its plane_stress() (model.cpp)
}

}  // namespace

template <>
const LawRegistration& law_registration<MicropolarElastic>() {
  static const LawRegistration r{"Micropolar Elastic",
                                 "Micropolar Elastic (eqs 80-81)",
                                 nullptr,
                                 nullptr,
                                 nullptr,
                                 0,
                                 true,
                                 build<2>,
                                 build<3>};
  return r;
}

}  // namespace mupm
