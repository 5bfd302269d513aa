#!/usr/bin/env bash
# mupm one-stop set-up for a Debian 12 machine (idempotent).
#
#  1. installs the Debian packages mupm needs (only those missing; needs root);
#  2. provides a Trilinos 13.2 (Kokkos on OpenMP, Teuchos, KokkosKernels, Tpetra, and for the
#     distributed pressure solves Belos (Krylov solvers) and Ifpack2 (preconditioners)):
#     - if a Trilinos with Tpetra, Belos and Ifpack2 is found through CMAKE_PREFIX_PATH, that
#       one is used;
#     - otherwise it is built once from Debian's `trilinos` source package into
#       ${XDG_CACHE_HOME:-$HOME/.cache}/mupm/trilinos-13.2.0-<options hash>, and later
#       runs find the finished prefix and skip the build;
#  3. prints `MUPM_TRILINOS_PREFIX=<prefix>` as its last line.
#
# Usage: bash cmake/setup.sh            (all of the above)
#        MUPM_SKIP_APT=1 bash cmake/setup.sh   (skip package installation)
#        MUPM_TRILINOS_EXTRA='-D...' bash cmake/setup.sh   (a Trilinos with further options)
set -euo pipefail

log() { printf '[mupm setup] %s\n' "$*" >&2; }

TRILINOS_VERSION=13.2.0
PACKAGES=(cmake make g++ pkg-config libopenmpi-dev openmpi-bin libhdf5-openmpi-dev
  libgtest-dev libgmock-dev libbenchmark-dev libblas-dev liblapack-dev libhypre64m-dev
  python3 python3-matplotlib python3-h5py python3-numpy clang-format ccache)

