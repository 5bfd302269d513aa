// The semi-implicit pore pressure (Solver->Pressure Integration = Semi-Implicit): the skeleton
// advances explicitly with its drained operator, the pore pressure comes from one linear solve
// per step that enforces each point's water balance at the new time level, with the volume
// change that the new pressure itself gives the skeleton within the step. A pressure
// projection in the family of Chorin's, and of the staggered schemes for pore fluid-soil
// interaction of Park (1983) and Zienkiewicz, Paul & Chan (1988).
//
// The semi-discrete system (lumped masses M: rho V per displacement, J V per rotation):
//   skeleton  M a = F(u, theta) + B~^T p + F_ext                          (eqs 46, 105-112, 127)
//   water     V C dp/dt + B~ (u, theta)' = -V H p + V g_w + V s             (eqs 14, 116, 143)
// with B~ and V H of include/mupm/solvers/pressure_system.hpp (B~^T p is the pore water's
// force, V H the flow operator, g_w its gravity part, s the sources, C = phi dS_r/dp +
// phi S_r / K_w the storage, which may be zero: incompressible water; in plane stress S_r is
// biot S_r in B~ and C gains the thickness's compliance, PoreCoupling in
// include/mupm/laws/micropolar_elastic.hpp).
//
// The step n -> n + 1 (velocity Verlet, include/mupm/kernels/central_difference.hpp):
//  1. move: v* = v_n + dt/2 a_n, (u*, theta*) = (u_n, theta_n) + dt v*, with a_n from the
//     forces at t_n and the pressure p_n (no undrained split: the solid's pass 1 sees p itself,
//     kernels/fluid.hpp fluid_constitutive).
//  2. the pressure increment dp: the correction a_dp = M^-1 B~^T dp, applied as a full-step
//     impulse, moves the skeleton by dt^2 a_dp within the step; the water balance at n + 1
//     (backward Euler in p, the storage and the flow operator at p_n):
//       V C dp + B~ (u_{n+1} - u_n) = -dt V H (p_n + dp) + dt V (g_w + s)
//     with u_{n+1} = u* + dt^2 M^-1 B~^T dp gives
//       A dp = [V C + dt V H + dt^2 B~ M^-1 B~^T] dp = -B~ (u* - u_n) - dt V div(p_n) + dt V s.
//     A is symmetric positive semi-definite (each term is), definite where C > 0 or where the
//     flow and the projection together reach a held pressure: with C = 0 it is the nonlocal
//     pressure "Laplacian" of the projection (two bond hops wide) plus the implicit flow.
//  3. correct: v* += dt a_dp, u* += dt^2 a_dp (free components: M^-1 is zero on prescribed
//     ones), p_{n+1} = p_n + dp.
//  4. finish: forces at t_{n+1} with p_{n+1}, v_{n+1} = v* + dt/2 a_{n+1}.
// In leapfrog form the skeleton's impulse over the step centred at t_n carries p_{n+1}:
// v_{n+1/2} - v_{n-1/2} = dt M^-1 (F_n + B~^T p_{n+1}). The pressure is therefore implicit in the
// coupling: the water's stiffness (K_w / phi in C^-1) and the flow never enter the explicit
// step, whose limit is the drained skeleton's (Automatic Time Step estimates it: the solid's
// estimate without the undrained stiffening). Why the drained step: with incompressible water
// and no flow, p_{n+1} is the multiplier that makes B~ (u_{n+1} - u_n) = 0, so the skeleton
// moves on the constraint's subspace, where the operator is the drained one restricted (a
// constraint removes modes, it adds no faster ones: the drained CFL bound holds); with C > 0
// the water is a stiffness taken implicitly (backward Euler in p, unconditionally stable for
// the flow's and the storage's symmetric positive parts), and the projection term damps the
// pressure's impulse at first order. This is the
// argument, not a proof for the nonlocal operators; measured: stable at 0.5 of the drained
// estimate in every test (tests/solvers/test_fluid_solver.cpp, FluidSolverSemiImplicit and
// FluidSolverLong.TerzaghiSemiImplicit*, tests/cli/semi_implicit.sh). Without the pressure
// stabilization below, mirrored pressure layers with stiff or incompressible water were
// unstable at any step tried (0.1 to 0.5 of it); with it they run (Terzaghi within 1 %), but a
// Fluid Flux layer (an even image) with incompressible water still diverges, which the input
// refuses (src/input/modules/solver.cpp, check_pressure_integration).
//
// What it conserves. Water: each free point's balance holds to the linear solve's tolerance;
// the bookkeeping (FluidSolver::finish_projection) adds C dp + biot S_r d(tr eps) to the water
// content with the skeleton's actual volume change and the linearized flow div(p_n) + H dp,
// whose volume integral is zero (H 1 = 0), so the CSV's water mass error is the accumulated
// residual of the solves. Energy: the solid's ledger is the central difference's
// L_n = E_int(u_n) + 1/2 m |v_n|^2 - dt^2/8 m |a_n|^2 (solid_ledger.hpp,
// SolidEnergy::kinetic_shift), a_n from the forces at t_n with p_n. In leapfrog form the impulse
// over the step centred at t_n is dt (F_n + B~^T p_{n+1}) (above), and for a linear skeleton
//   1/2 m |v_{n+1/2}|^2 - 1/2 m |v_{n-1/2}|^2 = (F_n + B~^T p_{n+1}) . (u_{n+1} - u_{n-1}) / 2
// together with L_n = 1/2 m |v_{n-1/2}|^2 + 1/2 u_{n-1} . K u_n + 1/2 (u_n - u_{n-1}) . G_n
// (G_n the pressure's and the external force at t_n; v_n = v_{n-1/2} + dt/2 a_n) give exactly
//   L_{n+1} - L_n = 1/2 (u_{n+1} - u_n) . (G_n + G_{n+1}) + B~^T dp . (u_{n+1} - u_{n-1}) / 2:
// the trapezoid of the pore water's force (p_n + p_{n+1})/2 over the step, which the fluid's
// balance books as its coupling work too, and the correction's work over the centred interval,
// booked on the free components as projection_work, with u_n - u_{n-1} = dt v_{n-1/2} =
// dt (v* - dt a_n) (at a start from rest the leapfrog's v_{-1/2} = -dt/2 a_0). The balance
// closes to round-off from the first step (tests/solvers/test_fluid_solver.cpp,
// FluidSolverSemiImplicit.ImpulsiveStartBalanceCloses; booking (u_{n+1} - u_n) instead left a
// constant O(dt^2) offset at an impulsive start, 4 % of the early largest term on Example 1 case
// 1). The projection work is what the correction's pressure does on the skeleton beyond the
// trapezoid; it is part of pore_pressure_work, not a dissipation of fixed sign.
//
// Pressure stabilization (Solver->Pressure Stabilization, G_p). On a regular grid the
// checkerboard p_i = (-1)^(i_x) (and its y, z and diagonal kin) has a zero nonlocal gradient at
// every interior point: sum_j omega (p_j - p_i) xi V_j pairs the bond xi with -xi, whose
// pressure differences are equal, so the terms cancel (eq 59); by the same pairing B~^T p, the
// pore water's force, vanishes. B~ M^-1 B~^T is blind to these modes, and with C = 0 only the
// flow holds them, through its stabilization alpha (eqs 72-78), which scales with k. In a tight
// soil dt V H is negligible against dt^2 B~ M^-1 B~^T (Example 1: k / mu_w = 2.8e-13 against
// dt / rho = 1.7e-9 in m^3 s/kg): the system is singular to round-off and GMRES stalls
// (measured: relative residual 0.22 after 1000 iterations). The remedy is the flow
// stabilization itself with a mobility of the projection's scale, on the increment only:
// every point's alpha_i gets
//   alpha_p,i = G_p S_r,i^2 dt / (rho_i k2 w0_i)   (eq 76's with lambda -> G_p S_r^2 dt / rho;
//   biot S_r in plane stress),
// in the matrix's flow operator (not in the right-hand side's div(p_n)). Why that mobility: for
// a smooth field B~ M^-1 B~^T -> -V div((S_r^2 / rho) grad), so dt^2 times it is a flow term
// dt V H with lambda = S_r^2 dt / rho; the stabilization then holds the modes the projection
// misses as strongly as the projection holds those it sees (G_p ~ 1), in the spirit of
// Brezzi and Pitkaranta's pressure stabilization, with tau ~ dt^2 / rho ~ dx^2 / M at the
// skeleton's step. What it changes: it acts on the non-uniform part R of the increment only
// (zero for linear increments, and for quadratic ones where alpha is uniform,
// kernels/fluid.hpp), so smooth consolidation is left alone (Terzaghi's incompressible column,
// k / mu_w = 5.2e-9: the same U and p to 4 digits with G_p = 0 and 1); per step it moves
// dt V S dp of water between neighbours, O(dt^2 dp): a flux, summing to zero over the body
// (S 1 = 0), booked with the flow (its part of the fluid's dissipation). The incompressible
// constraint B~ (u_{n+1} - u_n) = 0 becomes = -dt V S dp: a compressibility at the horizon's
// scale that vanishes as dt^2. It keeps A symmetric positive semi-definite (S is a sum of
// squares: sum_i alpha_i V_i sum_j V_j R_ij^2).
//
// Drucker-Prager in plane stress (include/mupm/laws/micropolar_drucker_prager.hpp): the water's
// volume change is biot S_r (tr eps + Pi / biot), Pi the plastic thickness change, whose step
// increment comes from the return at t_{n+1}, which needs p_{n+1} (sigma-bar_zz = S_r p). The
// solve takes the previous step's increment instead, as a source -biot S_r dPi_n / dt
// (FluidSolver::lagged_plastic_source): the right-hand side gains -V biot S_r dPi_n, the matrix
// is unchanged (a one-step lag of a bounded plastic increment adds no stiffness to the explicit
// step). The bookkeeping takes the same lagged increment, so the water balance holds as solved
// and water is conserved to the solve's tolerance; the water's coupling work then lags the
// solid's pore work of dPi by a step (each ledger closes on its own). Measured
// (tests/solvers/test_fluid_solver.cpp, SealedBodyPlaneStressDruckerPrager): the yielded sealed
// body's pore pressure within 0.3 % of the closed form, as the explicit scheme's.
//
// The crack water (Fracture->Fracture Flow; include/mupm/solvers/fracture_flow.hpp). The
// fracture pressure p_f of the network's points joins p in the same solve. Its water balance
// (fracture_flow.hpp: storage C_f, the crack's opening S_rf A dc, cubic-law flow Lambda, the
// exchange G of eq 19, sources Q), backward Euler in p_f and in the exchange on both sides,
//   V C_f dpf + S_rf A (c_{n+1} - c_ref) = dt sum_j Lambda (p_f,j - p_f,i)_{n+1}
//                                          + dt V G (p - p_f)_{n+1} + dt Q,
// and the crack water's force on the faces, B_f^T p_f (kernels/fracture_flow.hpp: the face force
// is the conjugate of the crack volume S_rf A c, c the mean opening of eq 39, linear in u with
// the broken bonds and the normal fixed over the step, so B_f = S_rf A dc/du exactly) enter as
// the bulk's do: B = [B~; B_f] in the projection, and with dpf the skeleton's correction is
// dt^2 M^-1 B^T [dp; dpf]. The system in [dp; dpf] is
//   [ A_pp + dt V G            dt^2 B~ M^-1 B_f^T - dt V G            ] [dp ]   [ r_p ]
//   [ sym.      V C_f + dt L + dt V G + dt^2 B_f M^-1 B_f^T ] [dpf] = [ r_f ],
// L the network's cubic-law Laplacian, r_f = -S_rf A (c* - c_ref) + dt (L-flow, exchange at
// p^n, p_f^n) + dt Q with c* the opening at the skeleton's prediction u*: symmetric positive
// semi-definite as the bulk's (each added term is), so it is solved as the bulk's is.
// Why this removes the K_w / a_min limit: the explicit scheme applies p_f through the undrained
// spring M_f = K_w / (c + a_min) between the faces (kernels/fracture_flow.hpp), a stiffness in
// the explicit step; here the faces see p_f^{n+1} of the implicit balance, so the crack water
// is a constraint (incompressible) or an implicit stiffness, as the bulk water is, and the
// step is the drained skeleton's (the solid's estimate leaves the crack water out,
// src/solvers/solid_stable_step.cpp). A point that joins the network takes p_f^n = p^n (its bulk
// pressure) for its storage and flows, but its faces have felt no p_f yet: its correction
// applies p_f^n too (CrackBlock::unfelt). Conservation: the crack water's content grows by the
// flows, sources and exchange the solve used (fracture_flow.hpp), the bulk loses the same
// exchange (a sink in finish_projection), so water is conserved to round-off; the crack
// water's energy balance closes as in the explicit scheme (its skeleton work is booked with the
// opening the correction reached, over the bonds the solve used; the jump of a point's mean
// opening when its bonds break enters the next step's balance); the correction's work on the
// faces is part of projection_work. The network's rows change every step (apertures set
// Lambda): with a network their values are written in place on a graph of their own, kept
// while their rows and columns are (network_values), and added to the kept rest in place, at
// their own positions alone while the rest's values are unchanged (compose); no matrix is built
// and no product formed in a step without image points. The preconditioner follows
// LinearSolve::refresh (below); the joint map changes when points join, or B_f's columns when
// bonds break: then the graphs are built again.
// Measured
// (tests/solvers/test_fracture_flow.cpp, FractureFlowSemiImplicit): incompressible water injected
// into a free slot opens it by the injected volume to 1e-10 at the drained step; against the
// explicit scheme on Example 1 case 1 at 66 x 66 (K_w = 2.2 GPa, a_min = 0.1 mm, the first 20 us):
// the semi-implicit run at 0.3 and 0.05 us gives the same external work to 0.1 %
// (2.217e-6, 2.216e-6 J; 1.95e-6 J at its automatic step, 6.65 us, three steps); the explicit
// one 1.706e-6, 2.094e-6 and 2.236e-6 J at 0.05, 0.01 and 0.002 us, first order in dt towards it
// (the explicit crack force lags by a step, fracture_flow.hpp).
//
// The matrix is kept while the bonds, the time step, the saturation, the relative permeability
// and the densities are unchanged (a saturated run without breakage assembles once). When they
// change its values are written again on kept graphs (include/mupm/solvers/kept_matrix.hpp):
// the graphs hold every bond of the lists (a broken one at zero) and change only with the
// network's points or B_f's columns; B~ = diag(S_r) B_0 and the transposes of B_0 and of the
// flow's gradient are kept while the bonds are, so a change of S_r, k_r or the densities needs
// no transpose, and a broken bond's new values reach them by one exchange of values on their
// kept graphs (KeptTranspose). The products B M^-1 B^T and Gr^T W Gr are formed again on their
// kept graphs only in the rows whose factors' values changed (KeptProduct): after a break, the
// rows within two horizons of its bonds; after a change of S_r or the densities, all. The
// sums after them are written again in full. The preconditioner then follows LinearSolve::refresh
// (kept up to Preconditioner Refresh Interval steps or until a solve takes Refresh Iteration Growth
// times the iterations of the first after its set-up, renewed after each checkpoint). The solve is
// CG where A is symmetric (no image points; krylov below), GMRES otherwise, each preconditioned by
// one V-cycle of hypre's algebraic multigrid of A (include/mupm/solvers/amg_preconditioner.hpp; its
// iterations stay bounded as the body is refined), or by ILU(k) of A less its small (far)
// entries (Pressure Solve -> Preconditioner, include/mupm/solvers/linear_solve_settings.hpp).
#ifndef MUPM_SOLVERS_PRESSURE_PROJECTION_HPP
#define MUPM_SOLVERS_PRESSURE_PROJECTION_HPP

