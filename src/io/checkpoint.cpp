#include "mupm/io/checkpoint.hpp"

#include <Teuchos_DefaultMpiComm.hpp>
#include <filesystem>
#include <stdexcept>
#include <type_traits>

#include "mupm/core/error.hpp"
#include "mupm/io/hdf5_io.hpp"
#include "mupm/io/point_rows.hpp"

namespace mupm {

namespace io {

MPI_Comm raw(const Teuchos::Comm<int>& c) {
  const auto* m = dynamic_cast<const Teuchos::MpiComm<int>*>(&c);
  return m ? (*m->getRawMpiComm())() : MPI_COMM_SELF;
}

}  // namespace io

namespace {

// Bond data in a rank-independent table: row = global id of the owning point, columns = its
// bonds in global-id order, padded to the largest family (width, the same on every rank).
struct BondLayout {
  int width = 0;
  std::vector<long long> neighbor_gid;  // [n_owned][width], -1 in the padding
};

template <int Dim>
BondLayout bond_layout(const Discretization<Dim>& disc, MPI_Comm comm) {
  const auto off = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.offsets);
  const auto nb = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.neighbor);
  const auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.gid);
  const std::size_t n = disc.points.n_owned;
  long long w = 0;
  for (std::size_t i = 0; i < n; ++i)
    w = std::max<long long>(w, off(i + 1) - off(i));
  MPI_Allreduce(MPI_IN_PLACE, &w, 1, MPI_LONG_LONG, MPI_MAX, comm);
  BondLayout t;
  t.width = int(std::max<long long>(w, 1));
  t.neighbor_gid.assign(n * std::size_t(t.width), -1);
  for (std::size_t i = 0; i < n; ++i)
    for (BondIndex b = off(i); b < off(i + 1); ++b)
      t.neighbor_gid[i * std::size_t(t.width) + std::size_t(b - off(i))] = gid(nb(b));
  return t;
}

// A per-bond View as its table (to_table) or back (from_table); a View of ncomp components per
// bond takes ncomp columns per bond, bond after bond (row width width * ncomp).
template <class V>
std::size_t bond_components(const V& f) {
  if constexpr (V::rank == 1)
    return 1;
  else
    return f.extent(1);
}
template <class V>
std::vector<typename V::value_type> to_table(const V& f, const View1<BondIndex>& offsets,
                                             std::size_t n, int width) {
  const auto off = Kokkos::create_mirror_view_and_copy(HostSpace(), offsets);
  const auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), f);
  const std::size_t nc = bond_components(f), row = std::size_t(width) * nc;
  std::vector<typename V::value_type> t(n * row, typename V::value_type(0));
  for (std::size_t i = 0; i < n; ++i)
    for (BondIndex b = off(i); b < off(i + 1); ++b)
      for (std::size_t c = 0; c < nc; ++c) {
        auto& cell = t[i * row + std::size_t(b - off(i)) * nc + c];
        if constexpr (V::rank == 1)
          cell = h(b);
        else
          cell = h(b, c);
      }
  return t;
}
template <class V>
void from_table(const V& f, const View1<BondIndex>& offsets, std::size_t n, int width,
                const std::vector<typename V::value_type>& t) {
  const auto off = Kokkos::create_mirror_view_and_copy(HostSpace(), offsets);
  auto h = Kokkos::create_mirror_view(f);
  const std::size_t nc = bond_components(f), row = std::size_t(width) * nc;
  for (std::size_t i = 0; i < n; ++i)
    for (BondIndex b = off(i); b < off(i + 1); ++b)
      for (std::size_t c = 0; c < nc; ++c) {
        const auto cell = t[i * row + std::size_t(b - off(i)) * nc + c];
        if constexpr (V::rank == 1)
          h(b) = cell;
        else
          h(b, c) = cell;
      }
  Kokkos::deep_copy(f, h);
}

// Value types a PointFile stores: a checkpointed field of another type is a programming error.
template <class V>
constexpr bool storable() {
  using T = std::remove_const_t<typename V::value_type>;
  return std::is_same_v<T, double> || std::is_same_v<T, unsigned char> ||
         std::is_same_v<T, long long> || std::is_same_v<T, int>;
}
// f(view, spec) for every checkpointed field of a registry (Points or Bonds).
template <class Registry, class F>
void for_each_checkpointed(Registry& r, F&& f) {
  r.for_each_field([&](auto& view, const FieldSpec& s) {
    using V = std::decay_t<decltype(view)>;
    if (!s.has(kCheckpoint))
      return;
    if constexpr (storable<V>())
      f(view, s);
    else
      throw std::logic_error(std::string("checkpointed field ") + s.name +
                             " has a type the checkpoint cannot store");
  });
}

}  // namespace

