// The fluid step of Algorithm 1: prescribed pore pressure and sources, the flow kernels of
// include/mupm/kernels/fluid.hpp, the explicit pressure update (eqs 141-146, beta_3 = 0), fluid
// mass and boundary inflow bookkeeping, and the stable-step estimate.
//
// Coupling with the solid (staggered): the solid writes tr(eps) of every owned point into
// Points::vol_strain whenever it evaluates its forces. A fluid update over an interval dt_total
// takes the rate (vol_strain - vol_strain_ref) / dt_total, then sets vol_strain_ref =
// vol_strain. Solid first: the interval is the solid steps just taken. Fluid first: it is the
// previous interval (the first update of a run sees no change).
//
// Mass bookkeeping: fluid_content m_i starts as phi S_r (1 + p/K_w) (plus c_z S_r^2 p in plane
// stress) and every step adds C dp + biot S_r d(tr eps) (PoreCoupling: biot = 1, c_z = 0 but in
// plane stress), which by the mass balance equals dt (s_i - div_i) on free points. On a
// prescribed-pressure point the reservoir supplies what the balance needs,
//   supply_i = V_i (C dp + biot S_r d(tr eps) + dt div_i - dt s_i),
// and sum_i V_i div_i = 0 (each bond's flow appears with both signs), so
//   rho_w sum_i V_i m_i (t) - rho_w sum_i V_i m_i (0) = inflow through pressure conditions +
//   injected water, to round-off. The test FluidSolver.MassConservation checks both.
// With fracture flow (Fracture->Fracture Flow) the fracture network's step runs inside every
// substep and takes the exchange X of eq 19 out of the bulk as a sink
// (include/mupm/solvers/fracture_flow.hpp); the CSV's fluid_mass_error is bulk + fracture water
// - initial water - everything that entered through the conditions, zero to round-off.
//
// Energy (eqs 147-149, in power form): multiplying the mass balance by p gives
//   d/dt sum V psi(p) = -sum V S_r p dV_s/dt - sum V p div + sum V p s + sum p supply,
// psi the stored energy density (include/mupm/kernels/fluid.hpp). A step changes a point's
// content by C dp = -S_r dv + dt (s - div) (C and div at its start), and its stored energy by
// psi(p + dp) - psi(p) = p_e C dp, with p_e = [psi(p + dp) - psi(p)] / (C dp) the pressure at
// which the stored energy takes the change in (p + dp/2 for constant C). The update books the
// coupling work W_c (the water's work on the skeleton), the external work W_ext (sources and
// reservoirs) and the flow dissipation D each at p_e, the pressure the step applies them at:
// the balance E_s(t) - E_s(0) + W_c + D - W_ext is then the scheme's own energy identity, zero
// to round-off (and to the quadrature of psi) whenever the update and the booking agree: a
// check of the kernels, the sources, the reservoirs and the coupling at every step. It is not
// a check of forward Euler's accuracy: D is the energy the explicit step removes, dt
// (p + dp/2) div, which differs from the continuous flow's by the step's first-order error
// (the flow's own part dt^2 div^2 / (2 C), the cross terms with the sources' and the volume
// change's increments). Booked with the start pressure, that error drew false alarms on
// well-resolved runs (a point source switched on at once, saturated, at 1/25 of the stable
// step: 1.3 % of the largest term at steps 21-29, and 2.3 % at every step with only the flow's
// own part left; Example 3's fast van Genuchten storage changes up to 4.8 %). An unstable step
// makes D negative in its growing modes and the stored energy grow beyond all supply: the
// driver's divergence check stops it (src/solvers/simulation.cpp, StepChecks). The driver
// checks the balance against Solver->Energy Tolerance like the solid's (eq 149).
#ifndef MUPM_FLUID_SOLVER_HPP
#define MUPM_FLUID_SOLVER_HPP

#include <mpi.h>

#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "mupm/core/error.hpp"
#include "mupm/core/scratch.hpp"
#include "mupm/kernels/boundary_conditions.hpp"
#include "mupm/kernels/fluid.hpp"
#include "mupm/mesh/discretization.hpp"
#include "mupm/solvers/fracture_flow.hpp"
#include "mupm/solvers/module.hpp"
#include "mupm/solvers/power_iteration.hpp"
#include "mupm/solvers/pressure_projection.hpp"

namespace mupm {

// Pass 1, ghost refresh, pass 2 for the pressure field p (owned + ghosts current).
template <int Dim>
void fluid_flow(Discretization<Dim>& disc, const FluidParams& prm, FluidState<Dim>& st,
                const Scalars& p, bool with_gravity = true) {
  ScopedRegion region("mupm::Fluid::flow");
  fluid_pass1(disc.points, disc.bonds, disc.shape, prm, st, p, with_gravity);
  disc.dist.refresh(st.pass2_ghosts());
  fluid_pass2(disc.points, disc.bonds, st, p);
}

template <int Dim>
class FluidSolver : public Module {
 public:
  FluidSolver(Discretization<Dim>& disc, const FluidParams& prm, std::vector<BoundaryCondition> bcs,
              MPI_Comm comm)
      : disc_(disc), prm_(prm), comm_(comm) {
    for (auto& bc : bcs)
      bc.mirror_column = face_column(disc.grid, bc.region_mask);
    for (auto& bc : bcs)
      if (bc.fluid() && !bc.fracture_fluid())
        bcs_.push_back(bc);
    all_bcs_ = bcs;
    for (const auto& bc : bcs_)
      if (bc.mirrored && disc.mirror.extent(0) == 0)
        throw std::logic_error("FluidSolver: condition '" + bc.name +
                               "' mirrors its layer, but the grid was built without mirrors "
                               "(GridSpec::mirrored_layers)");
    auto& p = disc_.points;
    st_.allocate(p.size(), p.n_owned);
    source_ = Scalars("mupm::fluid_source", p.n_owned);
    supply_ = Scalars("mupm::fluid_supply", p.n_owned);
    inflow_.assign(bcs_.size(), 0.0);
    region_volume_.assign(bcs_.size(), 0.0);
  }

