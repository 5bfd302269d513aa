# Sourced by the perf scripts: a cube of N^3 points with boundary layers on -z and +z.
# cube_input FOLDER N SPACING HORIZON_FACTOR STEPS PHYSICS BCS [SOLVER] [FLUID]: the input on
# stdout; BCS the Boundary Conditions' entries, SOLVER extra Solver parameters (default: a fixed
# Time Step of 1e-7 s), FLUID the Fluid list's parameters (none: no Fluid list, no porosity).
# The material is a soft soil skeleton (K = 10 MPa, G = 6 MPa, micropolar G_c = 3 MPa, l = the
# spacing, 2000 kg/m^3); no field output, no checkpoint, a time-series row every step.
cube_input() {
  local fluid="" porosity=""
  if [[ -n ${9:-} ]]; then
    fluid="<ParameterList name=\"Fluid\">$9</ParameterList>"
    porosity='<Parameter name="Porosity" type="double" value="0.3"/>'
  fi
  cat <<XML
<ParameterList name="mupm">
  <ParameterList name="Discretization">
    <Parameter name="Dimension" type="int" value="3"/>
    <Parameter name="Spacing" type="double" value="$3"/>
    <Parameter name="Counts" type="Array(int)" value="{$2, $2, $2}"/>
    <Parameter name="Horizon Factor" type="double" value="$4"/>
    <Parameter name="Boundary Layers" type="Array(string)" value="{-z, +z}"/>
  </ParameterList>
  <ParameterList name="Materials">
    <Parameter name="Bulk Modulus" type="double" value="10e6"/>
    <Parameter name="Shear Modulus" type="double" value="6e6"/>
    <Parameter name="Micropolar Shear Modulus" type="double" value="3e6"/>
    <Parameter name="Length Scale" type="double" value="$3"/>
    <Parameter name="Solid Density" type="double" value="2000"/>
    $porosity
  </ParameterList>
  $fluid
  <ParameterList name="Boundary Conditions">
    $7
  </ParameterList>
  <ParameterList name="Solver">
    <Parameter name="Physics" type="string" value="$6"/>
    ${8:-<Parameter name=\"Time Step\" type=\"double\" value=\"1e-7\"/>}
    <Parameter name="Number of Steps" type="int" value="$5"/>
  </ParameterList>
  <ParameterList name="Output">
    <Parameter name="Folder" type="string" value="$1"/>
    <Parameter name="Field Interval" type="int" value="0"/>
    <Parameter name="Checkpoint Interval" type="int" value="0"/>
    <Parameter name="Time Series Interval" type="int" value="1"/>
  </ParameterList>
</ParameterList>
XML
}
