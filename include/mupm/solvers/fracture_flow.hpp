// The fracture-flow step (paper eqs 18-19, 114, 118-120, 144, 146):
// the fracture pressure p_f on the fracture network, its water content, the exchange with the
// bulk and the fracture conditions (Fracture Pressure, Fracture Source). Conductances, storage
// and exchange are derived in include/mupm/kernels/fracture_flow.hpp.
//
// Why implicit (deviation from eqs 144, 146 with beta_3 = 0). The fracture's diffusivity is
// a^2 K_w / (12 mu_w): 1.8e3 m^2/s for a = 0.1 mm, so a forward-Euler step on dx = 2.5 mm would
// have to stay below ~1e-9 s, a thousandth of the solid's step. p_f is advanced by backward
// Euler instead, with the exchange implicit on both sides:
//   V_i C_f,i (p_i - p_i^n)/dt = sum_j Lambda_ij (p_j - p_i) + V_i G'_i (p^_i - p_i) + Q_i
//                                 - V_i S_rf,i (phi_f,i - phi_f,i^n)/dt,
// p^_i the bulk pressure the bulk's explicit step would reach without the exchange and
// G'_i = G_i C_i / (C_i + dt G_i) (C_i the bulk storage): eliminating the bulk's p_w^{n+1} from
// C_i (p_w^{n+1} - p_w^n) = (explicit terms) - dt G_i (p_w^{n+1} - p_i) gives exactly this,
// and the exchange then never limits the bulk's stable step. On a bulk point of prescribed
// pressure G' = G and p^ the prescribed value. The bulk takes X_i = dt V_i G'_i (p^_i - p_i) out
// as a sink (include/mupm/solvers/fluid_solver.hpp), the fracture takes it in: fluid mass is
// conserved to round-off. C_f and S_rf are those of p_f^n (linearized over the step).
//
// The crack's volume change (deviation from eq 19, which has none). The last term is the water
// the crack's opening makes room for: phi_f = (c_f + a_min)/(n_i dx) is the fracture space per
// unit volume (kernels header), c_f the point's mean opening (kernels/damage.hpp, eq 39 before
// its positive part is taken: negative when the faces are pressed together), phi_f^n that of
// the last step's opening (Points::pf_aperture, over the same n_i, so a change of n_i is no
// volume change). a_min is a film of water in the closed crack: faces pressed into it raise p_f
// and are pushed back, as opened ones lower it. (With the aperture's positive part in place of
// c_f, the faces closed onto each other without resistance while the injected water pushed
// them apart, and p_f and the bulk's p swung by MPa from step to step: measured in Example 1.)
// The film is bounded below by a_min/100 to keep a storage. It is the fracture's analogue of
// the bulk's S_r d(tr eps) (eq 141): without it, water injected into a crack could only
// compress (p_f rises by K_w/phi_f per unit content, ~1e3 times the skeleton's stiffness),
// and an opening crack would not draw water. Held at fixed content, an opening dc lowers p_f by
// M_f dc, M_f = S_rf/(C_f n_i dx) = K_w/(c_f + a_min) saturated (Points::pf_modulus, written
// here): the crack's water is a stiff spring between its faces. The solid applies it undrained,
// p_f* = p_f - M_f (c - c_ref) at the opening it is at (kernels header), and its stable-step
// estimate includes it (src/solvers/solid_stable_step.cpp); hence a_min also bounds the time step.
//
// Pressure Integration = Semi-Implicit: p_f is solved together with the bulk's p instead
// (implicit_rows, implicit_finish, implicit_opening; the joint system is derived in
// include/mupm/solvers/pressure_projection.hpp): the exchange is implicit on both sides (G in
// place of G'), M_f = 0 (the solid applies p_f itself) and the opening's work is booked with the
// opening the step reached after the pressure's correction.
//
// Plane stress (Discretization->Plane = Stress). The crack is a slit through the plate's
// thickness: its water pushes the faces, whose normals lie in the plane, so p_f loads the plane
// only. It takes no share of sigma_zz, so none of the bulk water's plane-stress coupling
// (PoreCoupling, include/mupm/laws/micropolar_elastic.hpp: biot 2 mu / (lambda + 2 mu) and the
// thickness compliance in the storage, which come from the pore pressure acting in z as well)
// applies to p_f: the face forces, C_f, phi_f and M_f are plane strain's, per unit thickness. The
// bulk side of the exchange keeps its own coupling (the predictor p^ and its storage C are the
// bulk's, fluid_solver.hpp). Left out: the slit's volume change with the plate's thickness, phi_f
// d(eps_zz), beside the opening's d(phi_f): phi_f eps_zz ~ 1e-4 of it at strains of 1e-4.
//
// The solve is distributed as the points are: each rank assembles the rows of its own fracture
// points as a Tpetra CrsMatrix over the network's map (the owned fracture points' global ids),
// its neighbours' data reaching it with the ghosts (two refreshes: on the network, held, p_f^n;
// then conductance and start value), and Belos' GMRES with Ifpack2's ILU(0) solves for the
// increment over p_f^n (include/mupm/solvers/linear_solve.hpp); no rank holds more of the
// network than its own points and their ghosts. The system (free rows; held points' increments
// are zero and their values move to the right-hand side) is symmetric with negative
// off-diagonals and a positive diagonal that dominates strictly (storage and exchange): an
// M-matrix, whose ILU(0) exists. The tolerance is 1e-14 of ||D x|| (D the diagonal, x the
// solution): the scale of A x's own round-off (eps |A| |x| <= 2 eps |D x|), so the residual is
// held to a hundred times round-off however stiff the conductances make the system (a scale of
// ||b|| could not be reached: an open crack's condition number kappa reaches 1e8, and the
// forward error of any double solve is kappa eps). It takes few iterations: along a crack the
// network is nearly one-dimensional, where ILU is close to exact; the
// subdomains of the ranks cost a few iterations more. Results therefore agree across rank and
// thread counts to the solve's tolerance (not bit for bit; the reductions' order and the
// subdomains differ) and restart bit for bit on the same ranks and threads. Water stays
// conserved to round-off whatever the tolerance: the contents are updated with the flows
// actually used, pair by pair antisymmetric. A singular system or a solve that does not
// converge stops the run (CollectiveError), never a silent garbage p_f.
//
// Water content: each fracture point's content grows by what flowed in over the step,
//   dt (sum_j Lambda_ij (p_j - p_i) + Q_i) + X_i,
// (on a point of prescribed p_f the reservoir supplies V C_f dp minus that, counted as the
// condition's inflow). Summed over the network the bond flows cancel pair by pair, so
// fracture water = injected + exchanged + supplied + joined, to round-off. A point joins the
// network (becomes a fracture point) with p_f^n = the volume-weighted mean p_f of the network
// points in its family (the water that reaches it; its bulk p_w where there is none) and
// phi_f^n = its phi_f: the crack's volume at joining is taken as filled at that pressure, and
// that water, V S_rf(p_f^n) phi_f, is booked as joined (joined(), the time series'
// fracture_fluid_joined: a source of the balance, as the crack's volume appeared at once); its
// opening from then on is booked as the content equation says.
//
// Energy of the crack water (issue 9 item 5; the fracture's analogue of eqs 147-149). Multiplying
// each point's content equation above by the step's mean pressure p_m = (p_i^n + p_i)/2 and
// summing over the network gives, per step,
//   sum V C_f (p - p^n) p_m + sum V S_rf dphi_f p_m
//     = -D + sum p_m dt Q + sum p_m X + sum p_m (reservoir supply),
//   D = -dt sum_i p_m,i sum_j Lambda_ij (p_j - p_i) = dt sum_pairs Lambda_ij (p_j - p_i)(p_m,j -
//   p_m,i),
// booked as: stored energy sum V phi_f [psi(p) - psi(p^n)] (psi the bulk's stored energy per
// unit pore volume, include/mupm/kernels/fluid.hpp, at phi = 1: the first term when C_f is
// constant), the work on the skeleton W_sk = sum V S_rf dphi_f p_m (what the crack's opening
// takes from the water: the solid books the same work as its face forces' work,
// SolidSolver::Energy::crack_work), the flow dissipation D, the external work W_ext (sources
// and prescribed p_f, at p_m: second order in dt) and the exchange W_x (the bulk's water
// entering at p_m; the bulk books it at its own pressure, fluid_solver.hpp, the difference is
// the exchange's dissipation). Their balance E - E_0 + W_sk + D - W_ext - W_x is zero to
// round-off for saturated crack water (C_f = phi_f / K_w constant over the step: psi's change is
// then exactly C_f (p - p^n) p_m), as the water mass is; it checks the bookkeeping and the
// linear solve, and for unsaturated crack water measures the step's linearization of C_f (taken
// at p^n). The energy of the water that fills the crack's volume at joining is not booked (its
// mass is, above). The stored term is
// sum V phi_f d(psi), not d(sum V phi_f psi): the energy psi dphi_f that the water filling an
// opening's new space carries (p^2 / (2 K_w) per unit volume when saturated, p / (2 K_w) of the
// skeleton work p dphi_f: 5e-4 at 2 MPa) is left out, as the content equation does. D, the
// mean-pressure weighting of the flow, is not sign-definite step by step (it is the new
// differences times the mean ones); summed over a run it is the dissipation to O(dt).
#ifndef MUPM_SOLVERS_FRACTURE_FLOW_HPP
#define MUPM_SOLVERS_FRACTURE_FLOW_HPP

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "mupm/core/collective.hpp"
#include "mupm/core/error.hpp"
#include "mupm/kernels/boundary_conditions.hpp"
#include "mupm/kernels/fluid.hpp"
#include "mupm/kernels/fracture.hpp"
#include "mupm/kernels/fracture_flow.hpp"
#include "mupm/mesh/discretization.hpp"
#include "mupm/solvers/linear_solve.hpp"
#include "mupm/solvers/module.hpp"
#include "mupm/solvers/pressure_system.hpp"

