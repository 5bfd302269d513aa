// The solid step of Algorithm 1 for the elastic micropolar solid: boundary conditions, forces,
// central difference, energy bookkeeping (eqs 137-140), reactions, stable-step estimate, and
// energy-based bond breakage (eqs 34-36, Algorithm 4): the bond energies are accumulated by the
// force evaluation of each step; bonds whose energy reached W_cr break at the end of the step,
// after its velocity update and before the fluid (Algorithm 1); the next step runs with the
// new bond set (after_breakage).
#ifndef MUPM_SOLID_SOLVER_HPP
#define MUPM_SOLID_SOLVER_HPP

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "mupm/core/scratch.hpp"
#include "mupm/kernels/boundary_conditions.hpp"
#include "mupm/kernels/central_difference.hpp"
#include "mupm/kernels/fracture.hpp"
#include "mupm/kernels/fracture_flow.hpp"
#include "mupm/kernels/shear_bands.hpp"
#include "mupm/kernels/solid.hpp"
#include "mupm/mesh/discretization.hpp"
#include "mupm/solvers/module.hpp"
#include "mupm/solvers/power_iteration.hpp"

namespace mupm {

// Pass 1, ghost refresh, pass 2: the force and moment densities of the current u, theta, p.
// u, theta (and p, S_r) must be current on the ghosts.
template <int Dim, class Law>
void solid_forces(Discretization<Dim>& disc, const SolidParams& prm, const Law& law,
                  SolidState<Dim>& st) {
  ScopedRegion region("mupm::Solid::forces");
  solid_pass1(disc.points, disc.bonds, disc.shape, prm, law, st);
  disc.dist.refresh(st.pass2_ghosts());
  solid_pass2(disc.points, disc.bonds, prm, st);
}
// The same with the elastic law of prm.
template <int Dim>
void solid_forces(Discretization<Dim>& disc, const SolidParams& prm, SolidState<Dim>& st) {
  solid_forces(disc, prm, prm.law, st);
}

// The fold of the slaved layers' forces and moments onto their mirrors
// (kernels/boundary_conditions.hpp): buf ([owned + ghosts][blocks * (Dim + R)]) zeroed, packed,
// its ghost rows added into their owners across ranks, added to the owned points' force, moment.
template <int Dim>
void fold_layer_forces(Discretization<Dim>& disc, const FaceSlots& slots, const Vectors& force,
                       const Vectors& moment, const Vectors& buf) {
  Kokkos::deep_copy(buf, 0.0);
  pack_layer_forces(disc.points, disc.mirror, slots, force, moment, buf);
  disc.dist.add_to_owners(buf);
  add_folded(disc.points, buf, force, moment);
  Kokkos::fence();
}

// The force and moment densities the discrete operator makes of a uniform total stress sigma
// (kernels/solid.hpp, uniform_stress_pass1), into st.force and st.moment (st allocated for the
// discretization, st.work Off).
template <int Dim>
void uniform_stress_forces(Discretization<Dim>& disc, const SolidParams& prm,
                           const Kokkos::Array<double, 9>& sigma, SolidState<Dim>& st) {
  uniform_stress_pass1(disc.points, disc.shape, sigma, st);
  disc.dist.refresh(st.pass2_ghosts());
  solid_pass2(disc.points, disc.bonds, prm, st);
}

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
// by the driver from Materials->Model.
template <int Dim, class Law = MicropolarElastic>
class SolidSolver : public Mechanics, public Skeleton {
 public:
  static constexpr int R = kRotDim<Dim>;

  using Settings = SolidSettings;
  struct Energy {
    double internal = 0, kinetic = 0, external_work = 0, dissipation = 0;
    // The central difference's kinetic energy is 1/2 m v^{n-1/2}.v^{n+1/2} = E_kin - dt^2/8
    // m|a^n|^2 (v^{n+-1/2} = v^n +- dt/2 a^n): with it, the strain energy of a linear operator
    // and the trapezoid's work, the balance closes exactly, whatever the loads do. Summed over
    // steps, m(v^{n+3/2} - v^{n-1/2}) = dt (f^n + f^{n+1}) - dt K (u^n + u^{n+1}) times
    // (u^{n+1} - u^n) / (2 dt) = v^{n+1/2} / 2 gives
    //   [1/2 m v^{n+1/2}.v^{n+3/2} + E(u^{n+1})] - [1/2 m v^{n-1/2}.v^{n+1/2} + E(u^n)]
    //     = 1/2 (f^n + f^{n+1}).(u^{n+1} - u^n).
    // With 1/2 m|v^n|^2 instead, the balance carries dt^2/8 m|a^n|^2, which a load that starts
    // at once puts into the fastest modes: 1-2 % of the largest term at steps 21-30 of Example 1
    // case 1 (its crack water's undrained spring sets the step). The shift is positive-definite
    // with E_int only below the stable step (omega dt < 2), so a blow-up still shows.
    double kinetic_shift = 0;  // -dt^2/8 sum V (rho |a|^2 + J |alpha|^2) over free components
    double fracture = 0;       // strain energy lost when bonds broke (fracture dissipation)
    double plastic = 0;        // plastic dissipation (Materials->Model = Micropolar Drucker-Prager)
    double bond_energy = 0;    // sum of W V_i V_j of the broken bonds (the criterion's energy)
    // Work of the pore water on the skeleton: sum over steps of sum_i V_i S_r p* d(tr eps_i)
    // (the -S_r p* 1 part of the total stress, eq 46; p* linear in tr eps within a step, so the
    // trapezoid rule is exact).
    double pore_work = 0;
    // The part of external_work done by the crack water's face forces (Fracture Flow with the
    // face pressure): the solid's side of the crack water's work on the skeleton, which the
    // fracture network books as Sigma V p_f S_rf dphi_f (solvers/fracture_flow.hpp).
    double crack_work = 0;
    // E_int + E_kin + D - W_ext - W_pore, which the scheme keeps constant (eq 140).
    double balance() const {
      return internal + kinetic + kinetic_shift + dissipation + fracture + plastic - external_work -
             pore_work;
    }
    double scale() const {
      return std::max(
          std::max(std::max(std::abs(internal), kinetic), std::max(fracture, plastic)),
          std::max(std::max(std::abs(external_work), dissipation), std::abs(pore_work)));
    }
  };

