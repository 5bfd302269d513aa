// Helpers shared by the tests: communicators and small grids.
#ifndef MUPM_TEST_UTILS_HPP
#define MUPM_TEST_UTILS_HPP

#include <Teuchos_DefaultMpiComm.hpp>
#include <Tpetra_Core.hpp>
#include <cstdlib>
#include <string>
#include <vector>

#include "mupm/mesh/discretization.hpp"

namespace mupm::test {

inline Teuchos::RCP<const Comm> world() {
  return Tpetra::getDefaultComm();
}
inline Teuchos::RCP<const Comm> self() {
  return Teuchos::rcp(new Teuchos::MpiComm<int>(MPI_COMM_SELF));
}

// A box of counts points of spacing dx, horizon factor*dx, origin 0.
template <int Dim>
GridSpec<Dim> box(std::array<long long, Dim> counts, double factor, double dx = 0.01) {
  GridSpec<Dim> g;
  g.counts = counts;
  g.dx = dx;
  g.horizon = factor * dx;
  return g;
}

// A 2D region [x0, x1] x [y0, y1].
inline Box box2(double x0, double x1, double y0, double y1) {
  Box b;
  b.lo[0] = x0;
  b.hi[0] = x1;
  b.lo[1] = y0;
  b.hi[1] = y1;
  return b;
}

// Lattice position of a global id (the tests' own version of the grid's numbering).
template <int Dim>
std::array<double, Dim> position(const GridSpec<Dim>& g, GlobalId gid) {
  std::array<double, Dim> x{};
  for (int d = 0; d < Dim; ++d) {
    const long long n = g.lattice_count(d);
    const long long k = gid % n - g.layers[d][0];
    gid /= n;
    x[d] = g.origin[d] + (double(k) + 0.5) * g.dx;
  }
  return x;
}

// Owned points at least `rows` spacings inside the lattice (boundary layers included): rows >=
// 2 delta/dx puts the families of the point and of all its neighbours inside the body.
template <int Dim>
std::vector<bool> interior_points(const Discretization<Dim>& disc, int rows) {
  auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), disc.points.x);
  const auto& g = disc.grid;
  std::vector<bool> in(disc.points.n_owned);
  for (std::size_t i = 0; i < disc.points.n_owned; ++i) {
    bool ok = true;
    for (int d = 0; d < Dim; ++d) {
      const double lo = g.origin[d] - g.layers[d][0] * g.dx;
      const double hi = g.origin[d] + (g.counts[d] + g.layers[d][1]) * g.dx;
      ok = ok && x(i, d) > lo + rows * g.dx && x(i, d) < hi - rows * g.dx;
    }
    in[i] = ok;
  }
  return in;
}

inline std::string tmp_dir() {
  const char* d = std::getenv("MUPM_TEST_TMPDIR");
  return d ? d : "/tmp";
}

}  // namespace mupm::test

#endif
