// The solid step of Algorithm 1 for the micropolar solid: the central difference with its
// prescribed components, the forces of the state, and energy-based bond breakage (eqs 34-36,
// Algorithm 4): the bond energies are accumulated by the force evaluation of each step; bonds
// whose energy reached W_cr break at the end of the step, after its velocity update and before
// the fluid (Algorithm 1); the next step runs with the new bond set (after_breakage).
// Its parts, each in a file of its own: the boundary conditions and layers
// (solid_boundary.hpp), the energy ledger (solid_ledger.hpp, kernels/solid_energy.hpp), the
// crack water's force (crack_face_force.hpp) and the stable step
// (src/solvers/solid_stable_step.cpp). Defined in src/solvers/solid_solver.cpp for Dim 2, 3 and
// each law of include/mupm/laws/laws.hpp.
//
// Gradual release (J-Integral->Release Time = T > 0; not in the paper, whose breakage is
// instantaneous). The J criterion breaks an increment's bonds at once: the forces they carried
// vanish in one step and the new faces spring open under the tip's stress concentration, a
// dynamic load that a quasi-static crack never sees. In the KGD input (inputs/README.md) the
// crack water, which has to fill that opening, fell to 0.65 of its pressure for ~20 steps after
// each increment, and the plate rang by +-5 % between increments. As in the node-release
// technique of finite-element crack growth, the forces are released over T instead. At a break
// at time t_b, at the same u and theta, every owned point's force and moment densities of the
// old bond set minus those of the new one, dF_i (after_breakage evaluates both), are kept in
// Points::release_force, F_i <- r(t_b) F_i + dF_i (a release under way goes on from where it
// is), and each force evaluation at t adds r(t) F_i to the point's body force and couple,
//   r(t) = max(0, 1 - (t - t_b) / T)   (t_b of the last break).
// The points' total forces, and so their accelerations, are then continuous across the break,
// and they reach the new bond set's after T. Momentum: dF sums to zero over the body (the
// forces of either bond set do, at the same u), so r F adds none. Energy: what the body loses
// at the break itself (the ledger's fracture term, as without release) plus the release
// force's work as the faces open, -int r F . du (booked as fracture dissipation, not as external
// work: it is the work of the bonds' last stretch, StepTerms::release_work). Stability: r F
// depends on time alone, not on the state, so it adds no stiffness and the stable step is the
// same. The next J decision should see the released field: the input check requires T at most
// the speed cap's wait Delta a / v.
#ifndef MUPM_SOLID_SOLVER_HPP
#define MUPM_SOLID_SOLVER_HPP

#include <mpi.h>

#include <memory>
#include <string>
#include <vector>

#include "mupm/core/scratch.hpp"
#include "mupm/kernels/fracture.hpp"
#include "mupm/laws/laws.hpp"
#include "mupm/mesh/discretization.hpp"
#include "mupm/solvers/crack_face_force.hpp"
#include "mupm/solvers/module.hpp"
#include "mupm/solvers/solid_boundary.hpp"
#include "mupm/solvers/solid_forces.hpp"
#include "mupm/solvers/solid_ledger.hpp"

namespace mupm {

// What the solid solver takes besides the law's parameters (the same for every law).
struct SolidSettings {
  double rho_s = 2000, rho_w = 1000;
  Kokkos::Array<double, 3> gravity{};
  double damping = 0;
  FractureParams fracture;
  // Steps per window of the second-order work (eq 42, include/mupm/kernels/shear_bands.hpp);
  // 0: none.
  int second_order_window = 0;
  // Solver->Pressure Integration = Semi-Implicit: the pore pressure's correction of each step
  // is booked (add_projection_work) and reported.
  bool semi_implicit = false;
  // A fluid module is coupled: pore pressures may arise even where none is set at the start
  // (with Semi-Implicit the undrained modulus is zero, so the points' state cannot tell).
  bool fluid = false;
};

// Law: the pointwise constitutive law of pass 1 (include/mupm/kernels/solid.hpp), chosen once
// from Materials->Model: its registration's factory (include/mupm/input/law_registry.hpp)
// builds the solver.
template <int Dim, class Law = MicropolarElastic>
class SolidSolver : public Mechanics, public Skeleton {
 public:
  static constexpr int R = kRotDim<Dim>;

