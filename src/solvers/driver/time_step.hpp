// The run's time step: chosen from the modules' stable-step estimates, watched as the state
// changes, and the run's end.
// A part of the driver (src/solvers/simulation.cpp), which alone includes it.
#ifndef MUPM_DRIVER_TIME_STEP_HPP
#define MUPM_DRIVER_TIME_STEP_HPP

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <ostream>
#include <sstream>
#include <string>

#include "assembly.hpp"
#include "mupm/input/input.hpp"
#include "mupm/input/model.hpp"
#include "run_environment.hpp"

namespace mupm::driver {

// A stable-step estimate rounded down to 3 significant digits: the power iteration's sums over
// ranks differ in the last bits between rank counts, and an automatic step must not, or runs
// on different rank counts (and restarts) would diverge at round-off.
inline double three_digits(double x) {
  if (!(x > 0))
    return x;
  const double scale = std::pow(10.0, std::floor(std::log10(x)) - 2);
  return std::floor(x / scale * (1 + 1e-12)) * scale;
}

// The most fluid substeps per fluid interval a run may take (each costs about a solid step).
constexpr double kMaxFluidSubsteps = 1e6;

// Why automatic fluid substeps cannot run: the fluid is too stiff for the time step.
inline std::string too_stiff(const FluidParams& f, double dx, double stable_f, double interval,
                             double needed) {
  std::ostringstream s;
  s << "Error, the pore fluid's estimated stable step is " << stable_f << " s: a fluid interval of "
    << interval << " s would need " << needed
    << " substeps (Solver->Fluid Substeps = 0), beyond the " << kMaxFluidSubsteps
    << " a run can take. The fluid is that stiff through k/mu_w = " << f.mobility
    << " m^2/(Pa s) (mupm->Fluid->Hydraulic Conductivity, or Intrinsic Permeability / Viscosity), "
       "K_w = "
    << f.bulk_modulus << " Pa (mupm->Fluid->Fluid Bulk Modulus) and dx = " << dx
    << " m (mupm->Discretization->Spacing): the stable step scales as dx^2 C / (k/mu_w), C ~ "
       "phi/K_w. Check those values, or use a smaller Solver->Time Step.";
  return s.str();
}

// The run's end: Number of Steps, or with End Time > 0 the first step whose time reaches End Time
// (within a millionth of a step, so that an End Time of a whole number of steps takes no extra
// step for the round-off of the accumulated time). Decided on the accumulated time, which a
// checkpoint keeps: a restart ends on the step the straight run ends on, also with another dt.
constexpr double kEndTimeSlack = 1e-6;  // of a step (run_ended, expected_last_step)
inline bool run_ended(const RunSettings& run, long long step, double time, double dt) {
  return run.end_time > 0 ? time >= run.end_time - kEndTimeSlack * dt : step >= run.n_steps;
}
// The step run_ended will stop at, for the progress line: exact but for that round-off.
inline long long expected_last_step(const RunSettings& run, long long step, double time,
                                    double dt) {
  if (!(run.end_time > 0))
    return run.n_steps;
  const double left = std::ceil((run.end_time - time) / dt - kEndTimeSlack);
  return step + (left > 0 ? static_cast<long long>(left) : 0);
}
// Refuses a run that cannot end or a restart that would take no step (the same on every rank).
inline void check_run_end(const RunSettings& run, long long step, double time, double dt,
                          bool restarted) {
  if (run.end_time > 0 && !(std::isfinite(dt) && dt > 0)) {
    std::ostringstream s;
    s << "Error, mupm->Solver->End Time = " << run.end_time << " s: the time step is " << dt
      << " s, which never reaches it. Set Solver->Time Step (with Automatic Time Step = false).";
    throw InputError(s.str());
  }
  // Also where Automatic Time Step chose dt, and from a checkpoint's time: the step counts of
  // the progress line and of the run's end must stay meaningful.
  const std::string why = end_time_steps_error(
      run.end_time, time, dt,
      run.automatic_time_step ? "Automatic Time Step's estimate" : "mupm->Solver->Time Step");
  if (!why.empty())
    throw InputError(why);
  if (!restarted || !run_ended(run, step, time, dt))
    return;
  std::ostringstream given;
  if (run.end_time > 0)
    given << "mupm->Solver->End Time = " << run.end_time << " s is not beyond its time " << time
          << " s";
  else
    given << "mupm->Solver->Number of Steps = " << run.n_steps << " is not beyond it";
  throw InputError("Error, mupm->Solver->Restart From = '" + run.restart_from +
                   "': the checkpoint is at step " + std::to_string(step) + ", and " + given.str() +
                   ": the restart would take no step.");
}

// The time step and the fluid's substeps from the modules' stable-step estimates (Automatic
// Time Step, Fluid Substeps = 0), with warnings where the given ones exceed them.
template <int Dim>
double choose_time_step(const RunSettings& run, Assembly<Dim>& ph, bool restarted, int rank,
                        std::ostream& out) {
  const double safety = run.safety;
  double dt = run.time_step;
  Mechanics* solid =
      ph.mechanics && ph.mechanics->limits_time_step() ? ph.mechanics.get() : nullptr;
  // A restart continues with the step of the run it continues: the estimate of the restarted
  // state differs from that of the run's start (the crack water's stiffness, broken bonds,
  // saturation), and a new step would not continue it bit for bit (measured: Example 1's
  // 100 x 100 run restarted at t = 0.1 s took 5.8e-7 s for its 4.705e-7 s). A Time Step
  // given with Automatic Time Step = false is the user's choice and is taken.
  const bool kept = restarted && run.automatic_time_step && ph.watch.time_step > 0;
  if (solid) {
    const double stiffening = ph.fluid ? ph.fluid->undrained_stiffening() : 0.0;
    const double stable = three_digits(solid->stable_time_step());
    // Constants far outside their physical range (a modulus of 1e300 Pa, a density of
    // 1e-300 kg/m^3) leave no step to choose: say so, rather than let a zero step reach the
    // fluid's substep count (it read "would need -0 substeps").
    if (run.automatic_time_step && !kept && !(stable > 0 && std::isfinite(stable)))
      throw InputError(
          "Error, the solid's estimated stable step is " + shortest(stable) +
          " s: Solver->Automatic Time Step has no step to choose. It is 2 / omega_max of the "
          "discrete operator, from mupm->Materials (Bulk Modulus, Shear Modulus, Micropolar "
          "Shear Modulus, Length Scale, Solid Density, Porosity), the fluid's undrained "
          "stiffening and mupm->Discretization (Spacing, Thickness): check them for values "
          "beyond their physical range.");
    if (kept)
      dt = ph.watch.time_step;
    else if (run.automatic_time_step)
      dt = safety * stable;
    const bool implicit = ph.fluid && ph.fluid->semi_implicit();
    if (rank == 0) {
      out << "mupm: " << solid->describe() << "; estimated stable dt = " << stable << " s"
          << (implicit   ? " (drained: the pore pressure is semi-implicit)"
              : ph.fluid ? " (undrained: the pore water adds up to "
                         : "");
      if (ph.fluid && !implicit)
        out << stiffening << " Pa to the bulk modulus)";
      out << "; dt = " << dt << " s" << (kept ? " (the restarted run's)" : "") << "\n";
      if (dt > safety * stable)
        out << "mupm: WARNING: Solver->Time Step = " << dt << " s exceeds "
            << "Time Step Safety Factor x the estimated stable step = " << safety * stable
            << " s: the run may blow up. Use a smaller Time Step or Automatic Time Step.\n";
    }
  }
  if (ph.fluid && ph.fluid->semi_implicit() && rank == 0) {
    const auto& f = ph.fluid->params();
    const auto& ls = run.pressure_solve;
    out << "mupm: pore fluid, semi-implicit pressure: k/mu_w = " << f.mobility
        << " m^2/(Pa s), K_w = " << f.bulk_modulus
        << " Pa, flow stabilization G = " << f.stabilization
        << ", pressure stabilization G_p = " << f.projection_stabilization
        << "; one solve per step (" << ph.fluid->pressure_solve_method();
    if (ph.fluid->pressure_solve_method() == "RCG")
      out << " with " << ls.recycle << " recycled vectors";
    out << ", " << ls.preconditioner;
    if (ls.preconditioner == "ILU")
      out << "(" << ls.fill_level << ")";
    if (ls.preconditioner == "AMG")
      out << " (hypre BoomerAMG, strong threshold " << ls.amg_strong_threshold << ")";
    const double drop = ls.preconditioner == "AMG" ? ls.amg_drop_tolerance : ls.drop_tolerance;
    if (ls.preconditioner == "ILU" || ls.preconditioner == "AMG")
      out << " of the matrix less its entries below " << drop
          << " of the diagonals' geometric mean, kept up to " << ls.refresh_interval
          << " steps or until a solve takes " << ls.refresh_growth
          << " times the iterations of the first after it";
    out << ", tolerance " << ls.tolerance << ")\n";
  }
  if (ph.fluid && !ph.fluid->semi_implicit()) {
    auto& fluid = *ph.fluid;
    const double stable_f = three_digits(fluid.estimate_stable_dt());
    if (!(stable_f > 0 && std::isfinite(stable_f)) && (run.fluid_substeps == 0 || !solid))
      throw InputError(
          "Error, the pore fluid's estimated stable step is " + shortest(stable_f) +
          " s: no fluid step can be chosen. It is about dx^2 C / (k/mu_w), from "
          "mupm->Fluid (Hydraulic Conductivity or Intrinsic Permeability / Viscosity, Water "
          "Density, Fluid Bulk Modulus, the retention curve), mupm->Materials->Porosity and "
          "mupm->Discretization (Spacing, Thickness): check them for values beyond their "
          "physical range.");
    if (!solid && run.automatic_time_step)
      dt = kept ? ph.watch.time_step : safety * stable_f;
    const int every = ph.sequence.fluid_every;
    const double interval = every * dt;
    int substeps = run.fluid_substeps;
    if (substeps == 0) {
      // In double: a stiff fluid can need more substeps than an int holds.
      const double needed = std::ceil(interval / (safety * stable_f) - 1e-9);
      if (!(needed <= kMaxFluidSubsteps && stable_f > 0 && dt > 0))
        throw InputError(too_stiff(fluid.params(), ph.spacing, stable_f, interval, needed));
      substeps = std::max(1, int(needed));
    }
    // A restart continues with the substeps the run had reached (StableStepWatch).
    if (restarted && ph.watch.substeps > 0)
      substeps = static_cast<int>(ph.watch.substeps);
    ph.sequence.substeps = substeps;
    ph.watch.substeps = substeps;
    const double dt_f = interval / substeps;
    if (rank == 0) {
      out << "mupm: pore fluid, k/mu_w = " << fluid.params().mobility
          << " m^2/(Pa s), K_w = " << fluid.params().bulk_modulus
          << " Pa, flow stabilization G = " << fluid.params().stabilization
          << "; estimated stable fluid dt = " << stable_f << " s; fluid dt = " << dt_f << " s ("
          << substeps << " substep(s) every " << every << " step(s), "
          << (solid ? (ph.sequence.fluid_first ? "fluid first" : "solid first") : "fluid only")
          << ")\n";
      if (dt_f > safety * stable_f)
        out << "mupm: WARNING: the fluid step " << dt_f << " s exceeds Time Step Safety Factor x "
            << "the estimated stable fluid step = " << safety * stable_f
            << " s: the pressure may blow up. Raise Solver->Fluid Substeps (0: automatic).\n";
    }
  }
  ph.watch.time_step = dt;
  return dt;
}

// Stable steps that follow the state. The estimates of choose_time_step are for the initial
// state; two changes of the state can shrink them during a run:
//   - bonds break (the solid's and the fluid's operators change at the broken bonds' ends);
//   - points wet towards saturation (the storage C falls from phi dS_r/dp to phi S_r/K_w: the
//     fluid's diffusivity and the pore water's undrained stiffness S_r^2/C grow).
// After each step this re-estimates both when the broken bond pairs grew by 1 % of all pairs
// since the last estimate, or the smallest storage fell below half of its value then (both
// counted the same on every rank, and the estimates rounded to 3 digits, so every rank count
// takes the same decisions). With Fluid Substeps = 0 the substeps follow the new fluid
// estimate (automatic sub-cycling); otherwise, and for the solid step, which is fixed, a step
// beyond Time Step Safety Factor x the new estimate draws a warning naming the step, once per
// estimate (the divergence check stops a run that then blows up).
template <int Dim>
class StableStepWatch {
 public:
  StableStepWatch(const RunSettings& run, Assembly<Dim>& ph, long long n_bonds, double dt,
                  bool restarted, int rank, std::ostream& out)
      : run_(run), ph_(ph), pairs_(double(n_bonds) / 2), dt_(dt), rank_(rank), out_(out) {
    solid_ = ph.mechanics && ph.mechanics->limits_time_step() ? ph.mechanics.get() : nullptr;
    if (!restarted)  // a restart has the state of the run it continues (Assembly::watch)
      remember();
  }