#include <mpi.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "mupm/solvers/module.hpp"
#include "mupm/solvers/pressure_system.hpp"

namespace mupm {

// How a point's pressure is set: by the solve, held (a Pore Pressure condition), or as the
// odd (Pore Pressure, mirrored) or even (Fluid Flux) image of its mirror's (FluidSolver's
// set_pressure).
enum class PressureRole : std::uint8_t { Free, Held, OddImage, EvenImage };

template <int Dim>
class PressureProjection {
 public:
  static constexpr int R = kRotDim<Dim>, NC = Dim + R;

  // `roles`, `images` (the local index of a point's mirror, for the images) of the owned points.
  PressureProjection(Discretization<Dim>& disc, const LinearSolveSettings& settings,
                     std::vector<PressureRole> roles, std::vector<LocalId> images, MPI_Comm comm)
      : disc_(disc),
        images_any_(any_images(roles, comm)),
        solver_(krylov(settings, images_any_)),
        roles_(std::move(roles)),
        images_(std::move(images)),
        comm_(comm) {
    dofs_ = component_map(disc, NC, false);
    offset_ = disc.dist.owned_map()->getMaxAllGlobalIndex() + 1;
  }
  // The fracture pressures' gid offset in the joint numbering (CrackBlock).
  GlobalId crack_offset() const { return offset_; }

