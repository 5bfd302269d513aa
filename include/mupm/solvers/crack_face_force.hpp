// The crack water's force on the skeleton with Fracture->Crack Water Force = Face Pressure
// (kernels/fracture_flow.hpp): p_f* of the current displacement (undrained split), the face
// loads g of that pressure onto the ghosts, then the forces of the broken bonds. Defined in
// src/solvers/crack_face_force.cpp for Dim 2, 3.
#ifndef MUPM_CRACK_FACE_FORCE_HPP
#define MUPM_CRACK_FACE_FORCE_HPP

#include "mupm/core/scratch.hpp"
#include "mupm/mesh/discretization.hpp"

namespace mupm {

template <int Dim>
class CrackFaceForce {
 public:
  explicit CrackFaceForce(Discretization<Dim>& disc);

  // The force density of the points' current state into force() (owned points).
  void evaluate();
  const Vectors& force() const { return force_; }
  // Adds the force density of the state of `pts` (the points, or a copy with other Views) to
  // `out` (owned points).
  void add(const Points<Dim>& pts, const Vectors& out);

  // `pts` with its crack-water fields replaced by copies in `scratch` that hold the force's
  // linear part, for the stable-step estimate's operator: p_f = 0 at c_ref = 0, and on a
  // fracture point not yet in the network the modulus it will join with, `joins` = K_w / a_min
  // (saturated, closed: a film a_min) and the face-area share of one row, V/dx (n_i = 1: the
  // stiffest). The points' own fields are not touched.
  Points<Dim> linear_part(Points<Dim> pts, Scratch& scratch, double joins) const;

 private:
  Discretization<Dim>& disc_;
  Vectors force_;      // [n_owned][Dim]
  Scalars pf_star_;    // p_f* of the force (owned points)
  Vectors face_load_;  // g of the force (owned and ghosts)
};

extern template class CrackFaceForce<2>;
extern template class CrackFaceForce<3>;

}  // namespace mupm

#endif
