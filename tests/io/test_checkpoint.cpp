// Checkpoint/restart keyed by global id: state written on the world communicator (1 or 2 ranks)
// is read back on one rank and must be bit-for-bit the same, points and bonds alike.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>

#include "mupm/core/error.hpp"
#include "mupm/io/checkpoint.hpp"
#include "mupm/io/hdf5_io.hpp"
#include "test_utils.hpp"

namespace mupm {
namespace {

double value(GlobalId g, int field, int c) {
  return std::sin(1e-3 * double(g) * (field + 1) + c) / 3.0 + 1e-17 * double(g);
}
bool broken(GlobalId a, GlobalId b) {
  return (a + b) % 7 == 0;
}
double energy(GlobalId a, GlobalId b) {
  return std::sqrt(double(a * 31 + b)) / 7.0;
}

// The checkpointed double fields of the registry, by name.
template <int Dim>
std::vector<std::pair<std::string, Vectors>> state_fields(const Points<Dim>& p) {
  std::vector<std::pair<std::string, Vectors>> out;
  p.for_each_field([&](const auto& view, const FieldSpec& s) {
    using V = std::decay_t<decltype(view)>;
    if constexpr (std::is_same_v<typename V::value_type, double>) {
      if (!s.has(kCheckpoint))
        return;
      if constexpr (V::rank == 1)
        out.push_back({s.name, as_vectors(view)});
      else
        out.push_back({s.name, view});
    }
  });
  return out;
}

template <int Dim>
void set_state(Discretization<Dim>& disc) {
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.gid);
  int field = 0;
  for (const auto& f : state_fields(disc.points)) {
    auto h = Kokkos::create_mirror_view(f.second);
    for (std::size_t i = 0; i < disc.points.n_owned; ++i)
      for (std::size_t c = 0; c < h.extent(1); ++c)
        h(i, c) = value(gid(i), field, int(c));
    Kokkos::deep_copy(f.second, h);
    ++field;
  }
  auto off = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.offsets);
  auto nb = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.neighbor);
  auto in = Kokkos::create_mirror_view(disc.bonds.intact);
  auto en = Kokkos::create_mirror_view(disc.bonds.energy);
  for (std::size_t i = 0; i < disc.points.n_owned; ++i)
    for (BondIndex b = off(i); b < off(i + 1); ++b) {
      in(b) = broken(gid(i), gid(nb(b))) ? 0 : 1;
      en(b) = energy(gid(i), gid(nb(b)));
    }
  Kokkos::deep_copy(disc.bonds.intact, in);
  Kokkos::deep_copy(disc.bonds.energy, en);
}

template <int Dim>
void check_state(const Discretization<Dim>& disc) {
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.gid);
  int field = 0;
  for (const auto& f : state_fields(disc.points)) {
    auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), f.second);
    for (std::size_t i = 0; i < disc.points.n_owned; ++i)
      for (std::size_t c = 0; c < h.extent(1); ++c)
        ASSERT_EQ(h(i, c), value(gid(i), field, int(c))) << f.first << " at gid " << gid(i);
    ++field;
  }
  auto off = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.offsets);
  auto nb = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.neighbor);
  auto in = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.intact);
  auto en = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.energy);
  for (std::size_t i = 0; i < disc.points.n_owned; ++i)
    for (BondIndex b = off(i); b < off(i + 1); ++b) {
      ASSERT_EQ(int(in(b)), broken(gid(i), gid(nb(b))) ? 0 : 1);
      ASSERT_EQ(en(b), energy(gid(i), gid(nb(b))));
    }
}