  std::string method() const { return solver_.method(); }
  // The bonds changed: assemble again before the next solve.
  void invalidate() { stale_ = true; }
  // A checkpoint was written: the next step computes the preconditioner's factors and starts
  // without a recycle space, as a restart from it does (LinearSolve::renew).
  void renew_preconditioner() { solver_.renew(); }
  long long assemblies() const { return assemblies_; }

  struct Result {
    int iterations = 0;
    double residual = 0;
    bool converged = false;
    bool finite_rhs = true;  // LinearSolveResult::finite_rhs
    double work = 0;         // the correction's work on the skeleton [J], all ranks
  };

  // Step 2-3 of the header: dp [n_owned] and, with a fracture network, dpf [its owned points,
  // crack's order] from the water balances, with `target` the new values of the held and image
  // points (images from their mirrors' p_n), `source` s [1/s], the fluid's state (C, flow) at
  // p_n, `crack` the network's rows (empty without one); corrects u, v, theta, omega of the free
  // components. `scale`: the largest right-hand side so far (LinearSolve::solve; a restart
  // global).
  Result step(double dt, const FluidParams& prm, const FluidState<Dim>& st, const Scalars& source,
              const Scalars& target, const SkeletonState& sk, const Scalars& dp, double& scale,
              const CrackBlock& crack, std::vector<double>& dpf);

