// Owned rows of registry fields as contiguous host arrays (what the HDF5 writer takes), and back.
#ifndef MUPM_POINT_ROWS_HPP
#define MUPM_POINT_ROWS_HPP

#include <mpi.h>

#include <Teuchos_Comm.hpp>
#include <type_traits>
#include <vector>

#include "mupm/core/types.hpp"

namespace mupm::io {

// The raw communicator of a Teuchos one (MPI_COMM_SELF for a serial one).
MPI_Comm raw(const Teuchos::Comm<int>& c);

// Rows 0..n_owned-1 of a rank-1 or rank-2 View, row-major, in the View's value type or as T.
template <class T = void, class V>
auto owned_rows(const V& f, std::size_t n_owned) {
  using Value = std::remove_const_t<typename V::value_type>;
  using Out = std::conditional_t<std::is_void_v<T>, Value, T>;
  const std::size_t nc = V::rank == 1 ? 1 : f.extent(1);
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), f);
  std::vector<Out> out(n_owned * nc);
  for (std::size_t i = 0; i < n_owned; ++i)
    for (std::size_t c = 0; c < nc; ++c) {
      if constexpr (V::rank == 1)
        out[i] = Out(h(i));
      else
        out[i * nc + c] = Out(h(i, c));
    }
  return out;
}

// The inverse: rows 0..n_owned-1 of f from `in` (other rows kept).
template <class V, class T>
void set_owned_rows(const V& f, std::size_t n_owned, const std::vector<T>& in) {
  const std::size_t nc = V::rank == 1 ? 1 : f.extent(1);
  auto h = Kokkos::create_mirror_view_and_copy(HostSpace(), f);
  for (std::size_t i = 0; i < n_owned; ++i)
    for (std::size_t c = 0; c < nc; ++c) {
      if constexpr (V::rank == 1)
        h(i) = in[i];
      else
        h(i, c) = in[i * nc + c];
    }
  Kokkos::deep_copy(f, h);
}

}  // namespace mupm::io

#endif
