#include "mupm/solvers/j_integral.hpp"

namespace mupm {

template <int Dim>
JIntegral<Dim>::JIntegral(Discretization<Dim>& disc, const JIntegralParams& prm,
                          const Damage<Dim>& damage, MPI_Comm comm)
    : disc_(disc), prm_(prm), damage_(damage), comm_(comm) {
  static_assert(Dim == 2 || Dim == 3);
  terms_ = Vectors("mupm::j_integral_terms", disc.points.n_owned, 4 * prm.half.size());
  const Crack& c = disc.grid.cracks.front();
  double len = 0;
  for (int k = 0; k < 2; ++k) {
    d_[k] = c.b[k] - c.a[k];
    len += d_[k] * d_[k];
  }
  for (int k = 0; k < 2; ++k)
    d_[k] /= std::sqrt(len);
}

template <int Dim>
void JIntegral<Dim>::globals(GlobalRefs& g) {
  if (prm_.criterion) {
    g("advances", advances_);
    g("last_advance_time", last_advance_);
  }
}

template <int Dim>
void JIntegral<Dim>::series(SeriesRow& row) const {
  const auto v = evaluate();
  row("j_integral", v[0].total);
  row("j_translational", v[0].translational);
  row("j_rotational", v[0].rotational);
  if (prm_.face)
    row("j_face", v[0].face);
  for (std::size_t k = 1; k < v.size(); ++k)
    row("j_integral_" + std::to_string(k + 1), v[k].total);
  if (prm_.criterion) {  // the crack the criterion grew: the pre-crack in the body + n da
    const Crack& c = disc_.grid.cracks.front();
    row("j_crack_length", damage_.inside_length(c) + double(advances_) * prm_.increment);
  }
}

template <int Dim>
std::array<double, 2> JIntegral<Dim>::tip() const {
  const Crack& c = disc_.grid.cracks.front();
  if (prm_.criterion)
    return {c.b[0] + double(advances_) * prm_.increment * d_[0],
            c.b[1] + double(advances_) * prm_.increment * d_[1]};
  const auto t = damage_.crack_tip();
  return {t.x[0], t.x[1]};
}

template <int Dim>
JContours JIntegral<Dim>::contours(const std::array<double, 2>& tip) const {
  const auto& g = disc_.grid;
  JContours jc;
  jc.count = int(prm_.half.size());
  jc.d[0] = d_[0];
  jc.d[1] = d_[1];
  jc.thickness = g.thickness;
  jc.dx = g.dx;
  auto face = [&](int k, double v) {
    return g.origin[k] + std::round((v - g.origin[k]) / g.dx) * g.dx;
  };
  for (int k = 0; k < 2; ++k) {
    jc.body.lo[k] = g.origin[k] - g.layers[k][0] * g.dx;
    jc.body.hi[k] = g.origin[k] + double(g.counts[k] + g.layers[k][1]) * g.dx;
  }
  for (int c = 0; c < jc.count; ++c)
    for (int k = 0; k < 2; ++k) {  // the tip to a face first, so that the box is centred on it
      const double t = face(k, tip[k]), h = std::round(prm_.half[c][k] / g.dx) * g.dx;
      jc.box[c].lo[k] = t - h;
      jc.box[c].hi[k] = t + h;
    }
  return jc;
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
  const auto t = tip();
  const auto& g = disc_.grid;
  for (int k = 0; k < 2; ++k)  // the crack has run through the body
    if (t[k] < g.origin[k] || t[k] >= g.origin[k] + double(g.counts[k]) * g.dx)
      return br;
  if (advances_ > 0 && prm_.max_speed > 0 &&
      time - last_advance_ < prm_.increment / prm_.max_speed * (1 - 1e-9))
    return br;
  if (!(evaluate(contours(t))[0].total >= prm_.critical))
    return br;
  last_advance_ = time;
  Crack seg;
  for (int k = 0; k < 2; ++k) {
    seg.a[k] = t[k];
    seg.b[k] = t[k] + prm_.increment * d_[k];
  }
  br.bonds = break_crossing<Dim>(disc_.points, disc_.bonds, seg);
  advances_ += 1;
  return br;
}

template class JIntegral<2>;
template class JIntegral<3>;

}  // namespace mupm
