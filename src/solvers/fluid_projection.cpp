// FluidSolver's semi-implicit pressure (include/mupm/solvers/fluid_solver.hpp, eqs in
// include/mupm/solvers/pressure_projection.hpp): set-up, the projection and its bookkeeping.
#include "mupm/solvers/fluid_solver.hpp"

#include "mupm/solvers/fracture_flow.hpp"
#include "mupm/solvers/pressure_projection.hpp"

namespace mupm {

template <int Dim>
void FluidSolver<Dim>::enable_semi_implicit(const LinearSolveSettings& settings) {
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

template <int Dim>
void FluidSolver<Dim>::project(double t, double dt, Skeleton& skeleton) {
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

template <int Dim>
void FluidSolver<Dim>::finish_projection(double dt) {
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

template <int Dim>
Scalars FluidSolver<Dim>::lagged_plastic_source(double dt, const Scalars& shift) {
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

template <int Dim>
void FluidSolver<Dim>::make_projection() {
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

template <int Dim>
void FluidSolver<Dim>::checkpointed() {
  if (projection_)
    projection_->renew_preconditioner();
}

template <int Dim>
std::string FluidSolver<Dim>::pressure_solve_method() const {
  return projection_ ? projection_->method() : std::string();
}

#define MUPM_FLUID_PROJECTION(D)                                                  \
  template void FluidSolver<D>::enable_semi_implicit(const LinearSolveSettings&); \
  template void FluidSolver<D>::project(double, double, Skeleton&);               \
  template void FluidSolver<D>::finish_projection(double);                        \
  template Scalars FluidSolver<D>::lagged_plastic_source(double, const Scalars&); \
  template void FluidSolver<D>::make_projection();                                \
  template void FluidSolver<D>::checkpointed();                                   \
  template std::string FluidSolver<D>::pressure_solve_method() const;
MUPM_FLUID_PROJECTION(2)
MUPM_FLUID_PROJECTION(3)

}  // namespace mupm
