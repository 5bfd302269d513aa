// A polite stop: SIGTERM or SIGINT (a batch system's time limit, Ctrl-C) asks the run to finish
// its step, write a checkpoint and exit with kExitInterrupted.
#ifndef MUPM_STOP_HPP
#define MUPM_STOP_HPP

#include "mupm/core/error.hpp"

namespace mupm {

// Exit code of a run stopped by a signal after writing its checkpoint.
inline constexpr int kExitInterrupted = 4;

// Thrown on every rank once they agree a stop was asked for and the checkpoint is written.
struct Interrupted : CollectiveError {
  using CollectiveError::CollectiveError;
};

// Installs the handlers (they only set a flag).
void install_stop_handlers();
// Whether this process received SIGTERM or SIGINT since install_stop_handlers().
bool stop_requested();

}  // namespace mupm

#endif
