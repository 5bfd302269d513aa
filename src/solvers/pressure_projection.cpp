#include "mupm/solvers/pressure_projection.hpp"

namespace mupm {

template <int Dim>
auto PressureProjection<Dim>::step(double dt, const FluidParams& prm, const FluidState<Dim>& st,
                                   const Scalars& source, const Scalars& target,
                                   const SkeletonState& sk, const Scalars& dp, double& scale,
                                   const CrackBlock& crack, std::vector<double>& dpf) -> Result {
  ScopedRegion region("mupm::Pressure::projection");
  auto& p = disc_.points;
  const std::size_t n = p.n_owned, m = crack.point.size();
  const bool refilled = needs_assembly(dt, st, sk, crack);
  if (refilled)
    assemble(dt, prm, st, sk, crack);
  if (any_crack_) {  // the network's rows change every step (apertures): new values
    bool graph = network_values(crack);
    // ns = R N S_H: without images S_H = diag(keep) (assemble), so ns is N scaled by keep on
    // both sides (exact: keep is 0 or 1), on N's graph; with images a product on a kept graph.
    if (!images_any_) {
      copy_values(ns_, *network_.matrix(), graph);
      ns_->rightScale(*keep_);
    } else {
      graph = graph || ns_graph_;
      ns_product_.update(graph, *network_.matrix(), *s_h_.matrix());
      ns_ = ns_product_.matrix();
    }
    // In place on ns_product_'s rows too: keep is 0 or 1, so a row it keeps comes out the same
    // scaled again, and a change of keep changes S_H's diagonal, which N's diagonal reaches,
    // so the row is formed again (KeptProduct).
    ns_->leftScale(*keep_);
    compose(*ns_, graph);
  } else if (system_ != composed_.matrix()) {
    system_ = composed_.matrix();
    solver_.set_matrix(system_);
  } else if (refilled || solver_.renewal_pending()) {
    // New values on the kept graph (or a checkpoint's renewal of the factors: a restart
    // computes them from these values).
    solver_.refresh();
  }
  const auto& owned = disc_.dist.owned_map();
  TpetraVector &du = work(kDu, dofs_), &bp = work(kBp, owned), &b = work(kB, joint_),
               &c = work(kC, joint_), &ac = work(kAc, joint_), &x = work(kX, joint_),
               &y = work(kY, joint_), &e = work(kE, joint_);
  {
    auto v = du.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t i = 0; i < n; ++i) {
      for (int d = 0; d < Dim; ++d)
        v(i * NC + d, 0) = p.u(i, d) - sk.start(i, d);
      for (int r = 0; r < R; ++r)
        v(i * NC + Dim + r, 0) = p.theta(i, r) - sk.start(i, Dim + r);
    }
  }
  coupling_.matrix()->apply(du, bp);  // B_0 du, then diag(S_r)
  bp.elementWiseMultiply(1.0, *saturation_, bp, 0.0);
  // Whether c (the held increments) and e (the unfelt p_f^n) have a nonzero anywhere: where
  // not, their products below are zero and skipped (most steps: held pressures that stay, no
  // point joining the network).
  int nonzero[2] = {0, 0};
  {
    auto cv = c.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t i = 0; i < n; ++i)
      nonzero[0] |= (cv(i, 0) = roles_[i] == PressureRole::Free ? 0.0 : target(i) - p.p(i)) != 0;
    for (std::size_t k = 0; k < m; ++k)
      nonzero[0] |= (cv(n + k, 0) = crack.held[k] ? crack.start[k] : 0.0) != 0;
    auto ev = e.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t i = 0; i < n; ++i)
      ev(i, 0) = 0.0;
    for (std::size_t k = 0; k < m; ++k)
      nonzero[1] |= (ev(n + k, 0) = crack.unfelt[k]) != 0;
  }
  MPI_Allreduce(MPI_IN_PLACE, nonzero, 2, MPI_INT, MPI_MAX, comm_);
  if (nonzero[0]) {
    static_.matrix()->apply(c, ac);  // A c = (static part + the network's rows) c
    if (any_crack_)
      network_.matrix()->apply(c, ac, Teuchos::NO_TRANS, 1.0, 1.0);
  } else {
    ac.putScalar(0.0);
  }
  if (nonzero[1]) {
    // ... and the volume change the unfelt p_f^n gives the skeleton within the step (the
    // correction applies it): dt^2 B M^-1 B^T e.
    TpetraVector &fe = work(kFe, dofs_), &be = work(kBe, joint_);
    coupling_s_->apply(e, fe, Teuchos::TRANS);
    fe.elementWiseMultiply(1.0, *inverse_mass_, fe, 0.0);
    coupling_s_->apply(fe, be);
    ac.update(dt * dt, be, 1.0);
  }
  {
    auto bv = b.getLocalViewHost(Tpetra::Access::OverwriteAll);
    auto pv = bp.getLocalViewHost(Tpetra::Access::ReadOnly);
    auto av = ac.getLocalViewHost(Tpetra::Access::ReadOnly);
    for (std::size_t i = 0; i < n; ++i)
      bv(i, 0) =
          solved_[i] ? -pv(i, 0) + dt * p.volume(i) * (source(i) - st.flow(i)) - av(i, 0) : 0.0;
    for (std::size_t k = 0; k < m; ++k) {
      const LocalId i = crack.point[k];  // the exchange at p^n, p_f^n
      if (solved_[std::size_t(i)])
        bv(i, 0) -= crack.exchange[k] * (p.p(i) - crack.pf0[k]);
      bv(n + k, 0) = solved_[n + k] ? crack.rhs[k] - av(n + k, 0) : 0.0;
    }
  }
  // The previous step's increment (p_rate dt, checkpointed: a restart starts the same
  // iteration) starts the iteration: the increments change smoothly.
  {
    auto xv = x.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t i = 0; i < n; ++i)
      xv(i, 0) = solved_[i] ? p.p_rate(i) * dt : 0.0;
    for (std::size_t k = 0; k < m; ++k)
      xv(n + k, 0) = solved_[n + k] ? crack.start[k] : 0.0;
  }
  Result r;
  const auto res = solver_.solve(b, x, scale);
  r.iterations = res.iterations;
  r.residual = res.residual;
  r.converged = res.converged;
  r.finite_rhs = res.finite_rhs;
  s_h_.matrix()->apply(x, y);  // the increments: S_H x + c
  y.update(1.0, c, 1.0);
  TpetraVector &yp = work(kYp, joint_), &f = work(kF, dofs_);  // the skeleton's correction:
                                                               // S_P x + c
  s_p_.matrix()->apply(x, yp);
  yp.update(1.0, c, 1.0, e, 1.0);
  coupling_s_->apply(yp, f, Teuchos::TRANS);
  double correction_work = 0;
  {
    auto yv = y.getLocalViewHost(Tpetra::Access::ReadOnly);
    auto fv = f.getLocalViewHost(Tpetra::Access::ReadOnly);
    auto mv = inverse_mass_->getLocalViewHost(Tpetra::Access::ReadOnly);
    dpf.assign(m, 0.0);
    for (std::size_t k = 0; k < m; ++k)
      dpf[k] = yv(n + k, 0);
    for (std::size_t i = 0; i < n; ++i) {
      dp(i) = yv(i, 0);
      for (int k = 0; k < NC; ++k) {
        const std::size_t q = i * NC + std::size_t(k);
        const double a = mv(q, 0) * fv(q, 0);
        if (a == 0)
          continue;
        double& pos = k < Dim ? p.u(i, k) : p.theta(i, k - Dim);
        double& vel = k < Dim ? p.v(i, k) : p.omega(i, k - Dim);
        // u_n - u_(n-1) = dt v_(n-1/2) = dt (v* - dt a_n) (header: the projection work)
        const double acc = k < Dim ? p.a(i, k) : p.alpha(i, k - Dim);
        const double before = dt * (vel - dt * acc);
        pos += dt * dt * a;
        vel += dt * a;
        correction_work += 0.5 * fv(q, 0) * (pos - sk.start(i, k) + before);
      }
    }
  }
  MPI_Allreduce(MPI_IN_PLACE, &correction_work, 1, MPI_DOUBLE, MPI_SUM, comm_);
  r.work = correction_work;
  return r;
}