  SolidSolver(Discretization<Dim>& disc, const SolidParams& prm, std::vector<BoundaryCondition> bcs,
              const Settings& settings, MPI_Comm comm, const Law& law = Law())
      : disc_(disc), prm_(prm), law_(law), bcs_(std::move(bcs)), set_(settings), comm_(comm) {
    if constexpr (std::is_same_v<Law, MicropolarElastic>)
      law_ = prm.law;
    int blocks = 0;  // faces with slaved layers, in the order of the conditions (every rank's)
    for (int f = 0; f < 6; ++f)
      slots_[f] = -1;
    for (auto& bc : bcs_)
      if (bc.kinematic() && bc.mirrored) {
        bc.mirror_column = face_column(disc.grid, bc.region_mask);
        (bc.slaved ? slaved_ : mirrored_) = true;
        const int face = face_index(disc.grid, bc.region_mask);
        if (bc.slaved && slots_[face] < 0)
          slots_[face] = blocks++;
      }
    slaved_disp_.assign(bcs_.size(), 0.0);
    twice_dg_.assign(bcs_.size(), 0.0);
    auto& p = disc_.points;
    if (slaved_)
      fold_ = Vectors("mupm::layer_fold", p.size(), std::size_t(blocks * (Dim + R)));
    st_.allocate(p.size(), p.n_owned);
    rho_ = Scalars("mupm::density", p.n_owned);
    inertia_ = Scalars("mupm::micro_inertia", p.n_owned);
    body_ = Vectors("mupm::body_force", p.n_owned, Dim);
    if (face_pressure()) {
      crack_ = Vectors("mupm::crack_force", p.n_owned, Dim);
      pf_star_ = Scalars("mupm::undrained_fracture_pressure", p.n_owned);
      face_load_ = Vectors("mupm::crack_face_load", p.size(), Dim);
    }
    if (set_.fracture.flow && !set_.fracture.face_pressure)  // eq 17 (kernels/solid.hpp)
      st_.allocate_eq17(p.size(), p.n_owned);
    couple_ = Vectors("mupm::body_couple", p.n_owned, R);
    du_ = Vectors("mupm::step_increment", energy_criterion() ? p.size() : p.n_owned, Dim + R);
    vs_old_ = Scalars("mupm::volumetric_strain_old", p.n_owned);
    if constexpr (Law::plastic)
      if (law_.pore_water && set_.semi_implicit)
        shift_step_ = Scalars("mupm::plastic_thickness_change", p.n_owned);
    if (breaks()) {
      f_old_ = Vectors("mupm::force_before_breakage", p.n_owned, Dim);
      l_old_ = Vectors("mupm::moment_before_breakage", p.n_owned, R);
    }
    if (energy_criterion()) {
      disc_.bonds.hold_pair_forces(Dim + R);
      st_.increment = du_;
      st_.max_energy = Scalars("mupm::max_bond_energy", p.n_owned);
    }
    build_consistent_tractions();
  }
  // Bonds break during the run (by either criterion); the bond energies are accumulated for the
  // energy criterion only.
  bool breaks() const { return set_.fracture.criterion != BondBreaking::None; }
  bool energy_criterion() const { return set_.fracture.criterion == BondBreaking::Energy; }
  // The pore-water part of the force state kept apart (SolidState::P1w) for the J-integral's
  // effective force state too, without breakage (before initialize).
  void keep_pore_part() { keep_pore_part_ = true; }

  const SolidState<Dim>& state() const { return st_; }
  const SolidParams& params() const { return prm_; }
  const Scalars& density() const { return rho_; }

  const char* name() const override { return "solid"; }
  // Work of the boundary and body forces, damping dissipation and pore work since t = 0, and
  // the balance at t = 0 (eq 140 keeps E_int + E_kin + D - W_ext - W_pore at it).
  void globals(GlobalRefs& g) override {
    g("external_work", work_);
    g("dissipation", dissipation_);
    g("pore_pressure_work", pore_work_);
    g("initial_balance", balance0_);
    if (set_.semi_implicit)
      g("projection_work", projection_work_);
    if (face_pressure())
      g("crack_force_work", crack_work_);
    if (breaks()) {
      g("fracture_energy", fracture_energy_);
      g("bond_energy_released", bond_energy_released_);
      g("broken_pairs", broken_pairs_);
    }
    if constexpr (Law::plastic)
      g("plastic_dissipation", plastic_dissipation_);
    for (std::size_t k = 0; k < bcs_.size(); ++k)
      if (slaved_velocity(bcs_[k]))
        g("slaved_displacement_" + bcs_[k].name, slaved_disp_[k]);
    if (set_.second_order_window > 0) {
      g("steps", steps_);
      g("negative_second_order_work_fraction", negative_fraction_);
    }
  }
  void series(SeriesRow& row) const override {
    const auto e = energy();
    row("internal_energy", e.internal);
    row("kinetic_energy", e.kinetic);
    row("external_work", e.external_work);
    row("dissipation", e.dissipation);
    row("pore_pressure_work", e.pore_work);
    if (set_.semi_implicit)  // its part from the pressure correction (pressure_projection.hpp)
      row("projection_work", projection_work_);
    if (face_pressure())
      row("crack_force_work", e.crack_work);
    if (breaks()) {
      row("fracture_energy", e.fracture);
      row("bond_energy_released", e.bond_energy);
    }
    if constexpr (Law::plastic) {
      row("plastic_dissipation", e.plastic);
      double angle, width;
      bands(angle, width);
      row("band_angle", angle);
      row("band_width", width);
    }
    if (set_.second_order_window > 0)
      row("negative_second_order_work_fraction", negative_fraction_);
    row("energy_error", e.balance() - balance0_);
    const auto names = reaction_names();
    const auto values = reactions();
    for (std::size_t k = 0; k < names.size(); ++k)
      row(names[k], values[k]);
  }
  // Energy balance (eqs 137-140).
  std::vector<EnergyBalance> energy_balances() const override {
    const auto e = energy();
    EnergyBalance b;
    b.what = "solid";
    b.expression = std::string("E_int + E_kin - dt^2/8 m|a|^2 + D") +
                   (breaks() ? " + D_frac" : "") + (Law::plastic ? " + D_plast" : "") +
                   " - W_ext - W_pore - E_0";
    b.error = std::abs(e.balance() - balance0_);
    b.scale = e.scale();
    b.stored_expression = "E_int + E_kin";
    b.stored = std::abs(e.internal) + e.kinetic;
    b.supplied_expression = "|E_0| + |W_ext| + |W_pore|";
    b.supplied = std::abs(balance0_) + std::abs(e.external_work) + std::abs(e.pore_work);
    b.external_expression = "E_0 + W_ext";
    b.external = balance0_ + e.external_work;
    b.gross = std::abs(balance0_) + std::abs(e.external_work);
    b.field = "displacement";
    if (st_.P1f.extent(0) > 0)
      b.hint =  // the blow-up's growth rate does not follow the step (inputs/README.md)
          "Fracture->Crack Water Force = Eq 17 puts p_f on the bonds along the crack's faces, "
          "whose work the crack water does not supply: it can blow up at any time step; use "
          "Face Pressure.";
    return {b};
  }

  // Mixture density (eq 1) and micro-inertia (eq 13) from the current porosity and saturation.
  void update_density() override {
    auto& p = disc_.points;
    auto phi = p.porosity, sr = p.saturation;
    auto rho = rho_, J = inertia_;
    const double rho_s = set_.rho_s, rho_w = set_.rho_w, l = prm_.law.length;
    Kokkos::parallel_for(
        "mupm::Solid::density", range(0, p.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
          rho(i) = mixture_density(phi(i), rho_s, sr(i), rho_w);
          J(i) = micro_inertia(phi(i), rho_s, l);
        });
  }