  const FluidState<Dim>& state() const { return st_; }

  // Fracture flow on the fracture network (include/mupm/solvers/fracture_flow.hpp), coupled to
  // this bulk by the exchange of eq 19 in every substep; takes the Fracture conditions.
  void enable_fracture_flow(const FractureParams& prm) {
    fracture_ = std::make_unique<FractureFlow<Dim>>(disc_, prm_, prm, all_bcs_, comm_);
    if (semi_implicit_)
      fracture_->set_implicit();
    phat_ = Scalars("mupm::bulk_predictor", disc_.points.n_owned);
    sink_ = Scalars("mupm::fracture_exchange", disc_.points.n_owned);
  }
  const FractureFlow<Dim>* fracture_flow() const { return fracture_.get(); }
  const FluidParams& params() const { return prm_; }

  struct Energy {
    double stored = 0, stored0 = 0, coupling_work = 0, dissipation = 0, external_work = 0;
    double balance() const {
      return stored - stored0 + coupling_work + dissipation - external_work;
    }
    double scale() const {
      return std::max(std::max(std::abs(stored - stored0), std::abs(coupling_work)),
                      std::max(std::abs(dissipation), std::abs(external_work)));
    }
  };
  Energy energy() const {
    Energy e = energy_;
    e.stored = stored_energy();
    return e;
  }

  const char* name() const override { return "fluid"; }
  // For restarts: the cumulative water mass [kg] that entered through each fluid condition,
  // then the energy terms booked so far.
  void globals(GlobalRefs& g) override {
    for (std::size_t k = 0; k < bcs_.size(); ++k)
      g("inflow_" + bcs_[k].name, inflow_[k]);
    g("stored_energy_initial", energy_.stored0);
    g("coupling_work", energy_.coupling_work);
    g("dissipation", energy_.dissipation);
    g("external_work", energy_.external_work);
    g("fluid_mass_initial", mass0_);
    if (semi_implicit())  // the pressure solves' scale (LinearSolve::solve)
      g("pressure_solve_scale", solve_scale_);
    if (fracture_) {
      for (std::size_t k = 0; k < fracture_->conditions().size(); ++k)
        g("inflow_" + fracture_->conditions()[k].name, fracture_->inflows()[k]);
      auto& fe = fracture_->energy();
      g("fracture_stored_energy", fe.stored);
      g("fracture_skeleton_work", fe.skeleton_work);
      g("fracture_dissipation", fe.dissipation);
      g("fracture_external_work", fe.external_work);
      g("fracture_exchange_work", fe.exchange_work);
    }
  }
  void series(SeriesRow& row) const override {
    const auto e = energy();
    row("fluid_stored_energy", e.stored - e.stored0);
    row("fluid_coupling_work", e.coupling_work);
    row("fluid_dissipation", e.dissipation);
    row("fluid_external_work", e.external_work);
    row("fluid_energy_error", e.balance());
    const double bulk = fluid_mass();
    double fracture = 0, supplied = 0;
    row("fluid_mass", bulk);
    for (std::size_t k = 0; k < bcs_.size(); ++k) {
      row("fluid_inflow_" + bcs_[k].name, inflow_[k]);
      supplied += inflow_[k];
    }
    if (fracture_) {
      fracture = fracture_->mass();
      row("fracture_fluid_mass", fracture);
      row("fracture_points", double(fracture_->network_size()));
      for (std::size_t k = 0; k < fracture_->conditions().size(); ++k) {
        row("fluid_inflow_" + fracture_->conditions()[k].name, fracture_->inflows()[k]);
        supplied += fracture_->inflows()[k];
      }
      const auto& fe = fracture_->energy();  // include/mupm/solvers/fracture_flow.hpp header
      row("fracture_fluid_stored_energy", fe.stored);
      row("fracture_fluid_skeleton_work", fe.skeleton_work);
      row("fracture_fluid_dissipation", fe.dissipation);
      row("fracture_fluid_external_work", fe.external_work);
      row("fracture_fluid_exchange_work", fe.exchange_work);
      row("fracture_fluid_energy_error", fe.balance());
    }
    if (semi_implicit()) {  // the last step's pressure solve (pressure_projection.hpp)
      row("pressure_solve_iterations", stats_.iterations);
      row("pressure_solve_residual", stats_.residual);
      row("pressure_assemblies", stats_.assemblies);
    }
    // Water conservation [kg]: bulk + fracture - initial - everything that entered.
    row("fluid_mass_error", (bulk + fracture - mass0_) - supplied);
  }
  // Energy balance (eqs 147-149, include/mupm/solvers/fluid_solver.hpp header).
  std::vector<EnergyBalance> energy_balances() const override {
    const auto e = energy();
    EnergyBalance b;
    b.what = "fluid";
    b.expression = "E_s - E_s0 + W_c + D - W_ext";
    b.error = std::abs(e.balance());
    b.scale = e.scale();
    b.stored_expression = "E_s";
    b.stored = std::abs(e.stored);
    b.supplied_expression = "|E_s0| + |W_c| + |W_ext|";
    b.supplied = std::abs(e.stored0) + std::abs(e.coupling_work) + std::abs(e.external_work);
    b.external_expression = "E_s0 + W_ext";
    b.external = e.stored0 + e.external_work;
    b.gross = std::abs(e.stored0) + std::abs(e.external_work);
    b.field = "pore_pressure";
    if (!fracture_)
      return {b};
    // The crack water's balance (include/mupm/solvers/fracture_flow.hpp header).
    const auto& fe = fracture_->energy();
    EnergyBalance f;
    f.what = "fracture fluid";
    f.expression = "E_f - E_f0 + W_sk + D_f - W_ext,f - W_x";
    f.error = std::abs(fe.balance());
    f.scale = fe.scale();
    // A fall of its energy is energy it gave (E_f0 of an initial Fracture Pressure), not held.
    f.stored_expression = "max(E_f - E_f0, 0)";
    f.stored = std::max(fe.stored, 0.0);
    f.supplied_expression = "|W_ext,f| + |W_x| + |W_sk|";
    f.supplied =
        std::abs(fe.external_work) + std::abs(fe.exchange_work) + std::abs(fe.skeleton_work);
    f.external_expression = "W_ext,f + W_x";
    f.external = fe.external_work + fe.exchange_work;
    f.gross = std::abs(fe.external_work) + std::abs(fe.exchange_work);
    f.field = "fracture_pressure";
    return {b, f};
  }
  const std::vector<double>& inflows() const { return inflow_; }

