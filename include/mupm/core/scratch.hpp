// Work space of an operation repeated in the time loop (a stable-step estimate after breakage,
// its saved fields): Views kept by name between calls, allocated on the first call and again
// only when their extents change, so that the loop allocates none (timers::loop_allocations).
#ifndef MUPM_SCRATCH_HPP
#define MUPM_SCRATCH_HPP

#include <map>
#include <string>

#include "mupm/core/types.hpp"

namespace mupm {

class Scratch {
 public:
  // The kept [n][m] View `name` (contents undefined).
  Vectors vectors(const std::string& name, std::size_t n, std::size_t m) {
    Vectors& v = vectors_[name];
    if (v.extent(0) != n || v.extent(1) != m)
      v = Vectors(Kokkos::view_alloc(Kokkos::WithoutInitializing, "mupm::scratch::" + name), n, m);
    return v;
  }
  // The kept [n] View `name` (contents undefined).
  Scalars scalars(const std::string& name, std::size_t n) {
    Scalars& s = scalars_[name];
    if (s.extent(0) != n)
      s = Scalars(Kokkos::view_alloc(Kokkos::WithoutInitializing, "mupm::scratch::" + name), n);
    return s;
  }
  // A kept copy of f under `name`.
  Vectors copy(const std::string& name, const Vectors& f) {
    Vectors c = vectors(name, f.extent(0), f.extent(1));
    Kokkos::deep_copy(c, f);
    return c;
  }
  Scalars copy(const std::string& name, const Scalars& f) {
    Scalars c = scalars(name, f.extent(0));
    Kokkos::deep_copy(c, f);
    return c;
  }

 private:
  std::map<std::string, Vectors> vectors_;
  std::map<std::string, Scalars> scalars_;
};

}  // namespace mupm

#endif
