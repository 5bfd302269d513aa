#include "mupm/simulation.hpp"

#include <Teuchos_CommHelpers.hpp>
#include <Teuchos_DefaultMpiComm.hpp>
#include <Teuchos_XMLParameterListCoreHelpers.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>

#include "mupm/csv.hpp"
#include "mupm/fluid_solver.hpp"
#include "mupm/hdf5_io.hpp"
#include "mupm/solid_solver.hpp"
#include "mupm/staggered.hpp"
#include "mupm/timers.hpp"
#include "mupm/xdmf.hpp"

namespace mupm {

namespace {

MPI_Comm raw(const Teuchos::Comm<int>& c) {
  const auto* m = dynamic_cast<const Teuchos::MpiComm<int>*>(&c);
  return m ? (*m->getRawMpiComm())() : MPI_COMM_SELF;
}

// Owned rows of a device field, copied to a contiguous host array.
std::vector<double> owned_rows(const Vectors& f, std::size_t n_owned) {
  std::vector<double> out(n_owned * f.extent(1));
  Kokkos::View<double**, Kokkos::LayoutRight, HostSpace, Kokkos::MemoryUnmanaged> h(
      out.data(), n_owned, f.extent(1));
  Kokkos::deep_copy(h, Kokkos::subview(f, std::make_pair(std::size_t(0), n_owned), Kokkos::ALL));
  return out;
}

void set_owned_rows(const Vectors& f, std::size_t n_owned, const std::vector<double>& in) {
  Kokkos::View<const double**, Kokkos::LayoutRight, HostSpace, Kokkos::MemoryUnmanaged> h(
      in.data(), n_owned, f.extent(1));
  Kokkos::deep_copy(Kokkos::subview(f, std::make_pair(std::size_t(0), n_owned), Kokkos::ALL), h);
}

template <class T>
std::vector<double> owned_as_double(const View1<T>& f, std::size_t n_owned) {
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), f);
  std::vector<double> out(n_owned);
  for (std::size_t i = 0; i < n_owned; ++i)
    out[i] = double(h(i));
  return out;
}

std::vector<GlobalId> owned_gids(const GlobalIds& gid, std::size_t n_owned) {
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), gid);
  return std::vector<GlobalId>(h.data(), h.data() + n_owned);
}

}  // namespace

template <int Dim>
std::vector<NamedField> state_fields(const Points<Dim>& p) {
  return {{"displacement", p.u},
          {"velocity", p.v},
          {"acceleration", p.a},
          {"micro_rotation", p.theta},
          {"micro_rotation_rate", p.omega},
          {"micro_rotation_acceleration", p.alpha},
          {"pore_pressure", as_vectors(p.p)},
          {"pore_pressure_rate", as_vectors(p.p_rate)},
          {"fracture_pressure", as_vectors(p.pf)},
          {"fracture_pressure_rate", as_vectors(p.pf_rate)},
          {"porosity", as_vectors(p.porosity)},
          {"saturation", as_vectors(p.saturation)},
          {"relative_permeability", as_vectors(p.rel_perm)},
          {"darcy_flux", p.darcy_flux},
          {"volumetric_strain", as_vectors(p.vol_strain)},
          {"volumetric_strain_reference", as_vectors(p.vol_strain_ref)},
          {"fluid_content", as_vectors(p.fluid_content)},
          {"solid_pressure", as_vectors(p.solid_pressure)},
          {"damage", as_vectors(p.damage)},
          {"stress", p.stress},
          {"couple_stress", p.couple_stress},
          {"plastic_strain", as_vectors(p.plastic_strain)}};
}

template <int Dim>
void apply_initial_conditions(const std::vector<InitialCondition>& ics, Points<Dim>& p,
                              Kokkos::Array<double, 3> rho_w_g) {
  for (const auto& ic : ics) {
    if (ic.field == "Hydrostatic Pore Pressure") {
      Kokkos::Array<double, 3> x0{};
      for (std::size_t c = 0; c < ic.value.size() && c < 3; ++c)
        x0[c] = ic.value[c];
      const std::uint32_t mask = ic.region_mask;
      auto regions = p.regions;
      auto x = p.x;
      auto pw = p.p;
      Kokkos::parallel_for(
          "mupm::Setup::hydrostatic", range(0, p.size()), KOKKOS_LAMBDA(const std::size_t i) {
            if (mask != 0 && (regions(i) & mask) == 0)
              return;
            double s = 0;
            for (int d = 0; d < Dim; ++d)
              s += rho_w_g[d] * (x(i, d) - x0[d]);
            pw(i) = s;
          });
      continue;
    }
    Vectors target;
    for (const auto& f : state_fields(p)) {
      if ((ic.field == "Displacement" && f.name == "displacement") ||
          (ic.field == "Velocity" && f.name == "velocity") ||
          (ic.field == "Micro-Rotation" && f.name == "micro_rotation") ||
          (ic.field == "Micro-Rotation Rate" && f.name == "micro_rotation_rate") ||
          (ic.field == "Pore Pressure" && f.name == "pore_pressure") ||
          (ic.field == "Fracture Pressure" && f.name == "fracture_pressure") ||
          (ic.field == "Porosity" && f.name == "porosity") ||
          (ic.field == "Saturation" && f.name == "saturation"))
        target = f.view;
    }
    Kokkos::Array<double, 3> value{};
    for (std::size_t c = 0; c < ic.value.size() && c < 3; ++c)
      value[c] = ic.value[c];
    const std::uint32_t mask = ic.region_mask;
    auto regions = p.regions;
    const std::size_t nc = target.extent(1);
    Kokkos::parallel_for(
        "mupm::Setup::initial_condition", range(0, p.size()), KOKKOS_LAMBDA(const std::size_t i) {
          if (mask != 0 && (regions(i) & mask) == 0)
            return;
          for (std::size_t c = 0; c < nc; ++c)
            target(i, c) = value[c];
        });
  }
  Kokkos::fence();
}