template <int Dim>
void PressureProjection<Dim>::flow_increment(const Scalars& dp, const Scalars& out) const {
  const auto& owned = disc_.dist.owned_map();
  TpetraVector &x = work(kFlowX, owned), &y = work(kFlowY, owned);
  {
    auto v = x.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t i = 0; i < disc_.points.n_owned; ++i)
      v(i, 0) = dp(i);
  }
  flow_.matrix()->apply(x, y);
  auto v = y.getLocalViewHost(Tpetra::Access::ReadOnly);
  for (std::size_t i = 0; i < disc_.points.n_owned; ++i)
    out(i) = v(i, 0);
}

template <int Dim>
bool PressureProjection<Dim>::needs_assembly(double dt, const FluidState<Dim>& st,
                                             const SkeletonState& sk, const CrackBlock& crack) {
  const auto& p = disc_.points;
  const std::size_t n = p.n_owned;
  int flags[4] = {stale_ || dt != dt_ ? 1 : 0, crack.point.empty() ? 0 : 1, 0, 0};
  int& changed = flags[0];
  int& structure = flags[2];
  int& geometry = flags[3];  // the bonds or B_f changed: B_0, Gr and their transposes
  structure = composed_.matrix().is_null() || crack.point != crack_points_ ||
              crack.held != crack_held_ || !same_columns(crack.coupling, crack_coupling_);
  geometry = structure || stale_ || crack.coupling != crack_coupling_;
  changed = changed || geometry;
  for (std::size_t i = 0; i < n && !changed; ++i)
    changed = seen_[kSeen * i] != p.saturation(i) || seen_[kSeen * i + 1] != p.rel_perm(i) ||
              seen_[kSeen * i + 2] != sk.density(i) || seen_[kSeen * i + 3] != sk.inertia(i) ||
              seen_[kSeen * i + 4] != st.storage(i);
  MPI_Allreduce(MPI_IN_PLACE, flags, 4, MPI_INT, MPI_MAX, comm_);
  any_crack_ = flags[1] != 0;
  structure_ = structure != 0;
  geometry_ = geometry != 0;
  return changed != 0;
}

