# Shared by the command-line tests: arguments and an mpirun wrapper that never hangs.
set -euo pipefail
MUPM=$1
SRC=$2
WORK=$3
PYTHON=$4
MPIEXEC=$5
rm -rf "$WORK" && mkdir -p "$WORK" && cd "$WORK"
export OMP_PROC_BIND=false OMP_PLACES=threads
# run RANKS THREADS ARGS...: mupm under mpirun with a time limit. Idle threads spin where ranks x
# threads fit the cores and sleep where they do not (tests/CMakeLists.txt, mupm_wait_policy).
run() {
  local ranks=$1 threads=$2 policy=active
  shift 2
  ((ranks * threads > $(nproc))) && policy=passive
  OMP_WAIT_POLICY=$policy OMP_NUM_THREADS=$threads timeout "${MUPM_RUN_TIMEOUT:-300}" "$MPIEXEC" --allow-run-as-root --oversubscribe \
    --bind-to none -np "$ranks" -x OMP_NUM_THREADS -x OMP_PROC_BIND -x OMP_PLACES -x OMP_WAIT_POLICY "$MUPM" "$@"
}
fail() {
  echo "FAIL: $*" >&2
  exit 1
}
