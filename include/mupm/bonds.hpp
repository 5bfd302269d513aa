// Bonds of the owned points in CSR form (Cabana `VerletList`, Peridigm `bondDamage`):
// bonds of owned point i are offsets(i) .. offsets(i+1)-1, sorted by the neighbour's global id
// so that every sum over a family runs in the same order on any number of ranks.
#ifndef MUPM_BONDS_HPP
#define MUPM_BONDS_HPP

#include <cstddef>

#include "mupm/types.hpp"

namespace mupm {

struct Bonds {
  View1<BondIndex> offsets;  // [n_owned + 1]
  View1<LocalId> neighbor;   // local index (owned or ghost) of the other end
  Bytes intact;              // 1 intact, 0 broken (the paper's rho; influence omega = 1 * intact)
  Scalars energy;            // accumulated bond energy W_ij (eq 34)
  // Previous bond states, for second-order work (eq 42): [n_bonds][n_prev]; n_prev = 0 unless a
  // model asks for them (allocate_previous).
  Vectors previous;

  std::size_t n_points() const { return offsets.extent(0) == 0 ? 0 : offsets.extent(0) - 1; }
  std::size_t size() const { return neighbor.extent(0); }

  void allocate_previous(int n_prev) {
    previous = Vectors("mupm::bond_previous", size(), static_cast<std::size_t>(n_prev));
  }

  std::size_t bytes_per_bond() const {
    return sizeof(LocalId) + sizeof(std::uint8_t) + sizeof(double) +
           sizeof(double) * previous.extent(1);
  }
};

}  // namespace mupm

#endif