namespace mupm {

template <int Dim>
class FractureFlow {
  static_assert(Kokkos::SpaceAccessibility<HostSpace, MemSpace>::accessible,
                "the network is assembled on the host");

 public:
  // The network's solve (header): ILU(0)-preconditioned GMRES to 1e-14 of ||D x||.
  static LinearSolveSettings solve_settings();

  FractureFlow(Discretization<Dim>& disc, const FluidParams& fluid, const FractureParams& prm,
               const std::vector<BoundaryCondition>& bcs, MPI_Comm comm);

  // Names of the conditions, with the water [kg] that entered through each so far.
  const std::vector<BoundaryCondition>& conditions() const { return bcs_; }
  std::vector<double>& inflows() { return inflow_; }
  // The water the points brought that joined the network [kg] (header; a restart global).
  double& joined() { return joined_; }
  double joined() const { return joined_; }
  const std::vector<double>& inflows() const { return inflow_; }
  long long network_size() const { return last_size_; }
  // GMRES iterations of the last solve (0 without a network), for the benchmarks.
  int last_iterations() const { return last_iterations_; }

  // The crack water's energy terms since t = 0 [J] (header), the same on every rank.
  struct Energy {
    double stored = 0, skeleton_work = 0, dissipation = 0, external_work = 0, exchange_work = 0;
    double balance() const {
      return stored + skeleton_work + dissipation - external_work - exchange_work;
    }
    double scale() const {
      return std::max(std::max(std::abs(stored), std::abs(skeleton_work)),
                      std::max(std::abs(dissipation),
                               std::max(std::abs(external_work), std::abs(exchange_work))));
    }
  };
  Energy& energy() { return energy_; }
  const Energy& energy() const { return energy_; }

