// A named scalar a run keeps across a restart (include/mupm/io/checkpoint.hpp): a pointer to
// its owner's real value or integer count.
#ifndef MUPM_CORE_GLOBAL_REF_HPP
#define MUPM_CORE_GLOBAL_REF_HPP

#include <cmath>
#include <stdexcept>
#include <string>

namespace mupm {

// One named scalar kept across a restart: a real value or an integer count. The checkpoint
// stores either as a double (counts up to 2^53 exactly).
struct GlobalRef {
  std::string name;
  double* real = nullptr;
  long long* count = nullptr;
  double get() const { return real ? *real : double(*count); }
  // Throws std::domain_error for a count that is not a whole number of at most 2^53.
  void set(double v) const {
    if (real) {
      *real = v;
    } else if (std::isfinite(v) && std::fabs(v) <= 9007199254740992.0 && v == std::trunc(v)) {
      *count = static_cast<long long>(v);  // |v| <= 2^53: a whole number a double holds exactly
    } else {
      throw std::domain_error("the count '" + name + "' is stored as " + std::to_string(v) +
                              ", not a whole number");
    }
  }
};

}  // namespace mupm

#endif