  // Marks prescribed components, computes densities (eqs 1, 13) from porosity and saturation,
  // and the forces of the current state; at a start (not a restart, whose state holds them)
  // also the boundary values at t and the accelerations.
  void initialize(double t, bool restarted) override {
    auto& p = disc_.points;
    mark_fixed(bcs_, p);
    if (mirrored_ || slaved_)
      mark_mirrored_layers(bcs_, p, disc_.mirror);
    update_density();
    // Pore water pressure, for the whole run: a fluid, or a held initial pressure (without a
    // fluid p never changes). The effective force state's bond energy then needs the pore-water
    // part of P1 apart. The same choice in a straight run and in its restart (which finds the
    // pressures the run developed: with Semi-Implicit a fluid run may start with none).
    pressure_ = (breaks() || keep_pore_part_) && (set_.fluid || has_pressure());
    if (pressure_ && set_.fracture.effective_state && st_.P1w.extent(0) == 0)
      st_.P1w = Vectors("mupm::pore_part_of_P1", p.size(), Dim * Dim);
    if (!restarted) {
      apply_kinematic(bcs_, p, t, 0.0);
      mirror_layers(t);
    }
    disc_.dist.refresh({as_vectors(p.p), as_vectors(p.saturation)});  // constant in the solid step
    // The pair force states of this state start the bond energies' trapezoid. A restart keeps
    // the checkpoint's: they are the states the forces had when applied, with the pore pressure
    // of before the step's fluid update (Solid First), which the forces evaluated here no
    // longer have.
    st_.work = energy_criterion() && !restarted ? BondWork::Record : BondWork::Off;
    // A restart's state holds the plastic state of the forces last applied (keeping_plastic_state).
    if (restarted)
      keeping_plastic_state([&] { forces(t); });
    else
      forces(t);
    // Points::solid_pressure is the p* of the forces last applied (the pore work of the next
    // step starts from it); a restart has it from the checkpoint, not from the pressure the
    // fluid has updated since.
    if (restarted)  // the forces the run applied last, not those of the updated pressure
      restore_applied();
    if (set_.second_order_window > 0 && !restarted)
      second_order_work(p, st_.eps, st_.kappa, p.second_order_work_start, Scalars());
    if (!restarted) {
      keep_applied();
      advance_velocities(p, st_.force, st_.moment, rho_, inertia_, body_, couple_, set_.gravity,
                         0.0, 0.0);
      balance0_ = energy().balance();
    }
    started_ = !restarted;
  }
  // A start's balance includes the kinetic shift of the run's step (Energy::kinetic_shift).
  void set_time_step(double dt) override {
    dt_ = dt;
    if (started_)
      balance0_ = energy().balance();
  }

  // One step from t to t + dt: move() then finish().
  void step(double t, double dt) override {
    dt_ = dt;
    move(t, dt);
    finish(t, dt);
  }
  // The same step in parts, the bond breakage between them (Mechanics; StepSequence).
  void step_to_forces(double t, double dt) override {
    dt_ = dt;
    move(t, dt);
    finish_forces(t, dt);
  }
  void complete_step(double t, double dt, const Breakage& broken) override {
    complete(t, dt, broken);
  }
  void finish(double t, double dt) {
    finish_forces(t, dt);
    complete(t, dt, energy_breakage());
  }
  // The step's first half: the velocities' first half and the positions at t + dt, prescribed
  // components at their values. The semi-implicit pressure corrects the free components here
  // (include/mupm/solvers/pressure_projection.hpp).
  void move(double t, double dt) override {
    ScopedRegion region("mupm::Solid::step");
    auto& p = disc_.points;
    if constexpr (Law::plastic)
      commit_plastic();
    save_positions();
    advance_positions(p, dt);
    apply_kinematic(bcs_, p, t, dt);
  }
  SkeletonState skeleton_state() const override { return {du_, rho_, inertia_, shift_step_}; }
  // The pressure correction's work on the skeleton, part of the pore work (W_pore).
  void add_projection_work(double w) override {
    pore_work_ += w;
    projection_work_ += w;
  }
  double projection_work() const { return projection_work_; }
  // The rest of the step, in parts. finish_forces: boundary layers, forces at t + dt and the
  // step's work (this rank's terms, kept in pending_ for complete()).
  void finish_forces(double t, double dt) override {
    ScopedRegion region("mupm::Solid::step");
    auto& p = disc_.points;
    if (slaved_)  // 2 dg of each slaved condition (twice_dg_)
      for (std::size_t k = 0; k < bcs_.size(); ++k) {
        const auto& bc = bcs_[k];
        if (slaved_velocity(bc)) {  // the displacement of apply_kinematic's midpoint rule
          const double before = slaved_disp_[k];
          slaved_disp_[k] += dt * bc.value * bc.time(t + 0.5 * dt);
          twice_dg_[k] = 2 * (slaved_disp_[k] - before);
        } else if (bc.kinematic() && bc.slaved) {
          twice_dg_[k] = 2 * bc.value * (bc.time(t + dt) - bc.time(t));
        }
      }
    mirror_layers(t + dt);
    increments();
    if (slaved_)
      for (std::size_t k = 0; k < bcs_.size(); ++k)
        if (bcs_[k].kinematic() && bcs_[k].slaved)
          slaved_increment(bcs_[k], p, du_, twice_dg_[k]);
    // External work and the crack force's share of it by the trapezoid rule on the forces at
    // the step's start and end, dissipation and pore work (this rank's points).
    StepTerms& w = pending_;
    w = StepTerms{};
    auto trapezoid_half = [&] {
      double half[2];
      power(half);
      w.external_work += 0.5 * half[0];
      w.crack_work += 0.5 * half[1];
    };
    trapezoid_half();
    Kokkos::deep_copy(vs_old_,
                      Kokkos::subview(p.vol_strain, std::make_pair(std::size_t(0), p.n_owned)));
    st_.work = energy_criterion() ? BondWork::Accumulate : BondWork::Off;
    forces(t + dt);
    trapezoid_half();
    w.dissipation = dt * damping_power();
    w.pore_work = pore_power() + eq17_power();
    keep_applied();
    if (breaks())
      w.stored_before = stored_energy();
  }
  // The energy criterion (Algorithm 4) on the bond energies of the forces at t + dt: the bonds
  // it broke on this rank and the energy they released.
  Breakage energy_breakage() override {
    if (!energy_criterion())
      return {};
    auto& p = disc_.points;
    return break_bonds(p, disc_.bonds, set_.fracture.critical_energy, st_.max_energy,
                       p.bond_energy_released);
  }
  // complete: with `broken` the directed bonds broken on this rank since finish_forces (by the
  // energy and J criteria) and their energy (collective): the step's one reduction, the
  // velocities at t + dt, then the forces of the new bond set.
  void complete(double t, double dt, const Breakage& broken) override {
    ScopedRegion region("mupm::Solid::step");
    auto& p = disc_.points;
    StepTerms& w = pending_;
    w.broken = double(broken.bonds);
    w.released = broken.energy;
    static_assert(sizeof(StepTerms) == 7 * sizeof(double));
    MPI_Allreduce(MPI_IN_PLACE, &w, 7, MPI_DOUBLE, MPI_SUM, comm_);
    work_ += w.external_work;
    crack_work_ += w.crack_work;
    dissipation_ += w.dissipation;
    pore_work_ += w.pore_work;
    bond_energy_released_ += w.released;
    advance_velocities(p, st_.force, st_.moment, rho_, inertia_, body_, couple_, set_.gravity,
                       set_.damping, dt);
    if (w.broken > 0) {
      after_breakage(t + dt, w.stored_before);
      broken_pairs_ += static_cast<long long>(w.broken) / 2;  // each pair twice over the ranks
    }
    if constexpr (Law::plastic)  // with the stress of the step's end, after any breakage
      plastic_dissipation_ += plastic_power();
    steps_ += 1;
    const int window = set_.second_order_window;
    if (window > 0 && steps_ % window == 0) {
      second_order_work(p, st_.eps, st_.kappa, p.second_order_work_start, p.second_order_work);
      double v[2];
      negative_volume(p, p.second_order_work, v[0], v[1]);
      MPI_Allreduce(MPI_IN_PLACE, v, 2, MPI_DOUBLE, MPI_SUM, comm_);
      negative_fraction_ = v[0] > 0 ? v[1] / v[0] : 0.0;
    }
  }
  long long broken_pairs() const override { return broken_pairs_; }

