// Distribution: the partition covers every point once, ghost values equal their owners', the
// bond list by global ids does not depend on the number of ranks, and exact sums over ranks
// (core/exact_sum.hpp) do not depend on the order or split of their terms.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>

#include "mupm/core/exact_sum.hpp"
#include "mupm/core/timers.hpp"
#include "mupm/kernels/boundary_conditions.hpp"
#include "test_utils.hpp"

namespace mupm {
namespace {

double field_value(GlobalId g, int c) {
  return std::sin(0.37 * double(g) + 1.3 * c) * 1e3 + g;
}

template <int Dim>
void check_ghosts(const GridSpec<Dim>& g) {
  auto disc = discretize(test::world(), g);
  auto& pts = disc.points;
  // Owned values from the global id; ghosts poisoned; the refresh must bring the owners' values.
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.gid);
  auto u = Kokkos::create_mirror_view(pts.u);
  auto p = Kokkos::create_mirror_view(pts.p);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const bool owned = i < pts.n_owned;
    for (int d = 0; d < Dim; ++d)
      u(i, d) = owned ? field_value(gid(i), d) : NAN;
    p(i) = owned ? -field_value(gid(i), 7) : NAN;
  }
  Kokkos::deep_copy(pts.u, u);
  Kokkos::deep_copy(pts.p, p);
  disc.dist.refresh({pts.u, as_vectors(pts.p)});
  Kokkos::deep_copy(u, pts.u);
  Kokkos::deep_copy(p, pts.p);
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.x);
  for (std::size_t i = pts.n_owned; i < pts.size(); ++i) {
    for (int d = 0; d < Dim; ++d)
      ASSERT_EQ(u(i, d), field_value(gid(i), d)) << "ghost " << gid(i);
    ASSERT_EQ(p(i), -field_value(gid(i), 7));
    // Constants travelled once at set-up: the ghost's position is its owner's.
    const auto xg = test::position(g, gid(i));
    for (int d = 0; d < Dim; ++d)
      ASSERT_EQ(x(i, d), xg[d]);
  }
  // Every neighbour of an owned point is present locally (owned or ghost).
  EXPECT_EQ(disc.dist.refresh_count(), 2u);
  long long n = static_cast<long long>(pts.n_owned), total = 0;
  MPI_Allreduce(&n, &total, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(total, g.n_global());
}

TEST(Distribution, GhostsEqualOwners2D) {
  auto g = test::box<2>({20, 9}, 3.015);
  g.layers[1] = {3, 3};
  check_ghosts(g);
}

// The mirrors of the boundary-layer points (Boundary Layer Values = Mirrored): column d of
// Discretization::mirror holds, for a point outside the face of axis d, the point reflected
// across that face (x_m = 2 face - x on axis d, the rest unchanged; layers thicker than the body
// clamp into it) and column Dim the same for points outside one face only. The body is 4 points
// across x with 3-row layers, so on 2 ranks the cut falls within the layers' reach and some
// mirrors are ghosts beyond the horizon.
template <int Dim>
void check_mirrors(GridSpec<Dim> g) {
  g.mirrored_layers = true;
  auto disc = discretize(test::world(), g);
  const auto& pts = disc.points;
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.x);
  auto m = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.mirror);
  ASSERT_EQ(m.extent(0), pts.n_owned);
  long long checked = 0;
  for (std::size_t i = 0; i < pts.n_owned; ++i) {
    int outside = 0;
    for (int d = 0; d < Dim; ++d) {
      const double lo = g.origin[d], hi = lo + g.counts[d] * g.dx;
      const bool out = x(i, d) < lo || x(i, d) > hi;
      outside += out;
      ASSERT_EQ(m(i, d) >= 0, out) << "point " << i << " axis " << d;
      if (!out)
        continue;
      double want = x(i, d) < lo ? 2 * lo - x(i, d) : 2 * hi - x(i, d);
      want = std::min(std::max(want, lo + 0.5 * g.dx), hi - 0.5 * g.dx);  // clamped
      for (int e = 0; e < Dim; ++e)
        ASSERT_NEAR(x(m(i, d), e), e == d ? want : x(i, e), 1e-12) << "point " << i;
      ++checked;
    }
    ASSERT_EQ(m(i, Dim), outside == 1 ? [&] {
      for (int d = 0; d < Dim; ++d)
        if (m(i, d) >= 0)
          return m(i, d);
      return -1;
    }()
                                      : -1);
  }
  long long total = 0;
  MPI_Allreduce(&checked, &total, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_GT(total, 0);
}

