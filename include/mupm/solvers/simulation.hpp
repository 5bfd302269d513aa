// The driver: assembles the physics modules the input asks for and runs Algorithm 1's steps,
// writing fields, time series, checkpoints and reports.
#ifndef MUPM_SIMULATION_HPP
#define MUPM_SIMULATION_HPP

#include <Teuchos_Comm.hpp>
#include <Teuchos_ParameterList.hpp>
#include <ostream>

#include "mupm/solvers/initial_conditions.hpp"

namespace mupm {

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