  // Bonds broke at the end of a step (Algorithm 4), after its velocity update: the step ran
  // with the old bond set, as its work and the bond energies were booked. K, its inverse and
  // the family volumes change at the broken bonds' ends, and with them eps, kappa and the
  // forces: the forces of the new bond set replace the old ones in the accelerations (for the
  // next step's first velocity half) and open the next step's trapezoids (work and bond
  // energies). The fracture dissipation is the strain energy the body loses in the breakage, at
  // the same u and theta: in the correspondence model a point's energy is its family's, not a
  // sum over its bonds, so the broken bonds' W (what the criterion compares with W_cr,
  // bond_energy_released) is not what the body loses; the loss is what closes the energy
  // balance (eq 140). `before`: the strain energy of the old bond set (summed over ranks).
  //
  // With pore water, tr(eps) of the points that lost bonds jumps with their shape tensors at
  // fixed u: no volume change of the skeleton, so the water must not see one. Their
  // volumetric-strain reference (of the undrained split and the fluid's next volume change)
  // moves by the jump, and the forces are evaluated again with it (p* continuous).
  void after_breakage(double t, double before) {
    auto& p = disc_.points;
    Kokkos::deep_copy(f_old_, st_.force);
    Kokkos::deep_copy(l_old_, st_.moment);
    const auto owned = std::make_pair(std::size_t(0), p.n_owned);
    Kokkos::deep_copy(vs_old_, Kokkos::subview(p.vol_strain, owned));
    disc_.update_shape();
    st_.work = energy_criterion() ? BondWork::Record : BondWork::Off;
    forces(t);
    if (pressure_) {
      auto ref = p.vol_strain_ref, vs = p.vol_strain;
      auto old = vs_old_;
      Kokkos::parallel_for(
          "mupm::Fracture::strain_reference", range(0, p.n_owned),
          KOKKOS_LAMBDA(const std::size_t i) { ref(i) += vs(i) - old(i); });
      forces(t);
    }
    keep_applied();
    double after[2] = {stored_energy(), -acceleration_sum()};
    auto a = p.a, al = p.alpha;
    auto f = st_.force, l = st_.moment, f0 = f_old_, l0 = l_old_;
    auto rho = rho_, J = inertia_;
    auto fixed = p.fixed;
    Kokkos::parallel_for(
        "mupm::Fracture::accelerations", range(0, p.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
          const std::uint32_t fx = fixed(i);
          for (int k = 0; k < Dim; ++k)
            if (!(fx & (1u << k)))
              a(i, k) += (f(i, k) - f0(i, k)) / rho(i);
          for (int r = 0; r < R; ++r)
            if (!(fx & (1u << (Dim + r))))
              al(i, r) += (l(i, r) - l0(i, r)) / J(i);
        });
    after[1] += acceleration_sum();
    MPI_Allreduce(MPI_IN_PLACE, after, 2, MPI_DOUBLE, MPI_SUM, comm_);
    // The kinetic shift -dt^2/8 m|a|^2 of the ledger (Energy::kinetic_shift) jumps with the
    // accelerations: the leapfrog's invariant for the new bond set, 1/2 m v_{n-1/2}' . v_{n+1/2}
    // with v_{n-1/2}' = v_{n+1/2} - dt a+, exceeds the old one by dt^2/8 m (|a-|^2 - |a+|^2) at
    // the same u (v_{n+1/2} = v_{n-1/2} + dt/2 (a- + a+)). That jump is the breakage's too:
    // booked with the fracture dissipation, the balance stays closed across a break
    // (tests/solvers/test_fracture_flow.cpp, CrackWaterBalanceHoldsThroughBreakage). It is
    // O(dt^2) per break, so it shows at the semi-implicit scheme's drained step (on the KGD
    // input at 60 x 60 to 20 ms, unbooked: -0.66 % of the external work after 56 broken pairs).
    fracture_energy_ += before - after[0] + 0.125 * dt_ * dt_ * after[1];
  }
  // acc += s m V |w|^2 over point i's free components: m = rho for the Dim translational ones
  // (w of `trans`), J for the rotational ones (w of `rot`). The kinetic energy is s = 1/2 with
  // v, omega; the acceleration sum s = 1 with a, alpha.
  template <class VT, class VR>
  KOKKOS_INLINE_FUNCTION static void add_free_squares(double& acc, double s, std::uint32_t fx,
                                                      double rho, double J, double vol,
                                                      const VT& trans, const VR& rot,
                                                      std::size_t i) {
    for (int k = 0; k < Dim; ++k)
      if (!(fx & (1u << k)))
        acc += s * rho * vol * trans(i, k) * trans(i, k);
    for (int r = 0; r < R; ++r)
      if (!(fx & (1u << (Dim + r))))
        acc += s * J * vol * rot(i, r) * rot(i, r);
  }
  // sum V (rho |a|^2 + J |alpha|^2) over this rank's free components.
  double acceleration_sum() const {
    const auto& p = disc_.points;
    auto a = p.a, al = p.alpha, vol = p.volume;
    auto fixed = p.fixed;
    auto rho = rho_, J = inertia_;
    double e = 0;
    Kokkos::parallel_reduce(
        "mupm::Solid::acceleration_sum", range(0, p.n_owned),
        KOKKOS_LAMBDA(const std::size_t i, double& acc) {
          add_free_squares(acc, 1.0, fixed(i), rho(i), J(i), vol(i), a, al, i);
        },
        e);
    return e;
  }

  // Whether any point has a pore pressure or an undrained modulus (the same on every rank).
  bool has_pressure() const {
    const auto& p = disc_.points;
    auto pw = p.p, bu = p.undrained_modulus;
    int any = 0;
    Kokkos::parallel_reduce(
        "mupm::Solid::has_pressure", range(0, p.n_owned),
        KOKKOS_LAMBDA(const std::size_t i, int& acc) {
          acc = (pw(i) != 0 || bu(i) != 0) ? 1 : acc;
        },
        Kokkos::Max<int>(any));
    MPI_Allreduce(MPI_IN_PLACE, &any, 1, MPI_INT, MPI_MAX, comm_);
    return any != 0;
  }

  // Strain energy (elastic and stabilization) of this rank's points.
  double stored_energy() const {
    auto en = st_.energy;
    double e = 0;
    Kokkos::parallel_reduce(
        "mupm::Solid::stored_energy", range(0, disc_.points.n_owned),
        KOKKOS_LAMBDA(const std::size_t i, double& acc) { acc += en(i); }, e);
    return e;
  }

