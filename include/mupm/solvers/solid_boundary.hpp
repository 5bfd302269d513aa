// The solid's boundary conditions as its step sees them (kernels/boundary_conditions.hpp):
// prescribed components, mirrored and slaved boundary layers with the fold of the slaved
// layers' forces onto their mirrors, consistent tractions and the reactions. Defined in
// src/solvers/solid_boundary.cpp for Dim 2, 3.
#ifndef MUPM_SOLID_BOUNDARY_HPP
#define MUPM_SOLID_BOUNDARY_HPP

#include <mpi.h>

#include <string>
#include <vector>

#include "mupm/kernels/boundary_conditions.hpp"
#include "mupm/kernels/solid.hpp"
#include "mupm/mesh/discretization.hpp"
#include "mupm/solvers/module.hpp"

namespace mupm {

template <int Dim>
class SolidBoundary {
 public:
  static constexpr int R = kRotDim<Dim>;

  SolidBoundary(Discretization<Dim>& disc, std::vector<BoundaryCondition> bcs, MPI_Comm comm);

  const std::vector<BoundaryCondition>& conditions() const { return bcs_; }
  bool layers() const { return mirrored_ || slaved_; }
  bool slaved() const { return slaved_; }

  // Marks the prescribed components and the layers' points (they only set bits: repeatable).
  void mark() const;
  // The mirrored Displacement conditions' layer points from their mirrors' current values
  // (mirror_kinematic), after the step has moved the body: the mirrors' new values reach the
  // ghosts first (one extra refresh per step, only with such conditions). The slaved layers'
  // likewise (slave_layer).
  void mirror_layers(double t) const;
  // The slaved conditions' g over the step from t to t + dt (before mirror_layers(t + dt)).
  void advance_slaved(double t, double dt);
  // The slaved layers' increments of the step (du: [owned][Dim + R], the step's increment).
  void slaved_increments(const Vectors& du) const;
  // The slaving's linear part (g = 0) on the state of `pts`, its ghosts refreshed after (the
  // stable-step estimate's P^T K P with fold()).
  void slave_linear(const Points<Dim>& pts) const;
  // The slaved layer points' forces and moments onto their mirrors (fold_layer_forces), across
  // ranks. The layer points keep theirs: the reactions and the external work are made of them.
  void fold(const Vectors& force, const Vectors& moment) const;

  // Traction Distribution = Consistent (kernels/boundary_conditions.hpp,
  // consistent_traction_load): each such traction's load of a unit Value, from the families at
  // construction (bonds broken later leave it as it was), on the strip within 2 delta + dx of its
  // face whose other coordinates lie in the condition's region box.
  void build_consistent_tractions(const SolidParams& prm);

  // Force (moment) the boundary applies on each kinematic condition's points: -sum f V; on a
  // slaved layer's points dPsi/dg = -2 sum f V (kernels/boundary_conditions.hpp, slave_layer).
  // Collective.
  std::vector<std::string> reaction_names() const;
  std::vector<double> reactions(const Vectors& force, const Vectors& moment) const;

  // The displacement each slaved Velocity condition has prescribed since t = 0.
  void globals(GlobalRefs& g);

 private:
  static bool slaved_velocity(const BoundaryCondition& bc) {
    return bc.slaved && bc.kind == BoundaryCondition::Velocity;
  }

  Discretization<Dim>& disc_;
  std::vector<BoundaryCondition> bcs_;
  MPI_Comm comm_;
  bool mirrored_ = false;  // mirrored Displacement conditions (mirror_layers)
  bool slaved_ = false;    // slaved layers (slave_layer, fold)
  Vectors fold_;           // fold's buffer [owned + ghosts][columns]
  FaceSlots slots_;        // fold_'s block of each face (-1: none)
  // The displacement a slaved Velocity condition has prescribed since t = 0 (by condition; a
  // restart global), the g its layer reflects about.
  std::vector<double> slaved_disp_;
  std::vector<double> twice_dg_;  // 2 dg of each slaved condition in the current step
};

extern template class SolidBoundary<2>;
extern template class SolidBoundary<3>;

}  // namespace mupm

#endif