  // V H dp [n_owned] with the flow operator of the last assembly (the flow's linearized
  // increment, for the water bookkeeping).
  void flow_increment(const Scalars& dp, const Scalars& out) const;

 private:
  // The state the matrix's values depend on, besides the bonds (invalidate): dt, S_r, k_r, C,
  // rho, J; the network's B_f (CrackBlock::coupling). Its graphs depend on the network's points
  // and the columns of B_f: structure_ when they changed (the same on every rank).
  static constexpr std::size_t kSeen = 5;
  bool needs_assembly(double dt, const FluidState<Dim>& st, const SkeletonState& sk,
                      const CrackBlock& crack);
  // Whether two sets of B_f rows have the same columns (values aside).
  static bool same_columns(const std::vector<std::vector<std::pair<GlobalId, double>>>& a,
                           const std::vector<std::vector<std::pair<GlobalId, double>>>& b);

  // CG where the system is symmetric: without image points (S_H = S_P = R in assemble, and the
  // network's rows are symmetric: Lambda_ij = Lambda_ji, the exchange on both sides); GMRES
  // with images (an image's row and column differ). The same choice on every rank.
  static bool any_images(const std::vector<PressureRole>& roles, MPI_Comm comm);
  static LinearSolveSettings krylov(LinearSolveSettings s, bool images) {
    s.method = images ? "GMRES" : "CG";
    return s;
  }

