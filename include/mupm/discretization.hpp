// The discretized body on this rank: the grid it came from, the points (owned, then ghosts),
// their bonds, and the distribution that keeps the ghosts current.
#ifndef MUPM_DISCRETIZATION_HPP
#define MUPM_DISCRETIZATION_HPP

#include "mupm/bonds.hpp"
#include "mupm/distribution.hpp"
#include "mupm/grid.hpp"
#include "mupm/neighbors.hpp"
#include "mupm/points.hpp"

namespace mupm {

template <int Dim>
struct Discretization {
  GridSpec<Dim> grid;
  LatticeBox<Dim> box;  // this rank's part of the lattice
  Distribution dist;
  Points<Dim> points;
  Bonds bonds;
};

// Sends the constant per-point data (position, volume, flags, regions, initial fracture flag) of
// the owned points to their ghost copies: once, not every step.
template <int Dim>
void exchange_constants(Distribution& dist, Points<Dim>& pts) {
  const std::size_t n = pts.size(), n_own = pts.n_owned;
  Vectors buf("mupm::constants", n, Dim + 4);
  auto x = pts.x;
  auto vol = pts.volume;
  auto flags = pts.flags;
  auto regions = pts.regions;
  auto frac = pts.fracture;
  Kokkos::parallel_for(
      "mupm::Comm::pack_constants", range(0, n_own), KOKKOS_LAMBDA(const std::size_t i) {
        for (int d = 0; d < Dim; ++d)
          buf(i, d) = x(i, d);
        buf(i, Dim) = vol(i);
        buf(i, Dim + 1) = double(flags(i));  // uint32 values are exact in a double
        buf(i, Dim + 2) = double(regions(i));
        buf(i, Dim + 3) = double(frac(i));
      });
  dist.refresh({buf});
  Kokkos::parallel_for(
      "mupm::Comm::unpack_constants", range(n_own, n), KOKKOS_LAMBDA(const std::size_t i) {
        for (int d = 0; d < Dim; ++d)
          x(i, d) = buf(i, d);
        vol(i) = buf(i, Dim);
        flags(i) = std::uint32_t(buf(i, Dim + 1));
        regions(i) = std::uint32_t(buf(i, Dim + 2));
        frac(i) = std::uint8_t(buf(i, Dim + 3));
      });
  Kokkos::fence();
}

// Partitions the lattice, builds maps and the import, generates the owned points, sends the
// constants to the ghosts and builds the bonds. Collective.
template <int Dim>
Discretization<Dim> discretize(const Teuchos::RCP<const Comm>& comm, const GridSpec<Dim>& grid) {
  ScopedRegion region("mupm::Setup::discretize");
  Discretization<Dim> disc;
  disc.grid = grid;
  disc.box = partition_lattice(grid, comm->getSize(), comm->getRank());
  const std::vector<GlobalId> owned = box_gids(grid, disc.box);
  const std::vector<GlobalId> ghosts = ghost_gids(grid, disc.box);
  disc.dist = Distribution(comm, owned, ghosts);
  disc.points.allocate(owned.size(), ghosts.size());
  fill_owned_from_lattice(grid, owned, disc.points);
  {
    auto gid = Kokkos::create_mirror_view(disc.points.gid);
    Kokkos::deep_copy(gid, disc.points.gid);
    for (std::size_t k = 0; k < ghosts.size(); ++k)
      gid(owned.size() + k) = ghosts[k];
    Kokkos::deep_copy(disc.points.gid, gid);
  }
  exchange_constants(disc.dist, disc.points);
  disc.bonds = build_bonds(disc.points, grid.horizon, grid.cracks);
  return disc;
}

}  // namespace mupm

#endif
