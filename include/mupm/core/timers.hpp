// Per-kernel timing through Kokkos' tool callbacks: every labelled parallel_for/reduce/scan and
// every ScopedRegion is timed in-process (on the OpenMP backend a kernel returns when it is
// done, so its launch-to-return time is its run time). Left off when an external Kokkos tool is
// loaded (KOKKOS_TOOLS_LIBS / KOKKOS_PROFILE_LIBRARY), so that tool keeps the callbacks.
#ifndef MUPM_TIMERS_HPP
#define MUPM_TIMERS_HPP

#include <mpi.h>

#include <ostream>
#include <string>
#include <vector>

namespace mupm::timers {

struct Entry {
  std::string label;
  bool region = false;  // a ScopedRegion (includes the kernels inside it) or a kernel
  double seconds = 0;
  long long calls = 0;
};

// Installs the callbacks (after Kokkos::initialize). Returns false if an external tool owns them.
bool enable();
void disable();
void reset();
// Marks the time loop: View allocations between time_loop(true) and time_loop(false) are
// counted by label and reported.
void time_loop(bool inside);
// This rank's View allocations counted since enable() or reset() (time_loop).
long long loop_allocations();
std::vector<Entry> local_entries();

// Collective: prints, on rank 0 of comm, one line per label of rank 0 with calls and the min and
// max over ranks of its seconds, sorted by max time, kernels and regions apart.
void report(MPI_Comm comm, std::ostream& out);

}  // namespace mupm::timers

#endif