  // Marks prescribed pressures; at a start (not a restart) sets them at t, the fluid content
  // and the volumetric-strain reference; computes S_r, k_r, C and the flow of the state.
  // A solid initialized afterwards computes tr(eps): then call reset_strain_reference().
  void initialize(double t, bool restarted) {
    psi_valid_ = false;
    auto& p = disc_.points;
    auto regions = p.regions;
    auto fixed = p.fixed, vol = p.volume;
    for (std::size_t k = 0; k < bcs_.size(); ++k) {
      const std::uint32_t mask = bcs_[k].region_mask;
      // Pore Pressure holds all its points; Fluid Flux those it continues p on (with a mirror).
      if (bcs_[k].prescribes_pressure()) {
        const bool flux = bcs_[k].kind == BoundaryCondition::FluidFlux;
        const auto m = disc_.mirror;
        const int col = bcs_[k].mirror_column;
        Kokkos::parallel_for(
            "mupm::Fluid::mark", range(0, p.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
              if ((mask == 0 || (regions(i) & mask)) && (!flux || m(i, col) >= 0))
                fixed(i) |= kFixedPressure;
            });
      }
      double v = 0;
      Kokkos::parallel_reduce(
          "mupm::Fluid::region_volume", range(0, p.n_owned),
          KOKKOS_LAMBDA(const std::size_t i, double& s) {
            if (mask == 0 || (regions(i) & mask))
              s += vol(i);
          },
          v);
      MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_DOUBLE, MPI_SUM, comm_);
      region_volume_[k] = v;
    }
    mark_mirrored();
    if (semi_implicit() && !projection_)
      make_projection();
    if (!restarted) {
      set_pressure(t, p.p);
      if (mirrored_.extent(0) > 0) {
        disc_.dist.refresh({as_vectors(p.p)});
        set_pressure(t, p.p, true);
      }
      energy_.stored0 = stored_energy();
      fluid_constitutive(p, prm_, st_);
      auto pw = p.p, phi = p.porosity, sr = p.saturation, m = p.fluid_content;
      auto vs = p.vol_strain, ref = p.vol_strain_ref;
      const double inv_kw = 1.0 / prm_.bulk_modulus;
      const double cz = prm_.pore.lateral_compliance;
      Kokkos::parallel_for(
          "mupm::Fluid::content", range(0, p.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
            m(i) = phi(i) * sr(i) * (1 + pw(i) * inv_kw) + cz * sr(i) * sr(i) * pw(i);
            ref(i) = vs(i);
          });
      mass0_ = fluid_mass();
    }
    evaluate();
  }

  // The semi-implicit pressure solve's kept preconditioner is computed again at the next step
  // (LinearSolve::renew), as a restart from this checkpoint computes it.
  void checkpointed() override {
    if (projection_)
      projection_->renew_preconditioner();
  }

  // The bond set changed (fracture): the flow of the current pressure again.
  void bonds_changed() {
    evaluate();
    if (projection_)
      projection_->invalidate();
  }

  // Solver->Pressure Integration = Semi-Implicit (include/mupm/solvers/pressure_projection.hpp),
  // before initialize(); FluidParams::semi_implicit must be set (no undrained split).
  void enable_semi_implicit(const LinearSolveSettings& settings) {
    if (!prm_.semi_implicit)
      throw std::logic_error(
          "FluidSolver: semi-implicit pressure without FluidParams::semi_implicit");
    if (fracture_)
      fracture_->set_implicit();
    solve_settings_ = settings;
    semi_implicit_ = true;
    const std::size_t n = disc_.points.n_owned;
    for (auto* v : {&dp_, &hdp_, &c_old_, &sr_old_, &flow_old_})
      *v = Scalars("mupm::projection_state", n);
  }
  // The same on every rank (a rank may own no point).
  bool semi_implicit() const { return semi_implicit_; }
  // The pressure solve's Krylov method (PressureProjection: CG or RCG, or GMRES with image
  // points).
  std::string pressure_solve_method() const {
    return projection_ ? projection_->method() : std::string();
  }
  struct SolveStats {
    double iterations = 0, residual = 0, assemblies = 0;
  };
  // The last pressure solve's iterations and residual, and the assemblies since this run (or
  // restart) began.
  SolveStats solve_stats() const { return stats_; }