template <int Dim>
void compute_damage(const Bonds& bonds, Points<Dim>& p) {
  auto offsets = bonds.offsets;
  auto neighbor = bonds.neighbor;
  auto intact = bonds.intact;
  auto volume = p.volume;
  auto damage = p.damage;
  Kokkos::parallel_for(
      "mupm::Fracture::damage", range(0, p.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        double all = 0, kept = 0;
        for (BondIndex b = offsets(i); b < offsets(i + 1); ++b) {
          const double vj = volume(neighbor(b));
          all += vj;
          kept += intact(b) * vj;
        }
        damage(i) = all > 0 ? 1.0 - kept / all : 0.0;
      });
}

namespace {

// Bond data in a rank-independent table: row = global id of the owning point, columns = its
// bonds in global-id order, padded to the largest family.
template <int Dim>
struct BondTable {
  int width = 0;
  std::vector<long long> neighbor_gid;
  std::vector<unsigned char> intact;
  std::vector<double> energy;
};

template <int Dim>
BondTable<Dim> bond_table(const Discretization<Dim>& disc, MPI_Comm comm) {
  const auto off = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.offsets);
  const auto nb = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.neighbor);
  const auto in = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.intact);
  const auto en = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.energy);
  const auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.gid);
  const std::size_t n = disc.points.n_owned;
  long long w = 0;
  for (std::size_t i = 0; i < n; ++i)
    w = std::max<long long>(w, off(i + 1) - off(i));
  MPI_Allreduce(MPI_IN_PLACE, &w, 1, MPI_LONG_LONG, MPI_MAX, comm);
  BondTable<Dim> t;
  t.width = int(std::max<long long>(w, 1));
  const std::size_t wd = std::size_t(t.width);
  t.neighbor_gid.assign(n * wd, -1);
  t.intact.assign(n * wd, 0);
  t.energy.assign(n * wd, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    for (BondIndex b = off(i); b < off(i + 1); ++b) {
      const std::size_t k = i * wd + std::size_t(b - off(i));
      t.neighbor_gid[k] = gid(nb(b));
      t.intact[k] = in(b);
      t.energy[k] = en(b);
    }
  return t;
}

}  // namespace

