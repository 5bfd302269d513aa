// Materials->Model = Micropolar Elastic (include/mupm/laws/micropolar_elastic.hpp): the
// elastic constants every law takes are Materials' own (src/input/modules/materials.cpp).
#include "solid_build.hpp"

namespace mupm {
namespace {

template <int Dim>
std::unique_ptr<Mechanics> build(const SolidBuild<Dim>& b) {
  // The solver takes the elastic law of its SolidParams (in plane stress the law's
  // plane_stress(), model_from_input); the same is passed here.
  return solid_module(b, b.model.solid.law);
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