  // Steps 2-3 of pressure_projection.hpp between the skeleton's move() and finish(): the new
  // pressure at t + dt, the skeleton corrected; then the state of the new pressure. The water
  // and energy are booked by finish_projection() once the skeleton's volume change is known.
  void project(double t, double dt, Skeleton& skeleton) {
    auto& p = disc_.points;
    const auto owned = std::make_pair(std::size_t(0), p.n_owned);
    sources(t, dt);
    auto target = supply_;
    Kokkos::deep_copy(target, 0.0);
    set_pressure(t + dt, target);
    if (mirrored_.extent(0) > 0)
      set_pressure(t + dt, target, true);  // the images of the mirrors' p_n (ghosts current)
    Kokkos::deep_copy(c_old_, st_.storage);
    Kokkos::deep_copy(sr_old_, Kokkos::subview(p.saturation, owned));
    Kokkos::deep_copy(flow_old_, st_.flow);
    CrackBlock crack;  // the fracture network's rows (fracture_flow.hpp), empty without one
    if (fracture_)
      fracture_->implicit_rows(t, dt, projection_->crack_offset(), crack);
    const SkeletonState skel = skeleton.skeleton_state();
    const Scalars source = lagged_plastic_source(dt, skel.plastic_shift);
    std::vector<double> dpf;
    const auto r =
        projection_->step(dt, prm_, st_, source, target, skel, dp_, solve_scale_, crack, dpf);
    stats_ = {double(r.iterations), r.residual, double(projection_->assemblies())};
    if (!r.converged) {
      std::ostringstream m;
      if (!r.finite_rhs) {
        m << "the pressure solve's right-hand side is not finite at t = " << t + dt
          << " s (the skeleton's predicted motion or the sources hold an inf or NaN): the run "
             "has become unstable; a smaller mupm->Solver->Time Step (or Time Step Safety "
             "Factor) may hold it";
        throw CollectiveError(m.str());
      }
      m << "the pressure solve did not converge at t = " << t + dt << " s: relative residual "
        << r.residual << " after " << r.iterations
        << " iterations (mupm->Solver->Pressure Solve: Tolerance, Maximum Iterations, "
           "Preconditioner)";
      // An ILU breakdown has been answered with Jacobi already (LinearSolve::solve).
      if (std::isnan(r.residual))
        m << "; a NaN residual, also with the Jacobi preconditioner an ILU breakdown falls back "
             "to: the system is singular or not finite (the run has become unstable?)";
      throw CollectiveError(m.str());
    }
    skeleton.add_projection_work(r.work);
    projection_->flow_increment(dp_, hdp_);
    psi_valid_ = false;
    auto pw = p.p, rate = p.p_rate, dp = dp_;
    Kokkos::parallel_for(
        "mupm::Fluid::projected_pressure", range(0, p.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
          pw(i) += dp(i);
          rate(i) = dp(i) / dt;
        });
    if (fracture_) {  // p_f, and the exchange the bulk lost: a sink in its bookkeeping
      fracture_->implicit_finish(dt, dpf, sink_);
      fracture_->implicit_opening();
      auto src = source_, sink = sink_;
      Kokkos::parallel_for(
          "mupm::Fluid::exchange", range(0, p.n_owned),
          KOKKOS_LAMBDA(const std::size_t i) { src(i) -= sink(i); });
    }
    evaluate();
  }

  // The water and energy of the step just projected (header of pressure_projection.hpp), with
  // the skeleton's volume change since the last fluid update (after its finish()).
  void finish_projection(double dt) {
    ScopedRegion region("mupm::Fluid::book_projection");
    auto& p = disc_.points;
    auto target = supply_;
    auto pw = p.p, m = p.fluid_content, vol = p.volume, phi = p.porosity;
    auto vs = p.vol_strain, ref = p.vol_strain_ref;
    auto fixed = p.fixed;
    auto C = c_old_, sr = sr_old_, f0 = flow_old_, hdp = hdp_, ddp = dp_, src = source_;
    auto lag = lag_, now = shift_;
    const bool lagged = shift_.extent(0) > 0;
    const RetentionEnergy energy(prm_.retention);
    const double inv_kw = 1.0 / prm_.bulk_modulus;
    const double biot = prm_.pore.biot, cz = prm_.pore.lateral_compliance;
    double w[3] = {0, 0, 0};
    Kokkos::parallel_reduce(
        "mupm::Fluid::book_projection", range(0, p.n_owned),
        KOKKOS_LAMBDA(const std::size_t i, double& wc, double& wd, double& we) {
          // the skeleton's volume change, with the plastic thickness change a step late
          // (lagged_plastic_source)
          const double dv = vs(i) - ref(i) + (lagged ? lag(i) - now(i) : 0.0);
          const double dp = ddp(i), p0 = pw(i) - dp;
          const double flow = f0(i) + hdp(i) / vol(i);  // div(p_n) + H dp: backward Euler's
          const double rhs = -biot * sr(i) * dv + dt * (src(i) - flow);
          const bool held = fixed(i) & kFixedPressure;
          target(i) = held ? vol(i) * (C(i) * dp - rhs) : 0.0;  // the reservoir's water [m^3]
          const double pm = p0 + 0.5 * dp;
          const double pe = src(i) != 0 || held
                                ? entry_pressure(energy, phi(i), inv_kw, p0, dp, C(i), cz)
                                : p0 + 0.5 * dp;
          wc += vol(i) * pm * biot * sr(i) * dv;
          wd += vol(i) * pm * dt * flow;
          we += vol(i) * pe * dt * src(i) + pe * target(i);
          m(i) += C(i) * dp + biot * sr(i) * dv;
        },
        w[0], w[1], w[2]);
    book(target, w);
    reset_strain_reference();
  }

  // The source the projection solves with: source_ itself, or in plane stress with plastic pore
  // water (SkeletonState::plastic_shift) source_ - biot S_r lag / dt with lag the plastic
  // thickness change of the previous step. The return that gives a step's change needs p_{n+1}
  // (sigma-bar_zz = S_r p, laws/micropolar_drucker_prager.hpp), so the solve for p_{n+1} takes
  // the change known at its start, a step late, as the explicit undrained split does; the
  // bookkeeping (finish_projection) books the same lagged change, so each balance holds as the
  // solve enforced it and water is conserved to the solve's tolerance. Over a run the water sees
  // every plastic thickness change but the last step's.
  Scalars lagged_plastic_source(double dt, const Scalars& shift) {
    shift_ = shift;
    if (shift.extent(0) == 0)
      return source_;
    const std::size_t n = disc_.points.n_owned;
    if (lag_.extent(0) != n) {
      lag_ = Scalars("mupm::lagged_plastic_thickness_change", n);
      lagged_source_ = Scalars("mupm::lagged_plastic_source", n);
    }
    Kokkos::deep_copy(lag_, Kokkos::subview(shift, std::make_pair(std::size_t(0), n)));
    auto out = lagged_source_, src = source_, lag = lag_, sr = sr_old_;
    const double b = prm_.pore.biot / dt;
    Kokkos::parallel_for(
        "mupm::Fluid::lagged_plastic_source", range(0, n),
        KOKKOS_LAMBDA(const std::size_t i) { out(i) = src(i) - b * sr(i) * lag(i); });
    return lagged_source_;
  }

