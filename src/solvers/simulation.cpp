#include "mupm/solvers/simulation.hpp"

#include <fcntl.h>
#include <sched.h>
#include <sys/file.h>
#include <unistd.h>
#include <Teuchos_CommHelpers.hpp>
#include <Teuchos_XMLParameterListCoreHelpers.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
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

namespace mupm {

namespace {

using Clock = std::chrono::steady_clock;

// A stable-step estimate rounded down to 3 significant digits: the power iteration's sums over
// ranks differ in the last bits between rank counts, and an automatic step must not, or runs
// on different rank counts (and restarts) would diverge at round-off.
double three_digits(double x) {
  if (!(x > 0))
    return x;
  const double scale = std::pow(10.0, std::floor(std::log10(x)) - 2);
  return std::floor(x / scale * (1 + 1e-12)) * scale;
}

std::string format_seconds(double s) {
  char buf[64];
  if (s < 120)
    std::snprintf(buf, sizeof buf, "%.1f s", s);
  else if (s < 7200)
    std::snprintf(buf, sizeof buf, "%.1f min", s / 60);
  else
    std::snprintf(buf, sizeof buf, "%.2f h", s / 3600);
  return buf;
}

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// The output folder's lock, held by rank 0 for the whole run: two runs writing one folder would
// interleave their time series and leave one's input beside the other's checkpoint. An advisory
// flock() on Output->Folder/run.lock, which the kernel releases when the process ends however it
// ends (a crash or SIGKILL leaves no stale lock; the file itself stays). The file holds the
// holder's process id and host for the message of a run refused.
class FolderLock {
 public:
  FolderLock() = default;
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;
  ~FolderLock() {
    if (fd_ >= 0)
      close(fd_);  // releases the lock
  }
  // "" when taken, else why not.
  std::string take(const std::string& folder) {
    const std::string path = folder + "/run.lock";
    fd_ = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0)
      return "cannot open " + path + ": " + std::strerror(errno);
    if (flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      char holder[256] = {};
      const ssize_t n = pread(fd_, holder, sizeof holder - 1, 0);
      std::string who = n > 0 ? std::string(holder, std::size_t(n)) : "";
      while (!who.empty() && (who.back() == '\n' || who.back() == ' '))
        who.pop_back();
      close(fd_);
      fd_ = -1;
      if (err != EWOULDBLOCK) {
        // A file system without locks (Lustre mounted without -o flock): run unguarded.
        unguarded_ = "mupm: WARNING: cannot lock " + path + " (" + std::strerror(err) +
                     "): nothing stops a second run from writing into this folder meanwhile.\n";
        return "";
      }
      return "another mupm run is writing it (" + (who.empty() ? "holder unknown" : who) +
             "; lock file " + path +
             "): two runs in one folder would mix their time series, fields and checkpoints. "
             "Wait for that run to end, or give this one another Output->Folder";
    }
    char host[256] = {};
    gethostname(host, sizeof host - 1);
    const std::string me = "process " + std::to_string(getpid()) + " on host " + host + "\n";
    if (ftruncate(fd_, 0) != 0 || pwrite(fd_, me.data(), me.size(), 0) < 0) {
      // The lock holds without the note; only the message of a refused run loses the holder.
    }
    return "";
  }
  // Why the folder is not locked although take() succeeded ("" when it is).
  const std::string& unguarded() const { return unguarded_; }