  void operator()(long long step, double time) {
    const bool broke =
        solid_ && double(solid_->broken_pairs() - ph_.watch.pairs_at) >= 0.01 * pairs_;
    const bool wetted = ph_.fluid && !ph_.fluid->semi_implicit() &&
                        ph_.fluid->min_storage() < 0.5 * ph_.watch.storage_at;
    if (!broke && !wetted)
      return;
    ScopedRegion region("mupm::Solver::stable_step_update");
    std::ostringstream why;
    why << "at step " << step << " (t = " << time << " s), "
        << (broke ? "after bond breakage" : "after wetting") << ": ";
    if (solid_) {
      const double stable = three_digits(solid_->stable_time_step());
      if (rank_ == 0) {
        out_ << "mupm: " << why.str() << "estimated stable dt = " << stable << " s\n";
        // Beyond the estimate the scheme may blow up; between Time Step Safety Factor x the
        // estimate and the estimate it is stable, only with less margin than the input asked.
        if (dt_ > stable)
          out_ << "mupm: WARNING: " << why.str() << "Time Step = " << dt_
               << " s exceeds the estimated stable step = " << stable
               << " s: the run may blow up; restart from a checkpoint with a smaller Time Step.\n";
        else if (dt_ > run_.safety * stable)
          out_ << "mupm: " << why.str() << "Time Step = " << dt_ << " s is "
               << three_digits(dt_ / stable) << " of the estimated stable step, above Time "
               << "Step Safety Factor = " << run_.safety << "\n";
      }
    }
    if (ph_.fluid && !ph_.fluid->semi_implicit()) {
      const double stable_f = three_digits(ph_.fluid->estimate_stable_dt());
      const double interval = ph_.sequence.fluid_every * dt_;
      if (run_.fluid_substeps == 0) {
        const double needed = std::ceil(interval / (run_.safety * stable_f) - 1e-9);
        if (!(needed <= kMaxFluidSubsteps && stable_f > 0))
          throw CollectiveError(
              why.str() + too_stiff(ph_.fluid->params(), ph_.spacing, stable_f, interval, needed));
        ph_.sequence.substeps = std::max(ph_.sequence.substeps, int(needed));
        ph_.watch.substeps = ph_.sequence.substeps;
      }
      const double dt_f = interval / ph_.sequence.substeps;
      if (rank_ == 0) {
        out_ << "mupm: " << why.str() << "estimated stable fluid dt = " << stable_f
             << " s; fluid dt = " << dt_f << " s (" << ph_.sequence.substeps << " substep(s))\n";
        if (dt_f > run_.safety * stable_f)
          out_ << "mupm: WARNING: " << why.str() << "the fluid step " << dt_f
               << " s exceeds Time Step Safety Factor x the estimated stable fluid step = "
               << run_.safety * stable_f
               << " s: the pressure may blow up; use Solver->Fluid Substeps = 0 (automatic).\n";
      }
    }
    remember();
  }

 private:
  void remember() {
    ph_.watch.pairs_at = solid_ ? solid_->broken_pairs() : 0;
    ph_.watch.storage_at = ph_.fluid ? ph_.fluid->min_storage() : 0.0;
  }
  const RunSettings& run_;
  Assembly<Dim>& ph_;
  Mechanics* solid_ = nullptr;
  double pairs_;
  double dt_;
  int rank_;
  std::ostream& out_;
};

}  // namespace mupm::driver

#endif
