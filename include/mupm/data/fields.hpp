// What the field registries (Points::for_each_field, Bonds::for_each_field) say of a field.
#ifndef MUPM_FIELDS_HPP
#define MUPM_FIELDS_HPP

#include <cstddef>
#include <string>

#include "mupm/core/types.hpp"

namespace mupm {

enum FieldTrait : unsigned {
  kConstant = 1u << 0,    // per-point constant: sent to the ghosts once, at discretization
  kGhosted = 1u << 1,     // state refreshed on the ghosts at a start and after a restart
  kCheckpoint = 1u << 2,  // kept by the checkpoint (points by global id, bonds by their ends)
  kOutput = 1u << 3,      // selectable in Output->Fields
  kFinite = 1u << 4,      // checked for NaN and Inf after every step (Diagnostics->Check Finite)
};

// Groups of point fields: a run allocates the groups its modules use (Points::groups,
// point_field_groups in src/input/input.cpp, from the input modules) and the fields of any group
// Output->Fields names.
enum FieldGroup : unsigned {
  kGroupCore = 1u << 0,       // every run: kinematics, stress, damage, the pressure the solid reads
  kGroupPoreWater = 1u << 1,  // the pore fluid's own state (Solver->Physics with a fluid)
  kGroupCrackWater = 1u << 2,  // the crack water (Fracture->Fracture Flow)
  kGroupPlastic = 1u << 3,     // the plastic state (Materials->Model = Micropolar Drucker-Prager)
  kGroupSecondOrderWork = 1u << 4,  // second-order work and its window's start (eq 42)
  kGroupRelease = 1u << 5,          // the J criterion's release force (J-Integral->Release Time)
  kAllGroups = (1u << 6) - 1,
};

struct FieldSpec {
  const char* name;  // output and checkpoint dataset name (snake_case)
  int ncomp;         // components per point (per bond for bond fields)
  unsigned traits;
  // Name under which Initial Conditions->NAME->Field sets it, or nullptr.
  const char* initial_condition = nullptr;
  unsigned group = kGroupCore;  // FieldGroup: allocated only in runs that use it
  bool has(unsigned t) const { return (traits & t) == t; }
};

// Allocates a registry field with n rows (n x ncomp for a rank-2 View; ncomp = 1 for rank 1).
template <class View>
void allocate_field(View& v, const FieldSpec& s, std::size_t n) {
  const std::string label = std::string("mupm::") + s.name;
  if constexpr (View::rank == 1)
    v = View(label, n);
  else
    v = View(label, n, std::size_t(s.ncomp));
}

}  // namespace mupm

#endif