  Energy energy() const {
    const auto& p = disc_.points;
    auto en = st_.energy;
    auto v = p.v, om = p.omega;
    auto vol = p.volume;
    auto fixed = p.fixed;
    auto a = p.a, al = p.alpha;
    auto rho = rho_, J = inertia_;
    double e[3] = {0, 0, 0};  // internal, kinetic, acceleration_sum() (one pass over the points)
    Kokkos::parallel_reduce(
        "mupm::Solid::energy", range(0, p.n_owned),
        KOKKOS_LAMBDA(const std::size_t i, double& ei, double& ek, double& ea) {
          ei += en(i);
          add_free_squares(ek, 0.5, fixed(i), rho(i), J(i), vol(i), v, om, i);
          add_free_squares(ea, 1.0, fixed(i), rho(i), J(i), vol(i), a, al, i);
        },
        e[0], e[1], e[2]);
    MPI_Allreduce(MPI_IN_PLACE, e, 3, MPI_DOUBLE, MPI_SUM, comm_);
    Energy out;
    out.internal = e[0];
    out.kinetic = e[1];
    out.kinetic_shift = -0.125 * dt_ * dt_ * e[2];
    out.external_work = work_;
    out.dissipation = dissipation_;
    out.pore_work = pore_work_;
    out.crack_work = crack_work_;
    out.fracture = fracture_energy_;
    out.plastic = plastic_dissipation_;
    out.bond_energy = bond_energy_released_;
    return out;
  }

  // Force (moment) the boundary applies on each kinematic condition's points: -sum f V; on a
  // slaved layer's points dPsi/dg = -2 sum f V (kernels/boundary_conditions.hpp, slave_layer).
  std::vector<std::string> reaction_names() const {
    std::vector<std::string> n;
    for (const auto& bc : bcs_)
      if (bc.kinematic())
        n.push_back("reaction_" + bc.name);
    return n;
  }
  std::vector<double> reactions() const {
    std::vector<double> out;
    const auto& p = disc_.points;
    for (const auto& bc : bcs_) {
      if (!bc.kinematic())
        continue;
      const bool rot = bc.kind == BoundaryCondition::MicroRotation;
      const Vectors f = rot ? st_.moment : st_.force;
      const int c = bc.component;
      const std::uint32_t mask = bc.region_mask;
      auto regions = p.regions;
      auto vol = p.volume;
      auto fixed = p.fixed;
      double s = 0;
      Kokkos::parallel_reduce(
          "mupm::Solid::reaction", range(0, p.n_owned),
          KOKKOS_LAMBDA(const std::size_t i, double& acc) {
            if (mask == 0 || (regions(i) & mask))
              acc -= ((fixed(i) & kFixedNoEnergy) ? 2.0 : 1.0) * f(i, c) * vol(i);
          },
          s);
      MPI_Allreduce(MPI_IN_PLACE, &s, 1, MPI_DOUBLE, MPI_SUM, comm_);
      out.push_back(s);
    }
    return out;
  }

  // Largest stable step of the undamped central difference, 2 / omega_max, with omega_max^2
  // the largest eigenvalue of M^-1 K of the discrete operator (prescribed components held),
  // by power iteration with the mass-weighted Rayleigh quotient (it approaches omega_max^2
  // from below). The state is restored afterwards.
  // With a fluid the operator includes the undrained stiffness (biot S_r)^2 / C of the undrained
  // split (include/mupm/kernels/solid.hpp): the fastest waves are the undrained ones.
  bool limits_time_step() const override { return true; }
  double stable_time_step() override {
    double dt = 0;
    keeping_plastic_state([&] { dt = estimate_stable_dt(); });
    return dt;
  }
  std::string describe() const override {
    std::ostringstream s;
    s << "micropolar solid, stabilization G = " << prm_.stabilization
      << ", D = " << prm_.stab_modulus << " Pa/m^2";
    return s.str();
  }
  double estimate_stable_dt(int iterations = 40) {
    ScopedRegion region("mupm::Solid::stable_step");
    auto& p = disc_.points;
    const Vectors u0 = scratch_.copy("u0", p.u), t0 = scratch_.copy("t0", p.theta);
    const Scalars p0 = scratch_.copy("p0", p.p), ref0 = scratch_.copy("ref0", p.vol_strain_ref);
    Kokkos::deep_copy(p.p, 0.0);  // the operator's linear part only
    Kokkos::deep_copy(p.vol_strain_ref, 0.0);
    const BondWork work = st_.work;
    st_.work = BondWork::Off;  // the iterates are no motion of the body
    // With the crack's water on its faces the operator includes its undrained stiffness M_f
    // (kernels/fracture_flow.hpp): its linear part (p_f = 0 at c_ref = 0), and on a fracture
    // point not yet in the network the modulus it will join with, K_w / a_min (saturated, closed:
    // a film a_min). The crack water's stiffness K_w / a_min is what limits the step of a
    // fluid-driven crack (Example 1 at 66 x 66, K_w = 2.2 GPa, a_min = 0.1 mm: stable at 0.4 us,
    // unstable at 0.95 us, the skeleton's own limit being 1.9 us). Semi-implicit: p_f comes from
    // the pressure solve (M_f = 0, pressure_projection.hpp), the crack water adds no stiffness.
    const bool crack = face_pressure() && !set_.semi_implicit;
    Scalars keep[5];
    if (crack) {
      Scalars fields[5] = {p.pf, p.pf_saturation, p.pf_modulus, p.pf_aperture, p.pf_area};
      for (int k = 0; k < 5; ++k)
        keep[k] = scratch_.copy("crack" + std::to_string(k), fields[k]);
      // A point that joins has the face-area share of one row, V/dx (n_i = 1: the stiffest).
      const double joins = set_.fracture.water_modulus / set_.fracture.min_aperture;
      const double inv_dx = 1.0 / disc_.grid.dx;
      auto pf = p.pf, sat = p.pf_saturation, mod = p.pf_modulus, ref = p.pf_aperture;
      auto area = p.pf_area, vol = p.volume;
      auto frac = p.fracture;
      Kokkos::parallel_for(
          "mupm::Solid::crack_stiffness", range(0, p.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
            if (frac(i) && !(sat(i) > 0)) {
              sat(i) = 1.0;
              mod(i) = joins;
              area(i) = vol(i) * inv_dx;
            }
            pf(i) = 0;
            ref(i) = 0;
          });
      disc_.dist.refresh({as_vectors(p.pf_saturation)});
    }
    const Operator op{p.u, p.theta, st_.force, st_.moment, rho_, inertia_, p.fixed};
    const double lambda = largest_eigenvalue(
        op, Dim + R, p.n_owned, p.gid, p.volume,
        [&] {
          disc_.dist.refresh({p.u, p.theta});
          if (slaved_) {  // the slaving's linear part (g = 0), then its fold: P^T K P
            for (const auto& bc : bcs_)
              if (bc.kinematic() && bc.slaved)
                slave_layer(bc, p, disc_.mirror, 0.0, 0.0, false);
            disc_.dist.refresh({p.u, p.theta});
          }
          solid_forces(disc_, prm_, prm_.law, st_);  // elastic: the stiffest tangent, no state
          fold_layers();
          if (crack)
            add_crack_force(st_.force);
        },
        comm_, iterations);
    if (crack) {
      Scalars fields[5] = {p.pf, p.pf_saturation, p.pf_modulus, p.pf_aperture, p.pf_area};
      for (int k = 0; k < 5; ++k)
        Kokkos::deep_copy(fields[k], keep[k]);
    }
    Kokkos::deep_copy(p.u, u0);
    Kokkos::deep_copy(p.theta, t0);
    Kokkos::deep_copy(p.p, p0);
    Kokkos::deep_copy(p.vol_strain_ref, ref0);
    disc_.dist.refresh({p.u, p.theta});
    solid_forces(disc_, prm_, law_, st_);
    fold_layers();
    st_.work = work;
    // The forces the run applied last, not those of the pressure the fluid has updated since
    // (the next step's external work starts from them).
    restore_applied();
    return lambda > 0 ? 2.0 / std::sqrt(lambda) : 0.0;
  }

