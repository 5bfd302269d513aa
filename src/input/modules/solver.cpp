#include "../input_module.hpp"

#include "mupm/input/options.hpp"
#include "mupm/solvers/linear_solve_settings.hpp"

namespace mupm {

using Teuchos::Array;
using Teuchos::ParameterList;
using Teuchos::rcp;

namespace {

void declare_solver(ParameterList& s) {
  s.set("Physics", std::string("Micropolar Solid"),
        "Physics advanced each step. Micropolar Solid: the stabilized micropolar "
        "correspondence solid (Materials), explicit central difference. Kinematics Only: no "
        "internal forces (points move with their velocity); damage from intact bonds (eq 37) "
        "either way. Pore Fluid: unsaturated flow in a rigid skeleton (Fluid), explicit in "
        "p. Hydro-Mechanical: both, staggered (Staggering), coupled by the total stress "
        "sigma-bar - S_r p 1 (eq 46), the mixture density (eq 1) and the volume change rate "
        "(eq 117).",
        physics_options().validator());
  s.set("Staggering", std::string("Solid First"),
        "Order of the staggered step (Hydro-Mechanical). Solid First: the solid steps with "
        "the pressure held, then the fluid with the volume change they made. Fluid First: the "
        "fluid steps with the previous interval's volume change, then the solid with the new "
        "pressure (fluid-driven problems). Both agree as Time Step -> 0.",
        staggering_options().validator());
  s.set("Solid Steps Per Fluid Step", 1,
        "Hydro-Mechanical: the fluid advances once every this many solid steps, over their "
        "combined interval (a larger fluid step when flow is slow).",
        at_least(1));
  s.set("Fluid Substeps", 1,
        "Equal fluid steps per fluid interval (sub-cycling when flow is faster than the "
        "solid); 0: as many as Time Step Safety Factor x the estimated stable fluid step "
        "requires. With Physics = Pore Fluid the interval is Time Step (Automatic Time Step "
        "sets it to the safety factor x the stable fluid step). At most 1e6, the automatic "
        "choice's limit too (2147483647 ran for ever).",
        rcp(new Teuchos::EnhancedNumberValidator<int>(0, 1000000)));
  s.set("Pressure Integration", std::string("Explicit"),
        "Hydro-Mechanical: how the pore pressure is advanced. Explicit: forward Euler in p "
        "with the undrained split (the pore water's stiffness K_w/phi in the solid's stable "
        "step, the fluid's own stable step by substeps). Semi-Implicit: one linear solve per "
        "step (Pressure Solve) for the pressure at the step's end, with the volume change it "
        "gives the skeleton within the step (a pressure projection, include/mupm/solvers/"
        "pressure_projection.hpp): the step is the drained skeleton's, any K_w (Fluid->"
        "Incompressible), no fluid substeps; with Fracture Flow the fracture pressure is in the "
        "same solve (no K_w / a_min limit). Refused for now: Crack Water Force = Eq 17, "
        "Fluid Flux, and "
        "Staggering, Solid Steps Per Fluid Step, Fluid Substeps other than Solid First, 1, 1.",
        pressure_integration_options().validator());
  s.set("Pressure Stabilization", 1.0,
        "Semi-Implicit: G_p >= 0 of the projection's pressure stabilization, the flow "
        "stabilization's bond-wise diffusion (eqs 72-78) on the step's pressure increment "
        "with the mobility G_p S_r^2 dt / rho in place of k_r k / mu_w. It holds the pressure "
        "modes the skeleton does not feel (checkerboards) whatever the permeability; "
        "without it incompressible water in a tight soil stalls the solve "
        "(include/mupm/solvers/pressure_projection.hpp).",
        at_least(0.0));
  {
    ParameterList& ps = s.sublist(
        "Pressure Solve", false,
        "The linear solve of Pressure Integration = Semi-Implicit (Trilinos: Belos' CG, or "
        "GMRES where mirrored pressure layers make the system unsymmetric; hypre's BoomerAMG "
        "or Ifpack2), distributed over the ranks like the points.");
    ps.set("Preconditioner", std::string("AMG"),
           "AMG: hypre's algebraic multigrid BoomerAMG, one V-cycle per iteration (its "
           "iterations stay bounded as the body is refined and over ranks; a set-up failure "
           "stops the run unless AMG Fallback). ILU: Ifpack2's RILUK on each rank's rows (a "
           "solve that fails with it, e.g. at a zero pivot, is repeated with the ILU of the "
           "current values if it was kept from earlier ones, then with Jacobi for that "
           "matrix). Jacobi or None. Measured side by side: perf/README.md.",
           one_of({"AMG", "ILU", "Jacobi", "None"}));
    ps.set("AMG Strong Threshold", 0.25,
           "AMG: BoomerAMG's strength threshold theta in (0, 1): a_ij is a strong connection "
           "where -a_ij >= theta max_k(-a_ik). Larger: coarser levels grow sparser, for more "
           "iterations.",
           rcp(new Teuchos::EnhancedNumberValidator<double>(1e-3, 0.999)));
    ps.set("AMG Interpolation Entries", 4,
           "AMG: the interpolation's largest entries kept a row (BoomerAMG's P max "
           "elements); 0: all.",
           rcp(new Teuchos::EnhancedNumberValidator<int>(0, 64)));
    ps.set("AMG Aggressive Levels", 0,
           "AMG: levels coarsened aggressively (cheaper, sparser hierarchy; more iterations).",
           rcp(new Teuchos::EnhancedNumberValidator<int>(0, 10)));
    ps.set("AMG Drop Tolerance", 0.0,
           "AMG: the hierarchy is of the matrix less its entries |a_ij| < this x "
           "sqrt(|a_ii a_jj|), each added to the diagonal (as Drop Tolerance for ILU). Cheaper "
           "V-cycles (Example 1 case 1 at 100 x 100: 0.005 makes a solve 1.3 times faster), "
           "but the added diagonal acts on the smoothest pressure modes, so the iterations grow "
           "under refinement (0.02: 21, 43, 117 iterations at 1e4, 4e4, 1.6e5 points, against "
           "11, 11, 12 with 0; perf/README.md). 0: the whole matrix.",
           rcp(new Teuchos::EnhancedNumberValidator<double>(0.0, 1.0)));
    ps.set("AMG Fallback", false,
           "AMG: where BoomerAMG's set-up fails, continue with ILU for that matrix's values "
           "instead of stopping the run (exit 3).");
    ps.set("ILU Fill Level", 0, "Level of fill k of ILU(k).", at_least(0));
    ps.set("Drop Tolerance", 0.02,
           "ILU: the factors are of the matrix without its entries |a_ij| < "
           "this x "
           "sqrt(|a_ii a_jj|), each added to the diagonal (the preconditioner stays symmetric "
           "positive definite; the solve is still of the whole matrix). The projection's "
           "matrix is two horizons wide with small far entries: 0.02 keeps about a quarter "
           "of them (an apply 3.6 times cheaper, 40 % more iterations, measured on Example 1 "
           "case 1). 0: the whole matrix.",
           rcp(new Teuchos::EnhancedNumberValidator<double>(0.0, 1.0)));
    ps.set("Preconditioner Refresh Interval", 100,
           "When the matrix's values change (every step with a fracture network or "
           "unsaturated water, at each step that breaks bonds) the preconditioner is computed "
           "again on every this-many-th change and at the step after a checkpoint (so that a "
           "restart continues bit for bit), and kept in between; the solve still reaches "
           "Tolerance on the current matrix, only its iterations depend on it. 1: every "
           "change. A new matrix graph (points joining the network) always computes it.",
           at_least(1));
    ps.set("Refresh Iteration Growth", 1.5,
           "When the preconditioner is kept from earlier values (Preconditioner Refresh "
           "Interval), it is computed again at the next change once a solve takes more than "
           "this many times the iterations of the first solve after its set-up (values "
           "drifted). At most 1 (0 for instance): only the interval decides.",
           rcp(new Teuchos::EnhancedNumberValidator<double>(0.0, 1e6)));
    ps.set("Tolerance", 1e-11,
           "Residual ||b - A x|| at which the solve stops, relative to the largest right-hand "
           "side ||b|| of the run so far (the water balances of a step): every point's water "
           "balance holds to it (the CSV's fluid_mass_error accumulates it). About one CG "
           "iteration a decade with AMG; Example 1's inputs take 1e-8 (the fields within 3e-10 "
           "of a 1e-11 run's, the same crack, perf/README.md).",
           rcp(new Teuchos::EnhancedNumberValidator<double>(1e-15, 1e-2)));
    ps.set("Maximum Iterations", 1000, "A solve not converged by then stops the run (exit 3).",
           at_least(1));
    ps.set("Recycled Vectors", 0,
           "> 0: CG becomes Belos' recycling CG (RCG): approximate eigenvectors of the "
           "smallest eigenvalues, this many, gathered over the steps and deflated from every "
           "later solve, for this many extra products and preconditioner applies per step. "
           "Pays where a solve takes many iterations (Example 1 case 1 at 100 x 100: 54 "
           "preconditioner applies a step become 28, the solve 1.3 times faster with 10, "
           "perf/README.md). The "
           "space is dropped at each checkpoint, so a restart continues bit for bit. Not "
           "used with GMRES (mirrored pressure layers). 0: CG. At most " +
               std::to_string(kRcgCycle - 1) + " (RCG gathers the space every " +
               std::to_string(kRcgCycle) + " iterations).",
           rcp(new Teuchos::EnhancedNumberValidator<int>(0, kRcgCycle - 1)));
  }
  s.set("Time Step", 1e-6, "Time step dt [s] (> 0).", positive());
  s.set("Automatic Time Step", false,
        "Use Time Step Safety Factor x the estimated stable step instead of Time Step.");
  s.set("Time Step Safety Factor", 0.5,
        "Fraction of the estimated stable step (power iteration on the discrete operator) used "
        "by Automatic Time Step, and the limit above which Time Step draws a warning.",
        rcp(new Teuchos::EnhancedNumberValidator<double>(1e-6, 1.0)));
  s.set("Gravity", Array<double>(), "Gravitational acceleration [m/s^2] (Dim values; default 0).");
  s.set("Damping", 0.0,
        "Mass-proportional damping c [1/s] (a = f/rho - c v), for quasi-static runs by dynamic "
        "relaxation; 0: none.",
        at_least(0.0));
  s.set("Energy Tolerance", 1e-2,
        "Largest accepted |E_int + E_kin - dt^2/8 sum m|a|^2 + D - W_ext - W_pore - E_0| "
        "(solid, eqs 137-140, with the central difference's kinetic energy) and "
        "|E_s - E_s0 + W_c + D_f - W_ext,f| (fluid, eqs 147-149) relative to the largest of "
        "their terms; beyond it a warning with the step.",
        at_least(0.0));
  s.set("Stop On Energy Violation", false, "Stop the run when the energy balance is violated.");
  s.set("Energy Check Start", 20,
        "Steps after the start (or a restart) before the energy balances are checked: in the "
        "first steps from rest every term is tiny and the scheme's start-up error (forward "
        "Euler weighs the first fluid step with p = 0; the first solid steps of a ramped load) "
        "is of the same size as the terms.",
        at_least(0));
  s.set("Number of Steps", 100,
        "Number of time steps (>= 0): the last step number (a restart continues up to it). "
        "Not used when End Time > 0.",
        at_least(0));
  s.set("End Time", 0.0,
        "Simulated time to run to [s]; > 0: the run ends on the first step whose time reaches "
        "it (within 1e-6 dt), ceil(End Time / dt) steps with the dt in use (Automatic Time "
        "Step's estimate, or Time Step; a restart may take another), and Number of Steps is "
        "not used; 0: run Number of Steps. More than 1e12 steps is refused.",
        at_least(0.0));
  s.set("Restart From", std::string(""),
        "Checkpoint file (.h5) to continue from; empty: start at t = 0. The run may use a "
        "different number of ranks and threads than the one that wrote it.");
}

// Solver->Pressure Integration = Semi-Implicit (include/mupm/solvers/pressure_projection.hpp):
// what it takes and what it does not have yet; Fluid->Incompressible needs it.
void check_pressure_integration(const ParameterList& input) {
  const ParameterList& solver = input.sublist("Solver");
  const std::string root = input.name();
  const bool si = pressure_integration_options()(solver.get<std::string>("Pressure Integration")) ==
                  PressureIntegration::SemiImplicit;
  const std::string path = root + "->Solver->Pressure Integration";
  if (input.sublist("Fluid").get<bool>("Incompressible") && !si)
    throw InputError("Error, " + root + "->Fluid->Incompressible = true needs " + path +
                     " = Semi-Implicit: the explicit scheme's stable steps (the solid's with "
                     "the undrained modulus K + K_w/phi, the fluid's with the storage phi/K_w) "
                     "shrink to zero as K_w grows.");
  if (!si)
    return;
  const std::string have = path + " = Semi-Implicit ";
  if (physics_options()(solver.get<std::string>("Physics")) != Physics::HydroMechanical)
    throw InputError("Error, " + have + "couples the pore pressure with the skeleton: it needs " +
                     root + "->Solver->Physics = Hydro-Mechanical.");
  // The crack water's force enters the joint solve as the transpose of the crack volume's
  // Jacobian (pressure_projection.hpp); eq 17's force on the fracture bonds has no such pair.
  const ParameterList& fracture = input.sublist("Fracture");
  if (fracture.get<bool>("Fracture Flow") &&
      crack_water_force_options()(fracture.get<std::string>("Crack Water Force")) !=
          CrackWaterForce::FacePressure)
    throw InputError("Error, " + have +
                     "solves the crack water's pressure with the face force "
                     "it does work through: " +
                     root +
                     "->Fracture->Crack Water Force must be Face Pressure (or use Explicit).");
  // Fluid Flux (an even image of the body's pressure in the layer): measured unstable with
  // incompressible water (inputs/consolidation.xml, mirrored layers, K_h / 100, the top drain a
  // Fluid Flux of 1e-6 m/s: the solid diverged at step 2130). Mirrored Pore Pressure layers
  // (odd images) run since the pressure stabilization (pressure_projection.hpp): the same input
  // with drains, K_h / 10 and / 100, closes its balances (solid 1e-6 J, water 5e-13 kg), and
  // Terzaghi's mirrored column is within 1 % (tests/solvers/test_fluid_solver.cpp).
  if (input.isSublist("Boundary Conditions")) {  // validated: every entry a sublist with a Type
    const ParameterList& bcs = input.sublist("Boundary Conditions");
    for (auto it = bcs.begin(); it != bcs.end(); ++it)
      if (bcs.sublist(bcs.name(it)).get<std::string>("Type") == "Fluid Flux")
        throw InputError("Error, " + have + "does not take " + root + "->Boundary Conditions->" +
                         bcs.name(it) +
                         "->Type = Fluid Flux yet: its layer's pressures, images of the body's, "
                         "were measured unstable with incompressible water. Use a Pore Pressure, "
                         "or Explicit.");
  }
  if (staggering_options()(solver.get<std::string>("Staggering")) != Staggering::SolidFirst ||
      solver.get<int>("Solid Steps Per Fluid Step") != 1 || solver.get<int>("Fluid Substeps") != 1)
    throw InputError("Error, " + have +
                     "solves the pressure once in every step, inside the "
                     "skeleton's step: " +
                     root +
                     "->Solver->Staggering, Solid Steps Per Fluid "
                     "Step and Fluid Substeps are for Explicit (leave them at Solid First, 1, 1).");
}

// Gravity fits the dimension; End Time asks for a number of steps that can run; the pressure
// integration's requirements.
void check_solver(ParameterList& input) {
  const int dim = input.sublist("Discretization").get<int>("Dimension");
  const ParameterList& solver = input.sublist("Solver");
  if (!solver.get<Array<double>>("Gravity").empty())
    get_array<double>(solver, "Gravity", dim, "m/s^2");
  // With Automatic Time Step the run checks it once dt is known (check_run_end).
  if (!solver.get<bool>("Automatic Time Step")) {
    const std::string why =
        end_time_steps_error(solver.get<double>("End Time"), 0, solver.get<double>("Time Step"),
                             "mupm->Solver->Time Step");
    if (!why.empty())
      throw InputError(why);
  }
  check_pressure_integration(input);
}

}  // namespace

InputModule solver_input() {
  return {"Solver", "Time stepping.", declare_solver, check_solver, nullptr};
}

}  // namespace mupm