std::string unique_path(const std::string& stem) {
  long long id = getpid();
  MPI_Bcast(&id, 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
  return test::tmp_dir() + "/mupm_" + stem + "_" + std::to_string(id) + ".h5";
}

template <int Dim>
void round_trip(const GridSpec<Dim>& g) {
  const std::string path = unique_path("checkpoint" + std::to_string(Dim));
  {
    auto disc = discretize(test::world(), g);
    set_state(disc);
    write_checkpoint(path, disc, 42, 4.2e-3, {0, 0, 10, 1e-3});
  }
  // Every rank reads the whole body on its own: a different rank count than the writer's.
  auto disc = discretize(test::self(), g);
  long long step = 0;
  double time = 0;
  std::vector<double> history;
  read_checkpoint(path, disc, step, time, history);
  EXPECT_EQ(step, 42);
  EXPECT_EQ(time, 4.2e-3);
  EXPECT_EQ(history, (std::vector<double>{0, 0, 10, 1e-3}));
  check_state(disc);
  // Also back onto the world communicator.
  auto disc2 = discretize(test::world(), g);
  read_checkpoint(path, disc2, step, time, history);
  check_state(disc2);
  MPI_Barrier(MPI_COMM_WORLD);
  if (test::world()->getRank() == 0)
    std::remove(path.c_str());
}

TEST(Checkpoint, RoundTripAcrossRankCounts2D) {
  auto g = test::box<2>({14, 9}, 3.015);
  g.layers[1] = {3, 3};
  round_trip(g);
}

TEST(Checkpoint, RoundTripAcrossRankCounts3D) {
  round_trip(test::box<3>({6, 5, 7}, 3.015));
}

TEST(Checkpoint, MismatchIsReportedOnEveryRank) {
  const std::string path = unique_path("mismatch");
  {
    auto disc = discretize(test::world(), test::box<2>({10, 10}, 3.015));
    write_checkpoint(path, disc, 1, 1.0, {});
  }
  auto other = discretize(test::world(), test::box<2>({10, 11}, 3.015));
  long long step;
  double time;
  std::vector<double> history;
  EXPECT_THROW(read_checkpoint(path, other, step, time, history), CollectiveError);
  auto wider = discretize(test::world(), test::box<2>({10, 10}, 4.015));
  EXPECT_THROW(read_checkpoint(path, wider, step, time, history), CollectiveError);
  MPI_Barrier(MPI_COMM_WORLD);
  if (test::world()->getRank() == 0)
    std::remove(path.c_str());
}

// A run writes the datasets of the field groups it allocated (include/mupm/data/fields.hpp). A
// restart that allocates more groups (its Output->Fields names more fields) finds the others
// zero, as the writer's were; one that allocates fewer reads those it has.
TEST(Checkpoint, FieldGroupsTheWriterDidNotAllocate) {
  const auto g = test::box<2>({8, 7}, 3.015);
  const auto specs = Points<2>::specs();
  // The value of field `name` at gid, keyed by the field's place in the whole registry.
  auto expected = [&](const char* name, GlobalId gid, int c) {
    int k = 0;
    while (std::string(specs[std::size_t(k)].name) != name)
      ++k;
    return value(gid, k, c);
  };
  auto each_double = [](const Points<2>& p, auto&& f) {
    p.for_each_field([&](const auto& view, const FieldSpec& s) {
      using V = std::decay_t<decltype(view)>;
      if constexpr (std::is_same_v<typename V::value_type, double>)
        if (s.has(kCheckpoint)) {
          if constexpr (V::rank == 1)
            f(as_vectors(view), s);
          else
            f(Vectors(view), s);
        }
    });
  };
  const unsigned written = kGroupCore | kGroupPoreWater;
  for (const unsigned read : {unsigned(kAllGroups), unsigned(kGroupCore)}) {
    const std::string path = unique_path("groups");
    {
      auto disc = discretize(test::world(), g, written);
      auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.gid);
      each_double(disc.points, [&](Vectors v, const FieldSpec& s) {
        auto h = Kokkos::create_mirror_view(v);
        for (std::size_t i = 0; i < disc.points.n_owned; ++i)
          for (std::size_t c = 0; c < h.extent(1); ++c)
            h(i, c) = expected(s.name, gid(i), int(c));
        Kokkos::deep_copy(v, h);
      });
      write_checkpoint(path, disc, 7, 1e-3, {});
    }
    auto disc = discretize(test::world(), g, read);
    long long step = 0;
    double time = 0;
    std::vector<double> history;
    read_checkpoint(path, disc, step, time, history);
    auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.gid);
    int zero = 0;
    each_double(disc.points, [&](Vectors v, const FieldSpec& s) {
      auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), v);
      zero += (s.group & written) ? 0 : 1;
      for (std::size_t i = 0; i < disc.points.n_owned; ++i)
        for (std::size_t c = 0; c < h.extent(1); ++c)
          ASSERT_EQ(h(i, c), (s.group & written) ? expected(s.name, gid(i), int(c)) : 0.0)
              << s.name << " at gid " << gid(i);
    });
    EXPECT_EQ(zero > 0, read == unsigned(kAllGroups));
    MPI_Barrier(MPI_COMM_WORLD);
    if (test::world()->getRank() == 0)
      std::remove(path.c_str());
  }
}

// Restart globals travel by name; a missing one and a checkpoint of another layout version are
// clear errors on every rank.
TEST(Checkpoint, NamedGlobalsAndVersion) {
  const std::string path = unique_path("globals");
  const auto g = test::box<2>({8, 6}, 3.015);
  {
    auto disc = discretize(test::world(), g);
    double work = 1.25e-3, inflow = -7.5;
    write_checkpoint(path, disc, 3, 0.5, {},
                     {{"solid/external_work", &work}, {"fluid/inflow_top", &inflow}});
  }
  auto disc = discretize(test::world(), g);
  long long step = 0;
  double time = 0, work = 0, inflow = 0;
  std::vector<double> history;
  read_checkpoint(path, disc, step, time, history,
                  {{"fluid/inflow_top", &inflow}, {"solid/external_work", &work}});
  EXPECT_EQ(work, 1.25e-3);
  EXPECT_EQ(inflow, -7.5);
  double other = 0;
  try {
    read_checkpoint(path, disc, step, time, history, {{"fluid/inflow_bottom", &other}});
    ADD_FAILURE() << "a missing global was not reported";
  } catch (const CollectiveError& e) {
    EXPECT_NE(std::string(e.what()).find("fluid/inflow_bottom"), std::string::npos) << e.what();
  }
  MPI_Barrier(MPI_COMM_WORLD);
  {
    auto file = io::PointFile::create(MPI_COMM_WORLD, path);
    file.write_attribute("mupm_checkpoint_version", kCheckpointVersion - 1);
  }
  try {
    read_checkpoint(path, disc, step, time, history);
    ADD_FAILURE() << "an old checkpoint version was not reported";
  } catch (const CollectiveError& e) {
    EXPECT_NE(std::string(e.what()).find("version " + std::to_string(kCheckpointVersion - 1)),
              std::string::npos)
        << e.what();
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (test::world()->getRank() == 0)
    std::remove(path.c_str());
}

}  // namespace
}  // namespace mupm