 private:
  // M^-1 K of the power iteration: the iterate is (u, theta), K x = -(f, l) (prescribed
  // components held), M = (rho, J).
  struct Operator {
    Vectors u, th, f, l;
    Scalars rho, J;
    Flags fixed;
    KOKKOS_INLINE_FUNCTION double& x(std::size_t i, int c) const {
      return c < Dim ? u(i, c) : th(i, c - Dim);
    }
    KOKKOS_INLINE_FUNCTION double ax(std::size_t i, int c) const {
      return c < Dim ? -f(i, c) : -l(i, c - Dim);
    }
    KOKKOS_INLINE_FUNCTION double mass(std::size_t i, int c) const {
      return c < Dim ? rho(i) : J(i);
    }
    KOKKOS_INLINE_FUNCTION bool held(std::size_t i, int c) const {
      return (fixed(i) & (1u << c)) != 0;
    }
    KOKKOS_INLINE_FUNCTION double start(std::size_t i, int c, double s) const {
      if (held(i, c))
        return 0.0;
      return c < Dim ? std::sin(1.3 * s + 0.7 * c) + 0.1 : std::cos(0.9 * s + 0.3 * (c - Dim));
    }
  };

  // The mirrored Displacement conditions' layer points from their mirrors' current values
  // (kernels/boundary_conditions.hpp, mirror_kinematic), after the step has moved the body: the
  // mirrors' new values reach the ghosts first (one extra refresh per step, only with such
  // conditions).
  // The slaved layers' likewise (slave_layer).
  void mirror_layers(double t) {
    if (!mirrored_ && !slaved_)
      return;
    auto& p = disc_.points;
    disc_.dist.refresh({p.u, p.theta, p.v});
    for (std::size_t k = 0; k < bcs_.size(); ++k) {
      const auto& bc = bcs_[k];
      if (!(bc.kinematic() && bc.mirrored))
        continue;
      if (!bc.slaved)
        mirror_kinematic(bc, p, disc_.mirror, t);
      else if (slaved_velocity(bc))
        slave_layer(bc, p, disc_.mirror, slaved_disp_[k], bc.value * bc.time(t));
      else
        slave_layer(bc, p, disc_.mirror, bc.value * bc.time(t), bc.value * bc.time.rate(t));
    }
  }
  static bool slaved_velocity(const BoundaryCondition& bc) {
    return bc.slaved && bc.kind == BoundaryCondition::Velocity;
  }
  // Traction Distribution = Consistent (kernels/boundary_conditions.hpp,
  // consistent_traction_load): each such traction's load of a unit Value, from the families at
  // construction (bonds broken later leave it as it was), on the strip within 2 delta + dx of its
  // face whose other coordinates lie in the condition's region box.
  // The slaved layers' marks first (initialize() repeats them; they only set bits): their points
  // carry no stress and their forces fold, as in the run. Built here, not in initialize(), so
  // that a restart, whose checkpoint breaks bonds in between, builds it from the same bonds.
  void build_consistent_tractions() {
    auto& p = disc_.points;
    const auto& g = disc_.grid;
    SolidState<Dim> tmp;
    for (auto& bc : bcs_) {
      if (!bc.consistent)
        continue;
      if (bc.face < 0 || bc.face >= 2 * Dim || bc.region_mask == 0 ||
          (bc.region_mask & (bc.region_mask - 1)) != 0)
        throw std::logic_error("SolidSolver: consistent traction '" + bc.name +
                               "' needs its face and one region (input/model.cpp)");
      if (tmp.force.extent(0) == 0) {
        tmp.allocate(p.size(), p.n_owned);
        mark_fixed(bcs_, p);
        if (mirrored_ || slaved_)
          mark_mirrored_layers(bcs_, p, disc_.mirror);
      }
      uniform_stress_forces(disc_, prm_, unit_traction_stress(Dim, bc.face, bc.component), tmp);
      if (slaved_)
        fold_layer_forces(disc_, slots_, tmp.force, tmp.moment, fold_);
      int r = 0;
      while (!(bc.region_mask & (1u << r)))
        ++r;
      const Box& box = g.regions[std::size_t(r)];
      const int axis = bc.face / 2;
      Kokkos::Array<double, 3> lo{}, hi{};
      for (int d = 0; d < Dim; ++d) {
        lo[d] = box.lo[d];
        hi[d] = box.hi[d];
      }
      const double plane = g.origin[axis] + (bc.face % 2 ? g.counts[axis] * g.dx : 0.0);
      bc.unit_load = Vectors("mupm::traction_load", p.n_owned, Dim + R);
      consistent_traction_load(p, bc.face, bc.component, 2 * g.horizon + g.dx, lo, hi, plane,
                               tmp.force, tmp.moment, bc.unit_load);
    }
  }

  // The slaved layer points' forces and moments onto their mirrors (pack_layer_forces), across
  // ranks. The layer points keep theirs: the reactions and the external work are made of them.
  void fold_layers() {
    if (!slaved_)
      return;
    ScopedRegion region("mupm::Solid::fold_layers");
    fold_layer_forces(disc_, slots_, st_.force, st_.moment, fold_);
  }

  void forces(double t) {
    auto& p = disc_.points;
    if (st_.work == BondWork::Accumulate)
      disc_.dist.refresh({p.u, p.theta, du_});
    else
      disc_.dist.refresh({p.u, p.theta});
    solid_forces(disc_, prm_, law_, st_);
    fold_layers();
    body_force_density(bcs_, p, disc_.grid.dx, t, body_, couple_);
    if (face_pressure()) {  // the crack's water on its faces (kernels/fracture_flow.hpp)
      Kokkos::deep_copy(crack_, 0.0);
      add_crack_force(crack_);
      add_to_body(crack_);
    }
    forces_time_ = t;
    auto eps = st_.eps;
    auto vs = p.vol_strain;
    const Law law = law_;
    Kokkos::parallel_for(
        "mupm::Solid::volumetric_strain", range(0, p.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
          // eq 117; plus the plastic thickness change in plane stress with pore water
          // (laws/micropolar_drucker_prager.hpp, pore_shift; 0 otherwise)
          double tr = law.pore_shift(i);
          for (int d = 0; d < Dim; ++d)
            tr += eps(i, d * Dim + d);
          vs(i) = tr;
        });
    update_shift_step();
  }
  // The plastic thickness change of the forces just evaluated, pore_shift(current) -
  // pore_shift(start) (SkeletonState::plastic_shift), from the law's state; again after a
  // restore by keeping_plastic_state, so that it is always the kept state's.
  void update_shift_step() {
    if constexpr (Law::plastic) {
      if (shift_step_.extent(0) == 0)
        return;
      const Law law = law_;
      auto s = shift_step_;
      Kokkos::parallel_for(
          "mupm::Solid::plastic_thickness_change", range(0, disc_.points.n_owned),
          KOKKOS_LAMBDA(const std::size_t i) {
            s(i) = law.pore_shift(i) - law.pore_shift_start(i);
          });
    }
  }