// A ghost refresh of a width it has refreshed before allocates nothing: its buffers are kept
// per width (a step refreshes several widths in turn). The allocation counter the runs report
// (timers::time_loop) must see a View allocated inside the loop.
TEST(Distribution, RefreshOfKnownWidthsAllocatesNothing) {
  auto disc = discretize(test::world(), test::box<2>({12, 10}, 3.015));
  auto& pts = disc.points;
  const std::vector<Vectors> narrow{pts.u}, wide{pts.u, as_vectors(pts.p), pts.x};
  disc.dist.refresh(narrow);
  disc.dist.refresh(wide);
  if (!timers::enable())
    GTEST_SKIP() << "an external Kokkos tool holds the callbacks";
  timers::reset();
  timers::time_loop(true);
  disc.dist.refresh(narrow);
  disc.dist.refresh(wide);
  disc.dist.refresh(narrow);
  const long long during_refreshes = timers::loop_allocations();
  Scalars one("one", 4);  // the counter's positive control
  const long long with_one = timers::loop_allocations();
  timers::time_loop(false);
  timers::disable();
  EXPECT_EQ(during_refreshes, 0);
  EXPECT_EQ(with_one, 1);
}

// Kokkos allocates each OpenMP thread's scratch in that thread (a reduction whose scratch grows
// inside the time loop), so the allocation counter is called from all threads at once: it counts
// every call, and neither crashes nor loses one. The concurrent calls are made directly, many of
// them with labels new to the tally, as the pool's own resize makes too few to race reliably.
TEST(Distribution, AllocationCounterTakesConcurrentCalls) {
  if (!timers::enable())
    GTEST_SKIP() << "an external Kokkos tool holds the callbacks";
  timers::reset();
  timers::time_loop(true);
  constexpr int calls = 40000;
  const auto host = Kokkos::Profiling::make_space_handle(Kokkos::HostSpace::name());
  Kokkos::parallel_for(
      "concurrent_allocations", Kokkos::RangePolicy<Kokkos::DefaultHostExecutionSpace>(0, calls),
      [=](int i) {
        Kokkos::Profiling::allocateData(host, "label " + std::to_string(i % 4000), nullptr, 8);
      });
  const long long counted = timers::loop_allocations();
  timers::time_loop(false);
  timers::disable();
  EXPECT_EQ(counted, calls);
}

TEST(Distribution, LayerMirrors2D) {
  auto g = test::box<2>({4, 5}, 1.5);
  g.layers = {{{3, 3}, {2, 2}}};
  check_mirrors(g);
}

TEST(Distribution, LayerMirrors3D) {
  auto g = test::box<3>({4, 3, 3}, 1.5);
  g.layers = {{{3, 3}, {2, 0}, {0, 2}}};
  check_mirrors(g);
}

