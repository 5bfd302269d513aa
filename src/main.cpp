// mupm: micro-periporomechanics simulations driven by a Teuchos XML input.
#include <mpi.h>
#include <Teuchos_DefaultComm.hpp>
#include <Teuchos_XMLParameterListCoreHelpers.hpp>
#include <Tpetra_Core.hpp>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>

#include "mupm/core/stop.hpp"
#include "mupm/core/version.hpp"
#include "mupm/input/input.hpp"
#include "mupm/input/model.hpp"
#include "mupm/io/checkpoint.hpp"
#include "mupm/io/point_rows.hpp"
#include "mupm/solvers/simulation.hpp"

namespace {

const char* kUsage =
    "usage: mupm INPUT.xml              run the simulation described by INPUT.xml\n"
    "       mupm --validate INPUT.xml   check the input only (exit 0 when valid)\n"
    "       mupm --print-defaults       print every parameter with its default and doc string\n"
    "       mupm --version              the version, git revision and build configuration\n"
    "       mupm --help                 this text\n"
    "Parallel: mpirun -np R mupm INPUT.xml, with OMP_NUM_THREADS=T threads per rank\n"
    "(also OMP_PROC_BIND=spread OMP_PLACES=threads). Kokkos options (--kokkos-...) are accepted.\n"
    "Exit codes: 0 success, 1 usage, 2 input error, 3 run-time error, 4 stopped by SIGTERM or\n"
    "SIGINT after writing a checkpoint.\n";

// --validate: the restart file matches the input's grid (the run checks it when it reads it).
void check_restart_file(const Teuchos::Comm<int>& comm, const Teuchos::ParameterList& input) {
  const std::string path = input.sublist("Solver").get<std::string>("Restart From");
  if (path.empty())
    return;
  const int dim = mupm::input_dimension(input);
  long long n = 0;
  double dx = 0, horizon = 0;
  if (dim == 2) {
    const auto g = mupm::grid_from_input<2>(input);
    n = g.n_global(), dx = g.dx, horizon = g.horizon;
  } else {
    const auto g = mupm::grid_from_input<3>(input);
    n = g.n_global(), dx = g.dx, horizon = g.horizon;
  }
  try {
    mupm::check_checkpoint(mupm::io::raw(comm), path, dim, n, dx, horizon,
                           mupm::fixed_settings(input));
  } catch (const mupm::CollectiveError& e) {
    throw mupm::InputError(mupm::restart_from_error(path, e));
  }
}

// Writes the input's verdict or the defaults without starting Kokkos, whose start-up chatter
// (affinity warnings, its --help banner) would otherwise land in stdout before them.
int without_kokkos(const std::string& mode, const std::string& path, int argc, char* argv[]) {
  MPI_Init(&argc, &argv);
  int code = 0;
  {
    auto comm = Teuchos::DefaultComm<int>::getComm();
    const bool root = comm->getRank() == 0;
    if (mode == "help") {
      if (root)
        std::cout << kUsage;
    } else if (mode == "defaults") {
      if (root)
        Teuchos::writeParameterListToXmlOStream(*mupm::valid_parameters(), std::cout);
    } else {
      try {
        auto input = mupm::read_input(*comm, path);
        mupm::validate_input(*input);
        mupm::check_files(*comm, *input);
        check_restart_file(*comm, *input);
        const auto m = mupm::check_memory(*comm, *input);
        if (root)
          std::cout << "mupm: " << path << " is valid; it needs about "
                    << m.bytes_per_rank / (1 << 20) << " MiB per rank on " << comm->getSize()
                    << " rank(s) (" << m.available_per_rank / (1 << 20)
                    << " MiB available per rank); its point fields take " << m.point_field_bytes
                    << " bytes per point\n";
      } catch (const mupm::InputError& e) {
        if (root)
          std::cerr << "mupm: input error in " << path << ":\n" << e.what() << "\n";
        code = 2;
      }
    }
  }
  MPI_Finalize();
  return code;
}

}  // namespace

int main(int argc, char* argv[]) {
  // Usage errors come before MPI starts: print them once, on Open MPI's rank 0 (or when run
  // without mpirun).
  const char* rank_env = std::getenv("OMPI_COMM_WORLD_RANK");
  const bool first = !rank_env || std::string(rank_env) == "0";
  std::string mode = "run", path;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a.rfind("--kokkos", 0) == 0) {
      continue;  // Kokkos' own options, taken by Kokkos when it starts
    } else if (a == "--help" || a == "-h") {
      mode = "help";
    } else if (a == "--version") {
      if (first)
        std::cout << mupm::version_text();
      return 0;
    } else if (a == "--print-defaults") {
      mode = "defaults";
    } else if (a == "--validate") {
      mode = "validate";
    } else if (!a.empty() && a[0] == '-') {
      if (first)
        std::cerr << "mupm: unknown option " << a << "\n" << kUsage;
      return 1;
    } else if (path.empty()) {
      path = a;
    } else {
      if (first)
        std::cerr << "mupm: more than one input file given\n" << kUsage;
      return 1;
    }
  }
  if ((mode == "run" || mode == "validate") && path.empty()) {
    if (first)
      std::cerr << "mupm: no input file given\n" << kUsage;
    return 1;
  }
  if (mode != "run")
    return without_kokkos(mode, path, argc, argv);
  Tpetra::ScopeGuard scope(&argc, &argv);
  auto comm = Tpetra::getDefaultComm();
  const bool root = comm->getRank() == 0;
  mupm::install_stop_handlers();
  try {
    auto input = mupm::read_input(*comm, path);
    mupm::validate_input(*input);
    mupm::check_files(*comm, *input);
    mupm::check_memory(*comm, *input);
    mupm::run_simulation(comm, *input, std::cout);
  } catch (const mupm::Interrupted& e) {
    if (root)
      std::cerr << "mupm: " << e.what() << "\n";
    return mupm::kExitInterrupted;
  } catch (const mupm::InputError& e) {
    if (root)
      std::cerr << "mupm: input error in " << path << ":\n" << e.what() << "\n";
    return 2;
  } catch (const mupm::CollectiveError& e) {
    if (root)
      std::cerr << "mupm: " << e.what() << "\n";
    return 3;
  } catch (const std::exception& e) {
    // Possibly thrown on this rank alone: stop every rank rather than leave them waiting.
    std::cerr << "mupm: rank " << comm->getRank() << ": " << e.what() << std::endl;
    if (comm->getSize() > 1)
      MPI_Abort(MPI_COMM_WORLD, 3);
    return 3;
  }
  return 0;
}