  // The p* and the force and moment densities of the forces just applied, into the points'
  // checkpointed fields: the next step's pore work and external work start from them, also
  // after a restart (whose fluid has updated p since they were applied).
  void keep_applied() {
    auto& p = disc_.points;
    const auto owned = std::make_pair(std::size_t(0), p.n_owned);
    Kokkos::deep_copy(Kokkos::subview(p.solid_pressure, owned), st_.pstar);
    Kokkos::deep_copy(Kokkos::subview(p.applied_force, owned, Kokkos::ALL), st_.force);
    Kokkos::deep_copy(Kokkos::subview(p.applied_moment, owned, Kokkos::ALL), st_.moment);
    if (face_pressure())
      Kokkos::deep_copy(Kokkos::subview(p.applied_crack_force, owned, Kokkos::ALL), crack_);
  }
  void restore_applied() {
    auto& p = disc_.points;
    const auto owned = std::make_pair(std::size_t(0), p.n_owned);
    Kokkos::deep_copy(st_.force, Kokkos::subview(p.applied_force, owned, Kokkos::ALL));
    Kokkos::deep_copy(st_.moment, Kokkos::subview(p.applied_moment, owned, Kokkos::ALL));
    if (face_pressure()) {  // the crack force applied last, with the p_f of then
      body_force_density(bcs_, p, disc_.grid.dx, forces_time_, body_, couple_);
      Kokkos::deep_copy(crack_, Kokkos::subview(p.applied_crack_force, owned, Kokkos::ALL));
      add_to_body(crack_);
    }
  }
  bool face_pressure() const { return set_.fracture.flow && set_.fracture.face_pressure; }
  // Adds the crack water's force density to `out` (owned points): p_f* at this displacement
  // (undrained split, kernels/fracture_flow.hpp), the face loads g of that pressure onto the
  // ghosts, then the forces of the broken bonds.
  void add_crack_force(const Vectors& out) {
    auto& p = disc_.points;
    undrained_fracture_pressure(disc_.bonds, p, pf_star_);
    crack_face_load(disc_.bonds, p, pf_star_, face_load_);
    disc_.dist.refresh({face_load_});
    crack_pressure_force(disc_.bonds, p, face_load_, out);
  }
  void add_to_body(const Vectors& f) {
    auto b = body_;
    Kokkos::parallel_for(
        "mupm::Solid::add_body", range(0, disc_.points.n_owned),
        KOKKOS_LAMBDA(const std::size_t i) {
          for (int d = 0; d < Dim; ++d)
            b(i, d) += f(i, d);
        });
  }

  // sum_i V_i biot S_r (p*_old + p*_new)/2 (tr eps_new - tr eps_old) of this step (this rank's
  // points; step() sums over ranks), with the p* the forces were evaluated with: the old one
  // is from before any fluid update in between, as the first half of the velocity update
  // used it (trapezoid rule on the applied forces, like the external work).
  double pore_power() const {
    const auto& p = disc_.points;
    auto vs = p.vol_strain, sr = p.saturation, vol = p.volume;
    auto ps = st_.pstar, ps_old = p.solid_pressure;
    auto old = vs_old_;
    const double biot = prm_.pore.biot;  // PoreCoupling: 1 but in plane stress
    double w = 0;
    Kokkos::parallel_reduce(
        "mupm::Solid::pore_work", range(0, p.n_owned),
        KOKKOS_LAMBDA(const std::size_t i, double& acc) {
          acc += vol(i) * biot * sr(i) * 0.5 * (ps(i) + ps_old(i)) * (vs(i) - old(i));
        },
        w);
    return w;
  }

  // Power of eq 17's crack-water forces on this step's increment (this rank's points), with the
  // forces at the step's end (rectangle rule: first order, and nothing to keep for a restart):
  // the work the crack's water does on the skeleton, booked with the pore work (eq 140).
  double eq17_power() const {
    if (st_.water_force.extent(0) == 0)
      return 0.0;
    const auto& p = disc_.points;
    auto fw = st_.water_force, du = du_;
    auto vol = p.volume;
    auto fixed = p.fixed;
    double w = 0;
    Kokkos::parallel_reduce(
        "mupm::Solid::eq17_work", range(0, p.n_owned),
        KOKKOS_LAMBDA(const std::size_t i, double& acc) {
          for (int c = 0; c < Dim + R; ++c)
            if (!(fixed(i) & (1u << c)))
              acc += fw(i, c) * du(i, c) * vol(i);
        },
        w);
    return w;
  }

  // band_angle [deg] and band_width [m] (include/mupm/kernels/shear_bands.hpp), collective.
  void bands(double& angle, double& width) const {
    auto sum = [this](double* d, int n) {
      MPI_Allreduce(MPI_IN_PLACE, d, n, MPI_DOUBLE, MPI_SUM, comm_);
    };
    auto max = [this](double* d, int n) {
      MPI_Allreduce(MPI_IN_PLACE, d, n, MPI_DOUBLE, MPI_MAX, comm_);
    };
    const auto& g = disc_.grid;  // the real body's centre
    measure_bands(disc_.points, g.origin[0] + 0.5 * g.counts[0] * g.dx,
                  g.origin[1] + 0.5 * g.counts[1] * g.dx, sum, max, angle, width);
  }

  // Runs f, an evaluation between two steps (a restart's first, the stable-step estimate), and
  // puts back the plastic law's current state: such an evaluation sees the pressure the fluid
  // has updated since the step's forces, and where the return depends on it (plane stress with
  // pore water, laws/micropolar_drucker_prager.hpp) it would change the state the next step
  // commits (a restart then differed from the straight run by 1e-7 after one step).
  template <class F>
  void keeping_plastic_state(F&& f) {
    std::vector<Vectors> kept;
    if constexpr (Law::plastic)
      for (const Vectors& v : plastic_current(disc_.points))
        kept.push_back(scratch_.copy("plastic" + std::to_string(kept.size()), v));
    f();
    for (std::size_t k = 0; k < kept.size(); ++k)
      Kokkos::deep_copy(plastic_current(disc_.points)[k], kept[k]);
    update_shift_step();
  }
  // The fields the plastic law's return writes (its current state, the stress it commits, the
  // water's volumetric strain).
  static std::vector<Vectors> plastic_current(const Points<Dim>& p) {
    return {p.stress,
            p.couple_stress,
            p.plastic_strain,
            p.plastic_wryness,
            as_vectors(p.plastic_strain_zz),
            as_vectors(p.equivalent_plastic_strain),
            as_vectors(p.plastic_volumetric_strain),
            as_vectors(p.cohesion),
            as_vectors(p.stress_zz),
            as_vectors(p.vol_strain)};
  }