 private:
  int fd_ = -1;
  std::string unguarded_;
};

// Creates the output folder, locks it (FolderLock, on rank 0) and writes the resolved input
// there, before the heavy work, so a bad or busy folder fails early.
void prepare_folder(const Teuchos::Comm<int>& comm, const std::string& folder,
                    const Teuchos::ParameterList& input, FolderLock& lock, std::ostream& out) {
  int ok = 1;  // 0: cannot write, -1: in use
  std::string why;
  if (comm.getRank() == 0) {
    std::error_code ec;
    std::filesystem::create_directories(folder, ec);
    if (ec) {
      ok = 0;
      why = "cannot write to it: " + ec.message();
    } else if (const std::string busy = lock.take(folder); !busy.empty()) {
      ok = -1;
      why = busy;
    } else {
      out << lock.unguarded();
      // A checkpoint being written when an earlier run was killed.
      std::filesystem::remove(folder + "/checkpoint.h5.tmp", ec);
      try {
        Teuchos::writeParameterListToXmlFile(input, folder + "/input_resolved.xml");
      } catch (const std::exception& e) {
        ok = 0;
        why = std::string("cannot write to it: ") + e.what();
      }
    }
  }
  Teuchos::broadcast(comm, 0, &ok);
  if (ok == 1)
    return;
  long long n = static_cast<long long>(why.size());
  Teuchos::broadcast(comm, 0, &n);
  why.resize(static_cast<std::size_t>(n));
  if (n > 0)
    Teuchos::broadcast(comm, 0, static_cast<int>(n), &why[0]);
  const std::string msg = "Error, mupm->Output->Folder = '" + folder + "': " + why + ".";
  if (ok < 0)
    throw InputError(msg);  // the folder is in use: exit 2, like a folder that is a file
  throw CollectiveError(msg);
}

// The largest global id of an owned point whose registry fields marked kFinite (the primary
// state: u, v, a, theta and its rates, p, p_f; every other field derives from them) hold a NaN
// or Inf, or -1. One pass.
template <int Dim>
GlobalId non_finite_point(const Points<Dim>& p) {
  constexpr int kMax = 16;
  Kokkos::Array<Vectors, kMax> f;
  int nf = 0;
  for (const auto& v : p.double_fields(kFinite))
    if (nf < kMax)
      f[nf++] = v;
  auto gid = p.gid;
  GlobalId g = -1;
  Kokkos::parallel_reduce(
      "mupm::Diagnostics::finite", range(0, p.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, GlobalId& m) {
        bool ok = true;
        for (int k = 0; k < nf; ++k)
          for (std::size_t c = 0; c < f[k].extent(1); ++c)
            ok = ok && std::isfinite(f[k](i, c));
        if (!ok && gid(i) > m)
          m = gid(i);
      },
      Kokkos::Max<GlobalId>(g));
  return g;
}

// Warns (rank 0) when the ranks of a node and their threads do not sit on cores of their own:
// threads x ranks beyond the node's cores, or OpenMP threads pinned (OMP_PROC_BIND not false)
// while the ranks' affinity masks overlap, which puts the threads of every rank on the same
// first cores (measured: the quick start 4-5x slower on 2 ranks).
void warn_placement(MPI_Comm comm, int threads, std::ostream& out) {
  MPI_Comm node;
  MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
  int node_rank = 0, node_size = 1;
  MPI_Comm_rank(node, &node_rank);
  MPI_Comm_size(node, &node_size);
  cpu_set_t mask;
  CPU_ZERO(&mask);
  sched_getaffinity(0, sizeof mask, &mask);
  std::vector<cpu_set_t> masks(static_cast<std::size_t>(node_size));
  MPI_Allgather(&mask, int(sizeof mask), MPI_BYTE, masks.data(), int(sizeof mask), MPI_BYTE, node);
  MPI_Comm_free(&node);
  const long cores = sysconf(_SC_NPROCESSORS_ONLN);
  const char* bind = std::getenv("OMP_PROC_BIND");
  std::string b = bind ? bind : "";
  for (auto& c : b)
    c = char(std::tolower(static_cast<unsigned char>(c)));
  const bool pinned = !b.empty() && b != "false";
  int shared = 0;
  for (int i = 0; i < node_size && !shared; ++i)
    for (int j = i + 1; j < node_size && !shared; ++j) {
      cpu_set_t both;
      CPU_AND(&both, &masks[std::size_t(i)], &masks[std::size_t(j)]);
      shared = CPU_COUNT(&both) > 0;
    }
  int flags[2] = {long(node_size) * threads > cores ? 1 : 0, pinned && shared ? 1 : 0};
  MPI_Allreduce(MPI_IN_PLACE, flags, 2, MPI_INT, MPI_MAX, comm);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank != 0)
    return;
  const std::string line =
      "OMP_NUM_THREADS=T OMP_PROC_BIND=spread OMP_PLACES=cores mpirun --map-by ppr:R:node:PE=T "
      "--bind-to core -x OMP_NUM_THREADS -x OMP_PROC_BIND -x OMP_PLACES mupm input.xml (R ranks "
      "x T threads a node)";
  if (flags[0])
    out << "mupm: WARNING: " << node_size << " rank(s) x " << threads << " thread(s) on a node of "
        << cores
        << " cores: they take turns on the cores and every step waits for the slowest. Launch "
        << line << ".\n";
  if (flags[1])
    out << "mupm: WARNING: ranks on one node share cores while OMP_PROC_BIND = " << bind
        << " pins their threads: the threads of every rank sit on the same first cores. Launch "
        << line << ", or set OMP_PROC_BIND=false.\n";
}