# ---------------------------------------------------------------- packages
install_packages() {
  if [[ "${MUPM_SKIP_APT:-0}" == 1 ]]; then return; fi
  local missing=()
  for p in "${PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("$p")
    fi
  done
  if ((${#missing[@]} == 0)); then
    log "Debian packages: all present"
    return
  fi
  if [[ $(id -u) != 0 ]]; then
    log "missing Debian packages: ${missing[*]} (run this script as root to install them)"
    exit 1
  fi
  log "installing: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

# ---------------------------------------------------------------- Trilinos
TRILINOS_OPTIONS=(
  -DCMAKE_BUILD_TYPE=Release -DBUILD_SHARED_LIBS=ON
  -DTrilinos_ENABLE_ALL_PACKAGES=OFF -DTrilinos_ENABLE_ALL_OPTIONAL_PACKAGES=OFF
  -DTrilinos_ENABLE_Tpetra=ON -DTrilinos_ENABLE_Teuchos=ON -DTrilinos_ENABLE_Kokkos=ON
  -DTrilinos_ENABLE_KokkosKernels=ON -DTrilinos_ENABLE_Belos=ON -DTrilinos_ENABLE_Ifpack2=ON
  -DTrilinos_ENABLE_OpenMP=ON -DTPL_ENABLE_MPI=ON
  -DKokkos_ENABLE_SERIAL=OFF -DKokkos_ENABLE_OPENMP=ON
  -DKokkosKernels_ADD_DEFAULT_ETI=OFF
  -DTrilinos_ENABLE_TESTS=OFF -DTrilinos_ENABLE_EXAMPLES=OFF
  -DTpetra_INST_SERIAL=OFF -DTpetra_INST_OPENMP=ON -DTpetra_INST_DOUBLE=ON
  -DTpetra_INST_INT_LONG_LONG=ON -DTpetra_INST_COMPLEX_DOUBLE=OFF -DTpetra_INST_FLOAT=OFF
  -DTpetra_ENABLE_DEPRECATED_CODE=OFF -DTrilinos_ENABLE_Fortran=OFF
)
# MUPM_TRILINOS_EXTRA: further options (a separate cached build, e.g. for the MueLu measurements of
# perf/README.md, "Semi-implicit pressure solve"); empty by default, leaving the options' hash.
# shellcheck disable=SC2206
TRILINOS_OPTIONS+=(${MUPM_TRILINOS_EXTRA:-})

find_existing_trilinos() {
  local IFS=':;'
  for p in ${CMAKE_PREFIX_PATH:-}; do
    for d in "$p/lib/cmake/Tpetra" "$p/lib64/cmake/Tpetra" "$p/lib/x86_64-linux-gnu/cmake/Tpetra"; do
      # mupm's pressure solves need Belos and Ifpack2 from the same Trilinos.
      if [[ -f "$d/TpetraConfig.cmake" && -f "$d/../Belos/BelosConfig.cmake" &&
        -f "$d/../Ifpack2/Ifpack2Config.cmake" ]]; then
        echo "$p"
        return 0
      fi
    done
  done
  return 1
}

build_trilinos() {
  local hash cache prefix work
  hash=$(printf '%s\n' "$TRILINOS_VERSION" "${TRILINOS_OPTIONS[@]}" "$(g++ -dumpfullversion)" | sha1sum | cut -c1-10)
  cache="${XDG_CACHE_HOME:-$HOME/.cache}/mupm"
  prefix="$cache/trilinos-$TRILINOS_VERSION-$hash"
  if [[ -f "$prefix/.mupm-complete" ]]; then
    log "Trilinos: cached at $prefix"
    echo "$prefix"
    return
  fi
  mkdir -p "$cache"
  exec 9>"$cache/.trilinos-$hash.lock"
  log "Trilinos: waiting for the build lock" && flock 9
  if [[ -f "$prefix/.mupm-complete" ]]; then echo "$prefix"; return; fi
  work="$cache/build-trilinos-$hash"
  mkdir -p "$work"
  local src="$work/Trilinos-trilinos-release-${TRILINOS_VERSION//./-}"
  # The source package is kept in one place for every option set, so a changed option set
  # (a new hash) builds without fetching it again.
  local download="$cache/source"
  mkdir -p "$download"
  if [[ ! -d "$src/packages/tpetra" ]]; then
    if ! ls "$download"/trilinos_"$TRILINOS_VERSION".orig.tar.* >/dev/null 2>&1; then
      if ! grep -rqs '^Types:.*deb-src' /etc/apt/sources.list.d/ && ! grep -qs '^deb-src' /etc/apt/sources.list; then
        log "adding a deb-src entry for Debian bookworm"
        cat >/etc/apt/sources.list.d/mupm-deb-src.sources <<SRC
Types: deb-src
URIs: http://deb.debian.org/debian
Suites: bookworm
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SRC
        apt-get update -qq
      fi
      log "fetching Debian's trilinos source package"
      (cd "$download" && apt-get source --download-only trilinos >/dev/null)
    fi
    log "unpacking the Trilinos source"
    tar -C "$work" -xf "$download"/trilinos_"$TRILINOS_VERSION".orig.tar.*
  fi
  log "configuring Trilinos (log: $work/configure.log)"
  rm -rf "$work/build" && mkdir -p "$work/build"
  (cd "$work/build" && cmake "$src" -DCMAKE_INSTALL_PREFIX="$prefix" \
    "${TRILINOS_OPTIONS[@]}" >"$work/configure.log" 2>&1) ||
    { tail -n 40 "$work/configure.log" >&2; exit 1; }
  log "building Trilinos with $(nproc) jobs: about 12 minutes on 2 cores (log: $work/build.log)"
  local t0=$SECONDS
  (cd "$work/build" && make -j"$(nproc)" install >"$work/build.log" 2>&1) ||
    { tail -n 60 "$work/build.log" >&2; exit 1; }
  log "Trilinos built in $((SECONDS - t0)) s"
  touch "$prefix/.mupm-complete"
  rm -rf "$work/build" "$src"
  echo "$prefix"
}

install_packages
if prefix=$(find_existing_trilinos); then
  log "Trilinos: using $prefix from CMAKE_PREFIX_PATH"
else
  prefix=$(build_trilinos)
fi
echo "MUPM_TRILINOS_PREFIX=$prefix"