  // The plastic law's current state becomes the start of the next step (the law's header).
  void commit_plastic() {
    auto& p = disc_.points;
    const Law law = law_;
    auto sig = p.stress, m = p.couple_stress;
    Kokkos::parallel_for(
        "mupm::Solid::plastic_commit", range(0, p.n_owned),
        KOKKOS_LAMBDA(const std::size_t i) { law.commit(i, sig, m); });
  }
  // Plastic dissipation of the step, summed over the ranks.
  double plastic_power() const {
    const auto& p = disc_.points;
    const Law law = law_;
    auto sig = p.stress, m = p.couple_stress, vol = p.volume;
    double d = 0;
    Kokkos::parallel_reduce(
        "mupm::Solid::plastic_dissipation", range(0, p.n_owned),
        KOKKOS_LAMBDA(const std::size_t i, double& acc) {
          acc += vol(i) * law.dissipation(i, sig, m);
        },
        d);
    MPI_Allreduce(MPI_IN_PLACE, &d, 1, MPI_DOUBLE, MPI_SUM, comm_);
    return d;
  }

  void save_positions() {
    auto& p = disc_.points;
    auto u = p.u, th = p.theta, du = du_;
    Kokkos::parallel_for(
        "mupm::Solid::save", range(0, p.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
          for (int k = 0; k < Dim; ++k)
            du(i, k) = u(i, k);
          for (int r = 0; r < R; ++r)
            du(i, Dim + r) = th(i, r);
        });
  }
  void increments() {
    auto& p = disc_.points;
    auto u = p.u, th = p.theta, du = du_;
    Kokkos::parallel_for(
        "mupm::Solid::increment", range(0, p.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
          for (int k = 0; k < Dim; ++k)
            du(i, k) = u(i, k) - du(i, k);
          for (int r = 0; r < R; ++r)
            du(i, Dim + r) = th(i, r) - du(i, Dim + r);
        });
  }
  // Power of the external agents on this step's increment (this rank's points), out[0]: on
  // prescribed components the boundary holds the point against the body's force density f (it
  // applies -f V); on free components gravity and the body/traction forces act. out[1]: the
  // crack water's face forces' share of it (crack_, part of the body force; free components).
  void power(double out[2]) const {
    const auto& p = disc_.points;
    auto f = st_.force, l = st_.moment, b = body_, bc = couple_, du = du_;
    auto vol = p.volume;
    auto fixed = p.fixed;
    auto rho = rho_;
    const auto g = set_.gravity;
    const bool crack = face_pressure();
    auto fc = crack_;
    out[0] = out[1] = 0;
    Kokkos::parallel_reduce(
        "mupm::Solid::external_work", range(0, p.n_owned),
        KOKKOS_LAMBDA(const std::size_t i, double& acc, double& acc_crack) {
          const std::uint32_t fx = fixed(i);
          for (int k = 0; k < Dim; ++k) {
            const bool held = (fx & (1u << k)) != 0;
            acc += (held ? -f(i, k) : b(i, k) + rho(i) * g[k]) * du(i, k) * vol(i);
            if (crack && !held)
              acc_crack += fc(i, k) * du(i, k) * vol(i);
          }
          for (int r = 0; r < R; ++r)
            acc += ((fx & (1u << (Dim + r))) ? -l(i, r) : bc(i, r)) * du(i, Dim + r) * vol(i);
        },
        out[0], out[1]);
  }
  // Damping power c (rho v.v + J omega.omega) V at the half step (this rank's points).
  double damping_power() const {
    if (set_.damping == 0)
      return 0.0;
    const auto& p = disc_.points;
    auto v = p.v, om = p.omega, vol = p.volume;
    auto fixed = p.fixed;
    auto rho = rho_, J = inertia_;
    const double c = set_.damping;
    double w = 0;
    Kokkos::parallel_reduce(
        "mupm::Solid::damping_power", range(0, p.n_owned),
        KOKKOS_LAMBDA(const std::size_t i, double& acc) {
          const std::uint32_t fx = fixed(i);
          for (int k = 0; k < Dim; ++k)
            if (!(fx & (1u << k)))
              acc += c * rho(i) * v(i, k) * v(i, k) * vol(i);
          for (int r = 0; r < R; ++r)
            if (!(fx & (1u << (Dim + r))))
              acc += c * J(i) * om(i, r) * om(i, r) * vol(i);
        },
        w);
    return w;
  }

  Discretization<Dim>& disc_;
  SolidParams prm_;
  Law law_;
  std::vector<BoundaryCondition> bcs_;
  Settings set_;
  MPI_Comm comm_;
  SolidState<Dim> st_;
  Scalars rho_, inertia_;
  Vectors body_, couple_, du_;
  Scalars shift_step_;      // SkeletonState::plastic_shift (semi-implicit, plastic plane stress)
  Vectors crack_;           // the crack water's force density (Fracture Flow)
  Scalars pf_star_;         // p_f* of the crack force (owned points)
  Vectors face_load_;       // g of the crack force (owned and ghosts; kernels/fracture_flow.hpp)
  double forces_time_ = 0;  // t of the last forces()
  Vectors f_old_, l_old_;   // forces of the old bond set at a breakage
  Scalars vs_old_;
  double work_ = 0, dissipation_ = 0, pore_work_ = 0, balance0_ = 0;
  double dt_ = 0;               // the run's step (Energy::kinetic_shift)
  bool started_ = false;        // initialized at a start, not a restart (set_time_step)
  double projection_work_ = 0;  // add_projection_work (Semi-Implicit)
  double crack_work_ = 0;       // work of the crack water's face forces since t = 0 [J] (Energy)
  double fracture_energy_ = 0;  // strain energy lost to bond breakage since t = 0 [J]
  double plastic_dissipation_ = 0;   // plastic dissipation since t = 0 [J] (plastic law)
  long long steps_ = 0;              // steps since t = 0 (second-order work windows)
  double negative_fraction_ = 0;     // volume fraction with d2E < 0, last window
  double bond_energy_released_ = 0;  // W V_i V_j of the bonds broken since t = 0 [J]
  long long broken_pairs_ = 0;       // bond pairs broken since t = 0 (a restart global)
  bool mirrored_ = false;            // mirrored Displacement conditions (mirror_layers)
  bool slaved_ = false;              // slaved layers (slave_layer, fold_layers)
  Vectors fold_;                     // fold_layers' buffer [owned + ghosts][columns]
  FaceSlots slots_;                  // fold_'s block of each face (-1: none)
  // The displacement a slaved Velocity condition has prescribed since t = 0 (by condition; a
  // restart global), the g its layer reflects about.
  std::vector<double> slaved_disp_;
  std::vector<double> twice_dg_;  // 2 dg of each slaved condition in the current step
  bool pressure_ = false;         // breakage run with pore pressure (initialize)
  bool keep_pore_part_ = false;   // P1w for the J-integral (keep_pore_part)
  // This rank's terms of a step, from finish_forces to complete's one reduction.
  struct StepTerms {
    double external_work = 0;  // [J] (the trapezoid rule, power())
    double crack_work = 0;     // [J] the crack water force's share of external_work
    double dissipation = 0;    // [J] damping
    double pore_work = 0;      // [J] pore pressure and eq 17's water force
    double stored_before = 0;  // [J] strain energy before the breakage (after_breakage)
    double broken = 0;         // directed bonds broken (energy and J criteria)
    double released = 0;       // [J] the bond energy they released (energy criterion)
  } pending_;
  Scratch scratch_;  // the fields estimate_stable_dt and keeping_plastic_state save
};

}  // namespace mupm

#endif
