// Neighbour search by cell binning (count -> scan -> fill), full lists for the owned points.
// Each row is sorted by the neighbour's global id afterwards, so the bond order, and with it
// every family sum, is the same on any number of ranks and threads.
#ifndef MUPM_NEIGHBORS_HPP
#define MUPM_NEIGHBORS_HPP

#include <vector>

#include "mupm/core/geometry.hpp"
#include "mupm/data/bonds.hpp"
#include "mupm/data/points.hpp"

namespace mupm {

namespace detail {

// In-place heap sort of keys[0..n) carrying vals along; runs inside a kernel (no allocation).
template <class Key, class Val>
KOKKOS_INLINE_FUNCTION void heap_sort(Key* keys, Val* vals, long n) {
  auto sift = [&](long root, long end) {
    while (2 * root + 1 < end) {
      long child = 2 * root + 1;
      if (child + 1 < end && keys[child] < keys[child + 1])
        ++child;
      if (!(keys[root] < keys[child]))
        return;
      Key tk = keys[root];
      keys[root] = keys[child];
      keys[child] = tk;
      Val tv = vals[root];
      vals[root] = vals[child];
      vals[child] = tv;
      root = child;
    }
  };
  for (long s = n / 2 - 1; s >= 0; --s)
    sift(s, n);
  for (long end = n - 1; end > 0; --end) {
    Key tk = keys[0];
    keys[0] = keys[end];
    keys[end] = tk;
    Val tv = vals[0];
    vals[0] = vals[end];
    vals[end] = tv;
    sift(0, end);
  }
}

}  // namespace detail

// Builds the bonds of the owned points of `pts` (owned and ghost positions must be set): every
// pair with |x_j - x_i| <= horizon, j != i. Bonds that cross a pre-crack start broken.
template <int Dim>
Bonds build_bonds(const Points<Dim>& pts, double horizon, const std::vector<Crack>& crack_list) {
  ScopedRegion region("mupm::Neighbors::build");
  const std::size_t n_all = pts.size(), n_own = pts.n_owned;
  Bonds bonds;
  bonds.offsets = View1<BondIndex>("mupm::bond_offsets", n_own + 1);
  auto x = pts.x;

  // Bounding box and cells of edge > horizon: a margin of 1e-6 so that a neighbour on the
  // horizon (within_horizon's 1e-10) is never two cells away by round-off. With edge = horizon,
  // a horizon of whole spacings (delta = 2 dx) put such neighbours on the cells' edges, and
  // bonds were lost depending on the bounding box, i.e. on the rank count (140 pairs of
  // Example 1's 66 x 66 grid on 2 ranks; test Neighbors.BruteForceWholeSpacings).
  double lo[Dim], hi[Dim];
  for (int d = 0; d < Dim; ++d) {
    double mn = 0, mx = 0;
    Kokkos::parallel_reduce(
        "mupm::Neighbors::bounds", range(0, n_all),
        KOKKOS_LAMBDA(const std::size_t i, double& a, double& b) {
          a = x(i, d) < a ? x(i, d) : a;
          b = x(i, d) > b ? x(i, d) : b;
        },
        Kokkos::Min<double>(mn), Kokkos::Max<double>(mx));
    lo[d] = mn;
    hi[d] = mx;
  }
  const double edge = horizon * (1 + 1e-6);
  Kokkos::Array<double, Dim> lo_a;
  Kokkos::Array<long, Dim> nc;
  long n_cells = 1;
  for (int d = 0; d < Dim; ++d) {
    lo_a[d] = lo[d];
    nc[d] = n_all == 0 ? 1 : static_cast<long>((hi[d] - lo[d]) / edge) + 1;
    n_cells *= nc[d];
  }
  const double inv_h = 1.0 / edge;
  auto cell_of = KOKKOS_LAMBDA(const std::size_t i, long* c) {
    for (int d = 0; d < Dim; ++d) {
      long k = static_cast<long>((x(i, d) - lo_a[d]) * inv_h);
      c[d] = k < 0 ? 0 : (k >= nc[d] ? nc[d] - 1 : k);
    }
  };
  auto linear = KOKKOS_LAMBDA(const long* c) {
    long l = c[Dim - 1];
    for (int d = Dim - 2; d >= 0; --d)
      l = l * nc[d] + c[d];
    return l;
  };

  View1<int> cell_count("mupm::cell_count", n_cells);
  View1<int> cell_start("mupm::cell_start", n_cells + 1);
  View1<int> cell_points("mupm::cell_points", n_all);
  Kokkos::parallel_for(
      "mupm::Neighbors::bin_count", range(0, n_all), KOKKOS_LAMBDA(const std::size_t i) {
        long c[Dim];
        cell_of(i, c);
        Kokkos::atomic_increment(&cell_count(linear(c)));
      });
  Kokkos::parallel_scan(
      "mupm::Neighbors::bin_scan", Kokkos::RangePolicy<ExecSpace>(0, n_cells),
      KOKKOS_LAMBDA(const long c, int& sum, const bool final) {
        if (final)
          cell_start(c) = sum;
        sum += cell_count(c);
        if (final && c == n_cells - 1)
          cell_start(n_cells) = sum;
      });
  Kokkos::deep_copy(cell_count, 0);
  Kokkos::parallel_for(
      "mupm::Neighbors::bin_fill", range(0, n_all), KOKKOS_LAMBDA(const std::size_t i) {
        long c[Dim];
        cell_of(i, c);
        const long l = linear(c);
        cell_points(cell_start(l) + Kokkos::atomic_fetch_add(&cell_count(l), 1)) = int(i);
      });

  // Visit the 3^Dim cells around point i; call f(j) for each j != i within the horizon.
  const double delta2 = horizon * horizon;
  auto for_each_neighbor = KOKKOS_LAMBDA(const std::size_t i, auto&& f) {
    long ci[Dim], c[Dim];
    cell_of(i, ci);
    const int n_stencil = Dim == 2 ? 9 : 27;
    for (int s = 0; s < n_stencil; ++s) {
      int rest = s;
      bool ok = true;
      for (int d = 0; d < Dim; ++d) {
        c[d] = ci[d] + rest % 3 - 1;
        rest /= 3;
        if (c[d] < 0 || c[d] >= nc[d])
          ok = false;
      }
      if (!ok)
        continue;
      const long l = linear(c);
      for (int k = cell_start(l); k < cell_start(l + 1); ++k) {
        const int j = cell_points(k);
        if (std::size_t(j) == i)
          continue;
        double d2 = 0;
        for (int d = 0; d < Dim; ++d)
          d2 += (x(j, d) - x(i, d)) * (x(j, d) - x(i, d));
        if (within_horizon(d2, delta2))
          f(j);
      }
    }
  };

  auto offsets = bonds.offsets;
  Kokkos::parallel_for(
      "mupm::Neighbors::count", range(0, n_own), KOKKOS_LAMBDA(const std::size_t i) {
        BondIndex count = 0;
        for_each_neighbor(i, [&](int) { ++count; });
        offsets(i + 1) = count;
      });
  BondIndex n_bonds = 0;
  Kokkos::parallel_scan(
      "mupm::Neighbors::scan", range(0, n_own + 1),
      KOKKOS_LAMBDA(const std::size_t i, BondIndex& sum, const bool final) {
        sum += offsets(i);
        if (final)
          offsets(i) = sum;
      },
      n_bonds);

  bonds.neighbor = View1<LocalId>("mupm::bond_neighbor", n_bonds);
  bonds.allocate_state(std::size_t(n_bonds));
  auto neighbor = bonds.neighbor;
  auto intact = bonds.intact;
  auto gid = pts.gid;
  View1<GlobalId> keys("mupm::bond_sort_keys", n_bonds);
  View1<Crack> cracks("mupm::cracks", crack_list.size());
  {
    auto ch = Kokkos::create_mirror_view(cracks);
    for (std::size_t c = 0; c < crack_list.size(); ++c)
      ch(c) = crack_list[c];
    Kokkos::deep_copy(cracks, ch);
  }
  Kokkos::parallel_for(
      "mupm::Neighbors::fill", range(0, n_own), KOKKOS_LAMBDA(const std::size_t i) {
        BondIndex b = offsets(i);
        for_each_neighbor(i, [&](int j) {
          neighbor(b) = j;
          keys(b) = gid(j);
          ++b;
        });
        const BondIndex b0 = offsets(i);
        detail::heap_sort(&keys(b0), &neighbor(b0), long(offsets(i + 1) - b0));
        double xi[3] = {0, 0, 0}, xj[3] = {0, 0, 0};
        for (int d = 0; d < Dim; ++d)
          xi[d] = x(i, d);
        for (BondIndex k = b0; k < offsets(i + 1); ++k) {
          for (int d = 0; d < Dim; ++d)
            xj[d] = x(neighbor(k), d);
          std::uint8_t ok = 1;
          for (std::size_t c = 0; c < cracks.extent(0); ++c)
            if (bond_crosses<Dim>(cracks(c), xi, xj))
              ok = 0;
          intact(k) = ok;
        }
      });
  Kokkos::fence();
  return bonds;
}

}  // namespace mupm

#endif
