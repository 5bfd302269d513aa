#include "mupm/solvers/solid_solver.hpp"

#include <sstream>
#include <type_traits>

#include "mupm/core/timers.hpp"
#include "mupm/kernels/central_difference.hpp"
#include "mupm/kernels/shear_bands.hpp"
#include "mupm/kernels/solid_energy.hpp"

namespace mupm {

template <int Dim, class Law>
SolidSolver<Dim, Law>::SolidSolver(Discretization<Dim>& disc, const SolidParams& prm,
                                   std::vector<BoundaryCondition> bcs, const Settings& settings,
                                   MPI_Comm comm, const Law& law)
    : disc_(disc),
      prm_(prm),
      law_(law),
      set_(settings),
      comm_(comm),
      boundary_(disc, std::move(bcs), comm),
      ledger_(settings.semi_implicit, settings.fracture.flow && settings.fracture.face_pressure,
              settings.fracture.criterion != BondBreaking::None, Law::plastic) {
  if constexpr (std::is_same_v<Law, MicropolarElastic>)
    law_ = prm.law;
  auto& p = disc_.points;
  if constexpr (Law::plastic)
    p.require(kGroupPlastic, "SolidSolver's plastic law");
  if (set_.second_order_window > 0)
    p.require(kGroupSecondOrderWork, "SolidSolver's second-order work");
  if (set_.fracture.flow)
    p.require(kGroupCrackWater, "SolidSolver's crack water force");
  if (releases())
    p.require(kGroupRelease, "SolidSolver's gradual release");
  st_.allocate(p.size(), p.n_owned);
  rho_ = Scalars("mupm::density", p.n_owned);
  inertia_ = Scalars("mupm::micro_inertia", p.n_owned);
  body_ = Vectors("mupm::body_force", p.n_owned, Dim);
  if (face_pressure())
    crack_ = std::make_unique<CrackFaceForce<Dim>>(disc_);
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
  boundary_.build_consistent_tractions(prm_);
}

template <int Dim, class Law>
void SolidSolver<Dim, Law>::globals(GlobalRefs& g) {
  ledger_.globals(g);
  if (breaks())
    g("broken_pairs", broken_pairs_);
  if (releases())
    g("release_start_time", release_start_);
  boundary_.globals(g);
  if (set_.second_order_window > 0) {
    g("steps", steps_);
    g("negative_second_order_work_fraction", negative_fraction_);
  }
}

template <int Dim, class Law>
void SolidSolver<Dim, Law>::series(SeriesRow& row) const {
  const auto e = energy();
  row("internal_energy", e.internal);
  row("kinetic_energy", e.kinetic);
  ledger_.series(row, e);
  if constexpr (Law::plastic) {
    double angle, width;
    bands(angle, width);
    row("band_angle", angle);
    row("band_width", width);
  }
  if (set_.second_order_window > 0)
    row("negative_second_order_work_fraction", negative_fraction_);
  row("energy_error", e.balance() - ledger_.initial_balance());
  const auto names = reaction_names();
  const auto values = reactions();
  for (std::size_t k = 0; k < names.size(); ++k)
    row(names[k], values[k]);
}

template <int Dim, class Law>
std::vector<EnergyBalance> SolidSolver<Dim, Law>::energy_balances() const {
  EnergyBalance b = ledger_.balance(energy());
  if (st_.P1f.extent(0) > 0)
    b.hint =  // the blow-up's growth rate does not follow the step (inputs/README.md)
        "Fracture->Crack Water Force = Eq 17 puts p_f on the bonds along the crack's faces, "
        "whose work the crack water does not supply: it can blow up at any time step; use "
        "Face Pressure.";
  return {b};
}

template <int Dim, class Law>
void SolidSolver<Dim, Law>::update_density() {
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

template <int Dim, class Law>
void SolidSolver<Dim, Law>::initialize(double t, bool restarted) {
  auto& p = disc_.points;
  boundary_.mark();
  update_density();
  // Pore water pressure, for the whole run: a fluid, or a held initial pressure (without a
  // fluid p never changes). The effective force state's bond energy then needs the pore-water
  // part of P1 apart. The same choice in a straight run and in its restart (which finds the
  // pressures the run developed: with Semi-Implicit a fluid run may start with none).
  pressure_ = (breaks() || keep_pore_part_) && (set_.fluid || has_pressure());
  if (pressure_ && set_.fracture.effective_state && st_.P1w.extent(0) == 0)
    st_.P1w = Vectors("mupm::pore_part_of_P1", p.size(), Dim * Dim);
  if (!restarted) {
    apply_kinematic(boundary_.conditions(), p, t, 0.0);
    boundary_.mirror_layers(t);
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
    advance_velocities(p, st_.force, st_.moment, rho_, inertia_, body_, couple_, set_.gravity, 0.0,
                       0.0);
    ledger_.set_initial_balance(energy().balance());
  }
  started_ = !restarted;
}

template <int Dim, class Law>
void SolidSolver<Dim, Law>::set_time_step(double dt) {
  dt_ = dt;
  if (started_)
    ledger_.set_initial_balance(energy().balance());
}

template <int Dim, class Law>
void SolidSolver<Dim, Law>::step(double t, double dt) {
  dt_ = dt;
  move(t, dt);
  finish(t, dt);
}

template <int Dim, class Law>
void SolidSolver<Dim, Law>::step_to_forces(double t, double dt) {
  dt_ = dt;
  move(t, dt);
  finish_forces(t, dt);
}

template <int Dim, class Law>
void SolidSolver<Dim, Law>::finish(double t, double dt) {
  finish_forces(t, dt);
  complete(t, dt, energy_breakage());
}

template <int Dim, class Law>
void SolidSolver<Dim, Law>::move(double t, double dt) {
  ScopedRegion region("mupm::Solid::step");
  auto& p = disc_.points;
  if constexpr (Law::plastic)
    commit_plastic();
  save_positions();
  advance_positions(p, dt);
  apply_kinematic(boundary_.conditions(), p, t, dt);
}

template <int Dim, class Law>
void SolidSolver<Dim, Law>::add_projection_work(double w) {
  ledger_.add(&SolidEnergy::pore_work, w);
  ledger_.add(&SolidEnergy::projection_work, w);
}

template <int Dim, class Law>
void SolidSolver<Dim, Law>::finish_forces(double t, double dt) {
  ScopedRegion region("mupm::Solid::step");
  auto& p = disc_.points;
  boundary_.advance_slaved(t, dt);  // 2 dg of each slaved condition
  boundary_.mirror_layers(t + dt);
  increments();
  boundary_.slaved_increments(du_);
  // External work and the crack force's share of it by the trapezoid rule on the forces at
  // the step's start and end, dissipation and pore work (this rank's points).
  StepTerms& w = pending_;
  w = StepTerms{};
  const Vectors crack = crack_ ? crack_->force() : Vectors();
  auto trapezoid_half = [&] {
    double half[2];
    external_power(p, st_.force, st_.moment, body_, couple_, du_, rho_, set_.gravity, crack, half);
    w.external_work += 0.5 * half[0];
    w.crack_work += 0.5 * half[1];
  };
  trapezoid_half();
  Kokkos::deep_copy(vs_old_,
                    Kokkos::subview(p.vol_strain, std::make_pair(std::size_t(0), p.n_owned)));
  st_.work = energy_criterion() ? BondWork::Accumulate : BondWork::Off;
  forces(t + dt);
  trapezoid_half();
  if (releases()) {  // the release force's share of the external work (header), if it acts
    const double r = 0.5 * (release_factor(t) + release_factor(t + dt));
    if (r > 0)
      w.release_work = r * release_work(p, du_);
  }
  w.dissipation = dt * damping_power();
  w.pore_work = pore_power();
  keep_applied();
  if (breaks())
    w.stored_before = stored_energy();
}

template <int Dim, class Law>
Breakage SolidSolver<Dim, Law>::energy_breakage() {
  if (!energy_criterion())
    return {};
  auto& p = disc_.points;
  return break_bonds(p, disc_.bonds, set_.fracture.critical_energy, st_.max_energy,
                     p.bond_energy_released);
}

template <int Dim, class Law>
void SolidSolver<Dim, Law>::complete(double t, double dt, const Breakage& broken) {
  ScopedRegion region("mupm::Solid::step");
  auto& p = disc_.points;
  StepTerms& w = pending_;
  w.broken = double(broken.bonds);
  w.released = broken.energy;
  static_assert(sizeof(StepTerms) == 8 * sizeof(double));
  MPI_Allreduce(MPI_IN_PLACE, &w, 8, MPI_DOUBLE, MPI_SUM, comm_);
  ledger_.book(w);
  advance_velocities(p, st_.force, st_.moment, rho_, inertia_, body_, couple_, set_.gravity,
                     set_.damping, dt);
  if (w.broken > 0) {
    after_breakage(t + dt, w.stored_before);
    broken_pairs_ += static_cast<long long>(w.broken) / 2;  // each pair twice over the ranks
  }
  if constexpr (Law::plastic) {  // with the stress of the step's end, after any breakage
    double d = plastic_power(p, law_);
    MPI_Allreduce(MPI_IN_PLACE, &d, 1, MPI_DOUBLE, MPI_SUM, comm_);
    ledger_.add(&SolidEnergy::plastic, d);
  }
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

// The step ran with the old bond set, as its work and the bond energies were booked. K, its
// inverse and the family volumes change at the broken bonds' ends, and with them eps, kappa and
// the forces: the forces of the new bond set replace the old ones in the accelerations (for the
// next step's first velocity half) and open the next step's trapezoids (work and bond
// energies). The fracture dissipation is the strain energy the body loses in the breakage, at
// the same u and theta: in the correspondence model a point's energy is its family's, not a
// sum over its bonds, so the broken bonds' W (what the criterion compares with W_cr,
// bond_energy_released) is not what the body loses; the loss is what closes the energy
// balance (eq 140).
//
// With pore water, tr(eps) of the points that lost bonds jumps with their shape tensors at
// fixed u: no volume change of the skeleton, so the water must not see one. Their
// volumetric-strain reference (of the undrained split and the fluid's next volume change)
// moves by the jump, and the forces are evaluated again with it (p* continuous).
template <int Dim, class Law>
void SolidSolver<Dim, Law>::after_breakage(double t, double before) {
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
  if (releases()) {  // the forces continue (header): no jump of the accelerations to book
    keep_release(t);
    double after = stored_energy();
    MPI_Allreduce(MPI_IN_PLACE, &after, 1, MPI_DOUBLE, MPI_SUM, comm_);
    ledger_.add(&SolidEnergy::fracture, before - after);
    return;
  }
  double after[2] = {stored_energy(), -acceleration_sum(p, rho_, inertia_)};
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
  after[1] += acceleration_sum(p, rho_, inertia_);
  MPI_Allreduce(MPI_IN_PLACE, after, 2, MPI_DOUBLE, MPI_SUM, comm_);
  // The kinetic shift -dt^2/8 m|a|^2 of the ledger (SolidEnergy::kinetic_shift) jumps with the
  // accelerations: the leapfrog's invariant for the new bond set, 1/2 m v_{n-1/2}' . v_{n+1/2}
  // with v_{n-1/2}' = v_{n+1/2} - dt a+, exceeds the old one by dt^2/8 m (|a-|^2 - |a+|^2) at
  // the same u (v_{n+1/2} = v_{n-1/2} + dt/2 (a- + a+)). That jump is the breakage's too:
  // booked with the fracture dissipation, the balance stays closed across a break
  // (tests/solvers/test_fracture_flow.cpp, CrackWaterBalanceHoldsThroughBreakage). It is
  // O(dt^2) per break, so it shows at the semi-implicit scheme's drained step (on the KGD
  // input at 60 x 60 to 20 ms, unbooked: -0.66 % of the external work after 56 broken pairs).
  ledger_.add(&SolidEnergy::fracture, before - after[0] + 0.125 * dt_ * dt_ * after[1]);
}

template <int Dim, class Law>
bool SolidSolver<Dim, Law>::has_pressure() const {
  const auto& p = disc_.points;
  auto pw = p.p, bu = p.undrained_modulus;
  int any = 0;
  Kokkos::parallel_reduce(
      "mupm::Solid::has_pressure", range(0, p.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, int& acc) { acc = (pw(i) != 0 || bu(i) != 0) ? 1 : acc; },
      Kokkos::Max<int>(any));
  MPI_Allreduce(MPI_IN_PLACE, &any, 1, MPI_INT, MPI_MAX, comm_);
  return any != 0;
}

template <int Dim, class Law>
double SolidSolver<Dim, Law>::stored_energy() const {
  return mupm::stored_energy(st_.energy, disc_.points.n_owned);
}

template <int Dim, class Law>
SolidEnergy SolidSolver<Dim, Law>::energy() const {
  double e[3];  // internal, kinetic, acceleration sum (one pass over the points)
  point_energies(disc_.points, st_.energy, rho_, inertia_, e);
  MPI_Allreduce(MPI_IN_PLACE, e, 3, MPI_DOUBLE, MPI_SUM, comm_);
  SolidEnergy out = ledger_.totals();
  out.internal = e[0];
  out.kinetic = e[1];
  out.kinetic_shift = -0.125 * dt_ * dt_ * e[2];
  return out;
}

template <int Dim, class Law>
double SolidSolver<Dim, Law>::stable_time_step() {
  double dt = 0;
  keeping_plastic_state([&] { dt = estimate_stable_dt(); });
  return dt;
}

template <int Dim, class Law>
std::string SolidSolver<Dim, Law>::describe() const {
  std::ostringstream s;
  s << "micropolar solid, stabilization G = " << prm_.stabilization << ", D = " << prm_.stab_modulus
    << " Pa/m^2";
  return s.str();
}

template <int Dim, class Law>
void SolidSolver<Dim, Law>::forces(double t) {
  auto& p = disc_.points;
  if (st_.work == BondWork::Accumulate)
    disc_.dist.refresh({p.u, p.theta, du_});
  else
    disc_.dist.refresh({p.u, p.theta});
  solid_forces(disc_, prm_, law_, st_);
  boundary_.fold(st_.force, st_.moment);
  body_force_density(boundary_.conditions(), p, disc_.grid.dx, t, body_, couple_);
  if (crack_) {  // the crack's water on its faces (kernels/fracture_flow.hpp)
    crack_->evaluate();
    add_to_body(crack_->force());
  }
  add_release(t);
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
template <int Dim, class Law>
void SolidSolver<Dim, Law>::update_shift_step() {
  if constexpr (Law::plastic) {
    if (shift_step_.extent(0) == 0)
      return;
    const Law law = law_;
    auto s = shift_step_;
    Kokkos::parallel_for(
        "mupm::Solid::plastic_thickness_change", range(0, disc_.points.n_owned),
        KOKKOS_LAMBDA(const std::size_t i) { s(i) = law.pore_shift(i) - law.pore_shift_start(i); });
  }
}

// The p* and the force and moment densities of the forces just applied, into the points'
// checkpointed fields: the next step's pore work and external work start from them, also
// after a restart (whose fluid has updated p since they were applied).
template <int Dim, class Law>
void SolidSolver<Dim, Law>::keep_applied() {
  auto& p = disc_.points;
  const auto owned = std::make_pair(std::size_t(0), p.n_owned);
  Kokkos::deep_copy(Kokkos::subview(p.solid_pressure, owned), st_.pstar);
  Kokkos::deep_copy(Kokkos::subview(p.applied_force, owned, Kokkos::ALL), st_.force);
  Kokkos::deep_copy(Kokkos::subview(p.applied_moment, owned, Kokkos::ALL), st_.moment);
  if (crack_)
    Kokkos::deep_copy(Kokkos::subview(p.applied_crack_force, owned, Kokkos::ALL), crack_->force());
}

template <int Dim, class Law>
void SolidSolver<Dim, Law>::restore_applied() {
  auto& p = disc_.points;
  const auto owned = std::make_pair(std::size_t(0), p.n_owned);
  Kokkos::deep_copy(st_.force, Kokkos::subview(p.applied_force, owned, Kokkos::ALL));
  Kokkos::deep_copy(st_.moment, Kokkos::subview(p.applied_moment, owned, Kokkos::ALL));
  if (crack_) {  // the crack force applied last, with the p_f of then
    body_force_density(boundary_.conditions(), p, disc_.grid.dx, forces_time_, body_, couple_);
    Kokkos::deep_copy(crack_->force(), Kokkos::subview(p.applied_crack_force, owned, Kokkos::ALL));
    add_to_body(crack_->force());
    add_release(forces_time_);
  }
}

template <int Dim, class Law>
double SolidSolver<Dim, Law>::release_factor(double t) const {
  return std::max(0.0, 1.0 - (t - release_start_) / set_.fracture.release_time);
}

template <int Dim, class Law>
void SolidSolver<Dim, Law>::add_release(double t) {
  if (!releases())
    return;
  const double r = release_factor(t);
  if (r == 0)
    return;
  auto b = body_, c = couple_, rel = disc_.points.release_force;
  Kokkos::parallel_for(
      "mupm::Solid::add_release", range(0, disc_.points.n_owned),
      KOKKOS_LAMBDA(const std::size_t i) {
        for (int k = 0; k < Dim; ++k)
          b(i, k) += r * rel(i, k);
        for (int k = 0; k < R; ++k)
          c(i, k) += r * rel(i, Dim + k);
      });
}

// After a break at t (after_breakage): st_ holds the forces of the new bond set, f_old_ and
// l_old_ those of the old one, body_ and couple_ the release of before the break at r(t).
template <int Dim, class Law>
void SolidSolver<Dim, Law>::keep_release(double t) {
  const double r = release_factor(t);
  auto rel = disc_.points.release_force;
  auto f = st_.force, l = st_.moment, f0 = f_old_, l0 = l_old_;
  auto b = body_, c = couple_;
  Kokkos::parallel_for(
      "mupm::Fracture::keep_release", range(0, disc_.points.n_owned),
      KOKKOS_LAMBDA(const std::size_t i) {
        for (int k = 0; k < Dim; ++k) {
          const double d = f0(i, k) - f(i, k);
          rel(i, k) = r * rel(i, k) + d;
          b(i, k) += d;
        }
        for (int k = 0; k < R; ++k) {
          const double d = l0(i, k) - l(i, k);
          rel(i, Dim + k) = r * rel(i, Dim + k) + d;
          c(i, k) += d;
        }
      });
  release_start_ = t;
}

template <int Dim, class Law>
void SolidSolver<Dim, Law>::add_to_body(const Vectors& f) {
  auto b = body_;
  Kokkos::parallel_for(
      "mupm::Solid::add_body", range(0, disc_.points.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        for (int d = 0; d < Dim; ++d)
          b(i, d) += f(i, d);
      });
}

template <int Dim, class Law>
double SolidSolver<Dim, Law>::damping_power() const {
  if (set_.damping == 0)
    return 0.0;
  return mupm::damping_power(disc_.points, rho_, inertia_, set_.damping);
}

// The pore water's and eq 17's crack water's power on the step (kernels/solid_energy.hpp).
template <int Dim, class Law>
double SolidSolver<Dim, Law>::pore_power() const {
  const auto& p = disc_.points;
  const bool eq17 = st_.water_force.extent(0) > 0;
  return mupm::pore_power(p, st_.pstar, vs_old_, prm_.pore.biot) +
         (eq17 ? eq17_power(p, st_.water_force, du_) : 0.0);
}

template <int Dim, class Law>
void SolidSolver<Dim, Law>::bands(double& angle, double& width) const {
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

// An evaluation between two steps sees the pressure the fluid has updated since the step's
// forces, and where the plastic return depends on it (plane stress with pore water,
// laws/micropolar_drucker_prager.hpp) it would change the state the next step commits (a
// restart then differed from the straight run by 1e-7 after one step).
template <int Dim, class Law>
template <class F>
void SolidSolver<Dim, Law>::keeping_plastic_state(F&& f) {
  // The fields the plastic law's return writes (its current state, the stress it commits, the
  // water's volumetric strain).
  auto current = [](const Points<Dim>& p) -> std::vector<Vectors> {
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
  };
  std::vector<Vectors> kept;
  if constexpr (Law::plastic)
    for (const Vectors& v : current(disc_.points))
      kept.push_back(scratch_.copy("plastic" + std::to_string(kept.size()), v));
  f();
  for (std::size_t k = 0; k < kept.size(); ++k)
    Kokkos::deep_copy(current(disc_.points)[k], kept[k]);
  update_shift_step();
}

// The plastic law's current state becomes the start of the next step (the law's header).
template <int Dim, class Law>
void SolidSolver<Dim, Law>::commit_plastic() {
  if constexpr (Law::plastic) {
    auto& p = disc_.points;
    const Law law = law_;
    auto sig = p.stress, m = p.couple_stress;
    Kokkos::parallel_for(
        "mupm::Solid::plastic_commit", range(0, p.n_owned),
        KOKKOS_LAMBDA(const std::size_t i) { law.commit(i, sig, m); });
  }
}

template <int Dim, class Law>
void SolidSolver<Dim, Law>::save_positions() {
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

template <int Dim, class Law>
void SolidSolver<Dim, Law>::increments() {
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

#define MUPM_SOLID_SOLVER(D, LAW) template class SolidSolver<D, LAW>;
MUPM_FOR_EACH_LAW(MUPM_SOLID_SOLVER, 2)
MUPM_FOR_EACH_LAW(MUPM_SOLID_SOLVER, 3)

}  // namespace mupm
