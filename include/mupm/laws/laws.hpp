// The constitutive laws of pass 1 (include/mupm/kernels/solid.hpp) that mupm is built for: the
// solid solver and its force evaluation are compiled once for each (src/solvers/solid_*.cpp).
// A new law adds its header here and its line to MUPM_FOR_EACH_LAW, and its registration
// (include/mupm/input/law_registry.hpp), which the registry lists in this order.
#ifndef MUPM_LAWS_LAWS_HPP
#define MUPM_LAWS_LAWS_HPP

#include "mupm/laws/micropolar_drucker_prager.hpp"
#include "mupm/laws/micropolar_elastic.hpp"

// X(D, Law) for each law in dimension D.
#define MUPM_FOR_EACH_LAW(X, D) \
  X(D, MicropolarElastic)       \
  X(D, MicropolarDruckerPrager<D>)

#endif