  using Settings = SolidSettings;
  using Energy = SolidEnergy;

  SolidSolver(Discretization<Dim>& disc, const SolidParams& prm, std::vector<BoundaryCondition> bcs,
              const Settings& settings, MPI_Comm comm, const Law& law = Law());
  // Bonds break during the run (by either criterion); the bond energies are accumulated for the
  // energy criterion only.
  bool breaks() const { return set_.fracture.criterion != BondBreaking::None; }
  bool energy_criterion() const { return set_.fracture.criterion == BondBreaking::Energy; }
  // The pore-water part of the force state kept apart (SolidState::P1w) for the J-integral's
  // effective force state too, without breakage (before initialize).
  void keep_pore_part() { keep_pore_part_ = true; }

  const SolidState<Dim>& state() const { return st_; }
  const SolidParams& params() const { return prm_; }
  const Law& law() const { return law_; }
  const Scalars& density() const { return rho_; }

  const char* name() const override { return "solid"; }
  // The ledger's terms since t = 0 and the balance at t = 0 (eq 140 keeps E_int + E_kin + D -
  // W_ext - W_pore at it), the slaved displacements, the counts.
  void globals(GlobalRefs& g) override;
  void series(SeriesRow& row) const override;
  // Energy balance (eqs 137-140).
  std::vector<EnergyBalance> energy_balances() const override;

  // Mixture density (eq 1) and micro-inertia (eq 13) from the current porosity and saturation.
  void update_density() override;
  // Marks prescribed components, computes densities (eqs 1, 13) from porosity and saturation,
  // and the forces of the current state; at a start (not a restart, whose state holds them)
  // also the boundary values at t and the accelerations.
  void initialize(double t, bool restarted) override;
  // A start's balance includes the kinetic shift of the run's step (SolidEnergy::kinetic_shift).
  void set_time_step(double dt) override;

  // One step from t to t + dt: move() then finish().
  void step(double t, double dt) override;
  // The same step in parts, the bond breakage between them (Mechanics; StepSequence).
  void step_to_forces(double t, double dt) override;
  void complete_step(double t, double dt, const Breakage& broken) override {
    complete(t, dt, broken);
  }
  void finish(double t, double dt);
  // The step's first half: the velocities' first half and the positions at t + dt, prescribed
  // components at their values. The semi-implicit pressure corrects the free components here
  // (include/mupm/solvers/pressure_projection.hpp).
  void move(double t, double dt) override;
  SkeletonState skeleton_state() const override { return {du_, rho_, inertia_, shift_step_}; }
  // The pressure correction's work on the skeleton, part of the pore work (W_pore).
  void add_projection_work(double w) override;
  double projection_work() const { return ledger_.totals().projection_work; }
  // The rest of the step, in parts. finish_forces: boundary layers, forces at t + dt and the
  // step's work (this rank's terms, kept in pending_ for complete()).
  void finish_forces(double t, double dt) override;
  // The energy criterion (Algorithm 4) on the bond energies of the forces at t + dt: the bonds
  // it broke on this rank and the energy they released.
  Breakage energy_breakage() override;
  // complete: with `broken` the directed bonds broken on this rank since finish_forces (by the
  // energy and J criteria) and their energy (collective): the step's one reduction, the
  // velocities at t + dt, then the forces of the new bond set.
  void complete(double t, double dt, const Breakage& broken) override;
  long long broken_pairs() const override { return broken_pairs_; }

  // Bonds broke at the end of a step (Algorithm 4), after its velocity update: the forces of
  // the new bond set at t (src/solvers/solid_solver.cpp). `before`: the strain energy of the old
  // bond set (summed over ranks).
  void after_breakage(double t, double before);