template <int Dim>
bool PressureProjection<Dim>::same_columns(
    const std::vector<std::vector<std::pair<GlobalId, double>>>& a,
    const std::vector<std::vector<std::pair<GlobalId, double>>>& b) {
  if (a.size() != b.size())
    return false;
  for (std::size_t k = 0; k < a.size(); ++k)
    if (!std::equal(a[k].begin(), a[k].end(), b[k].begin(), b[k].end(),
                    [](const auto& x, const auto& y) { return x.first == y.first; }))
      return false;
  return true;
}

template <int Dim>
bool PressureProjection<Dim>::any_images(const std::vector<PressureRole>& roles, MPI_Comm comm) {
  int images = 0;
  for (const PressureRole r : roles)
    images |= r == PressureRole::OddImage || r == PressureRole::EvenImage;
  MPI_Allreduce(MPI_IN_PLACE, &images, 1, MPI_INT, MPI_MAX, comm);
  return images != 0;
}

template <int Dim>
void PressureProjection<Dim>::compose(const CrsMatrix& ns, bool graph) {
  ScopedRegion region("mupm::Pressure::compose");
  const auto nl = ns.getLocalMatrixHost();
  const auto& composed = composed_.matrix();
  const bool rebuild = graph || system_.is_null() || system_ == composed;  // the same everywhere
  if (rebuild) {
    system_ = Tpetra::MatrixMatrix::add(1.0, false, *composed, 1.0, false, ns);
    if (!system_->getRowMap()->isSameAs(*joint_) || !composed->getRowMap()->isSameAs(*joint_))
      throw std::logic_error("PressureProjection::compose: the rows are not the joint map's");
    base_ = detail::positions_of(*system_, *composed);
    where_ = detail::positions_of(*system_, ns);
    ns_graph_ = false;
  }
  const auto v = system_->getLocalValuesView();
  const auto cv = composed->getLocalValuesView();
  if (rebuild || composed_changed_) {  // every value: composed_'s, then ns's added
    for (std::size_t q = 0; q < v.extent(0); ++q)
      v(q) = 0.0;
    for (std::size_t q = 0; q < base_.size(); ++q)
      v(base_[q]) = cv(q);
    for (std::size_t q = 0; q < where_.size(); ++q)
      v(where_[q]) += nl.values(q);
    if (rebuild) {  // composed_'s entry (or none: -1) at each of ns's positions
      std::vector<std::ptrdiff_t> of(v.extent(0), -1);
      for (std::size_t q = 0; q < base_.size(); ++q)
        of[base_[q]] = std::ptrdiff_t(q);
      under_.resize(where_.size());
      for (std::size_t q = 0; q < where_.size(); ++q)
        under_[q] = of[where_[q]];
    }
    composed_changed_ = false;
  } else {  // composed_ as before: ns's positions alone, to the same sums
    for (std::size_t q = 0; q < where_.size(); ++q)
      v(where_[q]) = (under_[q] < 0 ? 0.0 : cv(std::size_t(under_[q]))) + nl.values(q);
  }
  if (rebuild)
    solver_.set_matrix(system_);
  else
    solver_.refresh();
}