  // system_ = composed_ + ns (ns the network's rows of the step, R N S_H) on a graph kept while
  // ns's and composed_'s graphs do not change (`graph`: ns's is new): the values are written in
  // place (composed_'s, then ns's added: the same sums on every step, whether the graph is new
  // or kept, so a restart, which builds it again, gives the same matrix) and the
  // preconditioner's numeric part alone is computed again when the refresh interval is up
  // (LinearSolve::refresh).
  void compose(const CrsMatrix& ns, bool graph);

  // The network's rows of the step (CrackBlock, header) into network_: storage, flow and
  // exchange on the fracture pressures' rows, the exchange on its points' pore-pressure rows.
  // Written in place while the entries' rows and columns are the step before's; built again
  // when they changed (points joined, bonds broke): then true (on every rank).
  bool network_values(const CrackBlock& crack);

  // The system's graphs (structure_: built again) and values. Every value comes from the
  // kept-graph operations (include/mupm/solvers/kept_matrix.hpp) whether the graph is new or
  // kept: a restart, which builds the graphs, gives the straight run's matrix.
  void assemble(double dt, const FluidParams& prm, const FluidState<Dim>& st,
                const SkeletonState& sk, const CrackBlock& crack);

  Discretization<Dim>& disc_;
  bool images_any_;  // image points on some rank (the system is not symmetric)
  LinearSolve solver_;
  std::vector<PressureRole> roles_;
  std::vector<LocalId> images_;
  std::vector<char> solved_;  // the free rows of the last assembly (points, then the network's)
  MPI_Comm comm_;
  GlobalId offset_ = 0;
  Teuchos::RCP<const Map> dofs_, joint_;
  // The work vectors of step() and flow_increment(), kept while their maps are: a step
  // allocates none (each one written in full, or the output of an apply, before it is read).
  enum Work { kDu, kBp, kB, kC, kAc, kX, kY, kE, kFe, kBe, kYp, kF, kFlowX, kFlowY, kWorks };
  mutable std::array<Teuchos::RCP<TpetraVector>, kWorks> work_;
  TpetraVector& work(Work w, const Teuchos::RCP<const Map>& map) const {
    return kept_vector(work_[w], map);
  }
  // flow_, coupling_: over the points; the others over the joint map (static_: the system's
  // rows but the network's of the step, before R and S; composed_: after them).
  FlowOperator<Dim> flow_;
  VolumeCoupling<Dim> coupling_;
  KeptJoin joint_flow_, joint_coupling_, s_h_, s_p_;  // s_h_, s_p_: S_H, S_P of assemble
  KeptProduct projection_, flow_s_, rest_s_;
  KeptDiagonal storage_, other_;
  KeptSum rest_, static_, ras_, composed_;
  // coupling_: B_0 over the points; joint_coupling_: [B_0; B_f]; coupling_s_: B, its rows
  // scaled by sigma_ (S_r, 1 on the network's rows); coupling_t_: [B_0; B_f]^T
  Teuchos::RCP<CrsMatrix> coupling_s_, scaled_coupling_, scaled_static_, system_;
  KeptTranspose coupling_t_;
  Teuchos::RCP<TpetraVector> inverse_mass_, keep_, saturation_, sigma_;
  std::vector<double> seen_;
  // network_values: N (the network's rows) and its entries' (row, column) gids in their order;
  // ns_: R N S_H (a product with images); ns_graph_: S_H's graph changed since the last
  // compose. compose: composed_'s and ns_'s entries' positions in system_.
  KeptJoin network_;
  Teuchos::RCP<CrsMatrix> ns_;
  std::vector<GlobalId> network_pattern_;
  KeptProduct ns_product_;
  bool ns_graph_ = true;
  std::vector<std::size_t> base_;
  std::vector<std::size_t> where_;
  // compose: composed_'s entry at each of where_'s positions (-1: none), and whether composed_'s
  // values changed since (assemble): if not, only where_'s positions are written
  std::vector<std::ptrdiff_t> under_;
  bool composed_changed_ = true;
  std::vector<LocalId> crack_points_;
  std::vector<char> crack_held_;
  std::vector<std::vector<std::pair<GlobalId, double>>> crack_coupling_;
  bool structure_ = true, geometry_ = true;
  bool any_crack_ = false;
  double dt_ = 0;
  bool stale_ = true;
  long long assemblies_ = 0;
};

extern template class PressureProjection<2>;
extern template class PressureProjection<3>;

}  // namespace mupm

#endif
