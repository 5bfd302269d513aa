# Fails the configure with a clear message when the Kokkos found has no OpenMP backend: mupm's
# kernels are meant to run threaded, and Debian's own Trilinos packages ship Serial-only Kokkos.
function(mupm_check_kokkos_openmp)
  set(_has_openmp OFF)
  if(DEFINED Kokkos_DEVICES AND "OPENMP" IN_LIST Kokkos_DEVICES)
    set(_has_openmp ON)
  endif()
  if(NOT _has_openmp)
    # Fall back on the generated configuration header.
    find_file(_kokkos_cfg KokkosCore_config.h PATHS ${Kokkos_INCLUDE_DIRS} ${Kokkos_DIR}/../../../include
              NO_DEFAULT_PATH)
    if(_kokkos_cfg)
      file(STRINGS "${_kokkos_cfg}" _lines REGEX "^#define KOKKOS_ENABLE_OPENMP")
      if(_lines)
        set(_has_openmp ON)
      endif()
    endif()
  endif()
  if(NOT _has_openmp)
    message(FATAL_ERROR
      "The Kokkos found at ${Kokkos_DIR} has no OpenMP backend (Kokkos_DEVICES = '${Kokkos_DEVICES}'). "
      "mupm runs its kernels on Kokkos::OpenMP. Debian's Trilinos packages are Serial-only: run "
      "`bash cmake/setup.sh` to build an OpenMP Trilinos into the cache and pass the prefix it "
      "prints as -DCMAKE_PREFIX_PATH=<prefix>.")
  endif()
  message(STATUS "Kokkos: OpenMP backend found (${Kokkos_DIR})")
endfunction()