  void reset_strain_reference() {
    auto& p = disc_.points;
    Kokkos::deep_copy(Kokkos::subview(p.vol_strain_ref, std::make_pair(std::size_t(0), p.n_owned)),
                      Kokkos::subview(p.vol_strain, std::make_pair(std::size_t(0), p.n_owned)));
  }

  // Advances p from t over `substeps` equal steps spanning dt_total, with the solid's volume
  // change since the last update spread evenly over them.
  void advance(double t, double dt_total, int substeps) {
    ScopedRegion region("mupm::Fluid::advance");
    const double dt = dt_total / substeps;
    for (int k = 0; k < substeps; ++k)
      substep(t + k * dt, dt, dt_total);
    reset_strain_reference();
  }

  // Water mass in the body [kg]: rho_w sum_i V_i m_i.
  double fluid_mass() const {
    const auto& p = disc_.points;
    return prm_.water_density * volume_integral(p.fluid_content, p.volume, p.n_owned, comm_);
  }

  // sum_i V_i psi(p_i) [J]; psi as the last explicit update left it where p has not changed
  // since (the same values: one quadrature per point and step, not two).
  double stored_energy() const {
    const auto& p = disc_.points;
    auto pw = p.p, phi = p.porosity, vol = p.volume;
    const RetentionEnergy energy(prm_.retention);
    const double inv_kw = 1.0 / prm_.bulk_modulus;
    const double cz = prm_.pore.lateral_compliance;
    auto psi = psi_;
    const bool cached = psi_valid_;
    double s = 0;
    Kokkos::parallel_reduce(
        "mupm::Fluid::stored_energy", range(0, p.n_owned),
        KOKKOS_LAMBDA(const std::size_t i, double& acc) {
          acc += vol(i) * (cached ? psi(i) : energy.density(phi(i), inv_kw, pw(i), cz));
        },
        s);
    MPI_Allreduce(MPI_IN_PLACE, &s, 1, MPI_DOUBLE, MPI_SUM, comm_);
    return s;
  }

  // Smallest storage C over the points (free or not) [1/Pa]: it falls as points wet towards
  // saturation, and with it the stable steps.
  double min_storage() const {
    auto C = st_.storage;
    double m = 0;
    Kokkos::parallel_reduce(
        "mupm::Fluid::min_storage", range(0, disc_.points.n_owned),
        KOKKOS_LAMBDA(const std::size_t i, double& acc) { acc = C(i) < acc ? C(i) : acc; },
        Kokkos::Min<double>(m));
    MPI_Allreduce(MPI_IN_PLACE, &m, 1, MPI_DOUBLE, MPI_MIN, comm_);
    return m;
  }

  // Largest (biot S_r)^2 / C over the points: the pore water's contribution to the undrained bulk
  // modulus (K_w / phi when saturated in plane strain and 3D), for the solid's stable step.
  double undrained_stiffening() const {
    const auto& p = disc_.points;
    auto sr = p.saturation;
    auto C = st_.storage;
    const double biot = prm_.pore.biot;
    double m = 0;
    Kokkos::parallel_reduce(
        "mupm::Fluid::undrained", range(0, p.n_owned),
        KOKKOS_LAMBDA(const std::size_t i, double& acc) {
          const double bs = biot * sr(i);
          const double v = C(i) > 0 ? bs * bs / C(i) : 0.0;
          acc = v > acc ? v : acc;
        },
        Kokkos::Max<double>(m));
    MPI_Allreduce(MPI_IN_PLACE, &m, 1, MPI_DOUBLE, MPI_MAX, comm_);
    return m;
  }

  // Largest stable forward-Euler step 2 / lambda_max of C dp/dt = -L p (L: the flow operator at
  // the current k_r and C, prescribed pressures held), by power iteration with the
  // C-weighted Rayleigh quotient (from below).
  double estimate_stable_dt(int iterations = 40) {
    ScopedRegion region("mupm::Fluid::stable_step");
    auto& p = disc_.points;
    const Scalars x = scratch_.scalars("power_iterate", p.size());
    const Operator op{x, st_.flow, st_.storage, p.fixed};
    const double lambda = largest_eigenvalue(
        op, 1, p.n_owned, p.gid, p.volume,
        [&] {
          disc_.dist.refresh({as_vectors(x)});
          if (mirrored_.extent(0) > 0) {  // the layers mirror the perturbation (g = 0)
            mirror_pressure(x);
            disc_.dist.refresh({as_vectors(x)});
          }
          fluid_flow(disc_, prm_, st_, x, false);
        },
        comm_, iterations);
    evaluate();
    return lambda > 0 ? 2.0 / lambda : 0.0;
  }

 private:
  // C^-1 L of the power iteration: the iterate is a pressure field, L x its flow divergence,
  // M = C; prescribed pressures (and points without storage) held.
  struct Operator {
    Scalars xv, flow, C;
    Flags fixed;
    KOKKOS_INLINE_FUNCTION double& x(std::size_t i, int) const { return xv(i); }
    KOKKOS_INLINE_FUNCTION double ax(std::size_t i, int) const { return flow(i); }
    KOKKOS_INLINE_FUNCTION double mass(std::size_t i, int) const { return C(i); }
    KOKKOS_INLINE_FUNCTION bool held(std::size_t i, int) const {
      return (fixed(i) & kFixedPressure) || !(C(i) > 0);
    }
    KOKKOS_INLINE_FUNCTION double start(std::size_t i, int, double s) const {
      return (fixed(i) & kFixedPressure) ? 0.0 : std::sin(1.3 * s) + 0.1;
    }
  };