// A mirrored Displacement layer (mirror_kinematic) is the body's mirror image about u_n = g:
// a field that already has that symmetry about the face (u_n - g odd, u_t even, theta axial:
// theta_n even, theta_t odd; in 2D theta_z odd) continues into the layer unchanged. The field is
// set on the body only (the layer poisoned), so a wrong parity or sign of any component, or a
// wrong mirror, leaves the layer off the field. Face x = hi (3D) or y = lo (2D).
template <int Dim>
void check_mirror_image(GridSpec<Dim> g, int axis, int side) {
  constexpr int R = kRotDim<Dim>;
  g.mirrored_layers = true;
  const double face = g.origin[axis] + side * g.counts[axis] * g.dx, gn = 2.5e-3;
  Box out;  // the layer beyond the face
  for (int d = 0; d < Dim; ++d) {
    out.lo[d] = -10;
    out.hi[d] = 10;
  }
  (side ? out.lo : out.hi)[axis] = face + (side ? 0.25 : -0.25) * g.dx;
  g.regions = {out};
  auto disc = discretize(test::world(), g);
  auto& pts = disc.points;
  // Symmetric about the face: s = x_n - face enters u_n - g and theta_t oddly, the rest evenly.
  auto field = [&](const double* x, double* u, double* th) {
    const double s = x[axis] - face;
    double even = 1;
    for (int d = 0; d < Dim; ++d)
      if (d != axis)
        even += 0.3 * (d + 1) * x[d] + 0.1 * x[d] * x[d];
    for (int k = 0; k < Dim; ++k)
      u[k] = k == axis ? gn + s * even + 0.2 * s * s * s : (k + 2) * even + 0.7 * s * s;
    for (int r = 0; r < R; ++r) {
      const bool normal = R == 3 && r == axis;
      th[r] = normal ? 0.4 * even + s * s : (r + 1) * s * even;
    }
  };
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.x);
  auto flags = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.flags);
  auto u = Kokkos::create_mirror_view(pts.u);
  auto th = Kokkos::create_mirror_view(pts.theta);
  auto v = Kokkos::create_mirror_view(pts.v);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    double xi[3] = {0, 0, 0}, ui[3], ti[3];
    for (int d = 0; d < Dim; ++d)
      xi[d] = x(i, d);
    field(xi, ui, ti);
    const bool layer = flags(i) & kFlagBoundaryLayer;
    for (int d = 0; d < Dim; ++d)
      u(i, d) = v(i, d) = layer ? NAN : ui[d];
    for (int r = 0; r < R; ++r)
      th(i, r) = layer ? NAN : ti[r];
  }
  Kokkos::deep_copy(pts.u, u);
  Kokkos::deep_copy(pts.theta, th);
  Kokkos::deep_copy(pts.v, v);
  BoundaryCondition bc;
  bc.kind = BoundaryCondition::Displacement;
  bc.component = axis;
  bc.value = gn;
  bc.mirrored = true;
  bc.region_mask = 1u << 0;
  bc.mirror_column = axis;
  mirror_kinematic(bc, pts, disc.mirror, 0.0);
  Kokkos::deep_copy(u, pts.u);
  Kokkos::deep_copy(th, pts.theta);
  Kokkos::deep_copy(v, pts.v);
  auto m = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.mirror);
  long long n = 0;
  for (std::size_t i = 0; i < pts.n_owned; ++i) {
    if (!(side ? x(i, axis) > face : x(i, axis) < face) || m(i, Dim) < 0)
      continue;
    double xi[3] = {0, 0, 0}, ui[3], ti[3];
    for (int d = 0; d < Dim; ++d)
      xi[d] = x(i, d);
    field(xi, ui, ti);
    for (int d = 0; d < Dim; ++d) {
      EXPECT_NEAR(u(i, d), ui[d], 1e-12 * (1 + std::abs(ui[d]))) << "point " << i << " u " << d;
      // v = u on the body and g' = 0, so v_n = -u_n(m) = u_n - 2 g in the layer.
      const double vn = d == axis ? ui[d] - 2 * gn : ui[d];
      EXPECT_NEAR(v(i, d), vn, 1e-12 * (1 + std::abs(ui[d]))) << "point " << i << " v " << d;
    }
    for (int r = 0; r < R; ++r)
      EXPECT_NEAR(th(i, r), ti[r], 1e-12 * (1 + std::abs(ti[r]))) << "point " << i << " th " << r;
    ++n;
  }
  long long total = 0;
  MPI_Allreduce(&n, &total, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_GT(total, 0);
}

