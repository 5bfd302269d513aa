// Point-field output: mesh.h5 (coordinates and global ids, once), one fields_<step>.h5 per
// output step with the fields the input names (any kOutput field of the registry, as doubles),
// and fields.xmf, the XDMF time series ParaView opens.
#ifndef MUPM_FIELD_OUTPUT_HPP
#define MUPM_FIELD_OUTPUT_HPP

#include <string>
#include <vector>

#include "mupm/mesh/discretization.hpp"

namespace mupm {

template <int Dim>
class FieldOutput {
 public:
  // Collective. `history`: the (step, time) pairs already written (from a checkpoint).
  FieldOutput(const std::string& folder, const Discretization<Dim>& disc,
              const std::vector<std::string>& fields, std::vector<double> history);
  const std::vector<double>& history() const { return history_; }
  // Collective.
  void write(long long step, double time);

 private:
  void write_index() const;

  std::string folder_;
  const Discretization<Dim>& disc_;
  std::vector<std::string> fields_;
  std::vector<double> history_;  // (step, time) pairs of the outputs written so far
};

}  // namespace mupm

#endif