// The physics modules of a run and the step sequence over them (Algorithm 1).
template <int Dim>
struct Assembly {
  std::unique_ptr<FluidSolver<Dim>> fluid;
  std::unique_ptr<Mechanics> mechanics;  // the micropolar solid, kinematics, or none
  std::unique_ptr<Damage<Dim>> damage;
  std::unique_ptr<JIntegral<Dim>> j_integral;  // J-Integral->Half Widths given
  StepSequence<Dim> sequence;
  double spacing = 0;  // dx, for messages
  // The stable-step watch's state (StableStepWatch), kept across a restart so that a restarted
  // run re-estimates at the same steps and keeps the fluid substeps of the straight run.
  struct Watch {
    long long pairs_at = 0;  // broken pairs at the last estimate
    double storage_at = 0;   // smallest storage C at the last estimate [1/Pa]
    long long substeps = 0;  // fluid substeps in use (0: not set yet)
    double time_step = 0;    // the run's dt [s] (choose_time_step; 0: not set yet)
  } watch;
  // Time series, restart globals and energy balances, in the time series' column order.
  std::vector<Module*> modules() const {
    std::vector<Module*> m{damage.get()};
    if (mechanics)
      m.push_back(mechanics.get());
    if (fluid)
      m.push_back(fluid.get());
    if (j_integral)
      m.push_back(j_integral.get());
    return m;
  }
  // Module set-up in the order the coupling needs: the fluid (S_r, C, flow of the state), then
  // the mechanics, whose tr(eps) of the initial state is the fluid's reference.
  void initialize(double time, bool restarted) {
    if (fluid)
      fluid->initialize(time, restarted);
    if (mechanics) {
      mechanics->initialize(time, restarted);
      if (fluid && !restarted)
        fluid->reset_strain_reference();
    }
  }
  NamedGlobals globals() {
    NamedGlobals out;
    for (Module* m : modules()) {
      GlobalRefs g;
      m->globals(g);
      for (GlobalRef r : g.refs()) {
        r.name = std::string(m->name()) + "/" + r.name;
        out.push_back(r);
      }
    }
    GlobalRefs w;
    w("stable_steps/broken_pairs_at_estimate", watch.pairs_at);
    w("stable_steps/min_storage_at_estimate", watch.storage_at);
    w("stable_steps/fluid_substeps", watch.substeps);
    w("stable_steps/time_step", watch.time_step);
    out.insert(out.end(), w.refs().begin(), w.refs().end());
    return out;
  }
};

