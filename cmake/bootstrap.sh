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

export OMP_PROC_BIND=${OMP_PROC_BIND:-false} OMP_PLACES=${OMP_PLACES:-threads}
mpirun_flags=(--bind-to none -x OMP_NUM_THREADS -x OMP_PROC_BIND -x OMP_PLACES)
[[ $(id -u) == 0 ]] && mpirun_flags+=(--allow-run-as-root)

case "$what" in
  quickstart)
    mkdir -p build/quickstart && cd build/quickstart
    OMP_NUM_THREADS=${OMP_NUM_THREADS:-1} mpirun "${mpirun_flags[@]}" -np 2 ../mupm \
      "$root/inputs/quickstart.xml"
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
