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
// phi S_r / K_w the storage, which may be zero: incompressible water).
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
// pressure's impulse at first order (the projection work below is negative). This is the
// argument, not a proof for the nonlocal operators; measured: stable at 0.5 of the drained
// estimate in every test (tests/solvers/test_fluid_solver.cpp, FluidSolverSemiImplicit and
// FluidSolverLong.TerzaghiSemiImplicit*, tests/cli/semi_implicit.sh). Without the pressure
// stabilization below, mirrored pressure layers with stiff or incompressible water were
// unstable at any step tried (0.1 to 0.5 of it); with it they run (Terzaghi within 1 %), but a
// Fluid Flux layer (an even image) with incompressible water still diverges, which the input
// refuses (src/input/input.cpp, check_pressure_integration).
//
// What it conserves. Water: each free point's balance holds to the linear solve's tolerance;
// the bookkeeping (FluidSolver::finish_projection) adds C dp + S_r d(tr eps) to the water
// content with the skeleton's actual volume change and the linearized flow div(p_n) + H dp,
// whose volume integral is zero (H 1 = 0), so the CSV's water mass error is the accumulated
// residual of the solves. Energy: the step is velocity Verlet with the start-of-step force
// F_n + 2 B~^T dp (v* + dt a_dp = v_n + dt/2 M^-1 (F_n + 2 B~^T dp)), so the solid's ledger
// books, besides the trapezoid of the pore water's force (p_n + p_{n+1})/2 over the step,
// the correction's work (B~^T dp) . (u_{n+1} - u_n) on the free components: the projection
// work, negative where the pressure resists the volume change (what the projection
// dissipates, reported as projection_work). The fluid's balance books the same trapezoid as
// its coupling work.
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
//   alpha_p,i = G_p S_r,i^2 dt / (rho_i k2 w0_i)   (eq 76's with lambda -> G_p S_r^2 dt / rho),
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
// The matrix and its preconditioner are kept while the bonds, the time step, the saturation,
// the relative permeability and the densities are unchanged (a saturated run without breakage
// assembles once).
#ifndef MUPM_SOLVERS_PRESSURE_PROJECTION_HPP
#define MUPM_SOLVERS_PRESSURE_PROJECTION_HPP

#include <mpi.h>

