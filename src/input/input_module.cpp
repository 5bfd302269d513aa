#include "input_module.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace mupm {

const std::vector<InputModule>& input_modules() {
  static const std::vector<InputModule> modules = {
      discretization_input(),     materials_input(),  fluid_input(),
      fracture_input(),           j_integral_input(), boundary_conditions_input(),
      initial_conditions_input(), solver_input(),     output_input(),
      diagnostics_input()};
  return modules;
}

std::string path_of(const Teuchos::ParameterList& list, const std::string& name) {
  return list.name() + "->" + name;
}

std::string joined(const std::vector<std::string>& v, const char* last) {
  std::string out;
  for (std::size_t k = 0; k < v.size(); ++k)
    out += (k == 0 ? "" : k + 1 == v.size() ? last : ", ") + v[k];
  return out;
}

std::string exact(double x) {
  char buf[32];
  for (int digits = 15; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, x);
    if (std::strtod(buf, nullptr) == x)
      break;
  }
  return buf;
}

Teuchos::RCP<Teuchos::EnhancedNumberValidator<double>> positive() {
  return at_least(std::numeric_limits<double>::min());
}
Teuchos::RCP<Teuchos::StringValidator> one_of(const std::vector<std::string>& v) {
  return Teuchos::rcp(
      new Teuchos::StringValidator(Teuchos::Array<std::string>(v.begin(), v.end())));
}

double horizon_of(const Teuchos::ParameterList& d) {
  const double h = d.get<double>("Horizon");
  return h > 0 ? h : d.get<double>("Horizon Factor") * d.get<double>("Spacing");
}
double layer_rows(const Teuchos::ParameterList& d, double horizons) {
  return std::floor(horizons * horizon_of(d) / d.get<double>("Spacing") * (1 + 1e-10));
}

}  // namespace mupm
