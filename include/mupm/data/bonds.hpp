// Bonds of the owned points in CSR form (Cabana `VerletList`, Peridigm `bondDamage`):
// bonds of owned point i are offsets(i) .. offsets(i+1)-1, sorted by the neighbour's global id
// so that every sum over a family runs in the same order on any number of ranks.
//
// Per-bond state is declared once in the registry (Bonds::for_each_field, traits of
// include/mupm/data/fields.hpp): allocation, bytes per bond and the checkpoint (by the global ids
// of both ends) follow from it. A new per-bond field is one member and one line there.
#ifndef MUPM_BONDS_HPP
#define MUPM_BONDS_HPP

#include <cstddef>

#include "mupm/core/types.hpp"
#include "mupm/data/fields.hpp"

namespace mupm {

struct Bonds {
  // Topology (built by build_bonds, include/mupm/mesh/neighbors.hpp).
  View1<BondIndex> offsets;  // [n_owned + 1]
  View1<LocalId> neighbor;   // local index (owned or ghost) of the other end
  // State.
  Bytes intact;    // 1 intact, 0 broken (the paper's rho; influence omega = 1 * intact)
  Scalars energy;  // accumulated bond energy W_ij (eq 34), per pair of unit volumes [J/m^6]
  // The pair's force and moment states (T_ij - T_ji, M_ij - M_ji) of the last force evaluation
  // [n_bonds][pair_width], for the trapezoid rule of the bond energy (include/mupm/kernels/
  // solid.hpp). Held only by runs that break bonds (pair_width = Dim + RotDim, else 0).
  Vectors pair_force;
  int pair_width = 0;

  template <class F>
  void for_each_field(F&& f) {
    visit(*this, f);
  }
  template <class F>
  void for_each_field(F&& f) const {
    visit(*this, f);
  }

  std::size_t n_points() const { return offsets.extent(0) == 0 ? 0 : offsets.extent(0) - 1; }
  std::size_t size() const { return neighbor.extent(0); }

  // The state fields for n bonds (the topology is the neighbour search's).
  void allocate_state(std::size_t n) {
    for_each_field([n](auto& view, const FieldSpec& s) { allocate_field(view, s, n); });
  }
  // Adds the pair force states of bond breakage (width Dim + RotDim), zero.
  void hold_pair_forces(int width) {
    pair_width = width;
    pair_force = Vectors("mupm::bond_pair_force", size(), std::size_t(width));
  }

  // Resident bytes of one bond; pair_width: that of a run that breaks bonds (0: none).
  static std::size_t bytes_per_bond(int pair_width = 0) {
    std::size_t b = sizeof(LocalId);
    Bonds probe;
    probe.pair_width = pair_width;
    probe.for_each_field([&b](const auto& view, const FieldSpec& s) {
      b += sizeof(typename std::decay_t<decltype(view)>::value_type) * std::size_t(s.ncomp);
    });
    return b;
  }

 private:
  template <class B, class F>
  static void visit(B& b, F& f) {
    f(b.intact, FieldSpec{"intact", 1, kCheckpoint});
    f(b.energy, FieldSpec{"energy", 1, kCheckpoint});
    if (b.pair_width > 0)
      f(b.pair_force, FieldSpec{"pair_force", b.pair_width, kCheckpoint});
  }
};

}  // namespace mupm

#endif
