// Neighbour lists against brute force (2D and 3D, with pre-cracks), and the discrete shape
// tensor of a full family against its lattice sums.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>
#include <vector>

#include "mupm/kernels/shape_tensor.hpp"
#include "test_utils.hpp"

namespace mupm {
namespace {

// Brute force: every lattice pair within the horizon, and whether the bond crosses an
// axis-aligned crack lying in the plane x_axis = level with the other coordinates within
// [lo, hi] (written out here independently of geometry.hpp).
struct FlatCrack {
  int axis;
  double level;
  double lo[3], hi[3];
};

template <int Dim>
void check_against_brute_force(const GridSpec<Dim>& g, const std::vector<FlatCrack>& flat) {
  auto disc = discretize(test::world(), g);
  const auto& pts = disc.points;
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.gid);
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.x);
  auto off = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.offsets);
  auto nb = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.neighbor);
  auto intact = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.intact);
  const GlobalId n_global = g.n_global();
  long long checked = 0;
  for (std::size_t i = 0; i < pts.n_owned; ++i) {
    const auto xi = test::position(g, gid(i));
    for (int d = 0; d < Dim; ++d)
      ASSERT_DOUBLE_EQ(x(i, d), xi[d]);
    std::vector<std::pair<GlobalId, int>> expected;  // (gid, intact), ascending gid
    for (GlobalId j = 0; j < n_global; ++j) {
      if (j == gid(i))
        continue;
      const auto xj = test::position(g, j);
      double r2 = 0;
      for (int d = 0; d < Dim; ++d)
        r2 += (xj[d] - xi[d]) * (xj[d] - xi[d]);
      if (std::sqrt(r2) > g.horizon * (1 + 1e-9))
        continue;
      int ok = 1;
      for (const auto& c : flat) {
        const double si = xi[c.axis] - c.level, sj = xj[c.axis] - c.level;
        if (si * sj >= 0)
          continue;
        const double t = si / (si - sj);
        bool inside = true;
        for (int d = 0; d < Dim; ++d) {
          if (d == c.axis)
            continue;
          const double xc = xi[d] + t * (xj[d] - xi[d]);
          if (xc < c.lo[d] || xc > c.hi[d])
            inside = false;
        }
        if (inside)
          ok = 0;
      }
      expected.emplace_back(j, ok);
    }
    ASSERT_EQ(off(i + 1) - off(i), BondIndex(expected.size())) << "point " << gid(i);
    for (std::size_t k = 0; k < expected.size(); ++k) {
      const BondIndex b = off(i) + BondIndex(k);
      ASSERT_EQ(gid(nb(b)), expected[k].first) << "point " << gid(i) << " bond " << k;
      ASSERT_EQ(int(intact(b)), expected[k].second)
          << "point " << gid(i) << " neighbour " << expected[k].first;
    }
    ++checked;
  }
  long long total = 0;
  MPI_Allreduce(&checked, &total, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(total, n_global);
}

TEST(Neighbors, BruteForce2DWithCrackAndLayers) {
  auto g = test::box<2>({13, 11}, 3.015);
  g.layers = {{{3, 0}, {3, 3}}};
  // Crack on y = 0.05 (between lattice rows) from x = 0 to 0.062 (a tip inside the body).
  Crack c;
  c.a[0] = -0.001;
  c.a[1] = 0.05;
  c.b[0] = 0.062;
  c.b[1] = 0.05;
  g.cracks = {c};
  check_against_brute_force(g, {FlatCrack{1, 0.05, {-0.001, 0, 0}, {0.062, 0, 0}}});
}

// Both copies of every bond agree on whether it crosses a pre-crack, also for the bonds through
// a crack's tip on a lattice node (geometry.hpp, bond_crosses): the tip (-0.01, 0.05) at
// dx = 2.5 mm, inside a boundary layer, where the two copies of one bond disagreed by round-off.
TEST(Neighbors, CrackTipBondsAgreeBothWays) {
  auto g = test::box<2>({16, 40}, 3.015, 0.0025);
  g.layers = {{{6, 0}, {0, 0}}};
  Crack c;
  c.a[0] = -0.01;
  c.a[1] = 0.05;
  c.b[0] = 0.02;
  c.b[1] = 0.05;
  g.cracks = {c};
  auto disc = discretize(test::world(), g);
  const auto& pts = disc.points;
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.gid);
  auto off = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.offsets);
  auto nb = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.neighbor);
  auto intact = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.intact);
  // Every directed bond (i, j, intact) of every rank, gathered on each rank.
  std::vector<long long> mine;
  for (std::size_t i = 0; i < pts.n_owned; ++i)
    for (BondIndex b = off(i); b < off(i + 1); ++b)
      mine.insert(mine.end(), {(long long)gid(i), (long long)gid(nb(b)), (long long)intact(b)});
  int size = 0, count = int(mine.size());
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  std::vector<int> counts(size), displs(size, 0);
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
  for (int r = 1; r < size; ++r)
    displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<long long> all(std::size_t(displs[size - 1] + counts[size - 1]));
  MPI_Allgatherv(mine.data(), count, MPI_LONG_LONG, all.data(), counts.data(), displs.data(),
                 MPI_LONG_LONG, MPI_COMM_WORLD);
  std::map<std::pair<long long, long long>, long long> state;
  for (std::size_t k = 0; k < all.size(); k += 3)
    state[{all[k], all[k + 1]}] = all[k + 2];
  long long pairs = 0, broken = 0;
  for (const auto& [key, ok] : state) {
    const auto back = state.find({key.second, key.first});
    ASSERT_TRUE(back != state.end()) << key.first << " -> " << key.second << " has no copy";
    ++pairs;
    broken += ok ? 0 : 1;
    EXPECT_EQ(ok, back->second) << key.first << " -> " << key.second;
  }
  EXPECT_GT(pairs, 0);
  EXPECT_GT(broken, 0);  // the crack broke bonds
}

