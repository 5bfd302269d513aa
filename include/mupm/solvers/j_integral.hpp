// The J-integral module (paper eqs 125-126, Algorithm 3; kernel and derivation in
// include/mupm/kernels/j_integral.hpp): J on rectangular contours around the tip of the first
// pre-crack, its time-series columns, and the J criterion.
//
// The tip. With the J criterion (Fracture->Bond Breakage = J-Integral) the crack is the
// pre-crack's segment Start -> End grown by n increments Delta a along its direction d (n is
// kept across a restart); the tip is End + n Delta a d. Otherwise the tip is the tracked one of
// the damage module (crack_tip_x/y: the farthest fracture point along d, or End before growth).
// Each contour is centred on the tip with the given half width (along x) and half height, its
// edges moved to the nearest cell faces; the contours move with the tip.
//
// The J criterion (Algorithm 3): after the solid's step (its forces of the new state), while
// J/h of the first contour >= G_cr the crack advances one increment: the intact bonds that
// cross the segment tip -> tip + Delta a d break (both copies: the test is on reference
// positions, the same on every rank), at most one increment a step (the next step's J sees the
// new tip and the new bond set). A tip outside the real body (the crack ran through) stays.
// Speed cap (not in the paper's Algorithm 3): after an advance the next waits Delta a / c_R,
// c_R the skeleton's Rayleigh wave speed, the limit of a running mode I crack's speed. Without
// it the crack runs at Delta a / dt (above the wave speeds) for as long as the contours, whose
// edges the field of the last increment has not reached yet, still show J >= G_cr.
//
// Sums over ranks: every point's terms are added exactly (include/mupm/core/exact_sum.hpp), so
// that J, and with it the criterion's decision, is the same to the last bit on any number of
// ranks and threads, with messages whose size does not depend on the resolution.
#ifndef MUPM_SOLVERS_J_INTEGRAL_HPP
#define MUPM_SOLVERS_J_INTEGRAL_HPP

#include <mpi.h>

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "mupm/core/exact_sum.hpp"
#include "mupm/kernels/fracture.hpp"
#include "mupm/kernels/j_integral.hpp"
#include "mupm/solvers/damage.hpp"

namespace mupm {

template <int Dim>
class JIntegral : public Module {
 public:
  struct Value {
    double total = 0, translational = 0, rotational = 0;  // per unit thickness [J/m^2]
  };

  JIntegral(Discretization<Dim>& disc, const JIntegralParams& prm, const Damage<Dim>& damage,
            MPI_Comm comm)
      : disc_(disc), prm_(prm), damage_(damage), comm_(comm) {
    static_assert(Dim == 2 || Dim == 3);
    terms_ = Vectors("mupm::j_integral_terms", disc.points.n_owned, 3 * prm.half.size());
    const Crack& c = disc.grid.cracks.front();
    double len = 0;
    for (int k = 0; k < 2; ++k) {
      d_[k] = c.b[k] - c.a[k];
      len += d_[k] * d_[k];
    }
    for (int k = 0; k < 2; ++k)
      d_[k] /= std::sqrt(len);
  }
  // The solid's state and constants whose force states J integrates.
  void attach(const SolidState<Dim>& st, const SolidParams& sp) {
    st_ = &st;
    sp_ = sp;
  }

  const char* name() const override { return "j_integral"; }
  void globals(GlobalRefs& g) override {
    if (prm_.criterion) {
      g("advances", advances_);
      g("last_advance_time", last_advance_);
    }
  }
  // j_integral, j_translational, j_rotational of the first contour; j_integral_<k> of contour k;
  // with the J criterion j_crack_length, the pre-crack's part inside the body + n Delta a.
  void series(SeriesRow& row) const override {
    const auto v = evaluate();
    row("j_integral", v[0].total);
    row("j_translational", v[0].translational);
    row("j_rotational", v[0].rotational);
    for (std::size_t k = 1; k < v.size(); ++k)
      row("j_integral_" + std::to_string(k + 1), v[k].total);
    if (prm_.criterion) {  // the crack the criterion grew: the pre-crack in the body + n da
      const Crack& c = disc_.grid.cracks.front();
      row("j_crack_length", damage_.inside_length(c) + double(advances_) * prm_.increment);
    }
  }

  // The tip now (header). Collective.
  std::array<double, 2> tip() const {
    const Crack& c = disc_.grid.cracks.front();
    if (prm_.criterion)
      return {c.b[0] + double(advances_) * prm_.increment * d_[0],
              c.b[1] + double(advances_) * prm_.increment * d_[1]};
    const auto t = damage_.crack_tip();
    return {t.x[0], t.x[1]};
  }

  // The contours around `tip`, edges on the nearest cell faces.
  JContours contours(const std::array<double, 2>& tip) const {
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

  // J of every contour at the current tip (collective; the same bits on every rank).
  std::vector<Value> evaluate() const { return evaluate(contours(tip())); }
  std::vector<Value> evaluate(const JContours& jc) const {
    const int nc = jc.count;
    std::vector<Value> out(static_cast<std::size_t>(nc));
    if (!st_)
      throw std::logic_error("JIntegral::evaluate: no solid state attached (JIntegral::attach)");
    if constexpr (Dim == 2) {
      const auto& p = disc_.points;
      j_integral_terms(p, disc_.bonds, sp_, *st_, jc, terms_);
      auto h = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), terms_);
      // Per point with a term, for each contour: the translational part (its first two terms
      // added) and the rotational part; summed over ranks exactly (core/exact_sum.hpp).
      std::vector<double> mine;
      std::size_t rows = 0;
      for (std::size_t i = 0; i < p.n_owned; ++i) {
        bool any = false;
        for (int k = 0; k < 3 * nc; ++k)
          any = any || h(i, k) != 0;
        if (!any)
          continue;
        ++rows;
        for (int c = 0; c < nc; ++c) {
          mine.push_back(h(i, 3 * c) + h(i, 3 * c + 1));
          mine.push_back(h(i, 3 * c + 2));
        }
      }
      const std::vector<double> sums = exact_sums(comm_, mine.data(), rows, 2 * nc);
      for (std::size_t c = 0; c < std::size_t(nc); ++c) {
        out[c].translational = sums[2 * c];
        out[c].rotational = sums[2 * c + 1];
        out[c].total = out[c].translational + out[c].rotational;
      }
    }
    return out;
  }

  // The J criterion (header) at time `time`: breaks the bonds across the next increment if
  // J/h >= G_cr and the speed cap allows. Collective; returns the directed bonds broken on this
  // rank.
  Breakage advance(double time) {
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
  long long advances() const { return advances_; }

 private:
  Discretization<Dim>& disc_;
  JIntegralParams prm_;
  const Damage<Dim>& damage_;
  MPI_Comm comm_;
  const SolidState<Dim>* st_ = nullptr;
  SolidParams sp_;
  Vectors terms_;
  double d_[2] = {1, 0};
  long long advances_ = 0;   // increments the crack advanced (J criterion; a restart global)
  double last_advance_ = 0;  // time of the last advance (J criterion; a restart global)
};

}  // namespace mupm

#endif
