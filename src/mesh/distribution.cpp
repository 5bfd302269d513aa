#include "mupm/mesh/distribution.hpp"

#include <Tpetra_Import.hpp>
#include <Tpetra_Map.hpp>
#include <Tpetra_MultiVector.hpp>

#include <Teuchos_ArrayView.hpp>
#include <Tpetra_Access.hpp>
#include <algorithm>

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
  // The refresh's own plan: from the owned points some other rank holds as ghosts (the
  // importer's export rows, each once) to the ghosts alone. The overlap import would also copy
  // every owned row onto itself (its "same" rows): a refresh then costs the whole rank's rows
  // even on one rank, where there is nothing to send.
  std::vector<LocalId> sent(importer_->getExportLIDs().begin(), importer_->getExportLIDs().end());
  std::sort(sent.begin(), sent.end());
  sent.erase(std::unique(sent.begin(), sent.end()), sent.end());
  std::vector<GlobalId> sent_gids(sent.size());
  sent_lids_ = Kokkos::View<LocalId*>("mupm::sent_rows", sent.size());
  auto lids = Kokkos::create_mirror_view(sent_lids_);
  for (std::size_t k = 0; k < sent.size(); ++k) {
    sent_gids[k] = owned[static_cast<std::size_t>(sent[k])];
    lids(k) = sent[k];
  }
  Kokkos::deep_copy(sent_lids_, lids);
  sent_map_ =
      Teuchos::rcp(new Map(invalid, Teuchos::ArrayView<const GlobalId>(sent_gids), 0, comm));
  ghost_map_ = Teuchos::rcp(new Map(invalid, Teuchos::ArrayView<const GlobalId>(ghosts), 0, comm));
  ghost_importer_ = Teuchos::rcp(new Import(sent_map_, ghost_map_));
}

Distribution::Buffers& Distribution::buffers(std::map<std::size_t, Buffers>& kept,
                                             std::size_t width,
                                             const Teuchos::RCP<const Map>& source,
                                             const Teuchos::RCP<const Map>& target) {
  Buffers& b = kept[width];
  if (b.source.is_null()) {
    b.source = Teuchos::rcp(new MultiVector(source, width, false));
    b.target = Teuchos::rcp(new MultiVector(target, width, false));
  }
  return b;
}

void Distribution::refresh(const std::vector<Vectors>& fields) {
  ScopedRegion region("mupm::Comm::ghost_refresh");
  std::size_t width = 0;
  for (const auto& f : fields)
    width += f.extent(1);
  if (width == 0)
    return;
  const Buffers& bufs = buffers(refresh_bufs_, width, sent_map_, ghost_map_);
  const std::size_t n_own = n_owned_;
  const auto lids = sent_lids_;
  {
    auto buf = bufs.source->getLocalViewDevice(Tpetra::Access::OverwriteAll);
    std::size_t col = 0;
    for (const auto& f : fields) {
      const std::size_t nc = f.extent(1), c0 = col;
      Kokkos::parallel_for(
          "mupm::Comm::pack", range(0, lids.extent(0)), KOKKOS_LAMBDA(const std::size_t k) {
            for (std::size_t c = 0; c < nc; ++c)
              buf(k, c0 + c) = f(lids(k), c);
          });
      col += nc;
    }
  }
  bufs.target->doImport(*bufs.source, *ghost_importer_, Tpetra::INSERT);
  {
    auto buf = bufs.target->getLocalViewDevice(Tpetra::Access::ReadOnly);
    std::size_t col = 0;
    for (const auto& f : fields) {
      const std::size_t nc = f.extent(1), c0 = col;
      Kokkos::parallel_for(
          "mupm::Comm::unpack", range(0, n_ghost_), KOKKOS_LAMBDA(const std::size_t g) {
            for (std::size_t c = 0; c < nc; ++c)
              f(n_own + g, c) = buf(g, c0 + c);
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
  const Buffers& bufs = buffers(sum_bufs_, width, owned_map_, overlap_map_);
  const std::size_t n_own = n_owned_, n_all = n_owned_ + n_ghost_;
  {
    auto b = bufs.target->getLocalViewDevice(Tpetra::Access::OverwriteAll);
    Kokkos::parallel_for(
        "mupm::Comm::pack_sum", range(0, n_all), KOKKOS_LAMBDA(const std::size_t i) {
          for (std::size_t c = 0; c < width; ++c)
            b(i, c) = buf(i, c);
        });
  }
  bufs.source->putScalar(0.0);
  bufs.source->doExport(*bufs.target, *importer_, Tpetra::ADD);
  {
    auto b = bufs.source->getLocalViewDevice(Tpetra::Access::ReadOnly);
    Kokkos::parallel_for(
        "mupm::Comm::unpack_sum", range(0, n_own), KOKKOS_LAMBDA(const std::size_t i) {
          for (std::size_t c = 0; c < width; ++c)
            buf(i, c) = b(i, c);
        });
  }
  Kokkos::fence();
}

GlobalId Distribution::n_global() const {
  return static_cast<GlobalId>(owned_map_->getGlobalNumElements());
}

}  // namespace mupm
