// The damage module: the damage of every point from its intact bonds (eq 37) and the fracture
// points (eq 104) after the mechanics step (the solid breaks the bonds, Algorithm 4, at the end
// of its step: include/mupm/solvers/solid_solver.hpp), and its time-series columns: broken
// bonds, mean damage and, with a pre-crack, the crack's length and tip.
//
// Crack length and tip (2D and 3D), for the first pre-crack: its tip T is End in 2D (the
// segment Start -> End grows from End) and Corner + Edge 1 in 3D (the rectangle grows along
// Edge 1); d is the unit vector from Start (Corner) to T. The crack's grown part is the largest
// projection s = (x - T).d over the real points (not boundary layers) that are fracture points
// and not next to the pre-crack, if positive; the tip is that point (the lowest global id among
// equals), else the middle of the pre-crack's tip edge inside the body (T in 2D when inside).
// crack_length = (the pre-crack's extent along d inside the real body) + s: a 3D rectangle
// overhanging the body counts as the same cut clipped to it (crack_inside, core/geometry.hpp).
// For an edge crack from a face this is the distance from the face to the farthest fracture
// point along the crack's direction, as the paper measures it. Damage elsewhere ahead of the
// crack (e.g. at a loaded face) would count too: look at the damage field when in doubt.
#ifndef MUPM_SOLVERS_DAMAGE_HPP
#define MUPM_SOLVERS_DAMAGE_HPP

#include <mpi.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "mupm/kernels/damage.hpp"
#include "mupm/mesh/discretization.hpp"
#include "mupm/solvers/module.hpp"

namespace mupm {

template <int Dim>
class Damage : public Module {
 public:
  Damage(Discretization<Dim>& disc, double critical_damage, MPI_Comm comm)
      : disc_(disc), critical_damage_(critical_damage), comm_(comm) {}

  const char* name() const override { return "damage"; }

  // Damage and fracture points (after bonds broke).
  void update() { compute_damage(disc_.bonds, disc_.points, critical_damage_); }
  // Crack aperture (eqs 38-39) of the current displacement; u current on the ghosts.
  void update_aperture() { compute_aperture(disc_.bonds, disc_.points); }

  // Volume-weighted mean damage and the number of broken bonds (each bond is listed by both
  // its ends). Sums over ranks in a fixed order would be needed for bit-equal sums; these are
  // reports.
  void series(SeriesRow& row) const override;

  struct Tip {
    double length = 0;
    std::array<double, 3> x{};
  };
  // The first pre-crack's length and tip now (header). Collective.
  Tip crack_tip() const;

  // The farthest fracture point of the real body away from the pre-crack beyond T along the
  // unit direction d (header): s = (x - T).d, the lowest global id among equals, and its
  // position; s <= 0 when there is none beyond T. Collective.
  struct Reach {
    double s = 0;
    std::array<double, 3> x{};
  };
  Reach farthest(const double* T, const double* d) const;

  // Length of a crack's part inside the real body along its direction (crack_inside).
  double inside_length(const Crack& c) const;

 private:
  // s = (x_i - T).d of a fracture point of the real body away from the pre-crack (header).
  struct Ahead {
    Vectors x;
    Bytes frac;
    Flags flags;
    double T[3] = {0, 0, 0}, d[3] = {0, 0, 0};
    KOKKOS_INLINE_FUNCTION bool operator()(std::size_t i, double& s) const {
      if (!frac(i) || (flags(i) & (kFlagPreCrack | kFlagBoundaryLayer)))
        return false;
      s = 0;
      for (int k = 0; k < Dim; ++k)
        s += (x(i, k) - T[k]) * d[k];
      return true;
    }
  };

  Discretization<Dim>& disc_;
  double critical_damage_;
  MPI_Comm comm_;
};

extern template class Damage<2>;
extern template class Damage<3>;

}  // namespace mupm

#endif
