#include "mupm/solvers/kept_matrix.hpp"

#include <Teuchos_CommHelpers.hpp>
#include <Tpetra_Import.hpp>

namespace mupm {

void KeptTranspose::build(const Teuchos::RCP<const CrsMatrix>& a) {
  const auto values = a->getLocalValuesView();
  const std::size_t n = values.extent(0);
  const auto invalid = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
  // a's entries numbered rank by rank in storage order (the map's contiguous numbering), the
  // numbers + 1 as values (exact in a double below 2^53; none zero, so the transposer keeps
  // every entry).
  auto entries = Teuchos::rcp(new Map(invalid, n, 0, a->getRowMap()->getComm()));
  const GlobalId first = entries->getMinGlobalIndex();
  auto numbered = Teuchos::rcp(new CrsMatrix(*a, Teuchos::Copy));
  {
    const auto v = numbered->getLocalValuesView();
    for (std::size_t q = 0; q < n; ++q)
      v(q) = double(first + GlobalId(q) + 1);
  }
  m_ = transpose(numbered);
  const auto t = m_->getLocalValuesView();
  std::vector<GlobalId> source(t.extent(0));
  for (std::size_t q = 0; q < source.size(); ++q) {
    if (!(t(q) >= 1))
      throw std::logic_error("KeptTranspose: an entry of the transpose copies none of a's");
    source[q] = GlobalId(t(q)) - 1;
  }
  auto copies = Teuchos::rcp(
      new Map(invalid, Teuchos::ArrayView<const GlobalId>(source), 0, entries->getComm()));
  import_ = Teuchos::rcp(new Tpetra::Import<LocalId, GlobalId>(entries, copies));
  fill(*a);
}

// The two vectors live only here: a refill's memory is not held through the solves and the
// preconditioner's set-up (in 3D the values of B_0^T alone are gigabytes).
void KeptTranspose::fill(const CrsMatrix& a) {
  const auto values = a.getLocalValuesView();
  TpetraVector from(import_->getSourceMap()), to(import_->getTargetMap());
  {
    auto v = from.getLocalViewHost(Tpetra::Access::OverwriteAll);
    if (v.extent(0) != values.extent(0))
      throw std::logic_error("KeptTranspose: the matrix's graph changed");
    for (std::size_t q = 0; q < values.extent(0); ++q)
      v(q, 0) = values(q);
  }
  to.doImport(from, *import_, Tpetra::INSERT);
  const auto t = m_->getLocalValuesView();
  const auto v = to.getLocalViewHost(Tpetra::Access::ReadOnly);
  for (std::size_t q = 0; q < t.extent(0); ++q)
    t(q) = v(q, 0);
}

}  // namespace mupm
