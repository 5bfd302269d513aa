#!/usr/bin/env bash
# One command for a fresh Debian 12 machine (idempotent): set-up (Debian packages, cached OpenMP
# Trilinos), configure mupm in ./build, build what the command uses, then
#   bash cmake/bootstrap.sh quickstart   build mupm alone, run inputs/quickstart.xml on 2 ranks
#                                        (build/quickstart)
#   bash cmake/bootstrap.sh test         build mupm and its tests, run every test but the slow
#                                        tier (ctest -LE slow)
#   bash cmake/bootstrap.sh slow         build mupm and its tests, run the slow tier (ctest -L
#                                        slow: minutes-long accuracy runs; .ci/run runs it)
#   bash cmake/bootstrap.sh build        build everything (mupm, tests, benchmarks)
#   bash cmake/bootstrap.sh sanitize     build mupm and its tests with ASan + UBSan in
#                                        ./build-sanitize instead and run the tests labelled
#                                        sanitize there (ctest -L sanitize)
# Each stage's time is printed at the end ("[mupm] times: ...").
set -euo pipefail
what=${1:-build}
case "$what" in
  build | quickstart | test | slow | sanitize) ;;
  *)
    echo "usage: bash cmake/bootstrap.sh [build|quickstart|test|slow|sanitize]" >&2
    exit 1
    ;;
esac
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

t0=$SECONDS
times=""
stage() {  # stage NAME: the time since the last stage, added to the summary
  times+="${times:+, }$1 $((SECONDS - t0)) s"
  t0=$SECONDS
}
trap '[[ -n $times ]] && echo "[mupm] times ($what): $times"' EXIT

prefix_line=$(bash cmake/setup.sh | tail -n 1)
prefix=${prefix_line#MUPM_TRILINOS_PREFIX=}
jobs=$(nproc)
stage set-up
# The targets the tests run (the tests' CMakeLists: mupm, the GoogleTest binary, the kernels'
# MPI-free compile check).
test_targets=(mupm mupm_tests mupm_kernels_free_of_mpi)
# mupm's objects through ccache (cmake/setup.sh installs it), keyed by paths relative to the
# clone: a second clone (CI's) compiles only what changed. Trilinos is built without it.
launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER= -DCMAKE_C_COMPILER_LAUNCHER=)
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR=$root CCACHE_NOHASHDIR=true
fi

if [[ $what == sanitize ]]; then
  # mupm (not Trilinos) instrumented with AddressSanitizer + UndefinedBehaviorSanitizer. The options
  # reach the MPI ranks: Open MPI passes mpirun's environment to the ranks it starts locally.
  cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMUPM_SANITIZE=ON \
    -DMUPM_ENABLE_BENCHMARKS=OFF -DCMAKE_PREFIX_PATH="$prefix" "${launcher[@]}" \
    >build-configure.log 2>&1 ||
    { cat build-configure.log; exit 1; }
  rm -f build-configure.log
  cmake --build build-sanitize -j"$jobs" --target "${test_targets[@]}"
  stage build
  # Open MPI leaks at exit by design: no leak checking here (README: checking leaks by hand).
  export ASAN_OPTIONS=detect_leaks=0
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  ctest --test-dir build-sanitize --output-on-failure -j"$jobs" -L sanitize
  stage ctest
  exit
fi

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$prefix" "${launcher[@]}" \
  >build-configure.log 2>&1 ||
  { cat build-configure.log; exit 1; }
rm -f build-configure.log
case "$what" in
  quickstart) targets=(mupm) ;;
  test | slow) targets=("${test_targets[@]}") ;;
  *) targets=(all) ;;
esac
cmake --build build -j"$jobs" --target "${targets[@]}"
stage build

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
    stage run
    ;;
  test)
    ctest --test-dir build --output-on-failure -j"$jobs" -LE slow
    stage ctest
    ;;
  slow)
    ctest --test-dir build --output-on-failure -j"$jobs" -L slow
    stage ctest
    ;;
esac
