// Input layer: the Teuchos XML parameter list, read on rank 0 and broadcast, validated against
// the valid parameter lists below (defaults, doc strings, validators), and turned into the plain
// structs the lower layers take (no Teuchos below this layer).
#ifndef MUPM_INPUT_HPP
#define MUPM_INPUT_HPP

#include <Teuchos_Comm.hpp>
#include <Teuchos_ParameterList.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "mupm/core/error.hpp"
#include "mupm/kernels/boundary_conditions.hpp"
#include "mupm/mesh/grid.hpp"

namespace mupm {

// An error in the input. Its message names the parameter's full path and what was expected.
// Thrown on every rank alike (the list is identical on every rank after the broadcast).
struct InputError : CollectiveError {
  using CollectiveError::CollectiveError;
};

// Every parameter with its default, doc string and validator. User-named sublists (regions,
// pre-cracks, initial conditions) are shown by one example entry named "NAME".
Teuchos::RCP<Teuchos::ParameterList> valid_parameters();

// Reads the XML file on rank 0 and broadcasts it; every rank parses the same text. A missing
// file or malformed XML throws InputError on every rank.
Teuchos::RCP<Teuchos::ParameterList> read_input(const Teuchos::Comm<int>& comm,
                                                const std::string& path);
Teuchos::RCP<Teuchos::ParameterList> parse_input(const std::string& xml);

// Validates the list in place and fills in every default. Throws InputError.
void validate_input(Teuchos::ParameterList& input);

int input_dimension(const Teuchos::ParameterList& input);

// The most steps Solver->End Time may ask for: the step counter is a long long (9.2e18) but the
// time series writes it as a double (exact to 2^53 = 9e15), and 1e12 steps are beyond any run
// (a month at 4e5 steps per second); more is a mistaken End Time or Time Step.
inline constexpr double kMaxEndTimeSteps = 1e12;
// The message for End Time over Time Step beyond kMaxEndTimeSteps ("" when within), `dt_source`
// naming where dt comes from.
std::string end_time_steps_error(double end_time, double time, double dt,
                                 const std::string& dt_source);

template <int Dim>
GridSpec<Dim> grid_from_input(const Teuchos::ParameterList& input);

// Initial Conditions->NAME->Field value that sets the hydrostatic pore pressure (not a field).
inline constexpr const char* kHydrostaticPorePressure = "Hydrostatic Pore Pressure";

// One initial condition: set `field` (the initial-condition name of a registry field,
// include/mupm/data/points.hpp, or kHydrostaticPorePressure) to `value` on the points of
// `region_mask` (0: all points).
struct InitialCondition {
  std::string name, field;
  std::uint32_t region_mask = 0;
  std::vector<double> value;
};
std::vector<InitialCondition> initial_conditions_from_input(const Teuchos::ParameterList& input);

std::vector<BoundaryCondition> boundary_conditions_from_input(const Teuchos::ParameterList& input);

// The memory a run of this input needs per rank (points, bonds, solver state, ghost buffers;
// an estimate within tens of percent) and what the node offers per rank (MemAvailable / ranks
// on the node, the smallest over nodes). Collective over comm.
struct MemoryNeed {
  double points = 0, bonds_per_point = 0;
  double bytes_per_rank = 0, available_per_rank = 0;
  double point_field_bytes = 0;  // per point, of the point fields the run allocates
};
MemoryNeed memory_need(const Teuchos::Comm<int>& comm, const Teuchos::ParameterList& input);
// Throws InputError (on every rank) when the need exceeds what is available.
MemoryNeed check_memory(const Teuchos::Comm<int>& comm, const Teuchos::ParameterList& input);

// The files the input names, before any work: Solver->Restart From an HDF5 file, Output->Folder
// writable (or creatable). Throws InputError on every rank. Collective.
void check_files(const Teuchos::Comm<int>& comm, const Teuchos::ParameterList& input);

// The point-field groups (FieldGroup, include/mupm/data/fields.hpp) a run of this input
// allocates, of a validated input: those of its modules (a fluid: pore water; Fracture Flow:
// crack water; Micropolar Drucker-Prager: plastic and second-order work) and of every field
// Output->Fields names (second_order_work there also turns the second-order work on).
unsigned point_field_groups(const Teuchos::ParameterList& input);

// Names of the point fields that can be written (Output->Fields).
const std::vector<std::string>& output_field_names();

}  // namespace mupm

#endif
