// Error types. A CollectiveError is thrown by every rank alike, so every rank can stop cleanly
// with the same message and no rank is left waiting in a collective call.
#ifndef MUPM_ERROR_HPP
#define MUPM_ERROR_HPP

#include <stdexcept>

namespace mupm {

struct CollectiveError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace mupm

#endif
