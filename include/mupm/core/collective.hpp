// An error found on some ranks, thrown on all: every rank stops with the same message and no
// rank is left waiting in a collective call.
#ifndef MUPM_CORE_COLLECTIVE_HPP
#define MUPM_CORE_COLLECTIVE_HPP

#include <mpi.h>

#include <string>

namespace mupm {

// Throws the same CollectiveError on every rank if `local_error` is non-empty on any rank; the
// message is the one of the lowest failing rank (with " [on rank r]" when not every rank
// failed). Collective.
void agree(MPI_Comm comm, const std::string& local_error);

}  // namespace mupm

#endif