template <int Dim>
bool PressureProjection<Dim>::network_values(const CrackBlock& crack) {
  const auto& p = disc_.points;
  // Per network point its pore-pressure row (exchange), then its fracture-pressure row
  // (exchange, flows, diagonal); the (row, column) gids in that order.
  GlobalRows rows;
  std::vector<GlobalId> pattern;
  for (std::size_t k = 0; k < crack.point.size(); ++k) {
    const GlobalId g = p.gid(crack.point[k]), gf = crack.offset + g;
    const double ex = crack.exchange[k];
    rows.push_back({g, {{g, ex}, {gf, -ex}}});
    auto& f = rows.emplace_back(gf, std::vector<std::pair<GlobalId, double>>{{g, -ex}}).second;
    double diag = crack.storage[k] + ex;
    for (const auto& e : crack.flow[k]) {
      f.push_back({e.first, -e.second});
      diag += e.second;
    }
    f.push_back({gf, diag});
  }
  for (const auto& r : rows)
    for (const auto& e : r.second)
      pattern.insert(pattern.end(), {r.first, e.first});
  int rebuild = network_.matrix().is_null() ||
                        network_.matrix()->getRowMap().get() != joint_.get() ||
                        pattern != network_pattern_
                    ? 1
                    : 0;
  MPI_Allreduce(MPI_IN_PLACE, &rebuild, 1, MPI_INT, MPI_MAX, comm_);
  if (rebuild) {
    network_.build(nullptr, joint_, rows, joint_, joint_);
    network_pattern_ = std::move(pattern);
  } else {
    network_.fill(nullptr, rows);
  }
  return rebuild != 0;
}

