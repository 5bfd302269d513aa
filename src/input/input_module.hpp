// The input's modules. Each top-level sublist of the input is declared by one module, in a file
// of its own (src/input/modules/): its parameters with their defaults, doc strings and
// validators; the checks Teuchos' validators cannot make (across parameters and sublists); and
// the point-field groups (include/mupm/data/fields.hpp) it makes a run allocate.
// Discretization's and the conditions' files also hold their conversion for the model
// (grid_from_input, initial_conditions_from_input, boundary_conditions_from_input).
// valid_parameters, validate_input and point_field_groups (src/input/input.cpp) follow from the
// list of modules, input_modules(). Private to the input layer and the constitutive laws'
// registrations (src/solvers/laws/), which declare their parameters with its helpers.
#ifndef MUPM_SRC_INPUT_MODULE_HPP
#define MUPM_SRC_INPUT_MODULE_HPP

#include <Teuchos_Array.hpp>
#include <Teuchos_ParameterList.hpp>
#include <Teuchos_StandardParameterEntryValidators.hpp>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "mupm/input/input.hpp"

namespace mupm {

struct InputModule {
  const char* list;  // its sublist of mupm
  const char* doc;   // the sublist's doc string
  // Sets the sublist's parameters (and example "NAME" sublists of user-named entries).
  void (*declare)(Teuchos::ParameterList& list);
  // Checks after Teuchos' validation, the whole input in view with its defaults filled in; throws
  // InputError naming the parameter's full path. nullptr: none.
  void (*check)(Teuchos::ParameterList& input);
  // FieldGroup bits a run of this input allocates for the module. nullptr: none.
  unsigned (*field_groups)(const Teuchos::ParameterList& input);
};

// In the order of the input's sublists (--print-defaults) and of the checks.
const std::vector<InputModule>& input_modules();

InputModule discretization_input();       // modules/discretization.cpp
InputModule materials_input();            // modules/materials.cpp
InputModule fluid_input();                // modules/fluid.cpp
InputModule fracture_input();             // modules/fracture.cpp
InputModule j_integral_input();           // modules/fracture.cpp
InputModule boundary_conditions_input();  // modules/conditions.cpp
InputModule initial_conditions_input();   // modules/conditions.cpp
InputModule solver_input();               // modules/solver.cpp
InputModule output_input();               // modules/output.cpp
InputModule diagnostics_input();          // modules/output.cpp

// Helpers of the declarations and checks (input_module.cpp).
inline const std::vector<std::string> kFaces = {"-x", "+x", "-y", "+y", "-z", "+z"};
std::string path_of(const Teuchos::ParameterList& list, const std::string& name);
// The shortest text of x that reads back as x exactly (a change in the last bit is a change).
std::string exact(double x);
// "a, b or c" (`last` between the last two).
std::string joined(const std::vector<std::string>& v, const char* last = " or ");
template <class T>
Teuchos::RCP<Teuchos::EnhancedNumberValidator<T>> at_least(T lo) {
  return Teuchos::rcp(new Teuchos::EnhancedNumberValidator<T>(lo, std::numeric_limits<T>::max()));
}
Teuchos::RCP<Teuchos::EnhancedNumberValidator<double>> positive();
Teuchos::RCP<Teuchos::StringValidator> one_of(const std::vector<std::string>& v);
// The array `name` of list `l`, which must hold n values (`what` says what they are).
template <class T>
Teuchos::Array<T> get_array(const Teuchos::ParameterList& l, const std::string& name, std::size_t n,
                            const std::string& what) {
  Teuchos::Array<T> a = l.get<Teuchos::Array<T>>(name);
  if (static_cast<std::size_t>(a.size()) != n) {
    std::ostringstream s;
    s << "Error, " << path_of(l, name) << " must hold " << n << " values (" << what << "), not "
      << a.size() << ".";
    throw InputError(s.str());
  }
  return a;
}
// The horizon delta [m] of Discretization: Horizon, or Horizon Factor times Spacing.
double horizon_of(const Teuchos::ParameterList& discretization);
// Rows of a boundary layer `horizons` horizons thick: floor(horizons delta / dx) (grid_from_input).
double layer_rows(const Teuchos::ParameterList& discretization, double horizons);
// The names of Discretization's regions in the order of their bits in a condition's region mask
// (GridSpec::region_names): its Regions, then the boundary layers it asks for ('Layer -x', ...)
// by axis and side. Of a validated input (each listed face then has at least one row).
std::vector<std::string> region_names(const Teuchos::ParameterList& discretization);

}  // namespace mupm

#endif