TEST(Distribution, MirroredDisplacementLayerIsMirrorImage2D) {
  auto g = test::box<2>({6, 7}, 3.015);
  g.layers = {{{0, 0}, {6, 0}}};
  check_mirror_image(g, 1, 0);
}

TEST(Distribution, MirroredDisplacementLayerIsMirrorImage3D) {
  auto g = test::box<3>({5, 4, 4}, 2.015);
  g.layers = {{{0, 4}, {0, 0}, {0, 0}}};
  check_mirror_image(g, 0, 1);
}

TEST(Distribution, GhostsEqualOwners3D) {
  check_ghosts(test::box<3>({8, 7, 9}, 3.015));
}

// (gid_i, gid_j, intact) of every bond, gathered on rank 0 in gid order.
template <int Dim>
std::vector<long long> global_bond_list(const Teuchos::RCP<const Comm>& comm,
                                        const GridSpec<Dim>& g) {
  auto disc = discretize(comm, g);
  auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.gid);
  auto off = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.offsets);
  auto nb = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.neighbor);
  auto in = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.bonds.intact);
  std::vector<long long> mine;
  for (std::size_t i = 0; i < disc.points.n_owned; ++i)
    for (BondIndex b = off(i); b < off(i + 1); ++b) {
      mine.push_back(gid(i));
      mine.push_back(gid(nb(b)));
      mine.push_back(in(b));
    }
  int size = comm->getSize(), rank = comm->getRank();
  if (size == 1)
    return mine;
  int count = int(mine.size());
  std::vector<int> counts(size), displs(size, 0);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  for (int r = 1; r < size; ++r)
    displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<long long> all(rank == 0 ? displs[size - 1] + counts[size - 1] : 0);
  MPI_Gatherv(mine.data(), count, MPI_LONG_LONG, all.data(), counts.data(), displs.data(),
              MPI_LONG_LONG, 0, MPI_COMM_WORLD);
  // Rows of the triples sorted by (gid_i, position in row): a stable sort on gid_i keeps each
  // row's own order.
  std::vector<std::array<long long, 3>> rows(all.size() / 3);
  for (std::size_t k = 0; k < rows.size(); ++k)
    rows[k] = {all[3 * k], all[3 * k + 1], all[3 * k + 2]};
  std::stable_sort(rows.begin(), rows.end(),
                   [](const auto& a, const auto& b) { return a[0] < b[0]; });
  std::vector<long long> out;
  for (const auto& r : rows)
    out.insert(out.end(), r.begin(), r.end());
  return out;
}

template <int Dim>
void check_rank_independence(const GridSpec<Dim>& g) {
  const auto distributed = global_bond_list(test::world(), g);
  if (test::world()->getRank() == 0) {
    const auto serial = global_bond_list(test::self(), g);
    EXPECT_EQ(distributed, serial);
    EXPECT_GT(serial.size(), 0u);
  }
}

TEST(Distribution, BondListIndependentOfRanks) {
  auto g2 = test::box<2>({17, 12}, 3.015);
  Crack c;
  c.a[0] = 0.02;
  c.a[1] = 0.06;
  c.b[0] = 0.2;
  c.b[1] = 0.06;
  g2.cracks = {c};
  g2.layers[0] = {3, 3};
  check_rank_independence(g2);
  check_rank_independence(test::box<3>({6, 7, 5}, 4.015));
}

TEST(Distribution, PartitionCoversLattice) {
  for (int n_ranks : {1, 2, 3, 5, 8}) {
    auto g = test::box<3>({9, 4, 7}, 3.015);
    std::vector<int> owner(std::size_t(g.n_global()), -1);
    for (int r = 0; r < n_ranks; ++r)
      for (GlobalId k : box_gids(g, partition_lattice(g, n_ranks, r))) {
        ASSERT_EQ(owner[std::size_t(k)], -1) << "gid " << k << " owned twice";
        owner[std::size_t(k)] = r;
      }
    for (int o : owner)
      ASSERT_GE(o, 0);
  }
}