template <int Dim>
void write_checkpoint(const std::string& path, const Discretization<Dim>& disc, long long step,
                      double time, const std::vector<double>& output_history,
                      const std::vector<double>& solver_globals) {
  ScopedRegion region("mupm::Output::checkpoint");
  const MPI_Comm comm = raw(*disc.dist.comm());
  const std::size_t n = disc.points.n_owned;
  const GlobalId n_global = disc.dist.n_global();
  const auto gids = owned_gids(disc.points.gid, n);
  const std::string tmp = path + ".tmp";
  {
    auto file = io::PointFile::create(comm, tmp);
    file.write_attribute("mupm_checkpoint_version", 1LL);
    file.write_attribute("dimension", static_cast<long long>(Dim));
    file.write_attribute("n_global", static_cast<long long>(n_global));
    file.write_attribute("step", step);
    file.write_attribute("time", time);
    file.write_attribute("spacing", disc.grid.dx);
    file.write_attribute("horizon", disc.grid.horizon);
    file.write_global("output_history", output_history);
    file.write_global("solver_globals", solver_globals);
    for (const auto& f : state_fields(disc.points)) {
      const auto rows = owned_rows(f.view, n);
      file.write_points("points/" + f.name, gids, n_global, int(f.view.extent(1)), rows.data());
    }
    {
      auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.fracture);
      file.write_points("points/fracture", gids, n_global, 1, h.data());
    }
    const auto t = bond_table(disc, comm);
    file.write_points("bonds/neighbor_gid", gids, n_global, t.width, t.neighbor_gid.data());
    file.write_points("bonds/intact", gids, n_global, t.width, t.intact.data());
    file.write_points("bonds/energy", gids, n_global, t.width, t.energy.data());
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
                     double& time, std::vector<double>& output_history,
                     std::vector<double>* solver_globals) {
  ScopedRegion region("mupm::Output::restart");
  const MPI_Comm comm = raw(*disc.dist.comm());
  const std::size_t n = disc.points.n_owned;
  const auto gids = owned_gids(disc.points.gid, n);
  auto file = io::PointFile::open(comm, path);
  auto mismatch = [&](const std::string& what, const std::string& found,
                      const std::string& expected) {
    throw CollectiveError("Error, the checkpoint '" + path + "' does not match this input: " +
                          what + " is " + found + " there and " + expected + " here.");
  };
  if (file.read_attribute_int("dimension") != Dim)
    mismatch("the dimension", std::to_string(file.read_attribute_int("dimension")),
             std::to_string(Dim));
  if (file.read_attribute_int("n_global") != disc.dist.n_global())
    mismatch("the number of points", std::to_string(file.read_attribute_int("n_global")),
             std::to_string(disc.dist.n_global()));
  if (file.read_attribute_double("spacing") != disc.grid.dx ||
      file.read_attribute_double("horizon") != disc.grid.horizon)
    mismatch("the spacing/horizon",
             std::to_string(file.read_attribute_double("spacing")) + "/" +
                 std::to_string(file.read_attribute_double("horizon")),
             std::to_string(disc.grid.dx) + "/" + std::to_string(disc.grid.horizon));
  step = file.read_attribute_int("step");
  time = file.read_attribute_double("time");
  output_history = file.read_global("output_history");
  if (solver_globals)
    *solver_globals = file.read_global("solver_globals");
  for (const auto& f : state_fields(disc.points)) {
    std::vector<double> rows(n * f.view.extent(1));
    file.read_points("points/" + f.name, gids, int(f.view.extent(1)), rows.data());
    set_owned_rows(f.view, n, rows);
  }
  {
    auto h = Kokkos::create_mirror_view(disc.points.fracture);
    Kokkos::deep_copy(h, disc.points.fracture);
    file.read_points("points/fracture", gids, 1, h.data());
    Kokkos::deep_copy(disc.points.fracture, h);
  }
  // The bonds must be the same ones (same neighbours in the same order) for the state to apply.
  auto t = bond_table(disc, comm);
  std::vector<long long> stored(t.neighbor_gid.size());
  file.read_points("bonds/neighbor_gid", gids, t.width, stored.data());
  int same = stored == t.neighbor_gid ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &same, 1, MPI_INT, MPI_MIN, comm);
  if (!same)
    throw CollectiveError("Error, the checkpoint '" + path +
                          "' holds other bonds than this input makes (horizon, pre-cracks or "
                          "grid differ).");
  file.read_points("bonds/intact", gids, t.width, t.intact.data());
  file.read_points("bonds/energy", gids, t.width, t.energy.data());
  auto off = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.offsets);
  auto in = Kokkos::create_mirror_view(disc.bonds.intact);
  auto en = Kokkos::create_mirror_view(disc.bonds.energy);
  const std::size_t wd = std::size_t(t.width);
  for (std::size_t i = 0; i < n; ++i)
    for (BondIndex b = off(i); b < off(i + 1); ++b) {
      in(b) = t.intact[i * wd + std::size_t(b - off(i))];
      en(b) = t.energy[i * wd + std::size_t(b - off(i))];
    }
  Kokkos::deep_copy(disc.bonds.intact, in);
  Kokkos::deep_copy(disc.bonds.energy, en);
}

namespace {

// A stable-step estimate rounded down to 3 significant digits: the power iteration's sums over
// ranks differ in the last bits between rank counts, and an automatic step must not, or runs
// on different rank counts (and restarts) would diverge at round-off.
double three_digits(double x) {
  if (!(x > 0))
    return x;
  const double scale = std::pow(10.0, std::floor(std::log10(x)) - 2);
  return std::floor(x / scale * (1 + 1e-12)) * scale;
}

std::string format_seconds(double s) {
  char buf[64];
  if (s < 120)
    std::snprintf(buf, sizeof buf, "%.1f s", s);
  else if (s < 7200)
    std::snprintf(buf, sizeof buf, "%.1f min", s / 60);
  else
    std::snprintf(buf, sizeof buf, "%.2f h", s / 3600);
  return buf;
}

// Writes point fields of one output step and keeps the XDMF time series current.
template <int Dim>
class FieldOutput {
 public:
  FieldOutput(const std::string& folder, const Discretization<Dim>& disc,
              const std::vector<std::string>& fields, std::vector<double> history)
      : folder_(folder), disc_(disc), fields_(fields), history_(std::move(history)) {
    const MPI_Comm comm = raw(*disc.dist.comm());
    const std::size_t n = disc.points.n_owned;
    const auto gids = owned_gids(disc.points.gid, n);
    auto file = io::PointFile::create(comm, folder + "/mesh.h5");
    const auto x = owned_rows(disc.points.x, n);
    file.write_points("coordinates", gids, disc.dist.n_global(), Dim, x.data());
    file.write_points("global_id", gids, disc.dist.n_global(), 1, gids.data());
    file.write_attribute("dimension", static_cast<long long>(Dim));
  }

  const std::vector<double>& history() const { return history_; }

  void write(long long step, double time) {
    ScopedRegion region("mupm::Output::fields");
    const MPI_Comm comm = raw(*disc_.dist.comm());
    const std::size_t n = disc_.points.n_owned;
    const auto gids = owned_gids(disc_.points.gid, n);
    char name[64];
    std::snprintf(name, sizeof name, "fields_%09lld.h5", step);
    {
      auto file = io::PointFile::create(comm, folder_ + "/" + name);
      file.write_attribute("step", step);
      file.write_attribute("time", time);
      for (const auto& f : fields_) {
        const auto [ncomp, rows] = field_rows(f, n);
        file.write_points(f, gids, disc_.dist.n_global(), ncomp, rows.data());
      }
    }
    history_.push_back(double(step));
    history_.push_back(time);
    int rank = 0;
    MPI_Comm_rank(comm, &rank);
    if (rank == 0)
      write_index();
  }

