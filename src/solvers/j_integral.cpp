#include "mupm/solvers/j_integral.hpp"

namespace mupm {

template <int Dim>
JIntegral<Dim>::JIntegral(Discretization<Dim>& disc, const JIntegralParams& prm,
                          const Damage<Dim>& damage, MPI_Comm comm)
    : disc_(disc), prm_(prm), damage_(damage), comm_(comm) {
  static_assert(Dim == 2 || Dim == 3);
  terms_ = Vectors("mupm::j_integral_terms", disc.points.n_owned, 4 * prm.half.size());
  for (const CrackTip& t : crack_tips(disc.grid.cracks, disc.grid.body()))
    tips_.push_back({t});
  if (tips_.empty())  // the input check (src/input/modules/fracture.cpp) refuses it
    throw std::logic_error("JIntegral: no pre-crack end lies inside the body");
}

namespace {
// Column `name` of tip k (0-based): the name itself for the first tip, name_tip<k+1> else.
std::string tip_column(const std::string& name, std::size_t k) {
  return k == 0 ? name : name + "_tip" + std::to_string(k + 1);
}
}  // namespace

template <int Dim>
void JIntegral<Dim>::globals(GlobalRefs& g) {
  if (prm_.criterion)
    for (std::size_t k = 0; k < tips_.size(); ++k) {
      g(tip_column("advances", k), tips_[k].advances);
      g(tip_column("last_advance_time", k), tips_[k].last_advance);
    }
}

template <int Dim>
void JIntegral<Dim>::series(SeriesRow& row) const {
  for (std::size_t t = 0; t < tips_.size(); ++t) {
    const auto v = evaluate(t);
    row(tip_column("j_integral", t), v[0].total);
    row(tip_column("j_translational", t), v[0].translational);
    row(tip_column("j_rotational", t), v[0].rotational);
    if (prm_.face)
      row(tip_column("j_face", t), v[0].face);
    for (std::size_t k = 1; k < v.size(); ++k)
      row(tip_column("j_integral", t) + "_" + std::to_string(k + 1), v[k].total);
  }
  if (!prm_.criterion)
    return;
  // The crack the criterion grew: the first pre-crack in the body + its tips' n Delta a.
  double grown = 0;
  for (const Tip& t : tips_)
    if (t.at.crack == 0)
      grown += double(t.advances) * prm_.increment;
  row("j_crack_length", damage_.inside_length(disc_.grid.cracks.front()) + grown);
  if (tips_.size() > 1)
    for (std::size_t k = 0; k < tips_.size(); ++k)
      row("j_crack_length_tip" + std::to_string(k + 1),
          tips_[k].at.base + double(tips_[k].advances) * prm_.increment);
}

template <int Dim>
std::array<double, 2> JIntegral<Dim>::tip(std::size_t k) const {
  const Tip& t = tips_.at(k);
  if (prm_.criterion)
    return {t.at.x[0] + double(t.advances) * prm_.increment * t.at.d[0],
            t.at.x[1] + double(t.advances) * prm_.increment * t.at.d[1]};
  const double T[3] = {t.at.x[0], t.at.x[1], 0}, d[3] = {t.at.d[0], t.at.d[1], 0};
  const auto r = damage_.farthest(T, d);
  if (!(r.s > 0))
    return t.at.x;
  return {r.x[0], r.x[1]};
}

template <int Dim>
JContours JIntegral<Dim>::contours(const std::array<double, 2>& at, std::size_t k) const {
  const auto& g = disc_.grid;
  JContours jc;
  jc.count = int(prm_.half.size());
  jc.d[0] = tips_.at(k).at.d[0];
  jc.d[1] = tips_.at(k).at.d[1];
  jc.thickness = g.thickness;
  jc.dx = g.dx;
  auto face = [&](int a, double v) {
    return g.origin[a] + std::round((v - g.origin[a]) / g.dx) * g.dx;
  };
  for (int a = 0; a < 2; ++a) {
    jc.body.lo[a] = g.origin[a] - g.layers[a][0] * g.dx;
    jc.body.hi[a] = g.origin[a] + double(g.counts[a] + g.layers[a][1]) * g.dx;
  }
  // The face term's cut (kernels/j_integral.hpp): one spacing beyond the horizon's rows behind
  // the tip, nearer on a contour that does not reach so far.
  const double cut = double(g.horizon_cells() + 1) * g.dx;
  // The tip to a face first, so that the boxes are centred on it; a tip at a cell centre (after
  // an odd number of increments of dx/2) to the face ahead of it along d, alike for every tip
  // (rounding the position alone sent the two tips of a centre crack to opposite sides: their
  // J differed by 8 % after the KGD's first increment).
  for (int a = 0; a < 2; ++a)
    jc.tip[a] = face(a, at[a] + 0.25 * g.dx * jc.d[a]);
  for (int c = 0; c < jc.count; ++c) {
    double h[2];
    for (int a = 0; a < 2; ++a) {
      h[a] = std::round(prm_.half[c][a] / g.dx) * g.dx;
      jc.box[c].lo[a] = jc.tip[a] - h[a];
      jc.box[c].hi[a] = jc.tip[a] + h[a];
    }
    jc.cut[c] = std::min(cut, std::min(h[0], h[1]));
  }
  return jc;
}

template <int Dim>
bool JIntegral<Dim>::holds_other(std::size_t k,
                                 const std::vector<std::array<double, 2>>& now) const {
  const JContours jc = contours(now[k], k);
  for (std::size_t m = 0; m < now.size(); ++m)
    for (int c = 0; m != k && c < jc.count; ++c)
      if (now[m][0] >= jc.box[c].lo[0] && now[m][0] <= jc.box[c].hi[0] &&
          now[m][1] >= jc.box[c].lo[1] && now[m][1] <= jc.box[c].hi[1])
        return true;
  return false;
}

template <int Dim>
auto JIntegral<Dim>::evaluate(const JContours& jc) const -> std::vector<Value> {
  const int nc = jc.count;
  std::vector<Value> out(static_cast<std::size_t>(nc));
  if (!st_)
    throw std::logic_error("JIntegral::evaluate: no solid state attached (JIntegral::attach)");
  if constexpr (Dim == 2) {
    const auto& p = disc_.points;
    if (prm_.face && p.applied_crack_force.extent(0) == 0)
      throw std::logic_error("JIntegral::evaluate: the face term without the crack water's force");
    const Vectors face = prm_.face ? p.applied_crack_force : Vectors();
    j_integral_terms(p, disc_.bonds, sp_, *st_, jc, face, terms_);
    auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), terms_);
    // Per point with a term, for each contour: the translational part (its first two terms
    // added), the rotational part and the face term; summed over ranks exactly
    // (core/exact_sum.hpp).
    std::vector<double> mine;
    std::size_t rows = 0;
    for (std::size_t i = 0; i < p.n_owned; ++i) {
      bool any = false;
      for (int k = 0; k < 4 * nc; ++k)
        any = any || h(i, k) != 0;
      if (!any)
        continue;
      ++rows;
      for (int c = 0; c < nc; ++c) {
        mine.push_back(h(i, 4 * c) + h(i, 4 * c + 1));
        mine.push_back(h(i, 4 * c + 2));
        mine.push_back(h(i, 4 * c + 3));
      }
    }
    const std::vector<double> sums = exact_sums(comm_, mine.data(), rows, 3 * nc);
    for (std::size_t c = 0; c < std::size_t(nc); ++c) {
      out[c].translational = sums[3 * c];
      out[c].rotational = sums[3 * c + 1];
      out[c].face = sums[3 * c + 2];
      out[c].total = out[c].translational + out[c].rotational + out[c].face;
    }
  }
  return out;
}

