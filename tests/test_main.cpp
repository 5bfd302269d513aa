// The one GoogleTest main: initializes MPI and Kokkos (through Tpetra), prints from rank 0 only,
// and makes the exit code agree on every rank.
#include <gtest/gtest.h>
#include <mpi.h>

#include <Tpetra_Core.hpp>

int main(int argc, char* argv[]) {
  Tpetra::ScopeGuard scope(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank != 0) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  int failed = RUN_ALL_TESTS() != 0 ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &failed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return failed;
}