 private:
  std::pair<int, std::vector<double>> field_rows(const std::string& f, std::size_t n) const {
    const auto& p = disc_.points;
    if (f == "fracture")
      return {1, owned_as_double(p.fracture, n)};
    if (f == "flags")
      return {1, owned_as_double(p.flags, n)};
    if (f == "regions")
      return {1, owned_as_double(p.regions, n)};
    for (const auto& s : state_fields(p))
      if (s.name == f)
        return {int(s.view.extent(1)), owned_rows(s.view, n)};
    throw std::logic_error("unknown output field " + f);
  }

  int ncomp_of(const std::string& f) const {
    for (const auto& s : state_fields(disc_.points))
      if (s.name == f)
        return int(s.view.extent(1));
    return 1;
  }

  void write_index() const {
    std::vector<io::XdmfStep> steps;
    for (std::size_t k = 0; k + 1 < history_.size(); k += 2) {
      char name[64];
      std::snprintf(name, sizeof name, "fields_%09lld.h5", static_cast<long long>(history_[k]));
      io::XdmfStep s;
      s.time = history_[k + 1];
      for (const auto& f : fields_)
        s.fields.push_back({f, ncomp_of(f), name, "/" + f});
      steps.push_back(s);
    }
    io::write_xdmf(folder_ + "/fields.xmf", Dim, disc_.dist.n_global(), "mesh.h5", "/coordinates",
                   steps);
  }

  std::string folder_;
  const Discretization<Dim>& disc_;
  std::vector<std::string> fields_;
  std::vector<double> history_;  // (step, time) pairs of the outputs written so far
};

// The largest global id of an owned point whose primary state (u, v, a, theta and its rates,
// p, p_f) holds a NaN or Inf, or -1. Every other field derives from these. One pass.
template <int Dim>
GlobalId non_finite_point(const Points<Dim>& p) {
  auto u = p.u, v = p.v, a = p.a, th = p.theta, om = p.omega, al = p.alpha;
  auto pw = p.p, pf = p.pf;
  auto gid = p.gid;
  GlobalId g = -1;
  Kokkos::parallel_reduce(
      "mupm::Diagnostics::finite", range(0, p.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, GlobalId& m) {
        bool ok = std::isfinite(pw(i)) && std::isfinite(pf(i));
        for (int k = 0; k < Dim; ++k)
          ok = ok && std::isfinite(u(i, k)) && std::isfinite(v(i, k)) && std::isfinite(a(i, k));
        for (int k = 0; k < kRotDim<Dim>; ++k)
          ok = ok && std::isfinite(th(i, k)) && std::isfinite(om(i, k)) && std::isfinite(al(i, k));
        if (!ok && gid(i) > m)
          m = gid(i);
      },
      Kokkos::Max<GlobalId>(g));
  return g;
}

// The kinematics-only model: central difference (eqs 127-136) with zero force,
// v(n+1/2) = v(n) + dt/2 a(n), u(n+1) = u(n) + dt v(n+1/2), a(n+1) = 0, v(n+1) = v(n+1/2).
template <int Dim>
void kinematic_step(const Points<Dim>& pts, double dt) {
  auto u = pts.u, v = pts.v, a = pts.a;
  auto th = pts.theta, om = pts.omega, al = pts.alpha;
  Kokkos::parallel_for(
      "mupm::Solver::integrate", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        for (int k = 0; k < Dim; ++k) {
          u(i, k) += dt * (v(i, k) + 0.5 * dt * a(i, k));
          v(i, k) += 0.5 * dt * a(i, k);
          a(i, k) = 0.0;
        }
        for (int k = 0; k < kRotDim<Dim>; ++k) {
          th(i, k) += dt * (om(i, k) + 0.5 * dt * al(i, k));
          om(i, k) += 0.5 * dt * al(i, k);
          al(i, k) = 0.0;
        }
      });
}

