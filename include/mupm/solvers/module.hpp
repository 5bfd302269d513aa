// A physics module of the driver (solid, fluid, damage; later fracture, J-integral, plasticity,
// second-order work): what it adds to the time series, which scalars it keeps across a restart,
// and the energy balances it checks. Each declares these once, name and value together.
#ifndef MUPM_MODULE_HPP
#define MUPM_MODULE_HPP

#include <mpi.h>

#include <string>
#include <utility>
#include <vector>

#include "mupm/core/global_ref.hpp"
#include "mupm/core/types.hpp"
#include "mupm/kernels/fracture.hpp"

namespace mupm {

// One row of time_series.csv: column names and values added together, in order. The header is
// the names of the first row.
class SeriesRow {
 public:
  void operator()(const std::string& column, double value) {
    names_.push_back(column);
    values_.push_back(value);
  }
  const std::vector<std::string>& names() const { return names_; }
  const std::vector<double>& values() const { return values_; }

 private:
  std::vector<std::string> names_;
  std::vector<double> values_;
};

// The named scalars a module keeps across a restart (cumulative work, inflows, counts...): the
// checkpoint stores each as globals/<module>/<name> and a restart puts it back by name.
class GlobalRefs {
 public:
  void operator()(const std::string& name, double& value) { refs_.push_back({name, &value}); }
  void operator()(const std::string& name, long long& value) {
    refs_.push_back({name, nullptr, &value});
  }
  const std::vector<GlobalRef>& refs() const { return refs_; }

 private:
  std::vector<GlobalRef> refs_;
};

// One energy balance: |error| should stay below Solver->Energy Tolerance x scale. A stored
// energy far beyond what was supplied means the scheme diverged (an unstable step).
struct EnergyBalance {
  std::string what;        // "solid", "fluid"
  std::string expression;  // the balance as a formula, for the message
  double error = 0;        // the balance's value [J]
  double scale = 0;        // the largest of its terms [J]
  std::string stored_expression, supplied_expression;
  double stored = 0;    // energy held now [J]
  double supplied = 0;  // all the energy there was at the start and came in since [J]
  // What came from outside the skeleton-water coupling [J]: the start, loads, sources,
  // boundary layers, and the water exchanged between pores and crack (booked by the bulk at its
  // pressure, by the crack at its own), signed; `gross` sums the same terms' magnitudes. The
  // work exchanged between the solid and the waters (W_pore, W_c, W_sk) is not in them: it
  // grows with a blow-up of the coupling itself (StepChecks::coupled in
  // src/solvers/driver/step_checks.hpp).
  std::string external_expression;
  double external = 0, gross = 0;
  const char* field = "displacement";  // registry field whose largest value locates a blow-up
  std::string hint;  // what may have made it diverge beyond the time step (for the message)
};

class Module {
 public:
  virtual ~Module() = default;
  // Prefix of the module's restart globals.
  virtual const char* name() const = 0;
  // Columns and values of the time series (collective: may reduce over ranks).
  virtual void series(SeriesRow&) const {}
  // Restart globals (references to the module's own members).
  virtual void globals(GlobalRefs&) {}
  // Energy balances to check after each step (collective).
  virtual std::vector<EnergyBalance> energy_balances() const { return {}; }
  // A checkpoint of this step was written: state that is not in it (a kept preconditioner) is
  // renewed before the next step, as a restart from it builds it anew (collective).
  virtual void checkpointed() {}
};

// What advances u and theta in a step (the micropolar solid, or kinematics alone).
class Mechanics : public Module {
 public:
  // Boundary values and the forces of the state at t; at a start (not a restart, whose state
  // holds them) also the accelerations.
  virtual void initialize(double t, bool restarted) = 0;
  virtual void step(double t, double dt) = 0;
  // The same step in parts, with the bond breakage on the forces at t + dt between them
  // (StepSequence): step_to_forces up to those forces and the step's work; energy_breakage, the
  // energy criterion (Algorithm 4) on the step's bond energies; complete_step with all the bonds
  // broken on this rank (by the energy and J criteria; collective). Without forces (kinematics
  // alone) the whole step is the first part and nothing breaks.
  virtual void step_to_forces(double t, double dt) { step(t, dt); }
  virtual Breakage energy_breakage() { return {}; }
  virtual void complete_step(double /*t*/, double /*dt*/, const Breakage& /*broken*/) {}
  // The run's step, once chosen (after initialize): energies that depend on it.
  virtual void set_time_step(double /*dt*/) {}
  // Whether the scheme has a stability limit, and the largest stable step (collective).
  virtual bool limits_time_step() const { return false; }
  virtual double stable_time_step() { return 0.0; }
  // One line on the model and its constants, for the run's report.
  virtual std::string describe() const { return name(); }
  // Mixture density and micro-inertia after the fluid changed the saturation (eq 1).
  virtual void update_density() {}
  // Bond pairs broken since t = 0 (the same number on every rank).
  virtual long long broken_pairs() const { return 0; }
};

// The skeleton as the semi-implicit pressure step sees it (include/mupm/solvers/
// pressure_projection.hpp): (u, theta) at the step's start [n_owned][Dim + R] (after move()),
// the density rho and micro-inertia J [n_owned] of its lumped masses, and plastic_shift
// [n_owned]: the plastic thickness change of the last forces evaluated (plane stress with pore
// water, include/mupm/laws/micropolar_drucker_prager.hpp: pore_shift at their state minus at the
// step's start), a View the skeleton updates at each evaluation; empty where there is none.
struct SkeletonState {
  Vectors start;
  Scalars density, inertia, plastic_shift;
};

// A mechanics whose step the semi-implicit pressure splits: move() advances the positions,
// the pressure step corrects the free components of (u, v, theta, omega), finish() does the
// rest (step() is move() then finish()).
class Skeleton {
 public:
  virtual ~Skeleton() = default;
  virtual void move(double t, double dt) = 0;
  // The rest of the step after the pressure correction, in the parts of
  // Mechanics::step_to_forces / complete_step (the bond breakage between them).
  virtual void finish_forces(double t, double dt) = 0;
  virtual void complete(double t, double dt, const Breakage& broken) = 0;
  virtual SkeletonState skeleton_state() const = 0;
  // The correction's work on the skeleton [J] (summed over ranks), for the energy ledger.
  virtual void add_projection_work(double w) = 0;
};

// sum_i f_i V_i over the owned points of all ranks (e.g. a water content times the volume).
inline double volume_integral(const Scalars& f, const Scalars& vol, std::size_t n_owned,
                              MPI_Comm comm) {
  double s = 0;
  Kokkos::parallel_reduce(
      "mupm::volume_integral", range(0, n_owned),
      KOKKOS_LAMBDA(const std::size_t i, double& acc) { acc += f(i) * vol(i); }, s);
  MPI_Allreduce(MPI_IN_PLACE, &s, 1, MPI_DOUBLE, MPI_SUM, comm);
  return s;
}

}  // namespace mupm

#endif