template <int Dim>
Breakage JIntegral<Dim>::advance(double time) {
  Breakage br;
  const auto& g = disc_.grid;
  std::vector<std::array<double, 2>> now(tips_.size());
  for (std::size_t k = 0; k < tips_.size(); ++k)
    now[k] = tip(k);
  // Every tip's decision on the bonds of before this call, then the breaks: a tip's J does not
  // see another tip's increment of the same step (a symmetric crack's tips stay symmetric).
  std::vector<std::size_t> grow;
  for (std::size_t k = 0; k < tips_.size(); ++k) {
    const Tip& tp = tips_[k];
    const auto& t = now[k];
    bool out = false;  // the crack has run through the body
    for (int a = 0; a < 2; ++a)
      out = out || t[a] < g.origin[a] || t[a] >= g.origin[a] + double(g.counts[a]) * g.dx;
    if (out || holds_other(k, now))
      continue;
    if (tp.advances > 0 && prm_.max_speed > 0 &&
        time - tp.last_advance < prm_.increment / prm_.max_speed * (1 - 1e-9))
      continue;
    if (evaluate(contours(t, k))[0].total >= prm_.critical)
      grow.push_back(k);
  }
  for (std::size_t k : grow) {
    Tip& tp = tips_[k];
    const auto& t = now[k];
    tp.last_advance = time;
    Crack seg;
    for (int a = 0; a < 2; ++a) {
      seg.a[a] = t[a];
      seg.b[a] = t[a] + prm_.increment * tp.at.d[a];
    }
    br.bonds += break_crossing<Dim>(disc_.points, disc_.bonds, seg);
    tp.advances += 1;
  }
  mark_cuts();
  return br;
}

template <int Dim>
void JIntegral<Dim>::mark_cuts() {
  if (!prm_.cut)
    return;
  for (Tip& tp : tips_)
    for (; tp.marked < tp.advances; ++tp.marked) {
      Crack seg;
      for (int a = 0; a < 2; ++a) {
        seg.a[a] = tp.at.x[a] + double(tp.marked) * prm_.increment * tp.at.d[a];
        seg.b[a] = seg.a[a] + prm_.increment * tp.at.d[a];
      }
      mark_cut<Dim>(disc_.points, seg, disc_.grid.dx);
    }
}

template class JIntegral<2>;
template class JIntegral<3>;

}  // namespace mupm