  // S_r, k_r, C and the flow of the current pressure. Only p is read on the ghosts (k_r of a
  // neighbour reaches pass 2 inside its alpha).
  void evaluate() {
    auto& p = disc_.points;
    fluid_constitutive(p, prm_, st_);
    disc_.dist.refresh({as_vectors(p.p)});
    mirror_rel_perm();
    fluid_flow(disc_, prm_, st_, p.p);
  }

  // The semi-implicit step's roles of the owned points (held, images, free), from the marks.
  void make_projection() {
    const auto& p = disc_.points;
    std::vector<PressureRole> roles(p.n_owned, PressureRole::Free);
    std::vector<LocalId> images(p.n_owned, -1);
    for (std::size_t i = 0; i < p.n_owned; ++i) {
      const int f = mirrored_.extent(0) > 0 ? mirrored_(i) : 0;
      if (f) {
        roles[i] = f > kEvenMirror ? PressureRole::EvenImage : PressureRole::OddImage;
        images[i] = disc_.mirror(i, mirror_column(f));
      } else if (p.fixed(i) & kFixedPressure) {
        roles[i] = PressureRole::Held;
      }
    }
    projection_ =
        std::make_unique<PressureProjection<Dim>>(disc_, solve_settings_, roles, images, comm_);
  }

  // The mirrored layer points (Pore Pressure and Fluid Flux, mirrored_) take their mirror's k_r
  // (from its pressure, current on the ghosts): the layer is the mirror image of the medium, as
  // its pressures are of the body's. With the layer's own k_r(p_L) the conductances across the
  // face are not the body's. In unsaturated flow, where k_r changes across a horizon, a Fluid
  // Flux face let in 5.4 % more than q_n (2.35 % with the mirror's k_r), and 1.82 q_n in a
  // harsher column (1.27 q_n): FluidSolver.InflowFaceWithGravityAndUnsaturated. Saturated,
  // k_r = 1 on both sides.
  void mirror_rel_perm() {
    if (mirrored_.extent(0) == 0)
      return;
    auto kr = disc_.points.rel_perm, pw = disc_.points.p;
    const auto m = disc_.mirror;
    const Bytes only = mirrored_;
    const VanGenuchten vg = prm_.retention;
    Kokkos::parallel_for(
        "mupm::Fluid::mirror_rel_perm", range(0, disc_.points.n_owned),
        KOKKOS_LAMBDA(const std::size_t i) {
          const int f = only(i);
          if (!f)
            return;
          kr(i) = vg.relative_permeability(vg.saturation(pw(m(i, mirror_column(f)))));
        });
  }

  // p = value g(t) on the points of every pressure condition (later conditions win).
  // `mirror`: the mirrored layer points only (mirrored_), 2 g - p(mirror) (kernels/
  // boundary_conditions.hpp: the mirrors' pressures current on the ghosts); otherwise g on all.
  // Fluid Flux (mirrored points only): a layer point L whose mirror m lies at Delta = x_L - x_m
  // (outward, |Delta| = 2d) takes the body's pressure continued with the normal gradient of the
  // inflow q_in = g(t): Darcy's law (eq 54) q = -lambda (grad p - rho_w g_vec), lambda = k_r k /
  // mu_w, gives q_in = -q . n = lambda (dp/dn - rho_w g_vec . n), so
  //   p_L = p_m + |Delta| q_in / lambda_m + rho_w g_vec . Delta   (gravity as in the flow kernel),
  // with k_r at the mirror's pressure (floored at 1e-6 so that a dry mirror takes a large but
  // finite pressure). This is the even reflection of p about the face plus the flux's linear
  // part: exact for any field linear across the face, and a symmetric operator (the even
  // reflection of a scalar commutes with the lattice's mirror symmetry), so the explicit step
  // stays stable. The water it lets in is booked as a pressure condition's (the supply below).
  void set_pressure(double t, const Scalars& target, bool mirror = false) {
    auto& p = disc_.points;
    auto regions = p.regions;
    const auto m = disc_.mirror;
    const Bytes only = mirrored_;
    for (const auto& bc : bcs_) {
      if (!bc.prescribes_pressure())
        continue;
      const bool flux = bc.kind == BoundaryCondition::FluidFlux;
      if (flux && !mirror)
        continue;
      const std::uint32_t mask = bc.region_mask;
      const double v = bc.value * bc.time(t);
      auto pw = p.p, x = p.x;
      const bool reflect = mirror && bc.mirrored;
      const int col = bc.mirror_column;
      const double k0 = prm_.mobility, rho_w = prm_.water_density;
      const VanGenuchten vg = prm_.retention;
      const auto gv = prm_.gravity;
      Kokkos::parallel_for(
          "mupm::Fluid::pressure_bc", range(0, p.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
            if ((mask != 0 && !(regions(i) & mask)) || (mirror && !only(i)))
              return;
            if (!flux) {
              target(i) = reflect ? 2 * v - pw(m(i, col)) : v;
              return;
            }
            const auto j = m(i, col);
            double gap2 = 0, grav = 0;
            for (int d = 0; d < Dim; ++d) {
              const double delta = x(i, d) - x(j, d);
              gap2 += delta * delta;
              grav += rho_w * gv[d] * delta;
            }
            const double kr = vg.relative_permeability(vg.saturation(pw(j)));
            target(i) = pw(j) + std::sqrt(gap2) * v / (k0 * (kr > 1e-6 ? kr : 1e-6)) + grav;
          });
    }
  }
  // x = -x(mirror) on the mirrored layer points, +x(mirror) on the Fluid Flux ones (a
  // perturbation: g = 0; the flux's gradient is linear in g), reading the values from before the
  // update as set_pressure does.
  void mirror_pressure(const Scalars& x) {
    const auto m = disc_.mirror;
    const Bytes only = mirrored_;
    const Scalars src = scratch_.copy("mirror_sources", x);
    Kokkos::parallel_for(
        "mupm::Fluid::mirror_perturbation", range(0, disc_.points.n_owned),
        KOKKOS_LAMBDA(const std::size_t i) {
          const int f = only(i);
          if (!f)
            return;
          const double v = src(m(i, mirror_column(f)));
          x(i) = f > kEvenMirror ? v : -v;
        });
  }
  // Marks the points whose (last) pressure condition mirrors its layer values (1 + the column of
  // Discretization::mirror it reflects with; + kEvenMirror for Fluid Flux); empty if none.
  static constexpr int kEvenMirror = 4;
  // The column of Discretization::mirror that a non-zero mark of mark_mirrored() reflects with.
  static KOKKOS_INLINE_FUNCTION int mirror_column(int f) {
    return f > kEvenMirror ? f - 1 - kEvenMirror : f - 1;
  }
  void mark_mirrored() {
    bool any = false;
    for (const auto& bc : bcs_)
      any = any || (bc.prescribes_pressure() && bc.mirrored);
    if (!any)
      return;
    auto& p = disc_.points;
    mirrored_ = Bytes("mupm::mirrored_pressure", p.n_owned);
    auto regions = p.regions;
    const auto m = disc_.mirror, flag = mirrored_;
    for (const auto& bc : bcs_) {
      if (!bc.prescribes_pressure())
        continue;
      const std::uint32_t mask = bc.region_mask;
      const int col = bc.mirror_column,
                on = bc.mirrored
                         ? col + 1 + (bc.kind == BoundaryCondition::FluidFlux ? kEvenMirror : 0)
                         : 0;
      Kokkos::parallel_for(
          "mupm::Fluid::mark_mirrored", range(0, p.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
            if (mask == 0 || (regions(i) & mask))
              flag(i) = std::uint8_t(on && m(i, col) >= 0 ? on : 0);
          });
    }
  }

