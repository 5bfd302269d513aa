// The J-integral module (paper eqs 125-126, Algorithm 3; kernel and derivation in
// include/mupm/kernels/j_integral.hpp): J on rectangular contours around every crack tip, its
// time-series columns, and the J criterion.
//
// The tips: every pre-crack end strictly inside the real body (crack_tips: a centre crack has
// two, an edge crack from a face one), numbered crack by crack, End before Start; each grows
// along its own direction d (from the crack's other end). With the J criterion
// (Fracture->Bond Breakage = J-Integral) tip k is its pre-crack end advanced by n_k increments
// Delta a along d (n_k kept across a restart); otherwise it is the farthest fracture point
// beyond the end along d (Damage::farthest), or the end before growth. Each contour is centred
// on its tip with the given half width (along x) and half height, its edges moved to the
// nearest cell faces (a tip at a cell centre counts as the face ahead of it along d); the
// contours move with the tip.
//
// The J criterion (Algorithm 3), tip by tip and each by its own J: after the solid's step (its
// forces of the new state), while J/h of a tip's first contour >= G_cr that tip advances one
// increment: the intact bonds that cross the segment tip -> tip + Delta a d break (both copies:
// the test is on reference positions, the same on every rank), at most one increment a step per
// tip (the next step's J sees the new tip and the new bond set). A tip outside the real body
// (the crack ran through) stays, and so does a tip whose contours now hold another tip
// (two cracks meeting: J would be that of both; the input check refuses it at the start).
// With fracture flow the points within dx of an increment become fracture points at once
// (kFlagCut, kernels/damage.hpp: the pre-crack's rule), so that the network reaches the tip the
// criterion grew instead of waiting until their damage reaches D_cr; the flags follow from the
// advances, so a restart sets them again (mark_cuts).
// Speed cap (not in the paper's Algorithm 3): after an advance the tip's next waits
// Delta a / c_R, c_R the skeleton's Rayleigh wave speed, the limit of a running mode I crack's
// speed. Without it the crack runs at Delta a / dt (above the wave speeds) for as long as the
// contours, whose edges the field of the last increment has not reached yet, show J >= G_cr.
// J-Integral->Maximum Crack Speed replaces c_R by a given speed: a quasi-static crack (a
// hydraulic fracture) waits until the field and the crack water have settled.
// J-Integral->Release Time releases an increment's bond forces over a time instead of at once
// (include/mupm/solvers/solid_solver.hpp); the input check keeps it within the wait, so that
// each J decision sees a released field.
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
    // per unit thickness [J/m^2]; face: the crack water's term (kernels/j_integral.hpp)
    double total = 0, translational = 0, rotational = 0, face = 0;
  };

  JIntegral(Discretization<Dim>& disc, const JIntegralParams& prm, const Damage<Dim>& damage,
            MPI_Comm comm);
  // The solid's state and constants whose force states J integrates.
  void attach(const SolidState<Dim>& st, const SolidParams& sp) {
    st_ = &st;
    sp_ = sp;
  }

  const char* name() const override { return "j_integral"; }
  // Per tip k: advances and last_advance_time (tip 1), advances_tip<k> and
  // last_advance_time_tip<k> (k >= 2).
  void globals(GlobalRefs& g) override;
  // Tip 1: j_integral, j_translational, j_rotational (and j_face with the crack water's face
  // term) of the first contour, j_integral_<c> of contour c >= 2; tip k >= 2: the same names
  // with the suffix _tip<k> (j_integral_tip<k>, j_integral_tip<k>_<c>, ...). With the J
  // criterion j_crack_length, the first pre-crack's part inside the body + its tips' advances
  // n Delta a, and, with two or more tips, j_crack_length_tip<k> for every tip: its share of
  // its pre-crack (crack_tips) + n_k Delta a.
  void series(SeriesRow& row) const override;

  std::size_t tips() const { return tips_.size(); }
  // Tip k now (header). Collective.
  std::array<double, 2> tip(std::size_t k = 0) const;

  // The contours of tip k centred at `at`, edges on the nearest cell faces.
  JContours contours(const std::array<double, 2>& at, std::size_t k = 0) const;

  // J of every contour at tip k now (collective; the same bits on every rank).
  std::vector<Value> evaluate(std::size_t k = 0) const { return evaluate(contours(tip(k), k)); }
  std::vector<Value> evaluate(const JContours& jc) const;

  // The J criterion (header) at time `time`: breaks the bonds across each tip's next increment
  // where J/h >= G_cr and the speed cap allows. Collective; returns the directed bonds broken on
  // this rank.
  Breakage advance(double time);
  long long advances(std::size_t k = 0) const { return tips_[k].advances; }

  // Flags the points next to the increments not flagged yet (header; with JIntegralParams::cut).
  // advance() calls it; the driver after a restart, before the damage is computed.
  void mark_cuts();

 private:
  struct Tip {
    CrackTip at;              // the pre-crack end, direction and share (crack_tips)
    long long advances = 0;   // increments it advanced (J criterion; a restart global)
    double last_advance = 0;  // time of its last advance (J criterion; a restart global)
    long long marked = 0;     // increments whose points mark_cuts flagged
  };
  // Whether a contour of tip k, centred at now[k], holds another tip of `now`.
  bool holds_other(std::size_t k, const std::vector<std::array<double, 2>>& now) const;

  Discretization<Dim>& disc_;
  JIntegralParams prm_;
  const Damage<Dim>& damage_;
  MPI_Comm comm_;
  const SolidState<Dim>* st_ = nullptr;
  SolidParams sp_;
  Vectors terms_;
  std::vector<Tip> tips_;
};

extern template class JIntegral<2>;
extern template class JIntegral<3>;

}  // namespace mupm

#endif
