// The discretized body on this rank: the grid it came from, the points (owned, then ghosts),
// their bonds, the shape tensors of their intact families, and the distribution that keeps the
// ghosts current.
#ifndef MUPM_DISCRETIZATION_HPP
#define MUPM_DISCRETIZATION_HPP

#include "mupm/data/bonds.hpp"
#include "mupm/data/points.hpp"
#include "mupm/data/shape_tensors.hpp"
#include "mupm/kernels/shape_tensor.hpp"
#include "mupm/mesh/distribution.hpp"
#include "mupm/mesh/grid.hpp"
#include "mupm/mesh/neighbors.hpp"

namespace mupm {

template <int Dim>
struct Discretization {
  GridSpec<Dim> grid;
  LatticeBox<Dim> box;  // this rank's part of the lattice
  Distribution dist;
  Points<Dim> points;
  Bonds bonds;
  ShapeTensors<Dim> shape;  // of the intact bonds: update_shape() after any change of them
  // Local indices of each owned boundary-layer point's mirrors (mirror_locals in grid.hpp);
  // empty unless grid.mirrored_layers.
  View2<LocalId> mirror;

  void update_shape() { update_shape_tensors(points, bonds, shape); }
};

// Sends the registry's constant per-point fields (kConstant: position, volume, flags, regions,
// initial fracture flag) of the owned points to their ghost copies: once, not every step. They
// travel as doubles (the integer fields' values are exact in a double).
template <int Dim>
void exchange_constants(Distribution& dist, Points<Dim>& pts) {
  const std::size_t n = pts.size(), n_own = pts.n_owned;
  int width = 0;
  pts.for_each_field([&](const auto&, const FieldSpec& s) {
    if (s.has(kConstant))
      width += s.ncomp;
  });
  Vectors buf("mupm::constants", n, std::size_t(width));
  auto copy = [&](bool pack) {
    int col = 0;
    pts.for_each_field([&](auto& view, const FieldSpec& s) {
      if (!s.has(kConstant))
        return;
      using V = std::decay_t<decltype(view)>;
      using T = typename V::value_type;
      const int c0 = col, nc = s.ncomp;
      col += nc;
      auto f = view;
      const std::size_t lo = pack ? 0 : n_own, hi = pack ? n_own : n;
      Kokkos::parallel_for(
          pack ? "mupm::Comm::pack_constants" : "mupm::Comm::unpack_constants", range(lo, hi),
          KOKKOS_LAMBDA(const std::size_t i) {
            for (int c = 0; c < nc; ++c) {
              if constexpr (V::rank == 1) {
                if (pack)
                  buf(i, c0) = double(f(i));
                else
                  f(i) = T(buf(i, c0));
              } else {
                if (pack)
                  buf(i, c0 + c) = double(f(i, c));
                else
                  f(i, c) = T(buf(i, c0 + c));
              }
            }
          });
    });
  };
  copy(true);
  dist.refresh({buf});
  copy(false);
  Kokkos::fence();
}

// Partitions the lattice, builds maps and the import, generates the owned points (the point
// fields of `field_groups`, include/mupm/data/fields.hpp), sends the constants to the ghosts and
// builds the bonds. Collective.
template <int Dim>
Discretization<Dim> discretize(const Teuchos::RCP<const Comm>& comm, const GridSpec<Dim>& grid,
                               unsigned field_groups = kAllGroups) {
  ScopedRegion region("mupm::Setup::discretize");
  Discretization<Dim> disc;
  disc.grid = grid;
  disc.box = partition_lattice(grid, comm->getSize(), comm->getRank());
  const std::vector<GlobalId> owned = box_gids(grid, disc.box);
  const std::vector<GlobalId> ghosts = ghost_gids(grid, disc.box);
  disc.dist = Distribution(comm, owned, ghosts);
  disc.points.allocate(owned.size(), ghosts.size(), field_groups);
  fill_owned_from_lattice(grid, owned, disc.points);
  {
    auto gid = Kokkos::create_mirror_view(disc.points.gid);
    Kokkos::deep_copy(gid, disc.points.gid);
    for (std::size_t k = 0; k < ghosts.size(); ++k)
      gid(owned.size() + k) = ghosts[k];
    Kokkos::deep_copy(disc.points.gid, gid);
  }
  exchange_constants(disc.dist, disc.points);
  disc.mirror = mirror_locals(grid, owned, ghosts);
  disc.bonds = build_bonds(disc.points, grid.horizon, grid.cracks);
  disc.update_shape();
  return disc;
}

}  // namespace mupm

#endif
