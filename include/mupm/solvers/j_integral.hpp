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
  void globals(GlobalRefs& g) override;
  // j_integral, j_translational, j_rotational (and j_face with the crack water's face term) of
  // the first contour; j_integral_<k> of contour k;
  // with the J criterion j_crack_length, the pre-crack's part inside the body + n Delta a.
  void series(SeriesRow& row) const override;

  // The tip now (header). Collective.
  std::array<double, 2> tip() const;

  // The contours around `tip`, edges on the nearest cell faces.
  JContours contours(const std::array<double, 2>& tip) const;

  // J of every contour at the current tip (collective; the same bits on every rank).
  std::vector<Value> evaluate() const { return evaluate(contours(tip())); }
  std::vector<Value> evaluate(const JContours& jc) const;

  // The J criterion (header) at time `time`: breaks the bonds across the next increment if
  // J/h >= G_cr and the speed cap allows. Collective; returns the directed bonds broken on this
  // rank.
  Breakage advance(double time);
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

extern template class JIntegral<2>;
extern template class JIntegral<3>;

}  // namespace mupm

#endif
