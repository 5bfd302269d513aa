#include "mupm/io/field_output.hpp"

#include <cstdio>
#include <stdexcept>

#include "mupm/io/hdf5_io.hpp"
#include "mupm/io/point_rows.hpp"
#include "mupm/io/xdmf.hpp"

namespace mupm {

namespace {

std::string fields_file(long long step) {
  char name[64];
  std::snprintf(name, sizeof name, "fields_%09lld.h5", step);
  return name;
}

}  // namespace

template <int Dim>
FieldOutput<Dim>::FieldOutput(const std::string& folder, const Discretization<Dim>& disc,
                              const std::vector<std::string>& fields, std::vector<double> history)
    : folder_(folder), disc_(disc), fields_(fields), history_(std::move(history)) {
  const MPI_Comm comm = io::raw(*disc.dist.comm());
  const std::size_t n = disc.points.n_owned;
  const auto gids = io::owned_rows(disc.points.gid, n);
  auto file = io::PointFile::create(comm, folder + "/mesh.h5");
  const auto x = io::owned_rows(disc.points.x, n);
  file.write_points("coordinates", gids, disc.dist.n_global(), Dim, x.data());
  file.write_points("global_id", gids, disc.dist.n_global(), 1, gids.data());
  file.write_attribute("dimension", static_cast<long long>(Dim));
}

template <int Dim>
void FieldOutput<Dim>::write(long long step, double time) {
  ScopedRegion region("mupm::Output::fields");
  const MPI_Comm comm = io::raw(*disc_.dist.comm());
  const std::size_t n = disc_.points.n_owned;
  const auto gids = io::owned_rows(disc_.points.gid, n);
  const std::string name = fields_file(step);
  {
    auto file = io::PointFile::create(comm, folder_ + "/" + name);
    file.write_attribute("step", step);
    file.write_attribute("time", time);
    for (const auto& f : fields_) {
      bool found = false;
      disc_.points.for_each_field([&](const auto& view, const FieldSpec& s) {
        if (found || f != s.name || !s.has(kOutput))
          return;
        found = true;
        const auto rows = io::owned_rows<double>(view, n);
        file.write_points(f, gids, disc_.dist.n_global(), s.ncomp, rows.data());
      });
      if (!found)
        throw std::logic_error("unknown output field " + f);
    }
  }
  history_.push_back(double(step));
  history_.push_back(time);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank == 0)
    write_index();
}

template <int Dim>
void FieldOutput<Dim>::write_index() const {
  std::vector<io::XdmfStep> steps;
  for (std::size_t k = 0; k + 1 < history_.size(); k += 2) {
    const std::string name = fields_file(static_cast<long long>(history_[k]));
    io::XdmfStep s;
    s.time = history_[k + 1];
    for (const auto& f : fields_)
      for (const auto& spec : Points<Dim>::specs())
        if (f == spec.name)
          s.fields.push_back({f, spec.ncomp, name, "/" + f});
    steps.push_back(s);
  }
  io::write_xdmf(folder_ + "/fields.xmf", Dim, disc_.dist.n_global(), "mesh.h5", "/coordinates",
                 steps);
}

template class FieldOutput<2>;
template class FieldOutput<3>;

}  // namespace mupm