#include <cmath>
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
        solver_(settings),
        roles_(std::move(roles)),
        images_(std::move(images)),
        comm_(comm) {
    dofs_ = component_map(disc, NC, false);
  }

  // The bonds changed: assemble again before the next solve.
  void invalidate() { stale_ = true; }
  long long assemblies() const { return assemblies_; }

  struct Result {
    int iterations = 0;
    double residual = 0;
    bool converged = false;
    double work = 0;  // the correction's work on the skeleton [J], all ranks
  };

  // Step 2-3 of the header: dp [n_owned] from the water balance, with `target` the new
  // values of the held and image points (images from their mirrors' p_n), `source` s [1/s],
  // the fluid's state (C, flow) at p_n; corrects u, v, theta, omega of the free components.
  // `scale`: the largest right-hand side so far (LinearSolve::solve; a restart global).
  Result step(double dt, const FluidParams& prm, const FluidState<Dim>& st, const Scalars& source,
              const Scalars& target, const SkeletonState& sk, const Scalars& dp, double& scale) {
    ScopedRegion region("mupm::Pressure::projection");
    auto& p = disc_.points;
    const std::size_t n = p.n_owned;
    if (needs_assembly(dt, st, sk))
      assemble(dt, prm, st, sk);
    const auto& owned = disc_.dist.owned_map();
    TpetraVector du(dofs_), b(owned), c(owned), ac(owned), x(owned), y(owned);
    {
      auto v = du.getLocalViewHost(Tpetra::Access::OverwriteAll);
      for (std::size_t i = 0; i < n; ++i) {
        for (int d = 0; d < Dim; ++d)
          v(i * NC + d, 0) = p.u(i, d) - sk.start(i, d);
        for (int r = 0; r < R; ++r)
          v(i * NC + Dim + r, 0) = p.theta(i, r) - sk.start(i, Dim + r);
      }
    }
    coupling_->apply(du, b);
    {
      auto cv = c.getLocalViewHost(Tpetra::Access::OverwriteAll);
      for (std::size_t i = 0; i < n; ++i)
        cv(i, 0) = roles_[i] == PressureRole::Free ? 0.0 : target(i) - p.p(i);
    }
    full_->apply(c, ac);
    {
      auto bv = b.getLocalViewHost(Tpetra::Access::ReadWrite);
      auto av = ac.getLocalViewHost(Tpetra::Access::ReadOnly);
      for (std::size_t i = 0; i < n; ++i)
        bv(i, 0) =
            solved_[i] ? -bv(i, 0) + dt * p.volume(i) * (source(i) - st.flow(i)) - av(i, 0) : 0.0;
    }
    // The previous step's increment (p_rate dt, checkpointed: a restart starts the same
    // iteration) starts the iteration: the increments change smoothly.
    {
      auto xv = x.getLocalViewHost(Tpetra::Access::OverwriteAll);
      for (std::size_t i = 0; i < n; ++i)
        xv(i, 0) = solved_[i] ? p.p_rate(i) * dt : 0.0;
    }
    Result r;
    const auto res = solver_.solve(b, x, scale);
    r.iterations = res.iterations;
    r.residual = res.residual;
    r.converged = res.converged;
    images_matrix_->apply(x, y);  // dp = S_H x + c
    y.update(1.0, c, 1.0);
    TpetraVector yp(owned), f(dofs_);  // the skeleton's correction: S_P x + c
    free_matrix_->apply(x, yp);
    yp.update(1.0, c, 1.0);
    coupling_->apply(yp, f, Teuchos::TRANS);
    double work = 0;
    {
      auto yv = y.getLocalViewHost(Tpetra::Access::ReadOnly);
      auto fv = f.getLocalViewHost(Tpetra::Access::ReadOnly);
      auto mv = inverse_mass_->getLocalViewHost(Tpetra::Access::ReadOnly);
      for (std::size_t i = 0; i < n; ++i) {
        dp(i) = yv(i, 0);
        for (int k = 0; k < NC; ++k) {
          const std::size_t q = i * NC + std::size_t(k);
          const double a = mv(q, 0) * fv(q, 0);
          if (a == 0)
            continue;
          double& pos = k < Dim ? p.u(i, k) : p.theta(i, k - Dim);
          double& vel = k < Dim ? p.v(i, k) : p.omega(i, k - Dim);
          pos += dt * dt * a;
          vel += dt * a;
          work += fv(q, 0) * (pos - sk.start(i, k));
        }
      }
    }
    MPI_Allreduce(MPI_IN_PLACE, &work, 1, MPI_DOUBLE, MPI_SUM, comm_);
    r.work = work;
    return r;
  }

  // V H dp [n_owned] with the flow operator of the last assembly (the flow's linearized
  // increment, for the water bookkeeping).
  void flow_increment(const Scalars& dp, const Scalars& out) const {
    const auto& owned = disc_.dist.owned_map();
    TpetraVector x(owned), y(owned);
    {
      auto v = x.getLocalViewHost(Tpetra::Access::OverwriteAll);
      for (std::size_t i = 0; i < disc_.points.n_owned; ++i)
        v(i, 0) = dp(i);
    }
    flow_->apply(x, y);
    auto v = y.getLocalViewHost(Tpetra::Access::ReadOnly);
    for (std::size_t i = 0; i < disc_.points.n_owned; ++i)
      out(i) = v(i, 0);
  }

 private:
  // The state the matrix depends on, besides the bonds (invalidate): dt, S_r, k_r, C, rho, J.
  static constexpr std::size_t kSeen = 5;
  bool needs_assembly(double dt, const FluidState<Dim>& st, const SkeletonState& sk) {
    const auto& p = disc_.points;
    const std::size_t n = p.n_owned;
    int changed = stale_ || dt != dt_ ? 1 : 0;
    for (std::size_t i = 0; i < n && !changed; ++i)
      changed = seen_[kSeen * i] != p.saturation(i) || seen_[kSeen * i + 1] != p.rel_perm(i) ||
                seen_[kSeen * i + 2] != sk.density(i) || seen_[kSeen * i + 3] != sk.inertia(i) ||
                seen_[kSeen * i + 4] != st.storage(i);
    MPI_Allreduce(MPI_IN_PLACE, &changed, 1, MPI_INT, MPI_MAX, comm_);
    return changed != 0;
  }

  void assemble(double dt, const FluidParams& prm, const FluidState<Dim>& st,
                const SkeletonState& sk) {
    ScopedRegion region("mupm::Pressure::assemble");
    auto& p = disc_.points;
    const std::size_t n = p.n_owned;
    const auto& owned = disc_.dist.owned_map();
    seen_.resize(kSeen * n);
    for (std::size_t i = 0; i < n; ++i) {
      seen_[kSeen * i] = p.saturation(i);
      seen_[kSeen * i + 1] = p.rel_perm(i);
      seen_[kSeen * i + 2] = sk.density(i);
      seen_[kSeen * i + 3] = sk.inertia(i);
      seen_[kSeen * i + 4] = st.storage(i);
    }
    // The flow operator with the pressure stabilization added to the flow's (header).
    Scalars alpha("mupm::projection_alpha", p.size());
    Kokkos::deep_copy(alpha, st.alpha);
    add_pressure_stabilization(disc_, prm, dt, sk.density, alpha);
    flow_ = assemble_flow_operator(disc_, prm, alpha);
    coupling_ = assemble_volume_coupling(disc_);
    inverse_mass_ = Teuchos::rcp(new TpetraVector(dofs_));
    TpetraVector storage(owned);
    {
      auto m = inverse_mass_->getLocalViewHost(Tpetra::Access::OverwriteAll);
      auto sv = storage.getLocalViewHost(Tpetra::Access::OverwriteAll);
      for (std::size_t i = 0; i < n; ++i) {
        const std::uint32_t fx = p.fixed(i);
        for (int k = 0; k < NC; ++k) {
          const double mass = p.volume(i) * (k < Dim ? sk.density(i) : sk.inertia(i));
          m(i * NC + k, 0) = (fx & (1u << k)) || !(mass > 0) ? 0.0 : 1.0 / mass;
        }
        sv(i, 0) = p.volume(i) * st.storage(i);
      }
    }
    const auto projection = projection_operator(*coupling_, *inverse_mass_);
    const auto rest = Tpetra::MatrixMatrix::add(dt * dt, false, *projection, 1.0, false,
                                                *diagonal_matrix(storage));
    full_ = Tpetra::MatrixMatrix::add(dt, false, *flow_, 1.0, false, *rest);
    // The pressure increment is S x + c (x the solve's unknowns, c the held and lagged image
    // increments). S_H: the images follow their mirrors' increments (odd or even), for the flow;
    // S_P: they do not, for the skeleton's response within the step. An image's pressure reaches
    // the skeleton in the next step's forces, as a held pressure does (measured: with the
    // images' increments in the projection too (before the pressure stabilization), Terzaghi's
    // mirrored column with incompressible or stiff water (K_w / phi = 100 M) and slow consolidation
    // grew without bound: the image's force on the layer's skeleton, -p(mirror), answers the body's
    // compression within the same solve, a coupling no water balance books). The system is
    // R (dt V H S_H + (dt^2 P + V C) S_P) + D_c: R keeps the free rows, D_c puts the mean free
    // diagonal on the others.
    std::vector<std::vector<std::pair<LocalId, double>>> rows(n), free_rows(n);
    TpetraVector keep(owned), diag(owned), other(owned);
    full_->getLocalDiagCopy(diag);
    // A free point whose row is empty (it lost all its bonds, and its water has no storage:
    // incompressible) keeps its pressure: dp = 0, a row of the mean diagonal.
    double sum[2] = {0, 0};
    solved_.assign(n, 0);
    {
      auto kv = keep.getLocalViewHost(Tpetra::Access::OverwriteAll);
      auto dv = diag.getLocalViewHost(Tpetra::Access::ReadOnly);
      for (std::size_t i = 0; i < n; ++i) {
        const bool free = roles_[i] == PressureRole::Free && dv(i, 0) > 0;
        solved_[i] = free ? 1 : 0;
        kv(i, 0) = free ? 1.0 : 0.0;
        if (free) {
          rows[i].push_back({LocalId(i), 1.0});
          free_rows[i].push_back({LocalId(i), 1.0});
          sum[0] += dv(i, 0);
          sum[1] += 1;
        } else if (roles_[i] == PressureRole::OddImage || roles_[i] == PressureRole::EvenImage) {
          rows[i].push_back({images_[i], roles_[i] == PressureRole::OddImage ? -1.0 : 1.0});
        }
      }
    }
    MPI_Allreduce(MPI_IN_PLACE, sum, 2, MPI_DOUBLE, MPI_SUM, comm_);
    const double mean = sum[1] > 0 && sum[0] > 0 ? sum[0] / sum[1] : 1.0;
    {
      auto ov = other.getLocalViewHost(Tpetra::Access::OverwriteAll);
      for (std::size_t i = 0; i < n; ++i)
        ov(i, 0) = solved_[i] ? 0.0 : mean;
    }
    images_matrix_ = detail::from_rows(owned, disc_.dist.overlap_map(), owned, owned, rows);
    free_matrix_ = detail::from_rows(owned, owned, owned, owned, free_rows);
    auto flow_s = Teuchos::rcp(new CrsMatrix(owned, 0)),
         rest_s = Teuchos::rcp(new CrsMatrix(owned, 0));
    Tpetra::MatrixMatrix::Multiply(*flow_, false, *images_matrix_, false, *flow_s);
    Tpetra::MatrixMatrix::Multiply(*rest, false, *free_matrix_, false, *rest_s);
    auto ras = Tpetra::MatrixMatrix::add(dt, false, *flow_s, 1.0, false, *rest_s);
    ras->leftScale(keep);
    system_ = Tpetra::MatrixMatrix::add(1.0, false, *ras, 1.0, false, *diagonal_matrix(other));
    solver_.set_matrix(system_);
    dt_ = dt;
    stale_ = false;
    ++assemblies_;
  }

  Discretization<Dim>& disc_;
  LinearSolve solver_;
  std::vector<PressureRole> roles_;
  std::vector<LocalId> images_;
  std::vector<char> solved_;  // the free rows the last assembly kept
  MPI_Comm comm_;
  Teuchos::RCP<const Map> dofs_;
  Teuchos::RCP<CrsMatrix> flow_, coupling_, full_, images_matrix_, free_matrix_, system_;
  Teuchos::RCP<TpetraVector> inverse_mass_;
  std::vector<double> seen_;
  double dt_ = 0;
  bool stale_ = true;
  long long assemblies_ = 0;
};

}  // namespace mupm

#endif