namespace {

std::string fixed_attribute(const FixedSetting& f) {
  return "input " + f.path;
}

void check_header(const io::PointFile& file, const std::string& path, int dim, long long n_global,
                  double dx, double horizon, const FixedSettings& fixed) {
  const std::string where = "Error, the checkpoint '" + path + "' ";
  const long long version = file.has_attribute("mupm_checkpoint_version")
                                ? file.read_attribute_int("mupm_checkpoint_version")
                                : -1;
  if (version != kCheckpointVersion)
    throw CollectiveError(
        where +
        (version < 0 ? std::string("is not a mupm checkpoint (no mupm_checkpoint_version)")
                     : "has layout version " + std::to_string(version)) +
        "; this mupm reads version " + std::to_string(kCheckpointVersion) +
        ". Restart with the mupm that wrote it, or start the run again.");
  auto mismatch = [&](const std::string& what, const std::string& found,
                      const std::string& expected) {
    throw CollectiveError(where + "does not match this input: " + what + " is " + found +
                          " there and " + expected + " here.");
  };
  if (file.read_attribute_int("dimension") != dim)
    mismatch("the dimension", std::to_string(file.read_attribute_int("dimension")),
             std::to_string(dim));
  if (file.read_attribute_int("n_global") != n_global)
    mismatch("the number of points", std::to_string(file.read_attribute_int("n_global")),
             std::to_string(n_global));
  if (file.read_attribute_double("spacing") != dx ||
      file.read_attribute_double("horizon") != horizon)
    mismatch("the spacing/horizon",
             std::to_string(file.read_attribute_double("spacing")) + "/" +
                 std::to_string(file.read_attribute_double("horizon")),
             std::to_string(dx) + "/" + std::to_string(horizon));
  for (const auto& f : fixed) {
    const std::string name = fixed_attribute(f);
    if (!file.has_attribute(name))
      continue;
    const std::string there = file.read_attribute_string(name);
    if (there != f.value)
      throw CollectiveError(where + "was written with mupm->" + f.path + " = " + there +
                            ", and this input has " + f.value + ": " + f.why +
                            ". Restart with the checkpoint's value, or start the run again.");
  }
}

}  // namespace

void check_checkpoint(MPI_Comm comm, const std::string& path, int dim, long long n_global,
                      double dx, double horizon, const FixedSettings& fixed) {
  auto file = io::PointFile::open(comm, path);
  check_header(file, path, dim, n_global, dx, horizon, fixed);
}

std::string restart_from_error(const std::string& path, const std::exception& e) {
  std::string msg = e.what();
  if (msg.rfind("Error, ", 0) == 0)
    msg = msg.substr(7);
  return "Error, mupm->Solver->Restart From = '" + path + "': " + msg;
}

template <int Dim>
void write_checkpoint(const std::string& path, const Discretization<Dim>& disc, long long step,
                      double time, const std::vector<double>& output_history,
                      const NamedGlobals& globals, const FixedSettings& fixed) {
  ScopedRegion region("mupm::Output::checkpoint");
  const MPI_Comm comm = io::raw(*disc.dist.comm());
  const std::size_t n = disc.points.n_owned;
  const GlobalId n_global = disc.dist.n_global();
  const auto gids = io::owned_rows(disc.points.gid, n);
  const std::string tmp = path + ".tmp";
  {
    auto file = io::PointFile::create(comm, tmp);
    file.write_attribute("mupm_checkpoint_version", kCheckpointVersion);
    file.write_attribute("dimension", static_cast<long long>(Dim));
    file.write_attribute("n_global", static_cast<long long>(n_global));
    file.write_attribute("step", step);
    file.write_attribute("time", time);
    file.write_attribute("spacing", disc.grid.dx);
    file.write_attribute("horizon", disc.grid.horizon);
    file.write_attribute("point_field_groups", static_cast<long long>(disc.points.groups));
    for (const auto& f : fixed)
      file.write_attribute(fixed_attribute(f), f.value);
    file.write_global("output_history", output_history);
    for (const auto& g : globals)
      file.write_global("globals/" + g.name, {g.get()});
    for_each_checkpointed(disc.points, [&](const auto& view, const FieldSpec& s) {
      const auto rows = io::owned_rows(view, n);
      file.write_points(std::string("points/") + s.name, gids, n_global, s.ncomp, rows.data());
    });
    const auto t = bond_layout(disc, comm);
    file.write_points("bonds/neighbor_gid", gids, n_global, t.width, t.neighbor_gid.data());
    for_each_checkpointed(disc.bonds, [&](const auto& view, const FieldSpec& s) {
      const auto rows = to_table(view, disc.bonds.offsets, n, t.width);
      file.write_points(std::string("bonds/") + s.name, gids, n_global, t.width * s.ncomp,
                        rows.data());
    });
  }
  // Replace the previous checkpoint only once the new one is complete.
  MPI_Barrier(comm);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank == 0)
    std::filesystem::rename(tmp, path);
  MPI_Barrier(comm);
}

