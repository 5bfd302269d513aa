// FluidSolver's explicit substep (include/mupm/solvers/fluid_solver.hpp): sources, the pressure
// update and its bookkeeping.
#include "mupm/solvers/fluid_solver.hpp"

#include "mupm/solvers/fracture_flow.hpp"
#include "mupm/solvers/pressure_projection.hpp"

namespace mupm {

template <int Dim>
void FluidSolver<Dim>::sources(double t, double dt) {
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

template <int Dim>
void FluidSolver<Dim>::substep(double t, double dt, double dt_total) {
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
          phat(i) = (fixed(i) & kFixedPressure) ? target(i) : pw(i) + (C(i) > 0 ? rhs / C(i) : 0.0);
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

template <int Dim>
void FluidSolver<Dim>::book(const Scalars& supply, const double w[3]) {
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

#define MUPM_FLUID_SUBSTEP(D)                                    \
  template void FluidSolver<D>::sources(double, double);         \
  template void FluidSolver<D>::substep(double, double, double); \
  template void FluidSolver<D>::book(const Scalars&, const double[3]);
MUPM_FLUID_SUBSTEP(2)
MUPM_FLUID_SUBSTEP(3)

}  // namespace mupm
