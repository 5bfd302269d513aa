#include "../input_module.hpp"

#include <algorithm>

#include "mupm/data/points.hpp"

namespace mupm {

using Teuchos::Array;
using Teuchos::ParameterList;
using Teuchos::rcp;

namespace {

void declare_output(ParameterList& o) {
  o.set("Folder", std::string("output"), "Output folder (created if missing).");
  o.set("Field Interval", 10,
        "Steps between point-field outputs (HDF5 + XDMF); 0: first and last step only.",
        at_least(0));
  o.set("Fields", Array<std::string>({"displacement", "velocity", "damage", "fracture"}),
        "Point fields written at each field output. Any of: " + joined(output_field_names()) +
            ". Global id and reference position are always written.",
        rcp(new Teuchos::ArrayStringValidator(one_of(output_field_names()))));
  o.set("Time Series Interval", 1, "Steps between rows of time_series.csv (>= 1).", at_least(1));
  o.set("Second-Order Work Window", 0,
        "Steps over which the second-order work (eq 42; field second_order_work, CSV "
        "negative_second_order_work_fraction) takes its changes; 0: Field Interval. "
        "Computed with Materials->Model = Micropolar Drucker-Prager or when Fields lists "
        "second_order_work.",
        at_least(0));
  o.set("Checkpoint Interval", 0, "Steps between checkpoints; 0: none during the run.",
        at_least(0));
  o.set("Checkpoint At End", true, "Write a checkpoint after the last step.");
  o.set("Progress Interval", 5.0,
        "Wall-clock seconds between progress lines (step, time, ETA); 0: every step.",
        at_least(0.0));
}

// The group of every field Output->Fields names: a field that is written is allocated (zero where
// no module computes it).
unsigned output_field_groups(const ParameterList& input) {
  const auto fields = input.sublist("Output").get<Array<std::string>>("Fields");
  unsigned g = 0;
  for (const auto& s : Points<3>::specs())
    if (std::find(fields.begin(), fields.end(), s.name) != fields.end())
      g |= s.group;
  return g;
}

void declare_diagnostics(ParameterList& g) {
  g.set("Kernel Timers", true,
        "Print the per-kernel time table (min/max over ranks) at the end of the run.");
  g.set("Check Finite", true,
        "Stop the run when a field holds NaN or Inf, naming the step, global id and position.");
  g.set("Write Pressure System", 0,
        "N > 0: the semi-implicit pressure solve's N-th system of the run (matrix, right-hand "
        "side) is written to Output->Folder as pressure_system_N.mtx and pressure_rhs_N.mtx "
        "(MatrixMarket, rows numbered rank by rank, gathered on rank 0), for studies of the solve "
        "outside mupm (perf/bench_pressure_solve). 0: never.",
        at_least(0));
}

}  // namespace

const std::vector<std::string>& output_field_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& s : Points<3>::specs())
      if (s.has(kOutput))
        n.push_back(s.name);
    return n;
  }();
  return names;
}

InputModule output_input() {
  return {"Output", "Files written to Output->Folder.", declare_output, nullptr,
          output_field_groups};
}

InputModule diagnostics_input() {
  return {"Diagnostics", "Checks and reports.", declare_diagnostics, nullptr, nullptr};
}

}  // namespace mupm
