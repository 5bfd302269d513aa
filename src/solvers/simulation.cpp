#include "mupm/solvers/simulation.hpp"

#include <Teuchos_CommHelpers.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>

#include "mupm/core/stop.hpp"
#include "mupm/core/timers.hpp"
#include "mupm/input/model.hpp"
#include "mupm/io/checkpoint.hpp"
#include "mupm/io/csv.hpp"
#include "mupm/io/field_output.hpp"
#include "mupm/io/point_rows.hpp"
#include "mupm/solvers/j_integral.hpp"
#include "mupm/solvers/kinematics.hpp"
#include "mupm/solvers/solid_solver.hpp"
#include "mupm/solvers/step_sequence.hpp"

#include "driver/assembly.hpp"
#include "driver/run_environment.hpp"
#include "driver/step_checks.hpp"
#include "driver/time_step.hpp"

namespace mupm {

namespace {

using namespace driver;

// Reads Solver->Restart From: its errors are input errors naming the parameter.
template <int Dim>
void restart(const RunSettings& run, Discretization<Dim>& disc, long long& step, double& time,
             std::vector<double>& history, const NamedGlobals& globals) {
  try {
    read_checkpoint(run.restart_from, disc, step, time, history, globals, run.fixed);
  } catch (const CollectiveError& e) {
    throw InputError(restart_from_error(run.restart_from, e));
  }
}

template <int Dim>
RunSummary run(const Teuchos::RCP<const Teuchos::Comm<int>>& comm, Teuchos::ParameterList& input,
               std::ostream& out) {
  // ---------------------------------------------------------------- set-up
  const auto t_start = Clock::now();
  const MPI_Comm mpi = io::raw(*comm);
  const int rank = comm->getRank();
  const Model<Dim> model = model_from_input<Dim>(input);
  const RunSettings& run = model.run;
  const bool timers_on = run.kernel_timers && timers::enable();
  FolderLock lock;
  prepare_folder(*comm, run.folder, input, lock, out);
  for (const auto& w : model.warnings)
    if (rank == 0)
      out << "mupm: WARNING: " << w << ".\n";
  warn_placement(mpi, int(ExecSpace().concurrency()), out);

  Discretization<Dim> disc = discretize(comm, model.grid, model.run.field_groups);
  Points<Dim>& pts = disc.points;
  const int pair_width = model.fracture.criterion == BondBreaking::Energy ? Dim + kRotDim<Dim> : 0;
  const long long n_bonds = report_discretization(disc, *comm, pair_width, out);
  const long long n_global = disc.dist.n_global();
  check_regions(model, disc, mpi);
  initial_state(model, pts);
  Assembly<Dim> ph = assemble(model, disc, mpi);
  long long step = 0;
  double time = 0;
  std::vector<double> history;
  const bool restarted = !run.restart_from.empty();
  if (restarted) {
    restart(run, disc, step, time, history, ph.globals());
    if (rank == 0)
      out << "mupm: restarted from " << run.restart_from << " at step " << step << "\n";
  }
  if (ph.j_integral)  // a restart's increments: their points are fracture points (kFlagCut)
    ph.j_integral->mark_cuts();
  ph.damage->update();
  disc.dist.refresh(pts.double_fields(kGhosted));
  ph.damage->update_aperture();
  ph.initialize(time, restarted);
  const double dt = choose_time_step(run, ph, restarted, rank, out);
  if (ph.mechanics)
    ph.mechanics->set_time_step(dt);
  check_run_end(run, step, time, dt, restarted);
  if (rank == 0 && run.end_time > 0) {
    const long long last = expected_last_step(run, step, time, dt);
    out << "mupm: End Time = " << run.end_time << " s: the last step is " << last << " ("
        << last - step << " steps of " << dt << " s)\n";
  }
  // The time series continues from the checkpoint's row (after the checks: a restart refused
  // leaves it whole).
  if (restarted && rank == 0)
    io::keep_rows_through(run.folder + "/time_series.csv", double(step));

  FieldOutput<Dim> fields(run.folder, disc, run.fields, history);
  std::unique_ptr<io::CsvWriter> csv;
  auto write_series = [&] {
    ScopedRegion region("mupm::Output::time_series");
    SeriesRow row;
    row("step", double(step));
    row("time", time);
    row("max_displacement", max_displacement(pts, mpi));
    for (Module* m : ph.modules())
      m->series(row);
    row("wall_seconds", seconds_since(t_start));
    if (rank == 0 && !csv)
      csv =
          std::make_unique<io::CsvWriter>(run.folder + "/time_series.csv", row.names(), restarted);
    if (csv)
      csv->row(row.values());
  };
  const std::string checkpoint_path = run.folder + "/checkpoint.h5";
  auto checkpoint = [&] {
    write_checkpoint(checkpoint_path, disc, step, time, fields.history(), ph.globals(), run.fixed);
    for (Module* m : ph.modules())
      m->checkpointed();
  };
  if (!restarted) {
    fields.write(step, time);
    write_series();
  }

  // ---------------------------------------------------------------- loop
  const long long first_step = step;
  StepChecks<Dim> checks(run, disc, mpi, rank, out);
  StableStepWatch<Dim> stable_steps(run, ph, n_bonds, dt, restarted, rank, out);
  const auto t_loop = Clock::now();
  auto t_last_progress = t_loop;
  long long step_last_progress = first_step;
  double secs_last_progress = 0;
  while (!run_ended(run, step, time, dt)) {
    {
      ScopedRegion region("mupm::Solver::step");
      timers::time_loop(true);  // count the step's View allocations (not the output's)
      ph.sequence.step(step, time, dt);
      timers::time_loop(false);
    }
    ++step;
    time += dt;
    const bool last = run_ended(run, step, time, dt);
    checks(ph.modules(), step - first_step, step, time);
    stable_steps(step, time);
    if (step % run.series_interval == 0 || last)
      write_series();
    if ((run.field_interval > 0 && step % run.field_interval == 0) || last)
      fields.write(step, time);
    if (run.checkpoint_interval > 0 && step % run.checkpoint_interval == 0 && !last)
      checkpoint();
    // SIGTERM/SIGINT on any rank: checkpoint this step on all of them and stop.
    int stop = stop_requested() ? 1 : 0;
    MPI_Allreduce(MPI_IN_PLACE, &stop, 1, MPI_INT, MPI_MAX, mpi);
    if (stop && !last) {
      if (step % run.series_interval != 0)
        write_series();  // the row of the step the restart continues from
      checkpoint();
      throw Interrupted("stopped by a signal after step " + std::to_string(step) + " (t = " +
                        std::to_string(time) + " s); checkpoint written to " + checkpoint_path +
                        ": continue with Solver->Restart From = " + checkpoint_path + ".");
    }
    if (rank == 0 && (seconds_since(t_last_progress) >= run.progress_interval || last)) {
      t_last_progress = Clock::now();
      const double el = seconds_since(t_loop);
      const long long last_step = expected_last_step(run, step, time, dt);
      const double done = double(step - first_step), left = double(last_step - step);
      // The ETA at the pace since the last line: a step's cost changes in a run (the solve's
      // set-ups once bonds break cost ten times a step), and the mean since the start lags it.
      const double recent = double(step - step_last_progress), window = el - secs_last_progress;
      const double per_step = recent > 0 ? window / recent : (done > 0 ? el / done : 0);
      step_last_progress = step;
      secs_last_progress = el;
      char line[256];
      std::snprintf(line, sizeof line,
                    "step %lld/%lld (%.1f%%)  t = %.6g s  elapsed %s  ETA %s  %.3g point-steps/s\n",
                    step, last_step, 100.0 * double(step) / double(last_step), time,
                    format_seconds(el).c_str(), format_seconds(per_step * left).c_str(),
                    el > 0 ? double(n_global) * done / el : 0.0);
      out << line << std::flush;
    }
  }

  // ---------------------------------------------------------------- finish
  checks.finish(step, time);
  if (run.checkpoint_at_end)
    checkpoint();
  RunSummary summary;
  summary.steps = step - first_step;
  summary.wall_seconds = seconds_since(t_loop);
  summary.n_points = n_global;
  summary.n_bonds = n_bonds;
  if (timers_on) {
    timers::report(mpi, out);
    timers::disable();
  }
  if (rank == 0 && summary.steps > 0 && summary.wall_seconds > 0) {
    char line[256];
    std::snprintf(line, sizeof line,
                  "mupm: %lld steps in %s: %.4g point-steps/s, %.4g bond-updates/s\n",
                  summary.steps, format_seconds(summary.wall_seconds).c_str(),
                  double(n_global) * double(summary.steps) / summary.wall_seconds,
                  double(n_bonds) * double(summary.steps) / summary.wall_seconds);
    out << line;
  }
  return summary;
}

}  // namespace

RunSummary run_simulation(const Teuchos::RCP<const Teuchos::Comm<int>>& comm,
                          Teuchos::ParameterList& input, std::ostream& out) {
  return input_dimension(input) == 2 ? run<2>(comm, input, out) : run<3>(comm, input, out);
}

}  // namespace mupm
