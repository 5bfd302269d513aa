// Checkpoint and restart: the registries' checkpointed point fields keyed by global id, the
// checkpointed bond fields keyed by the global ids of both ends, and the modules' restart
// globals by name (globals/<module>/<name>). Independent of the number of ranks and threads.
#ifndef MUPM_CHECKPOINT_HPP
#define MUPM_CHECKPOINT_HPP

#include <mpi.h>

#include <exception>
#include <string>
#include <utility>
#include <vector>

#include "mupm/core/global_ref.hpp"
#include "mupm/mesh/discretization.hpp"

namespace mupm {

// The layout this mupm writes and reads (attribute mupm_checkpoint_version). 2: restart globals
// by name. 3: the crack water's face-area share (fracture_face_area), the run's time step
// (stable_steps/time_step) and the crack water's energy globals: a version-2 checkpoint lacks
// them, and is refused by its version rather than by a missing field. 4: only the point fields
// the run allocated (include/mupm/data/fields.hpp), their groups in the attribute
// point_field_groups.
inline constexpr long long kCheckpointVersion = 4;

// Named scalars, each pointing at its owner's value (written from it, read into it).
using NamedGlobals = std::vector<GlobalRef>;

// A setting the checkpoint's state was made under and a restart cannot change: its input path
// (e.g. "Materials->Model"), its value as text, and why the state cannot follow a change. Written
// as the attribute "input <path>"; a restart whose value differs is refused (a checkpoint without
// the attribute, from an earlier mupm, is not checked for it).
struct FixedSetting {
  std::string path, value, why;
};
using FixedSettings = std::vector<FixedSetting>;

// Collective checkpoint of points and bonds keyed by global id. The file is written beside
// `path` and renamed over it once complete.
template <int Dim>
void write_checkpoint(const std::string& path, const Discretization<Dim>& disc, long long step,
                      double time, const std::vector<double>& output_history,
                      const NamedGlobals& globals = {}, const FixedSettings& fixed = {});
// Collective check that `path` is a checkpoint of this layout version for a grid of this
// dimension, number of points, spacing and horizon, made under the same fixed settings (what
// --validate can tell without the run).
void check_checkpoint(MPI_Comm comm, const std::string& path, int dim, long long n_global,
                      double dx, double horizon, const FixedSettings& fixed = {});

// A checkpoint error as the input error it is: "Error, mupm->Solver->Restart From = 'path': ..."
// (the run and --validate both report it so).
std::string restart_from_error(const std::string& path, const std::exception& e);

// Collective restore of the step, the time, the output history, the point and bond fields and
// the named globals; then the shape tensors of the restored bonds. Throws CollectiveError (on
// every rank) when the checkpoint's version, discretization or fixed settings do not match, or a
// global is missing.
template <int Dim>
void read_checkpoint(const std::string& path, Discretization<Dim>& disc, long long& step,
                     double& time, std::vector<double>& output_history,
                     const NamedGlobals& globals = {}, const FixedSettings& fixed = {});

}  // namespace mupm

#endif
