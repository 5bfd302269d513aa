#include "mupm/solvers/solid_boundary.hpp"

#include <stdexcept>

#include "mupm/core/timers.hpp"
#include "mupm/solvers/solid_forces.hpp"

namespace mupm {

template <int Dim>
SolidBoundary<Dim>::SolidBoundary(Discretization<Dim>& disc, std::vector<BoundaryCondition> bcs,
                                  MPI_Comm comm)
    : disc_(disc), bcs_(std::move(bcs)), comm_(comm) {
  int blocks = 0;  // faces with slaved layers, in the order of the conditions (every rank's)
  for (int f = 0; f < 6; ++f)
    slots_[f] = -1;
  for (auto& bc : bcs_)
    if (bc.kinematic() && bc.mirrored) {
      bc.mirror_column = face_column(disc.grid, bc.region_mask);
      (bc.slaved ? slaved_ : mirrored_) = true;
      const int face = face_index(disc.grid, bc.region_mask);
      if (bc.slaved && slots_[face] < 0)
        slots_[face] = blocks++;
    }
  slaved_disp_.assign(bcs_.size(), 0.0);
  twice_dg_.assign(bcs_.size(), 0.0);
  if (slaved_)
    fold_ = Vectors("mupm::layer_fold", disc.points.size(), std::size_t(blocks * (Dim + R)));
}

template <int Dim>
void SolidBoundary<Dim>::mark() const {
  mark_fixed(bcs_, disc_.points);
  if (layers())
    mark_mirrored_layers(bcs_, disc_.points, disc_.mirror);
}

template <int Dim>
void SolidBoundary<Dim>::mirror_layers(double t) const {
  if (!layers())
    return;
  auto& p = disc_.points;
  disc_.dist.refresh({p.u, p.theta, p.v});
  for (std::size_t k = 0; k < bcs_.size(); ++k) {
    const auto& bc = bcs_[k];
    if (!(bc.kinematic() && bc.mirrored))
      continue;
    if (!bc.slaved)
      mirror_kinematic(bc, p, disc_.mirror, t);
    else if (slaved_velocity(bc))
      slave_layer(bc, p, disc_.mirror, slaved_disp_[k], bc.value * bc.time(t));
    else
      slave_layer(bc, p, disc_.mirror, bc.value * bc.time(t), bc.value * bc.time.rate(t));
  }
}

template <int Dim>
void SolidBoundary<Dim>::advance_slaved(double t, double dt) {
  if (!slaved_)
    return;
  for (std::size_t k = 0; k < bcs_.size(); ++k) {
    const auto& bc = bcs_[k];
    if (slaved_velocity(bc)) {  // the displacement of apply_kinematic's midpoint rule
      const double before = slaved_disp_[k];
      slaved_disp_[k] += dt * bc.value * bc.time(t + 0.5 * dt);
      twice_dg_[k] = 2 * (slaved_disp_[k] - before);
    } else if (bc.kinematic() && bc.slaved) {
      twice_dg_[k] = 2 * bc.value * (bc.time(t + dt) - bc.time(t));
    }
  }
}

template <int Dim>
void SolidBoundary<Dim>::slaved_increments(const Vectors& du) const {
  if (!slaved_)
    return;
  for (std::size_t k = 0; k < bcs_.size(); ++k)
    if (bcs_[k].kinematic() && bcs_[k].slaved)
      slaved_increment(bcs_[k], disc_.points, du, twice_dg_[k]);
}

template <int Dim>
void SolidBoundary<Dim>::slave_linear(const Points<Dim>& pts) const {
  if (!slaved_)
    return;
  for (const auto& bc : bcs_)
    if (bc.kinematic() && bc.slaved)
      slave_layer(bc, pts, disc_.mirror, 0.0, 0.0, false);
  disc_.dist.refresh({pts.u, pts.theta});
}

template <int Dim>
void SolidBoundary<Dim>::fold(const Vectors& force, const Vectors& moment) const {
  if (!slaved_)
    return;
  ScopedRegion region("mupm::Solid::fold_layers");
  fold_layer_forces(disc_, slots_, force, moment, fold_);
}

// The slaved layers' marks first: their points carry no stress and their forces fold, as in
// the run. Built at construction, not at the start, so that a restart, whose checkpoint breaks
// bonds in between, builds it from the same bonds.
template <int Dim>
void SolidBoundary<Dim>::build_consistent_tractions(const SolidParams& prm) {
  auto& p = disc_.points;
  const auto& g = disc_.grid;
  SolidState<Dim> tmp;
  for (auto& bc : bcs_) {
    if (!bc.consistent)
      continue;
    if (bc.face < 0 || bc.face >= 2 * Dim || bc.region_mask == 0 ||
        (bc.region_mask & (bc.region_mask - 1)) != 0)
      throw std::logic_error("SolidSolver: consistent traction '" + bc.name +
                             "' needs its face and one region (input/model.cpp)");
    if (tmp.force.extent(0) == 0) {
      tmp.allocate(p.size(), p.n_owned);
      mark();
    }
    uniform_stress_forces(disc_, prm, unit_traction_stress(Dim, bc.face, bc.component), tmp);
    if (slaved_)
      fold_layer_forces(disc_, slots_, tmp.force, tmp.moment, fold_);
    int r = 0;
    while (!(bc.region_mask & (1u << r)))
      ++r;
    const Box& box = g.regions[std::size_t(r)];
    const int axis = bc.face / 2;
    Kokkos::Array<double, 3> lo{}, hi{};
    for (int d = 0; d < Dim; ++d) {
      lo[d] = box.lo[d];
      hi[d] = box.hi[d];
    }
    const double plane = g.origin[axis] + (bc.face % 2 ? g.counts[axis] * g.dx : 0.0);
    bc.unit_load = Vectors("mupm::traction_load", p.n_owned, Dim + R);
    consistent_traction_load(p, bc.face, bc.component, 2 * g.horizon + g.dx, lo, hi, plane,
                             tmp.force, tmp.moment, bc.unit_load);
  }
}

template <int Dim>
std::vector<std::string> SolidBoundary<Dim>::reaction_names() const {
  std::vector<std::string> n;
  for (const auto& bc : bcs_)
    if (bc.kinematic())
      n.push_back("reaction_" + bc.name);
  return n;
}

template <int Dim>
std::vector<double> SolidBoundary<Dim>::reactions(const Vectors& force,
                                                  const Vectors& moment) const {
  std::vector<double> out;
  const auto& p = disc_.points;
  for (const auto& bc : bcs_) {
    if (!bc.kinematic())
      continue;
    const bool rot = bc.kind == BoundaryCondition::MicroRotation;
    const Vectors f = rot ? moment : force;
    const int c = bc.component;
    const std::uint32_t mask = bc.region_mask;
    auto regions = p.regions;
    auto vol = p.volume;
    auto fixed = p.fixed;
    double s = 0;
    Kokkos::parallel_reduce(
        "mupm::Solid::reaction", range(0, p.n_owned),
        KOKKOS_LAMBDA(const std::size_t i, double& acc) {
          if (mask == 0 || (regions(i) & mask))
            acc -= ((fixed(i) & kFixedNoEnergy) ? 2.0 : 1.0) * f(i, c) * vol(i);
        },
        s);
    MPI_Allreduce(MPI_IN_PLACE, &s, 1, MPI_DOUBLE, MPI_SUM, comm_);
    out.push_back(s);
  }
  return out;
}

template <int Dim>
void SolidBoundary<Dim>::globals(GlobalRefs& g) {
  for (std::size_t k = 0; k < bcs_.size(); ++k)
    if (slaved_velocity(bcs_[k]))
      g("slaved_displacement_" + bcs_[k].name, slaved_disp_[k]);
}

template class SolidBoundary<2>;
template class SolidBoundary<3>;

}  // namespace mupm