TEST(Neighbors, BruteForce3DWithCrack) {
  auto g = test::box<3>({7, 6, 8}, 3.015);
  g.layers[2] = {3, 0};
  Crack c;  // rectangle in z = 0.04, 0 <= x <= 0.035, 0 <= y <= 0.06
  c.a[2] = 0.04;
  c.b[0] = 0.035;
  c.c[1] = 0.06;
  g.cracks = {c};
  check_against_brute_force(g, {FlatCrack{2, 0.04, {0, 0, 0}, {0.035, 0.06, 0}}});
}

TEST(Neighbors, BruteForce4Dx) {
  check_against_brute_force(test::box<2>({9, 10}, 4.015), {});
  check_against_brute_force(test::box<3>({6, 5, 7}, 4.015), {});
}

// A horizon that is a whole number of spacings (Example 1 at 66 x 66: delta = 2 dx) puts
// neighbours exactly on the horizon, on the edges of the search cells: they must be found on
// every rank count (on 2 ranks 140 such pairs were once lost at the rank boundary).
TEST(Neighbors, BruteForceWholeSpacings) {
  auto g = test::box<2>({66, 66}, 2.0, 3.75e-3);  // Example 1's coarse grid, as its input has it
  g.horizon = 7.5e-3;
  g.layers = {{{0, 2}, {2, 2}}};
  check_against_brute_force(g, {});
  check_against_brute_force(test::box<2>({11, 12}, 3.0, 2.5e-3), {});
  check_against_brute_force(test::box<3>({6, 5, 7}, 2.0, 3.75e-3), {});
}

// K11 and the family size of an interior point, in units of dx: over the lattice offsets k != 0
// with |k| <= delta/dx, K11 = sum k_x^2 and the size is their count (2D, delta = 3.015 dx: 68
// and 28).
template <int Dim>
void check_shape_tensor(double factor, double k11_units, long long n_neighbors) {
  const double dx = 0.01;
  const long long n = Dim == 2 ? 15 : 11;
  std::array<long long, Dim> counts;
  counts.fill(n);
  auto g = test::box<Dim>(counts, factor, dx);
  auto disc = discretize(test::world(), g);
  Vectors K("K", disc.points.n_owned, Dim * Dim);
  compute_shape_tensor(disc.points, disc.bonds, K);
  auto Kh = Kokkos::create_mirror_view_and_copy(HostSpace(), K);
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.gid);
  auto off = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.offsets);
  // The centre point has a full family.
  GlobalId centre = 0;
  for (int d = Dim - 1; d >= 0; --d)
    centre = centre * n + n / 2;
  const double v = std::pow(dx, Dim) * (Dim == 2 ? g.thickness : 1.0);
  int found = 0;
  for (std::size_t i = 0; i < disc.points.n_owned; ++i) {
    if (gid(i) != centre)
      continue;
    found = 1;
    EXPECT_EQ(off(i + 1) - off(i), n_neighbors);
    // K11 = sum xi_x^2 V = (sum over neighbours of (k dx)^2) dx^Dim
    EXPECT_NEAR(Kh(i, 0) / (dx * dx * v), k11_units, 1e-9 * k11_units);
    EXPECT_NEAR(Kh(i, Dim + 1), Kh(i, 0), 1e-12 * Kh(i, 0));  // isotropic
    EXPECT_NEAR(Kh(i, 1), 0.0, 1e-12 * Kh(i, 0));             // no shear part
  }
  int total = 0;
  MPI_Allreduce(&found, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(total, 1);
}

TEST(NeighborsShapeTensor, ValidationTable) {
  check_shape_tensor<2>(3.015, 68, 28);
  check_shape_tensor<2>(4.015, 192, 48);
  check_shape_tensor<3>(3.015, 236, 122);
  check_shape_tensor<3>(4.015, 796, 256);
}

}  // namespace
}  // namespace mupm