template <int Dim>
Assembly<Dim> assemble(const Model<Dim>& model, Discretization<Dim>& disc, MPI_Comm mpi) {
  Assembly<Dim> ph;
  const Physics physics = model.run.physics;
  if (has_fluid(physics))
    ph.fluid =
        std::make_unique<FluidSolver<Dim>>(disc, model.fluid, model.boundary_conditions, mpi);
  ph.damage = std::make_unique<Damage<Dim>>(disc, model.fracture.critical_damage, mpi);
  if (!model.j_integral.half.empty())
    ph.j_integral = std::make_unique<JIntegral<Dim>>(disc, model.j_integral, *ph.damage, mpi);
  if (has_solid(physics)) {
    SolidSettings settings;
    settings.rho_s = model.solid_density;
    settings.rho_w = model.fluid.water_density;
    settings.gravity = model.gravity;
    settings.damping = model.damping;
    settings.fracture = model.fracture;
    settings.semi_implicit = model.run.semi_implicit;
    settings.fluid = has_fluid(physics);
    if (model.run.field_groups & kGroupSecondOrderWork)  // point_field_groups
      settings.second_order_window = model.run.second_order_window > 0
                                         ? model.run.second_order_window
                                         : model.run.field_interval;
    auto attach = [&](auto solid) {
      if (auto* j = ph.j_integral.get()) {
        j->attach(solid->state(), solid->params());
        solid->keep_pore_part();
      }
      ph.mechanics = std::move(solid);
    };
    switch (model.constitutive_model) {
      case ConstitutiveModel::MicropolarElastic:
        attach(std::make_unique<SolidSolver<Dim, MicropolarElastic>>(
            disc, model.solid, model.boundary_conditions, settings, mpi));
        break;
      case ConstitutiveModel::MicropolarDruckerPrager:
        attach(std::make_unique<SolidSolver<Dim, MicropolarDruckerPrager<Dim>>>(
            disc, model.solid, model.boundary_conditions, settings, mpi,
            MicropolarDruckerPrager<Dim>(model.material, model.plasticity, disc.points,
                                         model.plane_stress, has_fluid(physics))));
        break;
    }
  } else if (physics == Physics::KinematicsOnly) {
    ph.mechanics = std::make_unique<Kinematics<Dim>>(disc);
  }
  if (ph.fluid && model.fracture.flow)
    ph.fluid->enable_fracture_flow(model.fracture);
  if (ph.fluid && model.run.semi_implicit) {  // Hydro-Mechanical (src/input/modules/solver.cpp)
    ph.fluid->enable_semi_implicit(model.run.pressure_solve);
    ph.sequence.skeleton = dynamic_cast<Skeleton*>(ph.mechanics.get());
    if (!ph.sequence.skeleton)
      throw std::logic_error("Pressure Integration = Semi-Implicit without a solid skeleton");
  }
  ph.spacing = disc.grid.dx;
  ph.sequence.mechanics = ph.mechanics.get();
  ph.sequence.fluid = ph.fluid.get();
  ph.sequence.damage = ph.damage.get();
  if (model.j_integral.criterion && has_solid(physics))  // J integrates the solid's state
    ph.sequence.j_criterion = ph.j_integral.get();
  ph.sequence.fluid_first = model.run.staggering == Staggering::FluidFirst;
  ph.sequence.fluid_every = ph.mechanics ? model.run.solid_steps_per_fluid_step : 1;
  return ph;
}

// Prints the size of the discretization; returns the global number of bonds.
template <int Dim>
long long report_discretization(const Discretization<Dim>& disc, const Teuchos::Comm<int>& comm,
                                int pair_width, std::ostream& out) {
  long long counts[2] = {static_cast<long long>(disc.bonds.size()),
                         static_cast<long long>(disc.points.n_ghost)};
  MPI_Allreduce(MPI_IN_PLACE, counts, 2, MPI_LONG_LONG, MPI_SUM, io::raw(comm));
  const auto& g = disc.grid;
  if (comm.getRank() == 0)
    out << "mupm: " << Dim << "D, " << disc.dist.n_global() << " points (" << counts[1]
        << " ghost copies), " << counts[0] << " bonds, dx = " << g.dx
        << " m, horizon = " << g.horizon << " m (" << g.horizon / g.dx << " dx)\n"
        << "mupm: " << comm.getSize() << " rank(s) x " << ExecSpace().concurrency() << " "
        << ExecSpace::name() << " thread(s); " << Points<Dim>::bytes_per_point(disc.points.groups)
        << " bytes per point, " << Bonds::bytes_per_bond(pair_width) << " bytes per bond\n";
  return counts[0];
}

// The initial fields: Materials->Porosity, saturated, then the initial conditions in order.
template <int Dim>
void initial_state(const Model<Dim>& model, Points<Dim>& pts) {
  Kokkos::deep_copy(pts.porosity, model.porosity);
  Kokkos::deep_copy(pts.saturation, 1.0);
  Kokkos::Array<double, 3> rho_w_g{};
  for (int k = 0; k < 3; ++k)
    rho_w_g[k] = model.fluid.water_density * model.gravity[k];
  apply_initial_conditions(model.initial_conditions, pts, rho_w_g);
}

