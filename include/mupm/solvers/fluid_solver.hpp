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
// driver's divergence check stops it (src/solvers/driver/step_checks.hpp, StepChecks). The driver
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
#include "mupm/solvers/linear_solve_settings.hpp"
#include "mupm/solvers/module.hpp"

namespace mupm {

template <int Dim>
class FractureFlow;  // include/mupm/solvers/fracture_flow.hpp
template <int Dim>
class PressureProjection;  // include/mupm/solvers/pressure_projection.hpp

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
              MPI_Comm comm);
  ~FluidSolver() override;

  const FluidState<Dim>& state() const { return st_; }

  // Fracture flow on the fracture network (include/mupm/solvers/fracture_flow.hpp), coupled to
  // this bulk by the exchange of eq 19 in every substep; takes the Fracture conditions.
  void enable_fracture_flow(const FractureParams& prm);
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
  Energy energy() const;

  const char* name() const override { return "fluid"; }
  // For restarts: the cumulative water mass [kg] that entered through each fluid condition,
  // then the energy terms booked so far.
  void globals(GlobalRefs& g) override;
  void series(SeriesRow& row) const override;
  // Energy balance (eqs 147-149, include/mupm/solvers/fluid_solver.hpp header).
  std::vector<EnergyBalance> energy_balances() const override;
  const std::vector<double>& inflows() const { return inflow_; }

  // Marks prescribed pressures; at a start (not a restart) sets them at t, the fluid content
  // and the volumetric-strain reference; computes S_r, k_r, C and the flow of the state.
  // A solid initialized afterwards computes tr(eps): then call reset_strain_reference().
  void initialize(double t, bool restarted);

  // The semi-implicit pressure solve's kept preconditioner is computed again at the next step
  // (LinearSolve::renew), as a restart from this checkpoint computes it.
  void checkpointed() override;

  // The bond set changed (fracture): the flow of the current pressure again.
  void bonds_changed();

  // Solver->Pressure Integration = Semi-Implicit (include/mupm/solvers/pressure_projection.hpp),
  // before initialize(); FluidParams::semi_implicit must be set (no undrained split).
  void enable_semi_implicit(const LinearSolveSettings& settings);
  // The same on every rank (a rank may own no point).
  bool semi_implicit() const { return semi_implicit_; }
  // The pressure solve's Krylov method (PressureProjection: CG or RCG, or GMRES with image
  // points).
  std::string pressure_solve_method() const;
  struct SolveStats {
    double iterations = 0, residual = 0, assemblies = 0;
  };
  // The last pressure solve's iterations and residual, and the assemblies since this run (or
  // restart) began.
  SolveStats solve_stats() const { return stats_; }

  // Steps 2-3 of pressure_projection.hpp between the skeleton's move() and finish(): the new
  // pressure at t + dt, the skeleton corrected; then the state of the new pressure. The water
  // and energy are booked by finish_projection() once the skeleton's volume change is known.
  void project(double t, double dt, Skeleton& skeleton);

  // The water and energy of the step just projected (header of pressure_projection.hpp), with
  // the skeleton's volume change since the last fluid update (after its finish()).
  void finish_projection(double dt);

  // The source the projection solves with: source_ itself, or in plane stress with plastic pore
  // water (SkeletonState::plastic_shift) source_ - biot S_r lag / dt with lag the plastic
  // thickness change of the previous step. The return that gives a step's change needs p_{n+1}
  // (sigma-bar_zz = S_r p, laws/micropolar_drucker_prager.hpp), so the solve for p_{n+1} takes
  // the change known at its start, a step late, as the explicit undrained split does; the
  // bookkeeping (finish_projection) books the same lagged change, so each balance holds as the
  // solve enforced it and water is conserved to the solve's tolerance. Over a run the water sees
  // every plastic thickness change but the last step's.
  Scalars lagged_plastic_source(double dt, const Scalars& shift);

  void reset_strain_reference();

  // Advances p from t over `substeps` equal steps spanning dt_total, with the solid's volume
  // change since the last update spread evenly over them.
  void advance(double t, double dt_total, int substeps);

  // Water mass in the body [kg]: rho_w sum_i V_i m_i.
  double fluid_mass() const {
    const auto& p = disc_.points;
    return prm_.water_density * volume_integral(p.fluid_content, p.volume, p.n_owned, comm_);
  }

  // sum_i V_i psi(p_i) [J]; psi as the last explicit update left it where p has not changed
  // since (the same values: one quadrature per point and step, not two).
  double stored_energy() const;

  // Smallest storage C over the points (free or not) [1/Pa]: it falls as points wet towards
  // saturation, and with it the stable steps.
  double min_storage() const;

  // Largest (biot S_r)^2 / C over the points: the pore water's contribution to the undrained bulk
  // modulus (K_w / phi when saturated in plane strain and 3D), for the solid's stable step.
  double undrained_stiffening() const;

  // Largest stable forward-Euler step 2 / lambda_max of C dp/dt = -L p (L: the flow operator at
  // the current k_r and C, prescribed pressures held), by power iteration with the
  // C-weighted Rayleigh quotient (from below).
  double estimate_stable_dt(int iterations = 40);

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
  void evaluate();

  // The semi-implicit step's roles of the owned points (held, images, free), from the marks.
  void make_projection();

  // The mirrored layer points (Pore Pressure and Fluid Flux, mirrored_) take their mirror's k_r
  // (from its pressure, current on the ghosts): the layer is the mirror image of the medium, as
  // its pressures are of the body's. With the layer's own k_r(p_L) the conductances across the
  // face are not the body's. In unsaturated flow, where k_r changes across a horizon, a Fluid
  // Flux face let in 5.4 % more than q_n (2.35 % with the mirror's k_r), and 1.82 q_n in a
  // harsher column (1.27 q_n): FluidSolver.InflowFaceWithGravityAndUnsaturated. Saturated,
  // k_r = 1 on both sides.
  void mirror_rel_perm();

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
  void set_pressure(double t, const Scalars& target, bool mirror = false);
  // x = -x(mirror) on the mirrored layer points, +x(mirror) on the Fluid Flux ones (a
  // perturbation: g = 0; the flux's gradient is linear in g), reading the values from before the
  // update as set_pressure does.
  void mirror_pressure(const Scalars& x);
  // Marks the points whose (last) pressure condition mirrors its layer values (1 + the column of
  // Discretization::mirror it reflects with; + kEvenMirror for Fluid Flux); empty if none.
  static constexpr int kEvenMirror = 4;
  // The column of Discretization::mirror that a non-zero mark of mark_mirrored() reflects with.
  static KOKKOS_INLINE_FUNCTION int mirror_column(int f) {
    return f > kEvenMirror ? f - 1 - kEvenMirror : f - 1;
  }
  void mark_mirrored();

  // Sources [1/s] at t into source_: rate g(t) (per metre of thickness in 2D) over the
  // region's volume; books the water they bring over dt.
  void sources(double t, double dt);

  // One forward-Euler step from t to t + dt (eqs 141-146). evaluate() has run for the state at t.
  void substep(double t, double dt, double dt_total);

  // Books a step's water and energy: `supply` the water each held point's reservoir supplied
  // [m^3] (summed per pressure condition), w the coupling work, flow dissipation and external
  // work of this rank's points.
  void book(const Scalars& supply, const double w[3]);

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

extern template class FluidSolver<2>;
extern template class FluidSolver<3>;

}  // namespace mupm

#endif
