// Reads and validates a mupm input with the installed library and prints its version and the
// input's point count (tests/cli/install.sh compares the count with the installed mupm's run).
#include <mpi.h>

#include <Teuchos_DefaultComm.hpp>
#include <exception>
#include <iostream>

#include "mupm/core/version.hpp"
#include "mupm/input/input.hpp"

int main(int argc, char* argv[]) {
  MPI_Init(&argc, &argv);
  int code = 0;
  try {
    auto comm = Teuchos::DefaultComm<int>::getComm();
    auto input = mupm::read_input(*comm, argc > 1 ? argv[1] : "");
    mupm::validate_input(*input);
    const auto grid = mupm::grid_from_input<2>(*input);
    std::cout << "mupm " << mupm::version() << " (git " << mupm::git_revision()
              << "): " << grid.n_global() << " points\n";
  } catch (const std::exception& e) {
    std::cerr << "consumer: " << e.what() << "\n";
    code = 2;
  }
  MPI_Finalize();
  return code;
}
