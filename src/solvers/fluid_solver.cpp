#include "mupm/solvers/fluid_solver.hpp"

#include "mupm/solvers/fracture_flow.hpp"
#include "mupm/solvers/power_iteration.hpp"
#include "mupm/solvers/pressure_projection.hpp"

namespace mupm {

template <int Dim>
FluidSolver<Dim>::FluidSolver(Discretization<Dim>& disc, const FluidParams& prm,
                              std::vector<BoundaryCondition> bcs, MPI_Comm comm)
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
  p.require(kGroupPoreWater, "FluidSolver");
  st_.allocate(p.size(), p.n_owned);
  source_ = Scalars("mupm::fluid_source", p.n_owned);
  supply_ = Scalars("mupm::fluid_supply", p.n_owned);
  inflow_.assign(bcs_.size(), 0.0);
  region_volume_.assign(bcs_.size(), 0.0);
}

template <int Dim>
void FluidSolver<Dim>::enable_fracture_flow(const FractureParams& prm) {
  disc_.points.require(kGroupCrackWater, "FractureFlow");
  fracture_ = std::make_unique<FractureFlow<Dim>>(disc_, prm_, prm, all_bcs_, comm_);
  if (semi_implicit_)
    fracture_->set_implicit();
  phat_ = Scalars("mupm::bulk_predictor", disc_.points.n_owned);
  sink_ = Scalars("mupm::fracture_exchange", disc_.points.n_owned);
}

template <int Dim>
auto FluidSolver<Dim>::energy() const -> Energy {
  Energy e = energy_;
  e.stored = stored_energy();
  return e;
}

template <int Dim>
void FluidSolver<Dim>::globals(GlobalRefs& g) {
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
    g("fracture_joined", fracture_->joined());
  }
}

template <int Dim>
void FluidSolver<Dim>::series(SeriesRow& row) const {
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
    row("fracture_fluid_joined", fracture_->joined());
    supplied += fracture_->joined();
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

template <int Dim>
std::vector<EnergyBalance> FluidSolver<Dim>::energy_balances() const {
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
  f.supplied = std::abs(fe.external_work) + std::abs(fe.exchange_work) + std::abs(fe.skeleton_work);
  f.external_expression = "W_ext,f + W_x";
  f.external = fe.external_work + fe.exchange_work;
  f.gross = std::abs(fe.external_work) + std::abs(fe.exchange_work);
  f.field = "fracture_pressure";
  return {b, f};
}

template <int Dim>
void FluidSolver<Dim>::initialize(double t, bool restarted) {
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

template <int Dim>
void FluidSolver<Dim>::bonds_changed() {
  evaluate();
  if (projection_)
    projection_->invalidate();
}

template <int Dim>
void FluidSolver<Dim>::reset_strain_reference() {
  auto& p = disc_.points;
  Kokkos::deep_copy(Kokkos::subview(p.vol_strain_ref, std::make_pair(std::size_t(0), p.n_owned)),
                    Kokkos::subview(p.vol_strain, std::make_pair(std::size_t(0), p.n_owned)));
}

template <int Dim>
void FluidSolver<Dim>::advance(double t, double dt_total, int substeps) {
  ScopedRegion region("mupm::Fluid::advance");
  const double dt = dt_total / substeps;
  for (int k = 0; k < substeps; ++k)
    substep(t + k * dt, dt, dt_total);
  reset_strain_reference();
}

template <int Dim>
double FluidSolver<Dim>::stored_energy() const {
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

template <int Dim>
double FluidSolver<Dim>::min_storage() const {
  auto C = st_.storage;
  double m = 0;
  Kokkos::parallel_reduce(
      "mupm::Fluid::min_storage", range(0, disc_.points.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, double& acc) { acc = C(i) < acc ? C(i) : acc; },
      Kokkos::Min<double>(m));
  MPI_Allreduce(MPI_IN_PLACE, &m, 1, MPI_DOUBLE, MPI_MIN, comm_);
  return m;
}

template <int Dim>
double FluidSolver<Dim>::undrained_stiffening() const {
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

template <int Dim>
double FluidSolver<Dim>::estimate_stable_dt(int iterations) {
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

template <int Dim>
void FluidSolver<Dim>::evaluate() {
  auto& p = disc_.points;
  fluid_constitutive(p, prm_, st_);
  disc_.dist.refresh({as_vectors(p.p)});
  mirror_rel_perm();
  fluid_flow(disc_, prm_, st_, p.p);
}

template <int Dim>
void FluidSolver<Dim>::mirror_rel_perm() {
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

template <int Dim>
void FluidSolver<Dim>::set_pressure(double t, const Scalars& target, bool mirror) {
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

template <int Dim>
void FluidSolver<Dim>::mirror_pressure(const Scalars& x) {
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

template <int Dim>
void FluidSolver<Dim>::mark_mirrored() {
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

template <int Dim>
FluidSolver<Dim>::~FluidSolver() = default;

template class FluidSolver<2>;
template class FluidSolver<3>;

}  // namespace mupm