// Terms of wide magnitudes and both signs, by index: column 0 cancels in pairs up to 1e12,
// column 1 spans 1e-8 .. 1e8.
double term(long long k, int c) {
  const double s = std::sin(0.731 * double(k) + c);
  if (c == 0)
    return (k % 2 ? -1.0 : 1.0) * 1e12 * std::fabs(std::sin(0.731 * double(k / 2))) + s;
  return s * std::pow(10.0, double(k % 17) - 8.0);
}

// The same terms split over the ranks (index modulo size) in a shuffled order, on one rank in
// index order and in reverse: the three sums have the same bits.
TEST(DistributionExactSum, SameBitsForAnyOrderAndSplit) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const long long n = 20001;
  std::vector<long long> mine;
  for (long long k = rank; k < n; k += size)
    mine.push_back(k);
  std::shuffle(mine.begin(), mine.end(), std::mt19937(17 + rank));
  auto rows = [](const std::vector<long long>& ks) {
    std::vector<double> t;
    for (long long k : ks)
      for (int c = 0; c < 2; ++c)
        t.push_back(term(k, c));
    return t;
  };
  const auto split = rows(mine);
  const auto over_ranks = exact_sums(MPI_COMM_WORLD, split.data(), mine.size(), 2);
  std::vector<long long> all(n);
  for (long long k = 0; k < n; ++k)
    all[std::size_t(k)] = k;
  const auto forward = rows(all);
  std::reverse(all.begin(), all.end());
  const auto backward = rows(all);
  const auto one = exact_sums(MPI_COMM_SELF, forward.data(), all.size(), 2);
  const auto reversed = exact_sums(MPI_COMM_SELF, backward.data(), all.size(), 2);
  for (int c = 0; c < 2; ++c) {
    EXPECT_EQ(one[std::size_t(c)], reversed[std::size_t(c)]) << "column " << c;
    EXPECT_EQ(one[std::size_t(c)], over_ranks[std::size_t(c)]) << "column " << c;
  }
  // Within the header's bound of the sum in long double: 2^(e - 65) a term, |terms| < 2^e.
  for (int c = 0; c < 2; ++c) {
    long double ref = 0, big = 0;
    for (long long k = 0; k < n; ++k) {
      ref += term(k, c);
      big = std::max(big, std::fabs((long double)term(k, c)));
    }
    int e = 0;
    std::frexp(double(big), &e);
    const double bound = double(n) * std::ldexp(1.0, e - 65) + 4 * std::ldexp(1.0, e - 53) +
                         std::fabs(double(ref)) * 1e-15;
    EXPECT_NEAR(one[std::size_t(c)], double(ref), bound) << "column " << c;
  }
}

// Terms on the sums' grid (integers and halves up to 2^29) add with no error at all: the sum
// equals the integer sum computed here; and a column holding a NaN sums to NaN on every rank.
TEST(DistributionExactSum, GridTermsAreExactAndNaNPropagates) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  std::int64_t twice = 0;  // twice the exact sum of column 0
  std::vector<double> t;
  std::size_t rows = 0;
  for (long long k = 0; k < 4000; ++k) {
    const std::int64_t v = ((k * 7919) % (1LL << 30)) - (1LL << 29);  // halves: v / 2
    twice += v;
    if (k % size != rank)
      continue;
    t.push_back(double(v) / 2);
    t.push_back(k == 1234 ? NAN : 1.0);
    ++rows;
  }
  const auto s = exact_sums(MPI_COMM_WORLD, t.data(), rows, 2);
  EXPECT_EQ(s[0], double(twice) / 2);
  EXPECT_TRUE(std::isnan(s[1]));
}

}  // namespace
}  // namespace mupm