  // Water in the fracture spaces [kg]: rho_w sum_i V_i content_i.
  double mass() const {
    const auto& p = disc_.points;
    return fluid_.water_density * volume_integral(p.pf_content, p.volume, p.n_owned, comm_);
  }

  // One step t -> t + dt (header). phat: the bulk pressure of the explicit step without the
  // exchange, C: the bulk storage (owned points). sink: the exchange per unit volume and time
  // [1/s] the bulk loses, written for every owned point (0 off the network).
  void step(double t, double dt, const Scalars& phat, const Scalars& C, const Scalars& sink);

  // Pressure Integration = Semi-Implicit (include/mupm/solvers/pressure_projection.hpp): p_f
  // comes from the pore pressure's solve, one joint system. The exchange is then implicit on
  // both sides (G, not G'), and the solid applies p_f itself (M_f = 0: no undrained spring).
  void set_implicit() { implicit_ = true; }
  // The network's rows of the joint system for t -> t + dt (CrackBlock), at the skeleton's
  // predicted displacement u* (refreshed onto the ghosts here) and the bulk's p^n.
  void implicit_rows(double t, double dt, GlobalId offset, CrackBlock& blk);
  // After the joint solve: p_f = p_f^n + dpf (held: the prescribed value), the exchange with
  // the bulk's new pressure (p, owned) into `sink` [1/s], contents and energies (the skeleton
  // work in implicit_opening).
  void implicit_finish(double dt, const std::vector<double>& dpf, const Scalars& sink);
  // After the pressure's correction of the skeleton (u_{n+1}, refreshed onto the ghosts here),
  // before the skeleton's step breaks bonds: the crack's opening over the step with the bonds
  // the solve used, its work on the skeleton and, on a held point, the water its reservoir
  // supplied for it. (With the opening after breakage, the broken bonds' jump in the mean
  // opening was booked as work the solve never saw: the crack water's balance lost 0.03 J at
  // the first breakage in the KGD input.) The jump enters the next step's opening instead, as
  // in the explicit scheme.
  void implicit_opening();

 private:
  // An owned network point: its local id and its state at the step's start.
  struct Node {
    LocalId i;
    double open, open_ref, phat, C, G, pold;
    bool bulk_fixed, fresh;
    double nrm[Dim];
  };
  static constexpr double kConductanceCap = 1e8;  // assemble()

