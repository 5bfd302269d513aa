// Generated box grids: a lattice of cell-centred points of spacing dx, the real body extended by
// boundary layers (the paper's boundary-layer method, section 3) on chosen faces. Points are
// numbered lexicographically over the whole lattice (x fastest), which is the global id.
#ifndef MUPM_GRID_HPP
#define MUPM_GRID_HPP

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "mupm/core/geometry.hpp"
#include "mupm/data/points.hpp"

namespace mupm {

template <int Dim>
struct GridSpec {
  std::array<double, Dim> origin{};              // lower corner of the real body
  std::array<long long, Dim> counts{};           // real points per axis
  double dx = 0;                                 // spacing
  double horizon = 0;                            // delta (absolute)
  double thickness = 1;                          // out-of-plane thickness (2D)
  std::array<std::array<int, 2>, Dim> layers{};  // boundary-layer rows on face (axis, side)
  // Some condition mirrors its boundary-layer values (kernels/boundary_conditions.hpp): the
  // mirrors of the owned layer points become ghosts too.
  bool mirrored_layers = false;
  std::vector<Crack> cracks;
  std::vector<std::string> region_names;
  std::vector<Box> regions;

  // Lattice rows within the horizon: floor(delta/dx).
  int horizon_cells() const { return static_cast<int>(horizon / dx * (1 + 1e-10)); }
  long long lattice_count(int d) const { return counts[d] + layers[d][0] + layers[d][1]; }
  long long n_global() const {
    long long n = 1;
    for (int d = 0; d < Dim; ++d)
      n *= lattice_count(d);
    return n;
  }
  // Volume V_H of a full continuous family: pi delta^2 h (2D), 4/3 pi delta^3 (3D).
  double family_volume() const {
    return Dim == 2 ? kPi * horizon * horizon * thickness : 4.0 / 3.0 * kPi * std::pow(horizon, 3);
  }
  // The real body [origin, origin + counts dx] (cell faces; points at cell centres).
  Box body() const {
    Box b;
    for (int d = 0; d < Dim; ++d) {
      b.lo[d] = origin[d];
      b.hi[d] = origin[d] + double(counts[d]) * dx;
    }
    return b;
  }
  double point_volume() const {
    double v = Dim == 2 ? thickness : 1.0;
    for (int d = 0; d < Dim; ++d)
      v *= dx;
    return v;
  }
};

// A half-open box of lattice indices [lo, hi).
template <int Dim>
struct LatticeBox {
  std::array<long long, Dim> lo{}, hi{};
  long long size() const {
    long long n = 1;
    for (int d = 0; d < Dim; ++d)
      n *= (hi[d] > lo[d] ? hi[d] - lo[d] : 0);
    return n;
  }
};

// Recursive coordinate bisection of the lattice over n_ranks: cut the longest side of the box
// in proportion to the ranks on each side, recursively. Every rank gets a box of about
// n_global / n_ranks points with a small surface (few ghosts). Deterministic.
template <int Dim>
LatticeBox<Dim> partition_lattice(const GridSpec<Dim>& g, int n_ranks, int rank) {
  LatticeBox<Dim> box;
  for (int d = 0; d < Dim; ++d)
    box.hi[d] = g.lattice_count(d);
  int first = 0, count = n_ranks;
  while (count > 1) {
    int axis = 0;
    for (int d = 1; d < Dim; ++d)
      if (box.hi[d] - box.lo[d] > box.hi[axis] - box.lo[axis])
        axis = d;
    const int left = count / 2;
    const long long extent = box.hi[axis] - box.lo[axis];
    const long long cut = box.lo[axis] + (extent * left + count / 2) / count;
    if (rank < first + left) {
      box.hi[axis] = cut;
      count = left;
    } else {
      box.lo[axis] = cut;
      first += left;
      count -= left;
    }
  }
  return box;
}

template <int Dim>
KOKKOS_INLINE_FUNCTION GlobalId lattice_gid(const long long* idx, const long long* n) {
  GlobalId g = idx[Dim - 1];
  for (int d = Dim - 2; d >= 0; --d)
    g = g * n[d] + idx[d];
  return g;
}

// Calls f(idx) for every lattice index of the box, x fastest (ascending global id).
template <int Dim, class F>
void for_each_in_box(const LatticeBox<Dim>& b, F&& f) {
  if (b.size() == 0)
    return;
  long long idx[Dim];
  for (int d = 0; d < Dim; ++d)
    idx[d] = b.lo[d];
  while (true) {
    f(static_cast<const long long*>(idx));
    int d = 0;
    while (d < Dim && ++idx[d] == b.hi[d]) {
      idx[d] = b.lo[d];
      ++d;
    }
    if (d == Dim)
      return;
  }
}

// Global ids of the points in a lattice box, ascending.
template <int Dim>
std::vector<GlobalId> box_gids(const GridSpec<Dim>& g, const LatticeBox<Dim>& b) {
  std::vector<GlobalId> out;
  out.reserve(static_cast<std::size_t>(b.size()));
  long long n[Dim];
  for (int d = 0; d < Dim; ++d)
    n[d] = g.lattice_count(d);
  for_each_in_box(b, [&](const long long* idx) { out.push_back(lattice_gid<Dim>(idx, n)); });
  return out;
}

// The mirror of lattice point idx across the face of axis `axis` it lies outside of (the
// boundary-layer issue): a layer index k < 0 of the real body's numbering goes to -1 - k and
// k >= n to 2n - 1 - k, the point at the same distance inside the face (points sit at cell
// centres, the face on a cell boundary, so the mirror is a lattice point; layers thicker than
// the body clamp into it). Returns false if idx is not outside that face. The mirror of a corner
// (or 3D edge) point across one face is a layer point of the other face.
template <int Dim>
bool mirror_index(const GridSpec<Dim>& g, const long long* idx, int axis, long long* out) {
  for (int d = 0; d < Dim; ++d)
    out[d] = idx[d];
  const long long n = g.counts[axis], k = idx[axis] - g.layers[axis][0];
  if (k >= 0 && k < n)
    return false;
  long long m = k < 0 ? -1 - k : 2 * n - 1 - k;
  m = std::min(std::max(m, 0LL), n - 1);
  out[axis] = m + g.layers[axis][0];
  return true;
}

// The axis whose face a region lies entirely outside of (its box beyond the face: the
// boundary layers, or a user's box of layer rows), -1 if none or several: the face a mirrored
// condition on the region reflects across.
template <int Dim>
int face_axis(const GridSpec<Dim>& g, std::uint32_t mask) {
  if (mask == 0 || (mask & (mask - 1)) != 0)
    return -1;
  int r = 0;
  while (!(mask & (1u << r)))
    ++r;
  if (r >= int(g.regions.size()))
    return -1;
  const Box& b = g.regions[r];
  int axis = -1, count = 0;
  for (int d = 0; d < Dim; ++d) {
    const double lo = g.origin[d], hi = g.origin[d] + g.counts[d] * g.dx;
    if (b.hi[d] < lo || b.lo[d] > hi) {
      axis = d;
      ++count;
    }
  }
  return count == 1 ? axis : -1;
}
// 2 axis + side of the one face region `mask` lies outside of (side 0: below the body's low
// face), or -1 (face_axis).
template <int Dim>
int face_index(const GridSpec<Dim>& g, std::uint32_t mask) {
  const int axis = face_axis(g, mask);
  if (axis < 0)
    return -1;
  int r = 0;
  while (!(mask & (1u << r)))
    ++r;
  return 2 * axis + (g.regions[r].hi[axis] < g.origin[axis] ? 0 : 1);
}
// The column of Discretization::mirror a condition on region `mask` reflects with.
template <int Dim>
int face_column(const GridSpec<Dim>& g, std::uint32_t mask) {
  const int axis = face_axis(g, mask);
  return axis >= 0 ? axis : Dim;
}

// Ghost candidates of an owned box: lattice points outside it within delta of one of its points.
// The nearest owned point of a lattice point is its index clamped to the box, so the test is
// exact.
template <int Dim>
std::vector<GlobalId> ghost_gids(const GridSpec<Dim>& g, const LatticeBox<Dim>& b) {
  std::vector<GlobalId> out;
  if (b.size() == 0)
    return out;
  const long long m = g.horizon_cells();
  LatticeBox<Dim> wide;
  long long n[Dim];
  for (int d = 0; d < Dim; ++d) {
    n[d] = g.lattice_count(d);
    wide.lo[d] = std::max(0LL, b.lo[d] - m);
    wide.hi[d] = std::min(n[d], b.hi[d] + m);
  }
  const double delta2 = (g.horizon / g.dx) * (g.horizon / g.dx);
  for_each_in_box(wide, [&](const long long* idx) {
    double d2 = 0;
    bool inside = true;
    for (int d = 0; d < Dim; ++d) {
      const long long c = std::min(std::max(idx[d], b.lo[d]), b.hi[d] - 1);
      if (c != idx[d])
        inside = false;
      d2 += double(c - idx[d]) * double(c - idx[d]);
    }
    if (!inside && within_horizon(d2, delta2))
      out.push_back(lattice_gid<Dim>(idx, n));
  });
  if (g.mirrored_layers) {  // the mirrors of the owned layer points, where outside the box
    for_each_in_box(b, [&](const long long* idx) {
      long long m[Dim];
      for (int axis = 0; axis < Dim; ++axis) {
        if (!mirror_index(g, idx, axis, m))
          continue;
        bool inside = true;
        for (int d = 0; d < Dim; ++d)
          inside = inside && m[d] >= b.lo[d] && m[d] < b.hi[d];
        if (!inside)
          out.push_back(lattice_gid<Dim>(m, n));
      }
    });
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }
  return out;  // ascending
}

// Local indices (owned, then ghosts) of each owned point's mirrors: column d the mirror across
// the face of axis d (mirror_index; -1 if the point is not outside it), column Dim the mirror
// of a point outside one face only (-1 for body, corner and 3D edge points). Empty unless
// g.mirrored_layers.
template <int Dim>
View2<LocalId> mirror_locals(const GridSpec<Dim>& g, const std::vector<GlobalId>& owned,
                             const std::vector<GlobalId>& ghosts) {
  if (!g.mirrored_layers)
    return View2<LocalId>();
  long long n[Dim];
  for (int d = 0; d < Dim; ++d)
    n[d] = g.lattice_count(d);
  auto local_of = [&](GlobalId gid) -> LocalId {
    auto it = std::lower_bound(owned.begin(), owned.end(), gid);
    if (it != owned.end() && *it == gid)
      return LocalId(it - owned.begin());
    it = std::lower_bound(ghosts.begin(), ghosts.end(), gid);
    return LocalId(owned.size() + (it - ghosts.begin()));  // present by ghost_gids
  };
  View2<LocalId> mirror("mupm::mirror", owned.size(), Dim + 1);
  auto h = Kokkos::create_mirror_view(mirror);
  for (std::size_t i = 0; i < owned.size(); ++i) {
    long long idx[Dim], m[Dim];
    GlobalId rest = owned[i];
    for (int d = 0; d < Dim; ++d) {
      idx[d] = rest % n[d];
      rest /= n[d];
    }
    int outside = 0;
    h(i, Dim) = -1;
    for (int d = 0; d < Dim; ++d) {
      h(i, d) = mirror_index(g, idx, d, m) ? local_of(lattice_gid<Dim>(m, n)) : -1;
      if (h(i, d) >= 0) {
        ++outside;
        h(i, Dim) = h(i, d);
      }
    }
    if (outside != 1)
      h(i, Dim) = -1;
  }
  Kokkos::deep_copy(mirror, h);
  return mirror;
}

// Fills gid, x, volume, flags and regions of the owned points from their global ids, and marks
// points within dx of a pre-crack as fracture points. Ghost entries are left for the exchange.
template <int Dim>
void fill_owned_from_lattice(const GridSpec<Dim>& g, const std::vector<GlobalId>& owned_gids,
                             Points<Dim>& pts) {
  const std::size_t n = owned_gids.size();
  auto gid_host = Kokkos::create_mirror_view(pts.gid);
  for (std::size_t i = 0; i < n; ++i)
    gid_host(i) = owned_gids[i];
  Kokkos::deep_copy(pts.gid, gid_host);

  View1<Crack> cracks("mupm::cracks", g.cracks.size());
  View1<Box> regions("mupm::regions", g.regions.size());
  {
    auto ch = Kokkos::create_mirror_view(cracks);
    for (std::size_t c = 0; c < g.cracks.size(); ++c)
      ch(c) = g.cracks[c];
    Kokkos::deep_copy(cracks, ch);
    auto rh = Kokkos::create_mirror_view(regions);
    for (std::size_t r = 0; r < g.regions.size(); ++r)
      rh(r) = g.regions[r];
    Kokkos::deep_copy(regions, rh);
  }
  Kokkos::Array<long long, Dim> lat, lo_layers, real;
  Kokkos::Array<double, Dim> origin;
  for (int d = 0; d < Dim; ++d) {
    lat[d] = g.lattice_count(d);
    lo_layers[d] = g.layers[d][0];
    real[d] = g.counts[d];
    origin[d] = g.origin[d];
  }
  const double dx = g.dx, vol = g.point_volume(), tol = 1e-9 * g.dx;
  auto gid = pts.gid;
  auto x = pts.x;
  auto volume = pts.volume;
  auto flags = pts.flags;
  auto region_bits = pts.regions;
  auto fracture = pts.fracture;
  Kokkos::parallel_for(
      "mupm::Grid::fill_owned", range(0, n), KOKKOS_LAMBDA(const std::size_t i) {
        GlobalId rest = gid(i);
        double xi[3] = {0, 0, 0};
        std::uint32_t f = 0;
        for (int d = 0; d < Dim; ++d) {
          const long long k = rest % lat[d] - lo_layers[d];  // index in the real body
          rest /= lat[d];
          xi[d] = origin[d] + (double(k) + 0.5) * dx;
          x(i, d) = xi[d];
          if (k < 0)
            f |= kFlagBoundaryLayer | layer_face_flag(d, 0);
          if (k >= real[d])
            f |= kFlagBoundaryLayer | layer_face_flag(d, 1);
        }
        std::uint8_t frac = 0;
        for (std::size_t c = 0; c < cracks.extent(0); ++c)
          if (distance2_to_crack<Dim>(cracks(c), xi) < dx * dx)
            frac = 1;
        if (frac)
          f |= kFlagPreCrack;
        std::uint32_t r_bits = 0;
        for (std::size_t r = 0; r < regions.extent(0); ++r)
          if (in_box<Dim>(regions(r), xi, tol))
            r_bits |= 1u << r;
        volume(i) = vol;
        flags(i) = f;
        region_bits(i) = r_bits;
        fracture(i) = frac;
      });
}

}  // namespace mupm

#endif
