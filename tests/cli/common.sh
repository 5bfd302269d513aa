# Shared by the command-line tests: arguments and an mpirun wrapper that never hangs.
set -euo pipefail
MUPM=$1
SRC=$2
WORK=$3
PYTHON=$4
MPIEXEC=$5
rm -rf "$WORK" && mkdir -p "$WORK" && cd "$WORK"
export OMP_PROC_BIND=false OMP_PLACES=threads OMP_WAIT_POLICY=passive
# run RANKS THREADS ARGS...: mupm under mpirun with a time limit.
run() {
  local ranks=$1 threads=$2
  shift 2
  OMP_NUM_THREADS=$threads timeout "${MUPM_RUN_TIMEOUT:-300}" "$MPIEXEC" --allow-run-as-root --oversubscribe \
    --bind-to none -np "$ranks" -x OMP_NUM_THREADS -x OMP_PROC_BIND -x OMP_PLACES -x OMP_WAIT_POLICY "$MUPM" "$@"
}
fail() {
  echo "FAIL: $*" >&2
  exit 1
}