std::string shortest(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// The most fluid substeps per fluid interval a run may take (each costs about a solid step).
constexpr double kMaxFluidSubsteps = 1e6;

// Why automatic fluid substeps cannot run: the fluid is too stiff for the time step.
std::string too_stiff(const FluidParams& f, double dx, double stable_f, double interval,
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

// Every boundary and initial condition acts on some point: a region that holds none makes the
// condition a silent no-op.
template <int Dim>
void check_regions(const Model<Dim>& model, const Discretization<Dim>& disc, MPI_Comm mpi) {
  const auto regions = io::owned_rows(disc.points.regions, disc.points.n_owned);
  std::vector<long long> counts(model.grid.region_names.size(), 0);
  for (std::uint32_t bits : regions)
    for (std::size_t r = 0; r < counts.size(); ++r)
      counts[r] += (bits >> r) & 1u;
  MPI_Allreduce(MPI_IN_PLACE, counts.data(), int(counts.size()), MPI_LONG_LONG, MPI_SUM, mpi);
  auto check = [&](const std::string& list, const std::string& name, std::uint32_t mask) {
    for (std::size_t r = 0; r < counts.size(); ++r)
      if (mask == (1u << r) && counts[r] == 0)
        throw InputError("Error, mupm->" + list + "->" + name + "->Region = '" +
                         model.grid.region_names[r] +
                         "' holds no point: the condition would do nothing. Check the region's "
                         "Min and Max against the body (points sit at cell centres) or its "
                         "boundary layers.");
  };
  for (const auto& bc : model.boundary_conditions)
    check("Boundary Conditions", bc.name, bc.region_mask);
  for (const auto& ic : model.initial_conditions)
    check("Initial Conditions", ic.name, ic.region_mask);
}

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
      out << "(" << ls.fill_level << ") of the matrix less its entries below " << ls.drop_tolerance
          << " of the diagonals' geometric mean, kept up to " << ls.refresh_interval << " steps";
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

// After each step: the energy balances (eqs 140 and 149) against the tolerance, and the
// primary fields for NaN/Inf. Throws CollectiveError to stop the run.
template <int Dim>
class StepChecks {
 public:
  StepChecks(const RunSettings& run, const Discretization<Dim>& disc, MPI_Comm mpi, int rank,
             std::ostream& out)
      : run_(run), disc_(disc), mpi_(mpi), rank_(rank), out_(out) {}

  void operator()(const std::vector<Module*>& modules, long long steps_done, long long step,
                  double time) {
    if (run_.check_finite)
      finite(step, time);
    std::vector<EnergyBalance> all;
    for (Module* m : modules)
      for (auto& b : m->energy_balances())
        all.push_back(std::move(b));
    for (const auto& b : all)
      diverged(b, steps_done, step, time);
    coupled(all, steps_done, step, time);
    for (const auto& b : all)
      energy(b, steps_done, step, time);
  }

  // At the end of the run: the state is finite whatever Diagnostics->Check Finite says (a run
  // never ends with exit 0 on NaN), and how many energy warnings there were.
  void finish(long long step, double time) {
    finite(step, time);
    for (const auto& [what, n] : warnings_)
      if (rank_ == 0 && n > kShownWarnings)
        out_ << "mupm: " << n << " " << what << " energy-balance warnings in all ("
             << kShownWarnings << " shown in full, then every 1000th)\n";
  }

 private:
  static constexpr long long kShownWarnings = 5;
  // A stored energy this many times what the start and the loads supplied is a blow-up.
  static constexpr double kDivergence = 1e3;

  // Energy grown far beyond what was supplied: the scheme is unstable; stop now rather than at
  // the NaN many steps later (or never, in a short run).
  // Not after the first step: loads that start at 0 have then done no booked work (the
  // trapezoid books it on the step's displacement increment, zero on the first step), while the
  // step-end kinetic energy already holds their half kick. Any other supply, however small (a
  // drained layer at 1 Pa), then made a ramped run "diverge" at step 1 (inputs/consolidation.xml).
  void diverged(const EnergyBalance& b, long long steps_done, long long step, double time) {
    if (steps_done < 2 || !(b.supplied > 0 && b.stored > kDivergence * b.supplied))
      return;
    std::ostringstream why;
    why << "more than " << kDivergence << " times the energy supplied, " << b.supplied_expression
        << " = " << b.supplied << " J";
    stop(b, why.str(), step, time);
  }

  // All balances as one. A balance's own `supplied` holds the work it exchanges with the other
  // modules, which grows with a blow-up of the coupling itself: Example 1 with Crack Water
  // Force = Eq 17 blew up at 1.245, 0.3 and 0.1 us alike (inputs/README.md) while each
  // balance's stored energy stayed below its own supply. Energy conservation of the coupled
  // system bounds the summed stored energy by the summed external supply S (EnergyBalance::
  // external: the exchanges cancel); a blow-up is a summed store beyond kDivergence S or, where
  // S is small or negative (it fell to -3e3 J in that run while the stores reached 7e4 J),
  // beyond kGross times the external terms' magnitudes G, which a consistent scheme keeps
  // below G (the pores-crack exchange is in G on both sides, so G grows with such a blow-up
  // too: the stores reached 20-140 G in that run).
  static constexpr double kGross = 10;
  void coupled(const std::vector<EnergyBalance>& all, long long steps_done, long long step,
               double time) {
    if (steps_done < 2 || all.empty())
      return;
    EnergyBalance c;
    c.what = all.size() == 1 ? all[0].what : "coupled system";
    double largest = -1, gross = 0;
    for (const auto& b : all) {
      const std::string plus = c.stored_expression.empty() ? "" : " + ";
      c.stored_expression += plus + "(" + b.stored_expression + ")";
      c.supplied_expression += plus + "(" + b.external_expression + ")";
      c.stored += b.stored;
      c.supplied += b.external;
      gross += b.gross;
      if (!b.hint.empty())
        c.hint = b.hint;
      if (b.stored > largest) {  // locate the blow-up in the field of the largest store
        largest = b.stored;
        c.field = b.field;
      }
    }
    if (!(c.stored > kDivergence * c.supplied && c.stored > kGross * gross))
      return;
    std::ostringstream why;
    why << "more than " << kDivergence << " times the energy supplied from outside, "
        << c.supplied_expression << " = " << c.supplied << " J, and more than " << kGross
        << " times the sum of those terms' magnitudes, " << gross << " J";
    stop(c, why.str(), step, time);
  }

  void stop(const EnergyBalance& b, const std::string& why, long long step, double time) {
    const auto at = largest(b.field);
    std::ostringstream s;
    s << "Error, the " << b.what << " diverged at step " << step << " (t = " << time
      << " s): its stored energy " << b.stored_expression << " = " << b.stored << " J is " << why
      << ". The largest |" << b.field << "|, " << at.value << ", is at the point with global id "
      << at.gid << ", reference position (" << at.x[0] << ", " << at.x[1]
      << (Dim == 3 ? ", " + std::to_string(at.x[2]) : std::string())
      << ") m. The time step is likely beyond the stable one: use Solver->Automatic Time Step "
         "or a smaller Solver->Time Step (and for the fluid Solver->Fluid Substeps = 0).";
    if (!b.hint.empty())
      s << " " << b.hint;
    throw CollectiveError(s.str());
  }

  void energy(const EnergyBalance& b, long long steps_done, long long step, double time) {
    if (steps_done <= run_.energy_check_start ||
        !(b.error > run_.energy_tolerance * b.scale && b.scale > 0))
      return;
    std::ostringstream s;
    s << b.what << " energy balance violated at step " << step << " (t = " << time << " s): |"
      << b.expression << "| = " << b.error << " J is " << b.error / b.scale
      << " of the largest term (Solver->Energy Tolerance = " << run_.energy_tolerance << ")";
    if (run_.stop_on_energy_violation)
      throw CollectiveError("Error, " + s.str() + ".");
    long long& warnings = warnings_[b.what];
    if (rank_ == 0 && (warnings < kShownWarnings || warnings % 1000 == 0))
      out_ << "mupm: WARNING: " << s.str() << "\n";
    if (rank_ == 0 && warnings + 1 == kShownWarnings)
      out_ << "mupm: further " << b.what
           << " energy-balance warnings are suppressed (every 1000th is shown; the count is "
              "given at the end)\n";
    ++warnings;
  }

  // The point whose registry field `name` has the largest magnitude: value, global id, position.
  struct Location {
    double value = 0;
    GlobalId gid = -1;
    double x[3] = {0, 0, 0};
  };
  Location largest(const std::string& name) const {
    const auto& pts = disc_.points;
    std::vector<double> rows;
    int nc = 1;
    pts.for_each_field([&](const auto& view, const FieldSpec& s) {
      using V = std::decay_t<decltype(view)>;
      if constexpr (std::is_same_v<typename V::value_type, double>)
        if (name == s.name) {
          rows = io::owned_rows(view, pts.n_owned);
          nc = s.ncomp;
        }
    });
    struct {
      double v;
      int rank;
    } best{-1.0, rank_}, all{};
    std::size_t at = 0;
    for (std::size_t i = 0; i < pts.n_owned; ++i) {
      double m = 0;
      for (int c = 0; c < nc; ++c)
        m +=
            rows[i * std::size_t(nc) + std::size_t(c)] * rows[i * std::size_t(nc) + std::size_t(c)];
      if (m > best.v) {
        best.v = m;
        at = i;
      }
    }
    MPI_Allreduce(&best, &all, 1, MPI_DOUBLE_INT, MPI_MAXLOC, mpi_);
    // The owner supplies the point; the sum over ranks hands it to everyone.
    double buf[5] = {0, 0, 0, 0, 0};
    if (all.rank == rank_ && pts.n_owned > 0) {
      auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.gid);
      auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.x);
      buf[0] = std::sqrt(best.v);
      buf[1] = double(gid(at));
      for (int k = 0; k < Dim; ++k)
        buf[2 + k] = x(at, k);
    }
    MPI_Allreduce(MPI_IN_PLACE, buf, 5, MPI_DOUBLE, MPI_SUM, mpi_);
    Location l;
    l.value = buf[0];
    l.gid = GlobalId(buf[1]);
    for (int k = 0; k < 3; ++k)
      l.x[k] = buf[2 + k];
    return l;
  }

  void finite(long long step, double time) {
    const auto& pts = disc_.points;
    GlobalId bad = non_finite_point(pts);
    MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPI_LONG_LONG, MPI_MAX, mpi_);
    if (bad < 0)
      return;
    // The owner supplies the position; the sum over ranks hands it to everyone.
    double where[3] = {0, 0, 0};
    auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.gid);
    auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.x);
    for (std::size_t i = 0; i < pts.n_owned; ++i)
      if (gid(i) == bad)
        for (int k = 0; k < Dim; ++k)
          where[k] = x(i, k);
    MPI_Allreduce(MPI_IN_PLACE, where, 3, MPI_DOUBLE, MPI_SUM, mpi_);
    std::ostringstream s;
    s << "Error, a field is NaN or Inf at step " << step << " (t = " << time
      << " s), at the point with global id " << bad << ", reference position (" << where[0] << ", "
      << where[1] << (Dim == 3 ? ", " + std::to_string(where[2]) : std::string()) << ") m.";
    throw CollectiveError(s.str());
  }

  const RunSettings& run_;
  const Discretization<Dim>& disc_;
  MPI_Comm mpi_;
  int rank_;
  std::ostream& out_;
  std::map<std::string, long long> warnings_;
};

// The largest displacement magnitude over all points.
template <int Dim>
double max_displacement(const Points<Dim>& pts, MPI_Comm mpi) {
  auto u = pts.u;
  double umax2 = 0;
  Kokkos::parallel_reduce(
      "mupm::Diagnostics::max_displacement", range(0, pts.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, double& m) {
        double s = 0;
        for (int k = 0; k < Dim; ++k)
          s += u(i, k) * u(i, k);
        m = s > m ? s : m;
      },
      Kokkos::Max<double>(umax2));
  MPI_Allreduce(MPI_IN_PLACE, &umax2, 1, MPI_DOUBLE, MPI_MAX, mpi);
  return std::sqrt(umax2);
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
