#!/usr/bin/env bash
# One command for a fresh Debian 12 machine (idempotent): set-up (Debian packages, cached OpenMP
# Trilinos), configure and build mupm in ./build, then
#   bash cmake/bootstrap.sh quickstart   run inputs/quickstart.xml on 2 ranks (build/quickstart)
#   bash cmake/bootstrap.sh test         run the test suite (ctest)
#   bash cmake/bootstrap.sh build        only build
#   bash cmake/bootstrap.sh sanitize     build with ASan + UBSan in ./build-sanitize instead and run
#                                        the test suite there (ctest)
set -euo pipefail
what=${1:-build}
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

prefix_line=$(bash cmake/setup.sh | tail -n 1)
prefix=${prefix_line#MUPM_TRILINOS_PREFIX=}
jobs=$(nproc)

if [[ $what == sanitize ]]; then
  # mupm (not Trilinos) instrumented with AddressSanitizer + UndefinedBehaviorSanitizer. The options
  # reach the MPI ranks: Open MPI passes mpirun's environment to the ranks it starts locally.
  cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMUPM_SANITIZE=ON \
    -DMUPM_ENABLE_BENCHMARKS=OFF -DCMAKE_PREFIX_PATH="$prefix" >build-configure.log 2>&1 ||
    { cat build-configure.log; exit 1; }
  rm -f build-configure.log
  cmake --build build-sanitize -j"$jobs"
  # Open MPI leaks at exit by design: no leak checking here (README: checking leaks by hand).
  export ASAN_OPTIONS=detect_leaks=0
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  ctest --test-dir build-sanitize --output-on-failure -j"$jobs"
  exit
fi

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$prefix" >build-configure.log 2>&1 ||
  { cat build-configure.log; exit 1; }
rm -f build-configure.log
cmake --build build -j"$jobs"

case "$what" in
  quickstart)
    # 2 ranks x T threads, each rank on T cores of its own (README, "Ranks and threads"); on a
    # machine with fewer than 2 T cores the ranks share them unpinned.
    export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
    if ((jobs >= 2 * OMP_NUM_THREADS)); then
      export OMP_PROC_BIND=spread OMP_PLACES=cores
      mpirun_flags=(--map-by "ppr:2:node:PE=$OMP_NUM_THREADS" --bind-to core)
    else
      export OMP_PROC_BIND=false OMP_PLACES=threads
      mpirun_flags=(--oversubscribe --bind-to none)
    fi
    mpirun_flags+=(-x OMP_NUM_THREADS -x OMP_PROC_BIND -x OMP_PLACES)
    [[ $(id -u) == 0 ]] && mpirun_flags+=(--allow-run-as-root)
    mkdir -p build/quickstart && cd build/quickstart
    mpirun "${mpirun_flags[@]}" -np 2 ../mupm "$root/inputs/quickstart.xml"
    echo "Output in $root/build/quickstart/output: open fields.xmf in ParaView (Xdmf reader)."
    ;;
  test)
    ctest --test-dir build --output-on-failure -j"$jobs"
    ;;
  build) ;;
  *)
    echo "usage: bash cmake/bootstrap.sh [build|quickstart|test|sanitize]" >&2
    exit 1
    ;;
esac