template <int Dim>
void PressureProjection<Dim>::assemble(double dt, const FluidParams& prm, const FluidState<Dim>& st,
                                       const SkeletonState& sk, const CrackBlock& crack) {
  const bool build = structure_;
  ScopedRegion region(build ? "mupm::Pressure::assemble" : "mupm::Pressure::refill");
  auto& p = disc_.points;
  const std::size_t n = p.n_owned, m = crack.point.size();
  seen_.resize(kSeen * n);
  for (std::size_t i = 0; i < n; ++i) {
    seen_[kSeen * i] = p.saturation(i);
    seen_[kSeen * i + 1] = p.rel_perm(i);
    seen_[kSeen * i + 2] = sk.density(i);
    seen_[kSeen * i + 3] = sk.inertia(i);
    seen_[kSeen * i + 4] = st.storage(i);
  }
  crack_points_ = crack.point;
  crack_held_ = crack.held;
  crack_coupling_ = crack.coupling;
  // The joint map: the owned points' pore pressures, then their fracture pressures.
  if (build) {
    std::vector<GlobalId> ids(n + m);
    for (std::size_t i = 0; i < n; ++i)
      ids[i] = p.gid(i);
    for (std::size_t k = 0; k < m; ++k)
      ids[n + k] = offset_ + p.gid(crack.point[k]);
    const auto invalid = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
    joint_ = Teuchos::rcp(
        new Map(invalid, Teuchos::ArrayView<const GlobalId>(ids), 0, disc_.dist.comm()));
  }
  // The flow operator with the pressure stabilization added to the flow's (header).
  Scalars alpha("mupm::projection_alpha", p.size());
  Kokkos::deep_copy(alpha, st.alpha);
  add_pressure_stabilization(disc_, prm, dt, sk.density, alpha);
  GlobalRows extra;
  for (std::size_t k = 0; k < m; ++k)
    extra.push_back({offset_ + p.gid(crack.point[k]), crack.coupling[k]});
  if (build) {
    flow_.build(disc_, prm, alpha);
    coupling_.build(disc_, prm.pore.biot);
    joint_flow_.build(flow_.matrix().get(), joint_, {}, joint_, joint_);
    joint_coupling_.build(coupling_.matrix().get(), joint_, extra, dofs_, joint_);
    inverse_mass_ = Teuchos::rcp(new TpetraVector(dofs_));
    saturation_ = Teuchos::rcp(new TpetraVector(disc_.dist.owned_map()));
    sigma_ = Teuchos::rcp(new TpetraVector(joint_));
  } else {
    flow_.fill(disc_, prm, alpha, geometry_);
    joint_flow_.fill(flow_.matrix().get(), {});
    if (geometry_) {
      coupling_.fill(disc_, prm.pore.biot);
      joint_coupling_.fill(coupling_.matrix().get(), extra);
    }
  }
  // B = diag(sigma) [B_0; B_f]: sigma = S_r on the points' rows, 1 on the network's.
  {
    auto sv = saturation_->getLocalViewHost(Tpetra::Access::OverwriteAll);
    auto gv = sigma_->getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t i = 0; i < n; ++i)
      sv(i, 0) = gv(i, 0) = p.saturation(i);
    for (std::size_t k = 0; k < m; ++k)
      gv(n + k, 0) = 1.0;
  }
  copy_values(coupling_s_, *joint_coupling_.matrix(), build);
  coupling_s_->leftScale(*sigma_);
  if (geometry_)
    coupling_t_.update(build, joint_coupling_.matrix());  // [B_0; B_f]^T
  TpetraVector storage(joint_);
  {
    auto mv = inverse_mass_->getLocalViewHost(Tpetra::Access::OverwriteAll);
    auto sv = storage.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t fx = p.fixed(i);
      for (int k = 0; k < NC; ++k) {
        const double mass = p.volume(i) * (k < Dim ? sk.density(i) : sk.inertia(i));
        mv(i * NC + k, 0) = (fx & (1u << k)) || !(mass > 0) ? 0.0 : 1.0 / mass;
      }
      sv(i, 0) = p.volume(i) * st.storage(i);
    }
    for (std::size_t k = 0; k < m; ++k)
      sv(n + k, 0) = 0.0;  // the network's storage is in its rows of the step
  }
  // B M^-1 B^T = (B M^-1) [B_0; B_f]^T diag(sigma): B M^-1 a copy of B's values on its graph,
  // scaled; the transpose kept while the bonds and B_f do not change.
  copy_values(scaled_coupling_, *coupling_s_, build);
  scaled_coupling_->rightScale(*inverse_mass_);
  const auto& flow = *joint_flow_.matrix();
  projection_.update(build, *scaled_coupling_, *coupling_t_.matrix(), sigma_.get());
  storage_.update(build, storage);
  rest_.update(build, dt * dt, *projection_.matrix(), 1.0, *storage_.matrix());
  static_.update(build, dt, flow, 1.0, *rest_.matrix());
  // The pressure increment is S x + c (x the solve's unknowns, c the held and lagged image
  // increments). S_H: the images follow their mirrors' increments (odd or even), for the flow;
  // S_P: they do not, for the skeleton's response within the step. An image's pressure reaches
  // the skeleton in the next step's forces, as a held pressure does (measured: with the
  // images' increments in the projection too (before the pressure stabilization), Terzaghi's
  // mirrored column with incompressible or stiff water (K_w / phi = 100 M) and slow consolidation
  // grew without bound: the image's force on the layer's skeleton, -p(mirror), answers the body's
  // compression within the same solve, a coupling no water balance books). The system is
  // R (dt V H S_H + (dt^2 P + V C) S_P + N S_H) + D_c, N the network's rows of the step: R keeps
  // the free rows, D_c puts the mean free diagonal on the others. A fracture pressure is free
  // unless held, and has no image. A point that may be free has its entry in S_H and S_P
  // (1 where free, else 0: the graphs do not follow the values).
  if (build)
    keep_ = Teuchos::rcp(new TpetraVector(joint_));
  TpetraVector diag(joint_), other(joint_);
  static_.matrix()->getLocalDiagCopy(diag);
  // A free point whose row is empty (it lost all its bonds, and its water has no storage:
  // incompressible) keeps its pressure: dp = 0, a row of the mean diagonal.
  double sum[2] = {0, 0};
  solved_.assign(n + m, 0);
  GlobalRows srows(n + m), frows(n + m);
  {
    auto kv = keep_->getLocalViewHost(Tpetra::Access::OverwriteAll);
    auto dv = diag.getLocalViewHost(Tpetra::Access::ReadOnly);
    for (std::size_t i = 0; i < n + m; ++i) {
      const bool bulk = i < n;
      const GlobalId g = bulk ? p.gid(i) : offset_ + p.gid(crack.point[i - n]);
      srows[i].first = frows[i].first = g;
      const bool may = bulk ? roles_[i] == PressureRole::Free : !crack.held[i - n];
      const bool free = may && (!bulk || dv(i, 0) > 0);
      solved_[i] = free ? 1 : 0;
      kv(i, 0) = free ? 1.0 : 0.0;
      if (may) {
        srows[i].second.push_back({g, free ? 1.0 : 0.0});
        frows[i].second.push_back({g, free ? 1.0 : 0.0});
        if (bulk && free) {
          sum[0] += dv(i, 0);
          sum[1] += 1;
        }
      } else if (bulk &&
                 (roles_[i] == PressureRole::OddImage || roles_[i] == PressureRole::EvenImage)) {
        srows[i].second.push_back(
            {p.gid(images_[i]), roles_[i] == PressureRole::OddImage ? -1.0 : 1.0});
      }
    }
  }
  MPI_Allreduce(MPI_IN_PLACE, sum, 2, MPI_DOUBLE, MPI_SUM, comm_);
  const double mean = sum[1] > 0 && sum[0] > 0 ? sum[0] / sum[1] : 1.0;
  {
    auto ov = other.getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (std::size_t i = 0; i < n + m; ++i)
      ov(i, 0) = solved_[i] ? 0.0 : mean;
  }
  if (build) {
    s_h_.build(nullptr, joint_, srows, joint_, joint_);
    s_p_.build(nullptr, joint_, frows, joint_, joint_);
  } else {
    s_h_.fill(nullptr, srows);
    s_p_.fill(nullptr, frows);
  }
  // Without images S_H = S_P = diag(keep) (1 on the free rows, 0 on the others), so
  // R (dt V H S_H + (dt^2 P + V C) S_P) is static_ scaled by keep on both sides: no products.
  Teuchos::RCP<CrsMatrix> ras;
  if (!images_any_) {
    copy_values(scaled_static_, *static_.matrix(), build);
    scaled_static_->rightScale(*keep_);
    ras = scaled_static_;
  } else {
    flow_s_.update(build, flow, *s_h_.matrix());
    rest_s_.update(build, *rest_.matrix(), *s_p_.matrix());
    ras_.update(build, dt, *flow_s_.matrix(), 1.0, *rest_s_.matrix());
    ras = ras_.matrix();
  }
  ras->leftScale(*keep_);
  other_.update(build, other);
  composed_.update(build, 1.0, *ras, 1.0, *other_.matrix());
  composed_changed_ = true;
  if (build) {
    system_ = Teuchos::null;
    ns_graph_ = true;  // S_H's graph is new
  }
  dt_ = dt;
  stale_ = false;
  ++assemblies_;
}

template class PressureProjection<2>;
template class PressureProjection<3>;

}  // namespace mupm