  // The owned network points, whether each point is held, and what its neighbours need: on the
  // network, the held condition (-1: none), p_f^n (p_w for a point that joins now).
  void collect(const Scalars& phat, const Scalars& C) {
    auto& p = disc_.points;
    const auto& b = disc_.bonds;
    const double g0 = 2.0 * fluid_.mobility / (disc_.grid.dx * disc_.grid.dx);  // G / k_r (eq 19)
    net_.clear();
    Kokkos::deep_copy(shared_, 0.0);
    for (std::size_t i = 0; i < p.n_owned; ++i) {
      if (!p.fracture(i))
        continue;
      Node nd;
      nd.i = LocalId(i);
      if (!crack_normal<Dim>(b.offsets, b.neighbor, b.intact, p.x, i, nd.nrm))
        for (int d = 0; d < Dim; ++d)
          nd.nrm[d] = 0;
      nd.fresh = !(p.pf_saturation(i) > 0);
      nd.open = mean_opening<Dim>(b.offsets, b.neighbor, b.intact, p.x, p.u, p.volume, i);
      nd.open_ref = nd.fresh ? nd.open : p.pf_aperture(i);
      nd.phat = phat(i);
      nd.C = C(i);
      nd.G = g0 * p.rel_perm(i);
      nd.bulk_fixed = (p.fixed(i) & kFixedPressure) != 0;
      nd.pold = nd.fresh ? joining_pressure(i) : p.pf(i);
      int held = -1;  // later conditions win
      for (std::size_t k = 0; k < bcs_.size(); ++k)
        if (bcs_[k].kind == BoundaryCondition::FracturePressure && in(bcs_[k], i))
          held = int(k);
      shared_(i, 0) = 1;
      shared_(i, 1) = held + 1;  // 0: none, as off the network
      shared_(i, 2) = nd.pold;
      net_.push_back(nd);
    }
    disc_.dist.refresh({shared_});
  }

  // p_f^n of a point that joins the network now (header): the volume-weighted mean p_f of the
  // network points in its family (p_f and S_rf current on the ghosts since the last scatter),
  // or its bulk p_w where none is.
  double joining_pressure(std::size_t i) const {
    const auto& p = disc_.points;
    const auto& b = disc_.bonds;
    double sum = 0, vol = 0;
    for (BondIndex e = b.offsets(i); e < b.offsets(i + 1); ++e) {
      const LocalId j = b.neighbor(e);
      if (p.pf_saturation(j) > 0) {
        sum += p.volume(j) * p.pf(j);
        vol += p.volume(j);
      }
    }
    return vol > 0 ? sum / vol : p.p(i);
  }

  // collect(), then the network's size over the ranks: false (on every rank) when it is empty,
  // after checking that no Fracture Source injects then (it would have nowhere to put its
  // water).
  bool gather(double t, const Scalars& phat, const Scalars& C);

  bool in(const BoundaryCondition& bc, std::size_t i) const {
    return bc.region_mask == 0 || (disc_.points.regions(i) & bc.region_mask);
  }
  bool on(LocalId j) const { return shared_(j, 0) != 0; }
  int held(LocalId j) const { return int(shared_(j, 1)) - 1; }  // -1: none

  // A Fracture Source's rate q [m^3/s] at t; an error when it injects (q != 0) but its region
  // holds no fracture point (volume vsum, all ranks), the same on every rank.
  double check_source(const BoundaryCondition& bc, double t, double vsum) const;

  // The rows of the owned network points (header): adjacency, conductances, diagonal,
  // right-hand side; the sources at t, the prescribed p_f at t + dt.
  void assemble(double t, double dt);

  // The increment y = p_f - x0 of the free rows (header): A y = rhs - A_full x0, held rows
  // y = 0 (a diagonal row: held neighbours leave the matrix, keeping it symmetric).
  void solve(double dt);

  // The new p_f and S_rf (onto the ghosts too), rates and contents, the exchange into `sink`,
  // the reservoirs' supply into the conditions' inflows.
  void scatter(double dt, const Scalars& sink);

  Discretization<Dim>& disc_;
  FluidParams fluid_;
  FractureParams prm_;
  MPI_Comm comm_;
  LinearSolve solver_;
  std::vector<BoundaryCondition> bcs_;
  std::vector<double> inflow_;
  double joined_ = 0;  // joined() [kg]
  Vectors shared_;     // [points][3]: on the network, held condition + 1, p_f^n (collect)
  Vectors coupled_;    // [points][2]: conductance kappa, start value x0 (assemble)
  // The owned network points and their rows.
  std::vector<Node> net_;
  std::vector<std::size_t> adj_first_;
  std::vector<LocalId> adj_;
  std::vector<double> kappa_, lambda_, diag_, rhs_, source_, storage_, phi_f_, opening_, gexch_, x_,
      held_value_;
  std::vector<int> rows_;
  long long last_size_ = 0;
  int last_iterations_ = 0;
  bool implicit_ = false;  // set_implicit
  Energy energy_;
};

extern template class FractureFlow<2>;
extern template class FractureFlow<3>;

}  // namespace mupm

#endif