template <int Dim>
void read_checkpoint(const std::string& path, Discretization<Dim>& disc, long long& step,
                     double& time, std::vector<double>& output_history, const NamedGlobals& globals,
                     const FixedSettings& fixed) {
  ScopedRegion region("mupm::Output::restart");
  const MPI_Comm comm = io::raw(*disc.dist.comm());
  const std::size_t n = disc.points.n_owned;
  const auto gids = io::owned_rows(disc.points.gid, n);
  auto file = io::PointFile::open(comm, path);
  const std::string where = "Error, the checkpoint '" + path + "' ";
  check_header(file, path, Dim, disc.dist.n_global(), disc.grid.dx, disc.grid.horizon, fixed);
  step = file.read_attribute_int("step");
  time = file.read_attribute_double("time");
  output_history = file.read_global("output_history");
  for (const auto& g : globals) {
    if (!file.has_dataset("globals/" + g.name))
      throw CollectiveError(where + "holds no restart value '" + g.name +
                            "': it was written by a run with other physics or other boundary "
                            "conditions than this input's.");
    try {
      g.set(file.read_global("globals/" + g.name).at(0));
    } catch (const std::domain_error& e) {  // the same value, so the same error, on every rank
      throw CollectiveError(where + "is damaged: " + e.what() + ".");
    }
  }
  // A field group the writing run did not allocate (one that only this run's Output->Fields
  // asks for) has no datasets: its fields stay zero, as the writer's were.
  const unsigned written = unsigned(file.read_attribute_int("point_field_groups"));
  for_each_checkpointed(disc.points, [&](const auto& view, const FieldSpec& s) {
    if (!(s.group & written))
      return;
    std::vector<typename std::decay_t<decltype(view)>::value_type> rows(n * std::size_t(s.ncomp));
    file.read_points(std::string("points/") + s.name, gids, s.ncomp, rows.data());
    io::set_owned_rows(view, n, rows);
  });
  // The bonds must be the same ones (same neighbours in the same order) for the state to apply.
  const auto t = bond_layout(disc, comm);
  std::vector<long long> stored(t.neighbor_gid.size());
  file.read_points("bonds/neighbor_gid", gids, t.width, stored.data());
  int same = stored == t.neighbor_gid ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &same, 1, MPI_INT, MPI_MIN, comm);
  if (!same)
    throw CollectiveError(where +
                          "holds other bonds than this input makes (horizon, pre-cracks or "
                          "grid differ).");
  for_each_checkpointed(disc.bonds, [&](const auto& view, const FieldSpec& s) {
    std::vector<typename std::decay_t<decltype(view)>::value_type> rows(t.neighbor_gid.size() *
                                                                        std::size_t(s.ncomp));
    file.read_points(std::string("bonds/") + s.name, gids, t.width * s.ncomp, rows.data());
    from_table(view, disc.bonds.offsets, n, t.width, rows);
  });
  disc.update_shape();
}

#define MUPM_INSTANTIATE(D)                                                                     \
  template void write_checkpoint<D>(const std::string&, const Discretization<D>&, long long,    \
                                    double, const std::vector<double>&, const NamedGlobals&,    \
                                    const FixedSettings&);                                      \
  template void read_checkpoint<D>(const std::string&, Discretization<D>&, long long&, double&, \
                                   std::vector<double>&, const NamedGlobals&,                   \
                                   const FixedSettings&);
MUPM_INSTANTIATE(2)
MUPM_INSTANTIATE(3)
#undef MUPM_INSTANTIATE

}  // namespace mupm