  // Sources [1/s] at t into source_: rate g(t) (per metre of thickness in 2D) over the
  // region's volume; books the water they bring over dt.
  void sources(double t, double dt) {
    auto& p = disc_.points;
    auto regions = p.regions;
    const double h = Dim == 2 ? disc_.grid.thickness : 1.0;
    Kokkos::deep_copy(source_, 0.0);
    for (std::size_t k = 0; k < bcs_.size(); ++k) {
      const auto& bc = bcs_[k];
      if (bc.kind != BoundaryCondition::FluidSource || !(region_volume_[k] > 0))
        continue;
      const std::uint32_t mask = bc.region_mask;
      const double s = bc.value * bc.time(t) * h / region_volume_[k];
      auto src = source_;
      Kokkos::parallel_for(
          "mupm::Fluid::source", range(0, p.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
            if (mask == 0 || (regions(i) & mask))
              src(i) += s;
          });
      inflow_[k] += prm_.water_density * bc.value * bc.time(t) * h * dt;
    }
  }

  // One forward-Euler step from t to t + dt (eqs 141-146). evaluate() has run for the state at t.
  void substep(double t, double dt, double dt_total) {
    auto& p = disc_.points;
    auto regions = p.regions;
    sources(t, dt);
    // Prescribed pressures at t + dt go to supply_ first (the target), then the update.
    auto target = supply_;
    Kokkos::deep_copy(target, 0.0);
    set_pressure(t + dt, target);
    auto pw = p.p, rate = p.p_rate, sr = p.saturation, m = p.fluid_content, vol = p.volume;
    auto vs = p.vol_strain, ref = p.vol_strain_ref;
    auto fixed = p.fixed;
    auto C = st_.storage, flow = st_.flow, src = source_;
    auto phi = p.porosity;
    const VanGenuchten vg = prm_.retention;
    const RetentionEnergy energy(vg);
    const double inv_kw = 1.0 / prm_.bulk_modulus;
    const double biot = prm_.pore.biot, cz = prm_.pore.lateral_compliance;
    const double inv_total = 1.0 / dt_total;
    if (fracture_) {
      // The bulk's explicit step without the exchange (p^ of fracture_flow.hpp), then the
      // exchange the fracture step takes, as a sink in the update below. (Mirrored layer
      // points enter p^ with g, Fluid Flux ones with 0, not their mirrored value: layers are
      // far from cracks, and exchange only happens on fracture points.)
      auto phat = phat_, sink = sink_;
      Kokkos::parallel_for(
          "mupm::Fluid::predictor", range(0, p.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
            const double dv = (vs(i) - ref(i)) * inv_total * dt;
            const double rhs = -biot * sr(i) * dv + dt * (src(i) - flow(i));
            phat(i) =
                (fixed(i) & kFixedPressure) ? target(i) : pw(i) + (C(i) > 0 ? rhs / C(i) : 0.0);
          });
      fracture_->step(t, dt, phat, C, sink);
      Kokkos::parallel_for(
          "mupm::Fluid::exchange", range(0, p.n_owned),
          KOKKOS_LAMBDA(const std::size_t i) { src(i) -= sink(i); });
    }
    double w[3] = {0, 0, 0};  // coupling work, flow dissipation, external work (energy_ doc)
    // Phase 0 updates every point but the mirrored layer points (mirrored_), whose prescribed
    // values follow their mirrors' new pressures: phase 1, after a ghost refresh.
    const Bytes mirrored = mirrored_;
    const bool any_mirrored = mirrored.extent(0) > 0;
    if (psi_.extent(0) != p.n_owned)
      psi_ = Scalars("mupm::stored_energy_density", p.n_owned);
    auto psi = psi_;
    const bool cached = psi_valid_;
    auto update = [&](const int phase) {
      double ws[3] = {0, 0, 0};
      Kokkos::parallel_reduce(
          "mupm::Fluid::update", range(0, p.n_owned),
          KOKKOS_LAMBDA(const std::size_t i, double& wc, double& wd, double& we) {
            if (any_mirrored && (mirrored(i) != 0) != (phase == 1))
              return;
            const double dv = (vs(i) - ref(i)) * inv_total * dt;  // eq 117 over this step
            const double rhs = -biot * sr(i) * dv + dt * (src(i) - flow(i));
            double dp;
            const double p0 = pw(i);
            if (fixed(i) & kFixedPressure) {
              dp = target(i) - p0;
              target(i) = vol(i) * (C(i) * dp - rhs);  // what the reservoir supplies [m^3]
            } else {
              dp = C(i) > 0 ? rhs / C(i) : 0.0;  // eq 143
              target(i) = 0;
            }
            // The pressure at which the stored energy takes in the step's change of content:
            // the step's mean pressure p0 + dp/2 when C is constant (header). psi(p0) is the
            // last update's psi(p1) (psi_, which stored_energy() sums).
            const double p1 = p0 + dp;
            const double psi1 = energy.density(phi(i), inv_kw, p1, cz);
            const bool varies = storage_varies(vg, p0, p1);
            const double psi0 =
                varies ? (cached ? psi(i) : energy.density(phi(i), inv_kw, p0, cz)) : 0.0;
            psi(i) = psi1;
            const double pe = entry_pressure(p0, dp, C(i), psi0, psi1, varies);
            wc += vol(i) * pe * biot * sr(i) * dv;
            wd += vol(i) * pe * dt * flow(i);
            we += vol(i) * pe * dt * src(i) + pe * target(i);
            m(i) += C(i) * dp + biot * sr(i) * dv;
            rate(i) = dp / dt;
            pw(i) = p1;  // eq 145, beta_3 = 0
          },
          ws[0], ws[1], ws[2]);
      for (int k = 0; k < 3; ++k)
        w[k] += ws[k];
    };
    update(0);
    if (any_mirrored) {
      disc_.dist.refresh({as_vectors(p.p)});
      set_pressure(t + dt, target, true);
      update(1);
    }
    psi_valid_ = true;  // every owned point's psi(p), by phase 0 or 1
    book(target, w);
    evaluate();
  }

