#include "mupm/core/version.hpp"

#include <H5public.h>
#include <Trilinos_version.h>
#include <mpi.h>
#include <Kokkos_Core.hpp>

#include <sstream>

#include "mupm_revision.hpp"  // generated at build time (cmake/revision.cmake)

namespace mupm {

std::string version() {
  return MUPM_VERSION;
}

std::string git_revision() {
  return MUPM_GIT_REVISION;
}

std::string version_text() {
  std::ostringstream o;
  o << "mupm " << version() << " (git " << git_revision() << ")\n";
  o << "Trilinos " << TRILINOS_VERSION_STRING << " (Tpetra, Belos, Ifpack2); Kokkos "
    << KOKKOS_VERSION / 10000 << "." << KOKKOS_VERSION / 100 % 100 << "." << KOKKOS_VERSION % 100
    << ", execution space " << Kokkos::DefaultExecutionSpace::name() << "\n";
  // MPI_Get_library_version may be called before MPI_Init (MPI 3.1, section 8.7).
  char mpi[MPI_MAX_LIBRARY_VERSION_STRING];
  int len = 0;
  MPI_Get_library_version(mpi, &len);
  std::string m(mpi, std::size_t(len));
  m = m.substr(0, m.find_first_of("\n,"));
  o << "MPI: " << m << "\n";
  o << "HDF5 " << H5_VERS_MAJOR << "." << H5_VERS_MINOR << "." << H5_VERS_RELEASE
#ifdef H5_HAVE_PARALLEL
    << " (parallel)"
#endif
    << "\n";
  o << "Compiler: "
#if defined(__clang__)
    << "Clang "
#elif defined(__GNUC__)
    << "GCC "
#endif
    << __VERSION__ << ", C++ " << __cplusplus << "\n";
  return o.str();
}

}  // namespace mupm
