// Distribution of points over MPI ranks with Tpetra: an owned map by global id, an overlap map
// (owned first, then the ghosts within the horizon), persistent Imports, and a ghost refresh
// that packs several per-point fields into one MultiVector (one message per neighbour rank) and
// moves only the rows other ranks hold as ghosts.
#ifndef MUPM_DISTRIBUTION_HPP
#define MUPM_DISTRIBUTION_HPP

// Tpetra's map, import and multivector declared only: their headers are the heaviest a file of
// mupm parses, and only src/mesh/distribution.cpp and the pressure solves use them (a file that
// calls into owned_map() includes <Tpetra_Map.hpp> itself).
#include <Teuchos_Comm.hpp>
#include <Teuchos_RCP.hpp>
#include <Tpetra_Import_fwd.hpp>
#include <Tpetra_Map_fwd.hpp>
#include <Tpetra_MultiVector_fwd.hpp>
#include <map>
#include <vector>

#include "mupm/core/types.hpp"

namespace mupm {

using Map = Tpetra::Map<LocalId, GlobalId>;
using Import = Tpetra::Import<LocalId, GlobalId>;
using MultiVector = Tpetra::MultiVector<double, LocalId, GlobalId>;
using Comm = Teuchos::Comm<int>;

class Distribution {
 public:
  Distribution() = default;
  Distribution(const Teuchos::RCP<const Comm>& comm, const std::vector<GlobalId>& owned,
               const std::vector<GlobalId>& ghosts);

  const Teuchos::RCP<const Comm>& comm() const { return comm_; }
  const Teuchos::RCP<const Map>& owned_map() const { return owned_map_; }
  const Teuchos::RCP<const Map>& overlap_map() const { return overlap_map_; }
  std::size_t n_owned() const { return n_owned_; }
  std::size_t n_ghost() const { return n_ghost_; }
  GlobalId n_global() const;

  // Copies the owned rows of every field (each [n_owned + n_ghost][ncomp]) into the ghost rows
  // of the other ranks that need them. Fields of one call travel together in one MultiVector.
  void refresh(const std::vector<Vectors>& fields);
  std::size_t refresh_count() const { return refresh_count_; }
  // The reverse of refresh: every rank's ghost rows of `buf` ([n_owned + n_ghost][ncomp]) are
  // added to the owned rows of their owners (Tpetra doExport with ADD through the same Import,
  // in reverse mode), which then hold their own rows plus the other ranks' contributions. The
  // ghost rows are left as they were. The sum over ranks is in Tpetra's order: bit-identical on
  // any rank count only when each entry has at most one nonzero contribution (the fold of the
  // slaved boundary layers, kernels/boundary_conditions.hpp, is built so).
  void add_to_owners(const Vectors& buf);

 private:
  Teuchos::RCP<const Comm> comm_;
  Teuchos::RCP<const Map> owned_map_, overlap_map_;
  Teuchos::RCP<const Import> importer_;
  // The refresh's plan: the owned points other ranks hold as ghosts (sent_map_, their local rows
  // sent_lids_) to this rank's ghosts (ghost_map_, in the overlap map's order).
  Teuchos::RCP<const Map> sent_map_, ghost_map_;
  Teuchos::RCP<const Import> ghost_importer_;
  Kokkos::View<LocalId*> sent_lids_;
  std::size_t n_owned_ = 0, n_ghost_ = 0, refresh_count_ = 0;
  // Pairs of (source, target) buffers by width, kept for the run: a step refreshes fields of a
  // few widths in turn, and a buffer made anew for each would be allocated (and Tpetra's
  // communication buffers with it) several times a step.
  struct Buffers {
    Teuchos::RCP<MultiVector> source, target;
  };
  Buffers& buffers(std::map<std::size_t, Buffers>& kept, std::size_t width,
                   const Teuchos::RCP<const Map>& source, const Teuchos::RCP<const Map>& target);
  std::map<std::size_t, Buffers> refresh_bufs_, sum_bufs_;  // refresh, add_to_owners
};

}  // namespace mupm

#endif
