#include "mupm/solvers/kept_matrix.hpp"

#include <Kokkos_Core.hpp>
#include <Kokkos_UniqueToken.hpp>
#include <Teuchos_CommHelpers.hpp>
#include <Tpetra_Import.hpp>
#include <cstdint>
#include <cstring>

namespace mupm {

namespace {
using Import = Tpetra::Import<LocalId, GlobalId>;

// A copy of a whose values are the numbers of its entries + 1, numbered rank by rank in storage
// order (the contiguous map `entries`): exact in a double below 2^53, and none zero, so that
// Tpetra's transposer and imports keep every entry.
Teuchos::RCP<CrsMatrix> numbered_copy(const CrsMatrix& a, Teuchos::RCP<const Map>& entries) {
  const std::size_t n = a.getLocalValuesView().extent(0);
  const auto invalid = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
  entries = Teuchos::rcp(new Map(invalid, n, 0, a.getRowMap()->getComm()));
  const GlobalId first = entries->getMinGlobalIndex();
  auto numbered = Teuchos::rcp(new CrsMatrix(a, Teuchos::Copy));
  const auto v = numbered->getLocalValuesView();
  for (std::size_t q = 0; q < n; ++q)
    v(q) = double(first + GlobalId(q) + 1);
  return numbered;
}

// The import from `entries` to the entries whose numbers + 1 are `numbers`, in their order.
Teuchos::RCP<const Import> import_of(const Teuchos::RCP<const Map>& entries,
                                     const std::vector<double>& numbers, const char* who) {
  std::vector<GlobalId> source(numbers.size());
  for (std::size_t q = 0; q < source.size(); ++q) {
    if (!(numbers[q] >= 1))
      throw std::logic_error(std::string(who) + ": an entry copies none of the matrix's");
    source[q] = GlobalId(numbers[q]) - 1;
  }
  const auto invalid = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
  auto copies = Teuchos::rcp(
      new Map(invalid, Teuchos::ArrayView<const GlobalId>(source), 0, entries->getComm()));
  return Teuchos::rcp(new Import(entries, copies));
}

// a's values moved by `import` (from a's entries to their copies), into `out`. The two vectors
// live only here: a refill's memory is not held through the solves and the preconditioner's
// set-up (in 3D the values of B_0^T alone are gigabytes).
template <class Out>
void import_values(const CrsMatrix& a, const Import& import, Out&& out, const char* who) {
  const auto values = a.getLocalValuesView();
  TpetraVector from(import.getSourceMap()), to(import.getTargetMap());
  {
    auto v = from.getLocalViewHost(Tpetra::Access::OverwriteAll);
    if (v.extent(0) != values.extent(0))
      throw std::logic_error(std::string(who) + ": the matrix's graph changed");
    for (std::size_t q = 0; q < values.extent(0); ++q)
      v(q, 0) = values(q);
  }
  to.doImport(from, import, Tpetra::INSERT);
  const auto v = to.getLocalViewHost(Tpetra::Access::ReadOnly);
  for (std::size_t q = 0; q < v.extent(0); ++q)
    out(q, v(q, 0));
}

bool differs(double x, double y) {
  std::uint64_t a, b;
  std::memcpy(&a, &x, sizeof a);
  std::memcpy(&b, &y, sizeof b);
  return a != b;
}
}  // namespace

void KeptTranspose::build(const Teuchos::RCP<const CrsMatrix>& a) {
  Teuchos::RCP<const Map> entries;
  m_ = transpose(numbered_copy(*a, entries));
  const auto t = m_->getLocalValuesView();
  import_ =
      import_of(entries, std::vector<double>(t.data(), t.data() + t.extent(0)), "KeptTranspose");
  fill(*a);
}

void KeptTranspose::fill(const CrsMatrix& a) {
  const auto t = m_->getLocalValuesView();
  import_values(
      a, *import_, [&](std::size_t q, double v) { t(q) = v; }, "KeptTranspose");
}

void KeptProduct::build(const CrsMatrix& a, const CrsMatrix& b, const TpetraVector* s) {
  m_ = Teuchos::rcp(new CrsMatrix(a.getRowMap(), 0));
  Tpetra::MatrixMatrix::Multiply(a, false, b, false, *m_);
  scale_import_ = m_->getGraph()->getImporter();
  // b's rows at a's columns, their values the numbers of b's entries.
  Teuchos::RCP<const Map> entries;
  const auto numbered = numbered_copy(b, entries);
  const auto& acols = *a.getColMap();
  CrsMatrix ext(a.getColMap(), std::max<std::size_t>(1, b.getGlobalMaxNumRowEntries()));
  ext.doImport(*numbered, Import(b.getRowMap(), a.getColMap()), Tpetra::INSERT);
  const auto& mcols = *m_->getColMap();
  const std::size_t nk = acols.getNodeNumElements();
  ext_start_.assign(nk + 1, 0);
  ext_col_.clear();
  std::vector<double> numbers;
  CrsMatrix::nonconst_global_inds_host_view_type idx("idx", b.getGlobalMaxNumRowEntries());
  CrsMatrix::nonconst_values_host_view_type val("val", b.getGlobalMaxNumRowEntries());
  for (std::size_t k = 0; k < nk; ++k) {
    std::size_t len = 0;
    ext.getGlobalRowCopy(acols.getGlobalElement(LocalId(k)), idx, val, len);
    if (len == Teuchos::OrdinalTraits<std::size_t>::invalid())
      len = 0;
    for (std::size_t q = 0; q < len; ++q) {
      const LocalId c = mcols.getLocalElement(idx(q));
      if (c == Teuchos::OrdinalTraits<LocalId>::invalid())
        throw std::logic_error("KeptProduct: a column of b is not in the product's graph");
      ext_col_.push_back(c);
      numbers.push_back(val(q));
    }
    ext_start_[k + 1] = ext_col_.size();
  }
  import_ = import_of(entries, numbers, "KeptProduct");
  // Every column a row reaches must be in that row's graph (else the accumulator would carry
  // it into the next row): Tpetra's product keeps structural zeros; checked once here.
  const auto al = a.getLocalMatrixHost();
  const auto ml = m_->getLocalMatrixHost();
  std::vector<LocalId> mark(mcols.getNodeNumElements(), -1);
  for (LocalId r = 0; r < LocalId(al.numRows()); ++r) {
    for (auto p = ml.graph.row_map(r); p < ml.graph.row_map(r + 1); ++p)
      mark[std::size_t(ml.graph.entries(p))] = r;
    for (auto q = al.graph.row_map(r); q < al.graph.row_map(r + 1); ++q) {
      const std::size_t k = std::size_t(al.graph.entries(q));
      for (std::size_t e = ext_start_[k]; e < ext_start_[k + 1]; ++e)
        if (mark[std::size_t(ext_col_[e])] != r)
          throw std::logic_error("KeptProduct: the product's graph lacks an entry");
    }
  }
  a_.assign(al.values.extent(0), 0.0);
  ext_.assign(ext_col_.size(), 0.0);
  s_.clear();
  fresh_ = true;
  fill(a, b, s);
}

void KeptProduct::fill(const CrsMatrix& a, const CrsMatrix& b, const TpetraVector* s) {
  const auto al = a.getLocalMatrixHost();
  const auto ml = m_->getLocalMatrixHost();
  const auto mv = m_->getLocalValuesView();
  const std::size_t rows = std::size_t(al.numRows()), nk = ext_start_.size() - 1,
                    ncol = m_->getColMap()->getNodeNumElements();
  if (al.values.extent(0) != a_.size() || std::size_t(ml.numRows()) != rows)
    throw std::logic_error("KeptProduct: a's graph changed");
  const bool all = fresh_ || (s != nullptr) != scaled_;
  // What changed since the last fill: b's rows at a's columns, s at m_'s columns, a's rows.
  std::vector<char> ext_changed(nk, all), col_changed(ncol, all);
  {
    std::vector<double> ext(ext_.size());
    import_values(
        b, *import_, [&](std::size_t q, double v) { ext[q] = v; }, "KeptProduct");
    if (!all)
      for (std::size_t k = 0; k < nk; ++k)
        for (std::size_t e = ext_start_[k]; e < ext_start_[k + 1] && !ext_changed[k]; ++e)
          ext_changed[k] = differs(ext[e], ext_[e]);
    ext_.swap(ext);
  }
  if (s) {
    if (s->getMap()->getNodeNumElements() != m_->getDomainMap()->getNodeNumElements())
      throw std::logic_error("KeptProduct: the scaling is not over the product's domain map");
    std::vector<double> sc(ncol);
    if (scale_import_.is_null()) {
      const auto v = s->getLocalViewHost(Tpetra::Access::ReadOnly);
      for (std::size_t c = 0; c < ncol; ++c)
        sc[c] = v(c, 0);
    } else {
      TpetraVector at(m_->getColMap());
      at.doImport(*s, *scale_import_, Tpetra::INSERT);
      const auto v = at.getLocalViewHost(Tpetra::Access::ReadOnly);
      for (std::size_t c = 0; c < ncol; ++c)
        sc[c] = v(c, 0);
    }
    if (!all)
      for (std::size_t c = 0; c < ncol; ++c)
        col_changed[c] = differs(sc[c], s_[c]);
    s_.swap(sc);
  }
  scaled_ = s != nullptr;
  std::vector<LocalId> formed;
  for (std::size_t r = 0; r < rows; ++r) {
    bool f = all;
    for (auto q = al.graph.row_map(r); q < al.graph.row_map(r + 1); ++q) {
      f = f || differs(al.values(q), a_[q]) || ext_changed[std::size_t(al.graph.entries(q))];
      a_[q] = al.values(q);
    }
    for (auto p = ml.graph.row_map(r); p < ml.graph.row_map(r + 1) && !f && scaled_; ++p)
      f = col_changed[std::size_t(ml.graph.entries(p))];
    if (f)
      formed.push_back(LocalId(r));
  }
  // Each row summed by one thread in a's and b's storage order: the same values for any number
  // of threads, and for a row formed again or kept.
  formed_ = formed.size();
  fresh_ = false;
  if (formed.empty())
    return;
  using Exec = Kokkos::DefaultHostExecutionSpace;
  Kokkos::Experimental::UniqueToken<Exec> token;
  std::vector<double> acc(std::size_t(token.size()) * ncol, 0.0);
  const double* ev = ext_.data();
  const double* sv = s_.data();
  const bool scaled = scaled_;
  Kokkos::parallel_for("mupm::KeptProduct::fill", Kokkos::RangePolicy<Exec>(0, formed.size()),
                       [&](std::size_t i) {
                         const int t = token.acquire();
                         double* w = acc.data() + std::size_t(t) * ncol;
                         const LocalId r = formed[i];
                         for (auto q = al.graph.row_map(r); q < al.graph.row_map(r + 1); ++q) {
                           const double x = al.values(q);
                           const std::size_t k = std::size_t(al.graph.entries(q));
                           for (std::size_t e = ext_start_[k]; e < ext_start_[k + 1]; ++e)
                             w[ext_col_[e]] += x * ev[e];
                         }
                         for (auto p = ml.graph.row_map(r); p < ml.graph.row_map(r + 1); ++p) {
                           const std::size_t c = std::size_t(ml.graph.entries(p));
                           mv(p) = scaled ? w[c] * sv[c] : w[c];
                           w[c] = 0.0;
                         }
                         token.release(t);
                       });
}

}  // namespace mupm
