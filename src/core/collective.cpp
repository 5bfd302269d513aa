#include "mupm/core/collective.hpp"

#include <climits>

#include "mupm/core/error.hpp"

namespace mupm {

void agree(MPI_Comm comm, const std::string& local_error) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const bool failed = !local_error.empty();
  int in[2] = {failed ? rank : INT_MAX, failed ? 1 : 0};
  int out[2] = {0, 0};
  MPI_Allreduce(in, out, 2, MPI_INT, MPI_MIN, comm);
  const int first = out[0];
  if (first == INT_MAX) {
    return;
  }
  std::string msg = local_error;
  long long len = static_cast<long long>(msg.size());
  MPI_Bcast(&len, 1, MPI_LONG_LONG, first, comm);
  msg.resize(static_cast<std::size_t>(len));
  MPI_Bcast(msg.data(), static_cast<int>(len), MPI_CHAR, first, comm);
  const bool all_failed = out[1] == 1;
  int size = 1;
  MPI_Comm_size(comm, &size);
  if (!all_failed && size > 1) {
    msg += " [on rank " + std::to_string(first) + "]";
  }
  throw CollectiveError(msg);  // every rank throws it: the caller can stop cleanly
}

}  // namespace mupm
