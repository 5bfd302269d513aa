# Shared by cli_errors.sh and cli_guards.sh (after common.sh): a small valid input to derive bad
# ones from, and checks of a refused run's exit code and message.
# A rank that exits non-zero makes mpirun end the others, which it does after
# odls_base_sigkill_timeout (1 s by default: each refused input then took 2.4 s instead of 0.4 s);
# here every rank stops with the same error. The SIGTERM test keeps the default.
export OMPI_MCA_odls_base_sigkill_timeout=0

base() {  # base DISCRETIZATION_EXTRA SOLVER_EXTRA
  cat <<XML
<ParameterList name="mupm">
  <ParameterList name="Discretization">
    <Parameter name="Spacing" type="double" value="0.01"/>
    <Parameter name="Counts" type="Array(int)" value="{20, 10}"/>
    $1
  </ParameterList>
  <ParameterList name="Materials">
    <Parameter name="Bulk Modulus" type="double" value="1e8"/>
    <Parameter name="Shear Modulus" type="double" value="5e7"/>
    <Parameter name="Length Scale" type="double" value="1e-3"/>
  </ParameterList>
  <ParameterList name="Solver">
    <Parameter name="Number of Steps" type="int" value="2"/>
    $2
  </ParameterList>
  <ParameterList name="Output"><Parameter name="Folder" type="string" value="out"/></ParameterList>
</ParameterList>
XML
}

expect() {  # expect NAME CODE PATTERN... (input in NAME.xml)
  local name=$1 code=$2
  shift 2
  set +e
  run 2 1 "$name.xml" >"$name.out" 2>&1
  local got=$?
  set -e
  [[ $got == 124 ]] && fail "$name: timed out (hang)"
  [[ $got == "$code" ]] || { cat "$name.out"; fail "$name: exit code $got, expected $code"; }
  for p in "$@"; do
    grep -qF -- "$p" "$name.out" || { cat "$name.out"; fail "$name: message lacks '$p'"; }
  done
  echo "ok: $name (exit $got)"
}

expect_dir() {  # expect_dir NAME PATTERN ARGS...: exit 2 and one line of error
  local name=$1 pattern=$2
  shift 2
  set +e
  run 2 1 "$@" >"$name.out" 2>"$name.err"
  local got=$?
  set -e
  [[ $got == 2 ]] && grep -qF -- "$pattern" "$name.err" || { cat "$name.err"; fail "$name: exit $got"; }
  grep -q "HDF5-DIAG\|MPI_ERR\|packages/" "$name.err" && { cat "$name.err"; fail "$name: library noise"; }
  echo "ok: $name"
}