  // Books a step's water and energy: `supply` the water each held point's reservoir supplied
  // [m^3] (summed per pressure condition), w the coupling work, flow dissipation and external
  // work of this rank's points.
  void book(const Scalars& supply, const double w[3]) {
    auto& p = disc_.points;
    auto regions = p.regions;
    auto target = supply;
    std::vector<double> supplied(bcs_.size() + 3, 0.0);
    supplied[bcs_.size()] = w[0];
    supplied[bcs_.size() + 1] = w[1];
    supplied[bcs_.size() + 2] = w[2];
    for (std::size_t k = 0; k < bcs_.size(); ++k) {
      if (!bcs_[k].prescribes_pressure())
        continue;
      // Points of several pressure conditions count for the last one (set_pressure's order).
      std::uint32_t later = 0;
      bool later_all = false;
      for (std::size_t l = k + 1; l < bcs_.size(); ++l)
        if (bcs_[l].prescribes_pressure()) {
          later |= bcs_[l].region_mask;
          later_all = later_all || bcs_[l].region_mask == 0;
        }
      if (later_all)
        continue;
      const std::uint32_t mask = bcs_[k].region_mask;
      double s = 0;
      Kokkos::parallel_reduce(
          "mupm::Fluid::inflow", range(0, p.n_owned),
          KOKKOS_LAMBDA(const std::size_t i, double& acc) {
            if ((mask == 0 || (regions(i) & mask)) && !(regions(i) & later))
              acc += target(i);
          },
          s);
      supplied[k] = s;
    }
    // One reduction for all conditions and the energy terms.
    MPI_Allreduce(MPI_IN_PLACE, supplied.data(), int(supplied.size()), MPI_DOUBLE, MPI_SUM, comm_);
    for (std::size_t k = 0; k < bcs_.size(); ++k)
      inflow_[k] += prm_.water_density * supplied[k];
    energy_.coupling_work += supplied[bcs_.size()];
    energy_.dissipation += supplied[bcs_.size() + 1];
    energy_.external_work += supplied[bcs_.size() + 2];
  }

  Discretization<Dim>& disc_;
  FluidParams prm_;
  MPI_Comm comm_;
  std::vector<BoundaryCondition> bcs_, all_bcs_;
  FluidState<Dim> st_;
  std::unique_ptr<FractureFlow<Dim>> fracture_;
  Scalars phat_, sink_;
  // psi(p) of each owned point after the last explicit update, valid (psi_valid_) until
  // anything else sets p: initialize(), the semi-implicit projection.
  Scalars psi_;
  bool psi_valid_ = false;
  double mass0_ = 0;  // water in the body at t = 0 [kg]
  Scalars source_, supply_;
  Bytes mirrored_;  // mark_mirrored()
  std::vector<double> inflow_, region_volume_;
  Energy energy_;
  // Semi-implicit pressure: the solve, the step's increment, V H dp, and the storage,
  // saturation and flow at p_n (the matrix's), kept from project() for finish_projection().
  LinearSolveSettings solve_settings_;
  std::unique_ptr<PressureProjection<Dim>> projection_;
  Scalars dp_, hdp_, c_old_, sr_old_, flow_old_;
  // Plane stress with plastic pore water (lagged_plastic_source): the skeleton's plastic
  // thickness change (its View), the change this step's solve took, the source it solved with.
  Scalars shift_, lag_, lagged_source_;
  SolveStats stats_;
  double solve_scale_ = 0;
  bool semi_implicit_ = false;
  Scratch scratch_;  // estimate_stable_dt's iterate and mirror_pressure's sources
};

}  // namespace mupm

#endif
