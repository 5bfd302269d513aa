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
// estimate includes it (solvers/solid_solver.hpp); hence a_min also bounds the time step.
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
// fracture water = injected + exchanged + supplied, to round-off. A point joins the network
// (becomes a fracture point) with p_f = its bulk p_w, no content and phi_f^n = its phi_f: the
// crack's volume at joining is taken as filled at that pressure (not booked as water), its
// opening from then on is.
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
// at p^n). The crack's volume at joining is not booked (as its water is not). The stored term is
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
  static LinearSolveSettings solve_settings() {
    LinearSolveSettings s;
    s.preconditioner = "ILU";
    s.fill_level = 0;
    s.tolerance = 1e-14;
    return s;
  }

  FractureFlow(Discretization<Dim>& disc, const FluidParams& fluid, const FractureParams& prm,
               const std::vector<BoundaryCondition>& bcs, MPI_Comm comm)
      : disc_(disc), fluid_(fluid), prm_(prm), comm_(comm), solver_(solve_settings()) {
    for (const auto& bc : bcs)
      if (bc.kind == BoundaryCondition::FracturePressure ||
          bc.kind == BoundaryCondition::FractureSource) {
        bcs_.push_back(bc);
        bcs_.back().mirror_column = face_column(disc.grid, bc.region_mask);
        if (bc.mirrored && disc.mirror.extent(0) == 0)
          throw std::logic_error("FractureFlow: condition '" + bc.name +
                                 "' mirrors its layer, but the grid was built without mirrors "
                                 "(GridSpec::mirrored_layers)");
      }
    inflow_.assign(bcs_.size(), 0.0);
    const std::size_t n = disc.points.size();
    shared_ = Vectors("mupm::fracture_network", n, 3);
    coupled_ = Vectors("mupm::fracture_conductance", n, 2);
  }

  // Names of the conditions, with the water [kg] that entered through each so far.
  const std::vector<BoundaryCondition>& conditions() const { return bcs_; }
  std::vector<double>& inflows() { return inflow_; }
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
  void step(double t, double dt, const Scalars& phat, const Scalars& C, const Scalars& sink) {
    ScopedRegion region("mupm::FractureFlow::step");
    Kokkos::deep_copy(sink, 0.0);
    if (!gather(t, phat, C))
      return;
    assemble(t, dt);
    solve(dt);
    scatter(dt, sink);
  }

  // Pressure Integration = Semi-Implicit (include/mupm/solvers/pressure_projection.hpp): p_f
  // comes from the pore pressure's solve, one joint system. The exchange is then implicit on
  // both sides (G, not G'), and the solid applies p_f itself (M_f = 0: no undrained spring).
  void set_implicit() { implicit_ = true; }
  // The network's rows of the joint system for t -> t + dt (CrackBlock), at the skeleton's
  // predicted displacement u* (refreshed onto the ghosts here) and the bulk's p^n.
  void implicit_rows(double t, double dt, GlobalId offset, CrackBlock& blk) {
    ScopedRegion region("mupm::FractureFlow::rows");
    auto& p = disc_.points;
    const auto& b = disc_.bonds;
    blk = CrackBlock();
    blk.offset = offset;
    disc_.dist.refresh({p.u});
    if (!gather(t, p.p, p.p))
      return;
    assemble(t, dt);
    constexpr int NC = Dim + kRotDim<Dim>;
    const VanGenuchten vg = fluid_.retention;
    for (std::size_t k = 0; k < net_.size(); ++k) {
      const Node& nd = net_[k];
      const LocalId i = nd.i;
      const double v = p.volume(i);
      const bool h = held(i) >= 0;
      blk.point.push_back(i);
      blk.held.push_back(h ? 1 : 0);
      blk.start.push_back(h ? held_value_[k] - nd.pold : (nd.fresh ? 0.0 : p.pf_rate(i) * dt));
      blk.pf0.push_back(nd.pold);
      blk.unfelt.push_back(nd.fresh ? nd.pold : 0.0);
      blk.storage.push_back(v * storage_[k]);
      blk.exchange.push_back(dt * v * gexch_[k]);
      // The water balance at the increments' zero: the crack's opening to u*, the flows and the
      // exchange at p^n, p_f^n, the sources.
      double r = -v * opening_[k] + dt * source_[k] + dt * v * gexch_[k] * (nd.phat - nd.pold);
      std::vector<std::pair<GlobalId, double>> flow;
      for (std::size_t e = adj_first_[k]; e < adj_first_[k + 1]; ++e) {
        r += dt * lambda_[e] * (shared_(adj_[e], 2) - nd.pold);
        flow.push_back({offset + p.gid(adj_[e]), dt * lambda_[e]});
      }
      blk.rhs.push_back(r);
      blk.flow.push_back(std::move(flow));
      // B_f = S_rf A dc/du, c = sum_b w_b (u_j - u_i).n (eq 39; the kernels header): the crack
      // face force's transpose.
      std::vector<std::pair<GlobalId, double>> row;
      double nn = 0;
      for (int d = 0; d < Dim; ++d)
        nn += nd.nrm[d] * nd.nrm[d];
      if (prm_.face_pressure && nn > 0) {
        double vsum = 0;
        for (BondIndex e = b.offsets(i); e < b.offsets(i + 1); ++e)
          if (!b.intact(e))
            vsum += p.volume(b.neighbor(e));
        const double s = vg.saturation(nd.pold) * v / (rows_[k] * disc_.grid.dx);
        for (BondIndex e = b.offsets(i); e < b.offsets(i + 1); ++e) {
          if (b.intact(e))
            continue;
          const LocalId j = b.neighbor(e);
          for (int d = 0; d < Dim; ++d)
            row.push_back({p.gid(j) * NC + d, s * p.volume(j) / vsum * nd.nrm[d]});
        }
        for (int d = 0; d < Dim; ++d)
          row.push_back({p.gid(i) * NC + d, -s * nd.nrm[d]});
      }
      blk.coupling.push_back(std::move(row));
    }
  }
  // After the joint solve: p_f = p_f^n + dpf (held: the prescribed value), the exchange with
  // the bulk's new pressure (p, owned) into `sink` [1/s], contents and energies (the skeleton
  // work in implicit_opening).
  void implicit_finish(double dt, const std::vector<double>& dpf, const Scalars& sink) {
    Kokkos::deep_copy(sink, 0.0);
    if (last_size_ == 0)
      return;
    x_.assign(net_.size(), 0.0);
    for (std::size_t k = 0; k < net_.size(); ++k) {
      net_[k].phat = disc_.points.p(net_[k].i);
      x_[k] = held(net_[k].i) >= 0 ? held_value_[k] : net_[k].pold + dpf[k];
    }
    scatter(dt, sink);
  }
  // After the pressure's correction of the skeleton (u_{n+1}, refreshed onto the ghosts here),
  // before the skeleton's step breaks bonds: the crack's opening over the step with the bonds
  // the solve used, its work on the skeleton and, on a held point, the water its reservoir
  // supplied for it. (With the opening after breakage, the broken bonds' jump in the mean
  // opening was booked as work the solve never saw: the crack water's balance lost 0.03 J at
  // the first breakage in the KGD input.) The jump enters the next step's opening instead, as
  // in the explicit scheme.
  void implicit_opening() {
    if (last_size_ == 0)
      return;
    auto& p = disc_.points;
    disc_.dist.refresh({p.u});
    const auto& b = disc_.bonds;
    const VanGenuchten vg = fluid_.retention;
    std::vector<double> sums(2 + bcs_.size(), 0.0);
    for (std::size_t k = 0; k < net_.size(); ++k) {
      const Node& nd = net_[k];
      const LocalId i = nd.i;
      const double v = p.volume(i), pm = 0.5 * (nd.pold + x_[k]);
      const double open = mean_opening<Dim>(b.offsets, b.neighbor, b.intact, p.x, p.u, p.volume, i);
      const double d = vg.saturation(nd.pold) * (open - nd.open_ref) / (rows_[k] * disc_.grid.dx);
      sums[0] += pm * v * d;
      const int h = held(i);
      if (h >= 0) {  // the held point's storage equation, with the opening it reached
        const double extra = v * (d - opening_[k]);
        sums[2 + std::size_t(h)] += extra;
        sums[1] += pm * extra;
        p.pf_content(i) += extra / v;
      }
      p.pf_aperture(i) = open;
    }
    MPI_Allreduce(MPI_IN_PLACE, sums.data(), int(sums.size()), MPI_DOUBLE, MPI_SUM, comm_);
    energy_.skeleton_work += sums[0];
    energy_.external_work += sums[1];
    for (std::size_t c = 0; c < bcs_.size(); ++c)
      inflow_[c] += fluid_.water_density * sums[2 + c];
  }

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
      nd.pold = nd.fresh ? p.p(i) : p.pf(i);
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

  // collect(), then the network's size over the ranks: false (on every rank) when it is empty,
  // after checking that no Fracture Source injects then (it would have nowhere to put its
  // water).
  bool gather(double t, const Scalars& phat, const Scalars& C) {
    collect(phat, C);
    long long n = (long long)net_.size();
    MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_LONG_LONG, MPI_SUM, comm_);
    last_size_ = n;
    last_iterations_ = 0;
    if (n == 0)
      for (const auto& bc : bcs_)
        if (bc.kind == BoundaryCondition::FractureSource)
          check_source(bc, t, 0.0);
    return n > 0;
  }

  bool in(const BoundaryCondition& bc, std::size_t i) const {
    return bc.region_mask == 0 || (disc_.points.regions(i) & bc.region_mask);
  }
  bool on(LocalId j) const { return shared_(j, 0) != 0; }
  int held(LocalId j) const { return int(shared_(j, 1)) - 1; }  // -1: none

  // A Fracture Source's rate q [m^3/s] at t; an error when it injects (q != 0) but its region
  // holds no fracture point (volume vsum, all ranks), the same on every rank.
  double check_source(const BoundaryCondition& bc, double t, double vsum) const {
    const double h = Dim == 2 ? disc_.grid.thickness : 1.0;
    const double q = bc.value * bc.time(t) * h;
    if (q != 0 && !(vsum > 0))
      throw CollectiveError("Error, mupm->Boundary Conditions->" + bc.name +
                            " (Fracture Source) has no fracture point in its region at t = " +
                            std::to_string(t) + " s: put the region on the crack.");
    return q;
  }

  // The rows of the owned network points (header): adjacency, conductances, diagonal,
  // right-hand side; the sources at t, the prescribed p_f at t + dt.
  void assemble(double t, double dt) {
    auto& p = disc_.points;
    const auto& b = disc_.bonds;
    const std::size_t n = net_.size();
    const double dx = disc_.grid.dx;
    const double mu = prm_.viscosity, amin = prm_.min_aperture;
    const double inv_kw = 1.0 / fluid_.bulk_modulus;
    const VanGenuchten vg = fluid_.retention;
    adj_first_.assign(1, 0);
    adj_.clear();
    kappa_.assign(n, 0.0);
    storage_.assign(n, 0.0);
    phi_f_.assign(n, 0.0);
    opening_.assign(n, 0.0);
    rows_.assign(n, 1);
    gexch_.assign(n, 0.0);
    double floor = std::numeric_limits<double>::infinity();
    std::vector<LocalId> js;
    for (std::size_t k = 0; k < n; ++k) {
      const Node& nd = net_[k];
      const LocalId i = nd.i;
      js.clear();
      for (BondIndex e = b.offsets(i); e < b.offsets(i + 1); ++e) {
        const LocalId j = b.neighbor(e);
        if (j != i && on(j))
          js.push_back(j);
      }
      std::sort(js.begin(), js.end());
      js.erase(std::unique(js.begin(), js.end()), js.end());
      double m = 0;
      int rows = 1;
      for (const LocalId j : js) {
        double xi[Dim], xn = 0, par2 = 0;
        for (int d = 0; d < Dim; ++d) {
          xi[d] = p.x(j, d) - p.x(i, d);
          xn += xi[d] * nd.nrm[d];
        }
        for (int d = 0; d < Dim; ++d) {
          const double q = xi[d] - xn * nd.nrm[d];
          par2 += q * q;
        }
        m += par2 / (Dim - 1);
        rows += par2 < 0.25 * dx * dx ? 1 : 0;
        adj_.push_back(j);
      }
      adj_first_.push_back(adj_.size());
      const double v = p.volume(i);
      const double a = std::max(nd.open, amin);  // the aperture max(c, 0), at least a_min
      const double area = v / (rows * dx);       // A_i
      kappa_[k] = m > 0 ? a * a * a * area / (6.0 * mu * m) : 0.0;  // kernels header
      const double film = std::max(amin + nd.open, 0.01 * amin);    // header
      phi_f_[k] = film / (rows * dx);
      const double sat = vg.saturation(nd.pold);
      storage_[k] = phi_f_[k] * (vg.dsaturation_dp(nd.pold) + sat * inv_kw);
      opening_[k] = sat * (nd.open - nd.open_ref) / (rows * dx);  // S_rf d(phi_f)
      rows_[k] = rows;
      gexch_[k] =
          nd.bulk_fixed || implicit_ ? nd.G : (nd.C > 0 ? nd.G * nd.C / (nd.C + dt * nd.G) : 0.0);
      floor = std::min(floor, v * (storage_[k] / dt + gexch_[k]));
    }
    // Conditioning: a wide-open crack's conductances exceed V C_f / dt by more than the 16
    // digits of a double, and the pressure level of a network component (set by its storage)
    // would be lost in round-off. Conductances are capped at kConductanceCap times the
    // smallest storage-plus-exchange term of the network: at the cap the pressure evens out
    // over 1e4 points along the crack within one step, so the cap changes what the crack does
    // by less than the step's own error. Water is conserved whatever the cap (contents come
    // from the flows actually used).
    MPI_Allreduce(MPI_IN_PLACE, &floor, 1, MPI_DOUBLE, MPI_MIN, comm_);
    const double cap = kConductanceCap * floor;
    // Sources [m^3/s] spread by volume over their network points at t (region volumes summed
    // over the ranks); prescribed p_f at t + dt (later conditions win).
    std::vector<double> vsum(bcs_.size(), 0.0);
    for (std::size_t c = 0; c < bcs_.size(); ++c)
      if (bcs_[c].kind == BoundaryCondition::FractureSource)
        for (const Node& nd : net_)
          if (in(bcs_[c], nd.i))
            vsum[c] += p.volume(nd.i);
    if (!vsum.empty())
      MPI_Allreduce(MPI_IN_PLACE, vsum.data(), int(vsum.size()), MPI_DOUBLE, MPI_SUM, comm_);
    source_.assign(n, 0.0);
    held_value_.assign(n, 0.0);
    for (std::size_t c = 0; c < bcs_.size(); ++c) {
      const auto& bc = bcs_[c];
      if (bc.kind == BoundaryCondition::FractureSource) {
        const double q = check_source(bc, t, vsum[c]);
        for (std::size_t k = 0; k < n; ++k)
          if (in(bc, net_[k].i))
            source_[k] += q * p.volume(net_[k].i) / vsum[c];
        inflow_[c] += fluid_.water_density * q * dt;
      }
    }
    // Mirrored Fracture Pressure (Boundary Layer Values = Mirrored): a held point L outside
    // the condition's face whose mirror m is a network point that no condition holds takes
    // 2 g - q, q the mirror's pressure, so that p_f passes through g at the face. Implicit in m
    // it would couple m to L's neighbours unsymmetrically, so q comes from the step's start,
    // relaxed by a half:
    //   q = (q^n + p_f^n(m)) / 2,   q^n = 2 g(t) - p_f^n(L) (what L held; p_f^n(m) if L joins now).
    // Unrelaxed (q = p_f^n(m)) the crack's pressure oscillated without decay when its storage is
    // small against its conductances (the interior then follows the held values almost
    // one to one, a factor -1 per step; measured in the test's slot). Relaxed, an error e of q
    // becomes (1 - c) e / 2, c in [0, 1] that response: no oscillation, at least halved each
    // step, and a steady state is the reflection's exactly. q^n is rebuilt from the
    // checkpointed p_f, so a restart continues bit for bit. A held point whose mirror is not on
    // the network, or is held, keeps g.
    for (std::size_t k = 0; k < n; ++k) {
      const Node& nd = net_[k];
      const int h = held(nd.i);
      if (h < 0)
        continue;
      const auto& bc = bcs_[std::size_t(h)];
      const double g = bc.value * bc.time(t + dt);
      held_value_[k] = g;
      const LocalId m = bc.mirrored ? disc_.mirror(nd.i, bc.mirror_column) : LocalId(-1);
      if (m < 0 || !on(m) || held(m) >= 0)
        continue;
      const double pm = shared_(m, 2);
      const double q = nd.fresh ? pm : 0.5 * ((2 * bc.value * bc.time(t) - nd.pold) + pm);
      held_value_[k] = 2 * g - q;
    }
    // The start value x0 (held value or p_f^n) and the conductance reach the neighbours.
    for (std::size_t k = 0; k < n; ++k) {
      coupled_(net_[k].i, 0) = kappa_[k];
      coupled_(net_[k].i, 1) = held(net_[k].i) >= 0 ? held_value_[k] : net_[k].pold;
    }
    disc_.dist.refresh({coupled_});
    lambda_.resize(adj_.size());
    diag_.assign(n, 0.0);
    rhs_.assign(n, 0.0);
    std::string bad;
    for (std::size_t k = 0; k < n; ++k) {
      const Node& nd = net_[k];
      double s = 0;
      for (std::size_t e = adj_first_[k]; e < adj_first_[k + 1]; ++e) {
        lambda_[e] = std::min(0.5 * (kappa_[k] + coupled_(adj_[e], 0)), cap);
        s += lambda_[e];
      }
      const double v = p.volume(nd.i);
      diag_[k] = v * storage_[k] / dt + v * gexch_[k] + s;
      if (bad.empty() &&
          (!std::isfinite(diag_[k]) || !std::isfinite(nd.pold) || !std::isfinite(nd.phat)))
        bad = "Error, fracture point " + std::to_string(p.gid(nd.i)) + " at (" +
              std::to_string(p.x(nd.i, 0)) + ", " + std::to_string(p.x(nd.i, 1)) +
              ") has a non-finite aperture or pressure (aperture " +
              std::to_string(std::max(nd.open, 0.0)) + " m, p_f " + std::to_string(nd.pold) +
              " Pa): the run has become unstable.";
      rhs_[k] = v * storage_[k] / dt * nd.pold + v * gexch_[k] * nd.phat - v * opening_[k] / dt +
                source_[k];
    }
    agree(comm_, bad);
  }

  // The increment y = p_f - x0 of the free rows (header): A y = rhs - A_full x0, held rows
  // y = 0 (a diagonal row: held neighbours leave the matrix, keeping it symmetric).
  void solve(double dt) {
    auto& p = disc_.points;
    const std::size_t n = net_.size();
    std::vector<GlobalId> ids(n);
    for (std::size_t k = 0; k < n; ++k)
      ids[k] = p.gid(net_[k].i);
    const auto invalid = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
    auto map = Teuchos::rcp(
        new Map(invalid, Teuchos::ArrayView<const GlobalId>(ids), 0, disc_.dist.comm()));
    std::size_t longest = 1;
    for (std::size_t k = 0; k < n; ++k)
      longest = std::max(longest, adj_first_[k + 1] - adj_first_[k] + 1);
    auto a = Teuchos::rcp(new CrsMatrix(map, longest));
    TpetraVector rhs(map), y(map);
    {
      auto bv = rhs.getLocalViewHost(Tpetra::Access::OverwriteAll);
      auto yv = y.getLocalViewHost(Tpetra::Access::OverwriteAll);
      std::vector<GlobalId> cols;
      std::vector<double> vals;
      for (std::size_t k = 0; k < n; ++k) {
        const LocalId i = net_[k].i;
        cols.assign(1, ids[k]);
        vals.assign(1, diag_[k]);
        const bool free = held(i) < 0;
        const double x0 = coupled_(i, 1);
        double r = rhs_[k] - diag_[k] * x0;
        for (std::size_t e = adj_first_[k]; free && e < adj_first_[k + 1]; ++e) {
          const LocalId j = adj_[e];
          r += lambda_[e] * coupled_(j, 1);
          if (held(j) < 0) {
            cols.push_back(p.gid(j));
            vals.push_back(-lambda_[e]);
          }
        }
        a->insertGlobalValues(ids[k], Teuchos::ArrayView<const GlobalId>(cols),
                              Teuchos::ArrayView<const double>(vals));
        bv(k, 0) = free ? r : 0.0;
        yv(k, 0) = free && !net_[k].fresh ? p.pf_rate(i) * dt : 0.0;
      }
    }
    a->fillComplete(map, map);
    solver_.set_matrix(a);
    // The tolerance is relative to ||D x|| at the solution; that of the start value is tried
    // first, and when the solution is larger (water let into a network at rest), the solve
    // goes on from where it stopped with the solution's.
    // ||D x|| over the free rows, x = x0 + v (v = nullptr: x0): the round-off scale of A x.
    auto scaled = [&](const TpetraVector* v) {
      std::vector<double> dv(n, 0.0);
      if (v) {
        auto vv = v->getLocalViewHost(Tpetra::Access::ReadOnly);
        for (std::size_t k = 0; k < n; ++k)
          dv[k] = vv(k, 0);
      }
      double s = 0;
      for (std::size_t k = 0; k < n; ++k)
        if (held(net_[k].i) < 0) {
          const double t = diag_[k] * (coupled_(net_[k].i, 1) + dv[k]);
          s += t * t;
        }
      MPI_Allreduce(MPI_IN_PLACE, &s, 1, MPI_DOUBLE, MPI_SUM, comm_);
      return std::sqrt(s);
    };
    double scale = scaled(nullptr);
    LinearSolveResult res = solver_.solve(rhs, y, scale);
    last_iterations_ = res.iterations;
    if (!res.converged) {
      double again = scaled(&y);
      if (again > scale) {
        res = solver_.solve(rhs, y, again);
        last_iterations_ += res.iterations;
      }
    }
    if (!res.converged) {
      char text[160];
      std::snprintf(text, sizeof text,
                    "(relative residual %.3g after %d GMRES iterations, tolerance %.3g).",
                    res.residual, last_iterations_, solver_.settings().tolerance);
      throw CollectiveError("Error, the fracture-pressure system of " + std::to_string(last_size_) +
                            " fracture points did not converge " + text);
    }
    x_.assign(n, 0.0);
    auto yv = y.getLocalViewHost(Tpetra::Access::ReadOnly);
    for (std::size_t k = 0; k < n; ++k)
      x_[k] = coupled_(net_[k].i, 1) + (held(net_[k].i) < 0 ? yv(k, 0) : 0.0);
  }

  // The new p_f and S_rf (onto the ghosts too), rates and contents, the exchange into `sink`,
  // the reservoirs' supply into the conditions' inflows.
  void scatter(double dt, const Scalars& sink) {
    auto& p = disc_.points;
    const std::size_t n = net_.size();
    const VanGenuchten vg = fluid_.retention;
    const RetentionEnergy energy(vg);
    for (std::size_t k = 0; k < n; ++k) {
      p.pf(net_[k].i) = x_[k];
      p.pf_saturation(net_[k].i) = vg.saturation(x_[k]);
    }
    disc_.dist.refresh({as_vectors(p.pf), as_vectors(p.pf_saturation)});
    const double inv_kw = 1.0 / fluid_.bulk_modulus;
    // This step's energy terms (header), then the reservoirs' supply per condition.
    std::vector<double> sums(5 + bcs_.size(), 0.0);
    double* de = sums.data();
    double* supplied = sums.data() + 5;
    for (std::size_t k = 0; k < n; ++k) {
      const Node& nd = net_[k];
      const LocalId i = nd.i;
      double flow = 0;
      for (std::size_t e = adj_first_[k]; e < adj_first_[k + 1]; ++e)
        flow += lambda_[e] * (p.pf(adj_[e]) - x_[k]);
      const double v = p.volume(i), pold = nd.pold;
      const double pm = 0.5 * (pold + x_[k]);
      const double exch = dt * v * gexch_[k] * (nd.phat - x_[k]);
      double gain = dt * (flow + source_[k]) + exch;
      de[0] +=
          v * phi_f_[k] * (energy.density(1.0, inv_kw, x_[k]) - energy.density(1.0, inv_kw, pold));
      if (!implicit_)  // implicit: implicit_opening, with the opening the step reached
        de[1] += pm * v * opening_[k];
      de[2] -= pm * dt * flow;
      de[3] += pm * dt * source_[k];
      de[4] += pm * exch;
      const int h = held(i);
      if (h >= 0) {
        const double stored = v * (storage_[k] * (x_[k] - pold) + opening_[k]);
        supplied[h] += stored - gain;
        de[3] += pm * (stored - gain);
        gain = stored;
      }
      p.pf_rate(i) = (x_[k] - pold) / dt;
      p.pf_content(i) += gain / v;
      if (!implicit_)
        p.pf_aperture(i) = nd.open;
      p.pf_area(i) = v / (rows_[k] * disc_.grid.dx);  // A_i (kernels header)
      // The undrained modulus M_f = S_rf/(C_f n_i dx) of the solid's p_f* (kernels header):
      // 0 on a point of prescribed p_f, and in the semi-implicit scheme (p_f implicit).
      p.pf_modulus(i) = h >= 0 || implicit_
                            ? 0.0
                            : vg.saturation(pold) / (storage_[k] * rows_[k] * disc_.grid.dx);
      sink(i) = exch / (dt * v);
    }
    MPI_Allreduce(MPI_IN_PLACE, sums.data(), int(sums.size()), MPI_DOUBLE, MPI_SUM, comm_);
    energy_.stored += de[0];
    energy_.skeleton_work += de[1];
    energy_.dissipation += de[2];
    energy_.external_work += de[3];
    energy_.exchange_work += de[4];
    for (std::size_t c = 0; c < bcs_.size(); ++c)
      inflow_[c] += fluid_.water_density * supplied[c];
  }

  Discretization<Dim>& disc_;
  FluidParams fluid_;
  FractureParams prm_;
  MPI_Comm comm_;
  LinearSolve solver_;
  std::vector<BoundaryCondition> bcs_;
  std::vector<double> inflow_;
  Vectors shared_;   // [points][3]: on the network, held condition + 1, p_f^n (collect)
  Vectors coupled_;  // [points][2]: conductance kappa, start value x0 (assemble)
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

}  // namespace mupm

#endif
