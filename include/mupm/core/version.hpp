// What `mupm --version` prints: mupm's version and git revision, and the configuration it was
// built with (Trilinos, Kokkos and its execution space, MPI, HDF5, the compiler).
#ifndef MUPM_CORE_VERSION_HPP
#define MUPM_CORE_VERSION_HPP

#include <string>

namespace mupm {

// "0.1.0" (CMakeLists.txt, project VERSION).
std::string version();
// `git describe --always --dirty` of the source tree at build time, or "unknown".
std::string git_revision();
// Several lines, the first "mupm <version> (git <revision>)". Needs no MPI_Init.
std::string version_text();

}  // namespace mupm

#endif
