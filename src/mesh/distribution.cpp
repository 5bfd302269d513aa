#include "mupm/mesh/distribution.hpp"

#include <Teuchos_ArrayView.hpp>
#include <Tpetra_Access.hpp>

namespace mupm {

Distribution::Distribution(const Teuchos::RCP<const Comm>& comm, const std::vector<GlobalId>& owned,
                           const std::vector<GlobalId>& ghosts)
    : comm_(comm), n_owned_(owned.size()), n_ghost_(ghosts.size()) {
  const auto invalid = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
  owned_map_ = Teuchos::rcp(new Map(invalid, Teuchos::ArrayView<const GlobalId>(owned), 0, comm));
  std::vector<GlobalId> all(owned);
  all.insert(all.end(), ghosts.begin(), ghosts.end());
  overlap_map_ = Teuchos::rcp(new Map(invalid, Teuchos::ArrayView<const GlobalId>(all), 0, comm));
  importer_ = Teuchos::rcp(new Import(owned_map_, overlap_map_));
}

void Distribution::refresh(const std::vector<Vectors>& fields) {
  ScopedRegion region("mupm::Comm::ghost_refresh");
  std::size_t width = 0;
  for (const auto& f : fields)
    width += f.extent(1);
  if (width == 0)
    return;
  if (owned_buf_.is_null() || owned_buf_->getNumVectors() != width) {
    owned_buf_ = Teuchos::rcp(new MultiVector(owned_map_, width, false));
    overlap_buf_ = Teuchos::rcp(new MultiVector(overlap_map_, width, false));
  }
  const std::size_t n_own = n_owned_, n_gh = n_ghost_;
  {
    auto buf = owned_buf_->getLocalViewDevice(Tpetra::Access::OverwriteAll);
    std::size_t col = 0;
    for (const auto& f : fields) {
      const std::size_t nc = f.extent(1), c0 = col;
      Kokkos::parallel_for(
          "mupm::Comm::pack", range(0, n_own), KOKKOS_LAMBDA(const std::size_t i) {
            for (std::size_t c = 0; c < nc; ++c)
              buf(i, c0 + c) = f(i, c);
          });
      col += nc;
    }
  }
  overlap_buf_->doImport(*owned_buf_, *importer_, Tpetra::INSERT);
  {
    auto buf = overlap_buf_->getLocalViewDevice(Tpetra::Access::ReadOnly);
    std::size_t col = 0;
    for (const auto& f : fields) {
      const std::size_t nc = f.extent(1), c0 = col;
      Kokkos::parallel_for(
          "mupm::Comm::unpack", range(n_own, n_own + n_gh), KOKKOS_LAMBDA(const std::size_t i) {
            for (std::size_t c = 0; c < nc; ++c)
              f(i, c) = buf(i, c0 + c);
          });
      col += nc;
    }
  }
  Kokkos::fence();
  ++refresh_count_;
}

void Distribution::add_to_owners(const Vectors& buf) {
  ScopedRegion region("mupm::Comm::add_to_owners");
  const std::size_t width = buf.extent(1);
  if (width == 0)
    return;
  if (sum_owned_.is_null() || sum_owned_->getNumVectors() != width) {
    sum_owned_ = Teuchos::rcp(new MultiVector(owned_map_, width, false));
    sum_overlap_ = Teuchos::rcp(new MultiVector(overlap_map_, width, false));
  }
  const std::size_t n_own = n_owned_, n_all = n_owned_ + n_ghost_;
  {
    auto b = sum_overlap_->getLocalViewDevice(Tpetra::Access::OverwriteAll);
    Kokkos::parallel_for(
        "mupm::Comm::pack_sum", range(0, n_all), KOKKOS_LAMBDA(const std::size_t i) {
          for (std::size_t c = 0; c < width; ++c)
            b(i, c) = buf(i, c);
        });
  }
  sum_owned_->putScalar(0.0);
  sum_owned_->doExport(*sum_overlap_, *importer_, Tpetra::ADD);
  {
    auto b = sum_owned_->getLocalViewDevice(Tpetra::Access::ReadOnly);
    Kokkos::parallel_for(
        "mupm::Comm::unpack_sum", range(0, n_own), KOKKOS_LAMBDA(const std::size_t i) {
          for (std::size_t c = 0; c < width; ++c)
            buf(i, c) = b(i, c);
        });
  }
  Kokkos::fence();
}

}  // namespace mupm
