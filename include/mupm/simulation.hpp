// The solver layer: builds the discretization from the validated input, applies initial
// conditions, advances the steps, and writes fields, time series, checkpoints and reports.
#ifndef MUPM_SIMULATION_HPP
#define MUPM_SIMULATION_HPP

#include <Teuchos_Comm.hpp>
#include <Teuchos_ParameterList.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "mupm/discretization.hpp"
#include "mupm/input.hpp"

namespace mupm {

// A named per-point field as [n][ncomp] doubles (scalars seen through as_vectors).
struct NamedField {
  std::string name;
  Vectors view;
};

// The evolving state of every point that a checkpoint must keep.
template <int Dim>
std::vector<NamedField> state_fields(const Points<Dim>& p);

// Applies the initial conditions to owned and ghost points alike (they are pointwise).
// "Hydrostatic Pore Pressure" sets p = rho_w g . (x - x_0), x_0 (the Value) a point of the
// water table, from rho_w_g = rho_w g.
template <int Dim>
void apply_initial_conditions(const std::vector<InitialCondition>& ics, Points<Dim>& p,
                              Kokkos::Array<double, 3> rho_w_g = {});

// D_i = 1 - sum_j rho_ij omega V_j / sum_j omega V_j over the family (eq 37) on owned points.
template <int Dim>
void compute_damage(const Bonds& bonds, Points<Dim>& p);

// Collective checkpoint of points and bonds keyed by global id.
template <int Dim>
void write_checkpoint(const std::string& path, const Discretization<Dim>& disc, long long step,
                      double time, const std::vector<double>& output_history,
                      const std::vector<double>& solver_globals = {});
// Collective restore; returns the step and time stored and fills output_history. Throws
// std::runtime_error (on every rank) when the checkpoint does not match the discretization.
template <int Dim>
void read_checkpoint(const std::string& path, Discretization<Dim>& disc, long long& step,
                     double& time, std::vector<double>& output_history,
                     std::vector<double>* solver_globals = nullptr);

struct RunSummary {
  long long steps = 0;
  double wall_seconds = 0;
  long long n_points = 0, n_bonds = 0;
};

// Runs the validated input. Collective. Writes progress and reports to `out` on rank 0.
RunSummary run_simulation(const Teuchos::RCP<const Teuchos::Comm<int>>& comm,
                          Teuchos::ParameterList& input, std::ostream& out);

}  // namespace mupm

#endif