  // Strain energy (elastic and stabilization) of this rank's points.
  double stored_energy() const;
  // The ledger with the current state's energies (collective).
  Energy energy() const;
  // The reaction of each kinematic condition (SolidBoundary::reactions; collective).
  std::vector<std::string> reaction_names() const { return boundary_.reaction_names(); }
  std::vector<double> reactions() const { return boundary_.reactions(st_.force, st_.moment); }

  // Largest stable step of the undamped central difference, 2 / omega_max, with omega_max^2
  // the largest eigenvalue of M^-1 K of the discrete operator (prescribed components held),
  // by power iteration with the mass-weighted Rayleigh quotient (it approaches omega_max^2
  // from below; src/solvers/solid_stable_step.cpp). Collective.
  bool limits_time_step() const override { return true; }
  double stable_time_step() override;
  std::string describe() const override;
  double estimate_stable_dt(int iterations = 40);

 private:
  // Whether any point has a pore pressure or an undrained modulus (the same on every rank).
  bool has_pressure() const;
  // The forces at t of the current state (with the crack water's, the body forces and the
  // volumetric strain).
  void forces(double t);
  void update_shift_step();
  void keep_applied();
  void restore_applied();
  bool face_pressure() const { return set_.fracture.flow && set_.fracture.face_pressure; }
  void add_to_body(const Vectors& f);
  // Gradual release (header): on when J-Integral->Release Time > 0; r(t); the release force at
  // t added to the body force and couple; after a break, the kept field from the forces of the
  // old and the new bond set.
  bool releases() const { return set_.fracture.release_time > 0; }
  double release_factor(double t) const;
  void add_release(double t);
  void keep_release(double t);
  // Runs f, an evaluation between two steps (a restart's first, the stable-step estimate), and
  // puts back the plastic law's current state.
  template <class F>
  void keeping_plastic_state(F&& f);
  void commit_plastic();
  void save_positions();
  void increments();
  // This rank's damping power and pore power (with eq 17's) of the step (finish_forces).
  double damping_power() const;
  double pore_power() const;
  // band_angle [deg] and band_width [m] (include/mupm/kernels/shear_bands.hpp), collective.
  void bands(double& angle, double& width) const;

  Discretization<Dim>& disc_;
  SolidParams prm_;
  Law law_;
  Settings set_;
  MPI_Comm comm_;
  SolidBoundary<Dim> boundary_;
  SolidLedger ledger_;
  std::unique_ptr<CrackFaceForce<Dim>> crack_;  // Fracture Flow with the face pressure
  SolidState<Dim> st_;
  Scalars rho_, inertia_;
  Vectors body_, couple_, du_;
  Scalars shift_step_;      // SkeletonState::plastic_shift (semi-implicit, plastic plane stress)
  double forces_time_ = 0;  // t of the last forces()
  Vectors f_old_, l_old_;   // forces of the old bond set at a breakage
  Scalars vs_old_;
  double release_start_ = 0;      // t_b of the last break with gradual release (a restart global)
  double dt_ = 0;                 // the run's step (SolidEnergy::kinetic_shift)
  bool started_ = false;          // initialized at a start, not a restart (set_time_step)
  long long steps_ = 0;           // steps since t = 0 (second-order work windows)
  double negative_fraction_ = 0;  // volume fraction with d2E < 0, last window
  long long broken_pairs_ = 0;    // bond pairs broken since t = 0 (a restart global)
  bool pressure_ = false;         // breakage run with pore pressure (initialize)
  bool keep_pore_part_ = false;   // P1w for the J-integral (keep_pore_part)
  StepTerms pending_;             // this rank's terms, from finish_forces to complete
  Scratch scratch_;               // the fields estimate_stable_dt and keeping_plastic_state use
};

#define MUPM_SOLID_SOLVER(D, LAW) extern template class SolidSolver<D, LAW>;
MUPM_FOR_EACH_LAW(MUPM_SOLID_SOLVER, 2)
MUPM_FOR_EACH_LAW(MUPM_SOLID_SOLVER, 3)
#undef MUPM_SOLID_SOLVER

}  // namespace mupm

#endif