template <int Dim>
RunSummary run(const Teuchos::RCP<const Teuchos::Comm<int>>& comm, Teuchos::ParameterList& input,
               std::ostream& out) {
  using Clock = std::chrono::steady_clock;
  const auto t_start = Clock::now();
  const MPI_Comm mpi = raw(*comm);
  const int rank = comm->getRank();
  const auto& solver = input.sublist("Solver");
  const auto& output = input.sublist("Output");
  const auto& diag = input.sublist("Diagnostics");
  const std::string folder = output.get<std::string>("Folder");
  const bool timers_on = diag.get<bool>("Kernel Timers") && timers::enable();

  // Output folder and the resolved input, before the heavy work, so a bad folder fails early.
  int ok = 1;
  std::string why;
  if (rank == 0) {
    std::error_code ec;
    std::filesystem::create_directories(folder, ec);
    if (ec) {
      ok = 0;
      why = ec.message();
    } else {
      try {
        Teuchos::writeParameterListToXmlFile(input, folder + "/input_resolved.xml");
      } catch (const std::exception& e) {
        ok = 0;
        why = e.what();
      }
    }
  }
  Teuchos::broadcast(*comm, 0, &ok);
  if (!ok)
    throw CollectiveError("Error, cannot write to the output folder '" + folder +
                          "' (Output->Folder)" + (why.empty() ? "" : ": " + why));

  const GridSpec<Dim> grid = grid_from_input<Dim>(input);
  Discretization<Dim> disc = discretize(comm, grid);
  Points<Dim>& pts = disc.points;
  long long n_bonds_local = static_cast<long long>(disc.bonds.size()), n_bonds = 0;
  MPI_Allreduce(&n_bonds_local, &n_bonds, 1, MPI_LONG_LONG, MPI_SUM, mpi);
  long long n_ghost = static_cast<long long>(pts.n_ghost), n_ghost_total = 0;
  MPI_Allreduce(&n_ghost, &n_ghost_total, 1, MPI_LONG_LONG, MPI_SUM, mpi);
  const long long n_global = disc.dist.n_global();
  if (rank == 0) {
    out << "mupm: " << Dim << "D, " << n_global << " points (" << n_ghost_total
        << " ghost copies), " << n_bonds << " bonds, dx = " << grid.dx
        << " m, horizon = " << grid.horizon << " m (" << grid.horizon / grid.dx << " dx)\n"
        << "mupm: " << comm->getSize() << " rank(s) x " << ExecSpace().concurrency() << " "
        << ExecSpace::name() << " thread(s); " << Points<Dim>::bytes_per_point()
        << " bytes per point, " << disc.bonds.bytes_per_bond() << " bytes per bond\n";
  }

  const auto& materials = input.sublist("Materials");
  const auto& fluid_input = input.sublist("Fluid");
  const double rho_w = fluid_input.get<double>("Water Density");
  Kokkos::Array<double, 3> gravity{}, rho_w_g{};
  {
    const auto g = solver.get<Teuchos::Array<double>>("Gravity");
    for (Teuchos::Ordinal k = 0; k < g.size() && k < 3; ++k) {
      gravity[k] = g[k];
      rho_w_g[k] = rho_w * g[k];
    }
  }
  Kokkos::deep_copy(pts.porosity, materials.get<double>("Porosity"));
  Kokkos::deep_copy(pts.saturation, 1.0);  // saturated unless an initial condition says otherwise
  apply_initial_conditions(initial_conditions_from_input(input), pts, rho_w_g);
  long long step = 0;
  double time = 0;
  std::vector<double> history, solver_globals;
  const std::string restart = solver.get<std::string>("Restart From");
  if (!restart.empty()) {
    read_checkpoint(restart, disc, step, time, history, &solver_globals);
    if (rank == 0)
      out << "mupm: restarted from " << restart << " at step " << step << "\n";
  }
  compute_damage(disc.bonds, pts);
  const auto ghosted = [&] {
    return std::vector<Vectors>{
        pts.u, pts.v, pts.theta, as_vectors(pts.p), as_vectors(pts.pf), as_vectors(pts.damage)};
  }();
  disc.dist.refresh(ghosted);

  // The physics: the micropolar solid step, the pore-fluid step, both (staggered), or
  // kinematics only.
  const std::string physics = solver.get<std::string>("Physics");
  const bool solid = physics == "Micropolar Solid" || physics == "Hydro-Mechanical";
  const bool fluid = physics == "Pore Fluid" || physics == "Hydro-Mechanical";
  const auto bcs = boundary_conditions_from_input(input);
  std::unique_ptr<SolidSolver<Dim>> solid_solver;
  std::unique_ptr<FluidSolver<Dim>> fluid_solver;
  double dt = solver.get<double>("Time Step");
  const double safety = solver.get<double>("Time Step Safety Factor");
  const bool automatic_dt = solver.get<bool>("Automatic Time Step");
  const std::size_t solid_globals = solid ? SolidSolver<Dim>::n_globals + 1 : 0;
  if (fluid) {
    FluidParams fp;
    fp.water_density = rho_w;
    fp.bulk_modulus = fluid_input.get<double>("Fluid Bulk Modulus");
    const double k = fluid_input.get<double>("Intrinsic Permeability");
    fp.mobility =
        k > 0 ? k / fluid_input.get<double>("Viscosity")
              : fluid_input.get<double>("Hydraulic Conductivity") / (rho_w * kStandardGravity);
    if (fluid_input.get<std::string>("Retention Model") == "Van Genuchten") {
      const double n = fluid_input.get<double>("Van Genuchten n");
      fp.retention = VanGenuchten::mualem(fluid_input.get<double>("Air Entry Pressure"), n);
      const double m = fluid_input.get<double>("Van Genuchten m");
      if (m > 0)
        fp.retention.m = m;
    }
    fp.stabilization = fluid_input.get<double>("Flow Stabilization");
    fp.horizon_volume = grid.family_volume();
    fp.second_moment = family_second_moment<Dim>(grid.horizon, grid.thickness);
    if (fluid_input.get<bool>("Gravity In Darcy Flux"))
      fp.gravity = gravity;
    fluid_solver = std::make_unique<FluidSolver<Dim>>(disc, fp, bcs, mpi);
    if (solver_globals.size() > solid_globals)
      fluid_solver->set_globals(
          std::vector<double>(solver_globals.begin() + long(solid_globals), solver_globals.end()));
    fluid_solver->initialize(time, !restart.empty());
  }
  if (solid) {
    SolidParams prm;
    prm.law = MicropolarElastic::from_bulk_shear(
        materials.get<double>("Bulk Modulus"), materials.get<double>("Shear Modulus"),
        materials.get<double>("Micropolar Shear Modulus"), materials.get<double>("Length Scale"));
    prm.stabilization = materials.get<double>("Stabilization");
    const std::string sm = materials.get<std::string>("Stabilization Modulus");
    prm.stab_modulus =
        stabilization_modulus<Dim>(prm.law, grid.horizon, grid.thickness,
                                   sm == "Eq 71"           ? StabilizationModulus::Eq71
                                   : sm == "Bulk Matching" ? StabilizationModulus::BulkMatching
                                                           : StabilizationModulus::Automatic);
    prm.horizon_volume = grid.family_volume();
    typename SolidSolver<Dim>::Settings settings;
    settings.rho_s = materials.get<double>("Solid Density");
    settings.rho_w = rho_w;
    settings.gravity = gravity;
    settings.damping = solver.get<double>("Damping");
    solid_solver = std::make_unique<SolidSolver<Dim>>(disc, prm, bcs, settings, mpi);
    solid_solver->set_globals(solver_globals);
    solid_solver->initialize(time, !restart.empty());
    if (fluid && restart.empty())
      fluid_solver->reset_strain_reference();
    const double stiffening = fluid ? fluid_solver->undrained_stiffening() : 0.0;
    const double stable = three_digits(solid_solver->estimate_stable_dt());
    if (automatic_dt)
      dt = safety * stable;
    if (rank == 0) {
      out << "mupm: micropolar solid, stabilization G = " << prm.stabilization
          << ", D = " << prm.stab_modulus << " Pa/m^2; estimated stable dt = " << stable << " s"
          << (fluid ? " (undrained: the pore water adds up to " : "");
      if (fluid)
        out << stiffening << " Pa to the bulk modulus)";
      out << "; dt = " << dt << " s\n";
      if (dt > safety * stable)
        out << "mupm: WARNING: Solver->Time Step = " << dt << " s exceeds "
            << "Time Step Safety Factor x the estimated stable step = " << safety * stable
            << " s: the run may blow up. Use a smaller Time Step or Automatic Time Step.\n";
    }
  }
  // The fluid advances every `fluid_every` solid steps (1 without a solid) over that interval,
  // in `fluid_substeps` equal steps.
  const int fluid_every = solid ? solver.get<int>("Solid Steps Per Fluid Step") : 1;
  int fluid_substeps = solver.get<int>("Fluid Substeps");
  const bool fluid_first = solver.get<std::string>("Staggering") == "Fluid First";
  if (fluid) {
    const double stable_f = three_digits(fluid_solver->estimate_stable_dt());
    if (!solid && automatic_dt)
      dt = safety * stable_f;
    const double interval = fluid_every * dt;
    if (fluid_substeps == 0)
      fluid_substeps = std::max(1, int(std::ceil(interval / (safety * stable_f) - 1e-9)));
    const double dt_f = interval / fluid_substeps;
    if (rank == 0) {
      out << "mupm: pore fluid, k/mu_w = " << fluid_solver->params().mobility
          << " m^2/(Pa s), K_w = " << fluid_solver->params().bulk_modulus
          << " Pa, flow stabilization G = " << fluid_solver->params().stabilization
          << "; estimated stable fluid dt = " << stable_f << " s; fluid dt = " << dt_f << " s ("
          << fluid_substeps << " substep(s) every " << fluid_every << " step(s), "
          << (solid ? (fluid_first ? "fluid first" : "solid first") : "fluid only") << ")\n";
      if (dt_f > safety * stable_f)
        out << "mupm: WARNING: the fluid step " << dt_f << " s exceeds Time Step Safety Factor x "
            << "the estimated stable fluid step = " << safety * stable_f
            << " s: the pressure may blow up. Raise Solver->Fluid Substeps (0: automatic).\n";
    }
  }
  Staggered<Dim> staggered{solid_solver.get(), fluid_solver.get(), fluid_first, fluid_every,
                           fluid_substeps};
  const long long n_steps = solver.get<int>("Number of Steps");
  const long long first_step = step, last_step = n_steps;
  const int field_interval = output.get<int>("Field Interval");
  const int series_interval = output.get<int>("Time Series Interval");
  const int checkpoint_interval = output.get<int>("Checkpoint Interval");
  const double progress_interval = output.get<double>("Progress Interval");
  const bool check_finite = diag.get<bool>("Check Finite");
  const auto field_names = output.get<Teuchos::Array<std::string>>("Fields");
  FieldOutput<Dim> fields(folder, disc, {field_names.begin(), field_names.end()}, history);
  std::unique_ptr<io::CsvWriter> csv;
  std::vector<std::string> columns{"step", "time", "max_displacement", "mean_damage",
                                   "broken_bonds"};
  if (solid) {
    for (const char* c : {"internal_energy", "kinetic_energy", "external_work", "dissipation",
                          "pore_pressure_work", "energy_error"})
      columns.push_back(c);
    for (const auto& r : solid_solver->reaction_names())
      columns.push_back(r);
  }
  if (fluid) {
    for (const char* c : {"fluid_stored_energy", "fluid_coupling_work", "fluid_dissipation",
                          "fluid_external_work", "fluid_energy_error"})
      columns.push_back(c);
    columns.push_back("fluid_mass");
    for (const auto& r : fluid_solver->inflow_names())
      columns.push_back(r);
  }
  columns.push_back("wall_seconds");
  if (rank == 0)
    csv = std::make_unique<io::CsvWriter>(folder + "/time_series.csv", columns, !restart.empty());
  // Energy balance (eqs 137-140): E_int + E_kin + D - W_ext stays at its initial value.
  double energy0 = solid ? solid_solver->energy().balance() : 0.0;
  if (solid && solver_globals.size() >= solid_globals)
    energy0 = solver_globals[solid_globals - 1];
  const double energy_tol = solver.get<double>("Energy Tolerance");
  const bool energy_stop = solver.get<bool>("Stop On Energy Violation");
  long long energy_warnings = 0, fluid_energy_warnings = 0;
  const long long energy_skip = solver.get<int>("Energy Check Start");
  auto solver_state = [&] {
    auto g = solid ? solid_solver->globals() : std::vector<double>{};
    if (solid)
      g.push_back(energy0);
    if (fluid)
      for (double v : fluid_solver->globals())
        g.push_back(v);
    return g;
  };

  auto write_series = [&] {
    ScopedRegion region("mupm::Output::time_series");
    auto u = pts.u;
    auto damage = pts.damage;
    auto volume = pts.volume;
    double umax2 = 0, dam = 0, vol = 0;
    Kokkos::parallel_reduce(
        "mupm::Diagnostics::globals", range(0, pts.n_owned),
        KOKKOS_LAMBDA(const std::size_t i, double& m, double& d, double& v) {
          double s = 0;
          for (int k = 0; k < Dim; ++k)
            s += u(i, k) * u(i, k);
          m = s > m ? s : m;
          d += damage(i) * volume(i);
          v += volume(i);
        },
        Kokkos::Max<double>(umax2), dam, vol);
    long long broken = 0;
    auto intact = disc.bonds.intact;
    Kokkos::parallel_reduce(
        "mupm::Diagnostics::broken_bonds", range(0, disc.bonds.size()),
        KOKKOS_LAMBDA(const std::size_t b, long long& c) { c += intact(b) ? 0 : 1; }, broken);
    // Sums over ranks in a fixed order would be needed for bit-equal sums; these are reports.
    double sums[2] = {dam, vol};
    MPI_Allreduce(MPI_IN_PLACE, &umax2, 1, MPI_DOUBLE, MPI_MAX, mpi);
    MPI_Allreduce(MPI_IN_PLACE, sums, 2, MPI_DOUBLE, MPI_SUM, mpi);
    MPI_Allreduce(MPI_IN_PLACE, &broken, 1, MPI_LONG_LONG, MPI_SUM, mpi);
    std::vector<double> row{double(step), time, std::sqrt(umax2),
                            sums[1] > 0 ? sums[0] / sums[1] : 0.0,
                            double(broken) / 2};  // each bond is listed by both its ends
    if (solid) {
      const auto e = solid_solver->energy();
      for (double v : {e.internal, e.kinetic, e.external_work, e.dissipation, e.pore_work,
                       e.balance() - energy0})
        row.push_back(v);
      for (double r : solid_solver->reactions())
        row.push_back(r);
    }
    if (fluid) {
      const auto e = fluid_solver->energy();
      for (double v :
           {e.stored - e.stored0, e.coupling_work, e.dissipation, e.external_work, e.balance()})
        row.push_back(v);
      row.push_back(fluid_solver->fluid_mass());
      for (double r : fluid_solver->inflows())
        row.push_back(r);
    }
    row.push_back(std::chrono::duration<double>(Clock::now() - t_start).count());
    if (csv)
      csv->row(row);
  };

  if (restart.empty())
    fields.write(step, time);
  if (restart.empty())
    write_series();
  const auto t_loop = Clock::now();
  auto t_last_progress = t_loop;
  const std::string checkpoint_path = folder + "/checkpoint.h5";

  while (step < last_step) {
    {
      ScopedRegion region("mupm::Solver::step");
      if (solid && fluid) {
        staggered.step(step, time, dt);
        compute_damage(disc.bonds, pts);
      } else if (solid) {
        solid_solver->step(time, dt);
        compute_damage(disc.bonds, pts);
      } else if (fluid) {
        fluid_solver->advance(time, dt, fluid_substeps);
      } else {
        kinematic_step(pts, dt);
        compute_damage(disc.bonds, pts);
        disc.dist.refresh(ghosted);
      }
    }
    ++step;
    time += dt;
    // Energy balances (eqs 140 and 149): warn, or stop, beyond the tolerance.
    auto check_balance = [&](const char* what, const char* balance, double err, double scale,
                             long long& warnings) {
      if (step - first_step <= energy_skip || !(err > energy_tol * scale && scale > 0))
        return;
      std::ostringstream s;
      s << what << " energy balance violated at step " << step << " (t = " << time << " s): |"
        << balance << "| = " << err << " J is " << err / scale
        << " of the largest term (Solver->Energy Tolerance = " << energy_tol << ")";
      if (energy_stop)
        throw CollectiveError("Error, " + s.str() + ".");
      if (rank == 0 && (warnings < 5 || warnings % 1000 == 0))
        out << "mupm: WARNING: " << s.str() << "\n";
      ++warnings;
    };
    if (solid) {
      const auto e = solid_solver->energy();
      check_balance("solid", "E_int + E_kin + D - W_ext - W_pore - E_0",
                    std::abs(e.balance() - energy0), e.scale(), energy_warnings);
    }
    if (fluid) {
      const auto e = fluid_solver->energy();
      check_balance("fluid", "E_s - E_s0 + W_c + D - W_ext", std::abs(e.balance()), e.scale(),
                    fluid_energy_warnings);
    }
    if (check_finite) {
      GlobalId bad = non_finite_point(pts);
      MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPI_LONG_LONG, MPI_MAX, mpi);
      if (bad >= 0) {
        // The owner supplies the position; the sum over ranks hands it to everyone.
        double where[3] = {0, 0, 0};
        auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.gid);
        auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.x);
        for (std::size_t i = 0; i < pts.n_owned; ++i)
          if (gid(i) == bad)
            for (int k = 0; k < Dim; ++k)
              where[k] = x(i, k);
        MPI_Allreduce(MPI_IN_PLACE, where, 3, MPI_DOUBLE, MPI_SUM, mpi);
        std::ostringstream s;
        s << "Error, a field is NaN or Inf at step " << step << " (t = " << time
          << " s), at the point with global id " << bad << ", reference position (" << where[0]
          << ", " << where[1] << (Dim == 3 ? ", " + std::to_string(where[2]) : std::string())
          << ") m.";
        throw CollectiveError(s.str());
      }
    }
    if (step % series_interval == 0 || step == last_step)
      write_series();
    if ((field_interval > 0 && step % field_interval == 0) || step == last_step)
      fields.write(step, time);
    if (checkpoint_interval > 0 && step % checkpoint_interval == 0 && step != last_step)
      write_checkpoint(checkpoint_path, disc, step, time, fields.history(), solver_state());
    const auto now = Clock::now();
    if (rank == 0 &&
        (std::chrono::duration<double>(now - t_last_progress).count() >= progress_interval ||
         step == last_step)) {
      t_last_progress = now;
      const double el = std::chrono::duration<double>(now - t_loop).count();
      const double done = double(step - first_step), left = double(last_step - step);
      char line[256];
      std::snprintf(line, sizeof line,
                    "step %lld/%lld (%.1f%%)  t = %.6g s  elapsed %s  ETA %s  %.3g point-steps/s\n",
                    step, last_step, 100.0 * double(step) / double(last_step), time,
                    format_seconds(el).c_str(),
                    format_seconds(done > 0 ? el / done * left : 0).c_str(),
                    el > 0 ? double(n_global) * done / el : 0.0);
      out << line << std::flush;
    }
  }
  if (output.get<bool>("Checkpoint At End"))
    write_checkpoint(checkpoint_path, disc, step, time, fields.history(), solver_state());

  RunSummary summary;
  summary.steps = step - first_step;
  summary.wall_seconds = std::chrono::duration<double>(Clock::now() - t_loop).count();
  summary.n_points = n_global;
  summary.n_bonds = n_bonds;
  if (timers_on) {
    timers::report(mpi, out);
    timers::disable();
  }
  if (rank == 0 && summary.steps > 0 && summary.wall_seconds > 0) {
    char line[256];
    std::snprintf(line, sizeof line,
                  "mupm: %lld steps in %s: %.4g point-steps/s, %.4g bond-updates/s\n",
                  summary.steps, format_seconds(summary.wall_seconds).c_str(),
                  double(n_global) * double(summary.steps) / summary.wall_seconds,
                  double(n_bonds) * double(summary.steps) / summary.wall_seconds);
    out << line;
  }
  return summary;
}

}  // namespace

RunSummary run_simulation(const Teuchos::RCP<const Teuchos::Comm<int>>& comm,
                          Teuchos::ParameterList& input, std::ostream& out) {
  return input_dimension(input) == 2 ? run<2>(comm, input, out) : run<3>(comm, input, out);
}

#define MUPM_INSTANTIATE(D)                                                                     \
  template std::vector<NamedField> state_fields<D>(const Points<D>&);                           \
  template void apply_initial_conditions<D>(const std::vector<InitialCondition>&, Points<D>&,   \
                                            Kokkos::Array<double, 3>);                          \
  template void compute_damage<D>(const Bonds&, Points<D>&);                                    \
  template void write_checkpoint<D>(const std::string&, const Discretization<D>&, long long,    \
                                    double, const std::vector<double>&,                         \
                                    const std::vector<double>&);                                \
  template void read_checkpoint<D>(const std::string&, Discretization<D>&, long long&, double&, \
                                   std::vector<double>&, std::vector<double>*);
MUPM_INSTANTIATE(2)
MUPM_INSTANTIATE(3)
#undef MUPM_INSTANTIATE

}  // namespace mupm
