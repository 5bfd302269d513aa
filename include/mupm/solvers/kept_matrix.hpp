// Sparse matrices whose graph is built once and whose values are then written in place. The
// semi-implicit pressure's system (include/mupm/solvers/pressure_projection.hpp) is a chain of
// sums and products of matrices assembled from the bond lists; its graphs depend only on the
// lists and on the points' roles (a broken bond keeps its entries, at zero), its values on the
// bonds' state, the saturation, the permeability and the step. Each class here has build(),
// which makes the graph with Tpetra and then calls fill(), and fill(), which writes the values
// on the kept graph: a matrix's values therefore come from the same operations whether its
// graph is new or kept, so a restart, which builds the graphs again, continues the run's matrix
// to the bit.
#ifndef MUPM_SOLVERS_KEPT_MATRIX_HPP
#define MUPM_SOLVERS_KEPT_MATRIX_HPP

#include <Teuchos_RCP.hpp>
#include <TpetraExt_MatrixMatrix.hpp>
#include <Tpetra_CrsMatrix.hpp>
#include <Tpetra_RowMatrixTransposer.hpp>
#include <algorithm>
#include <stdexcept>
#include <utility>
#include <vector>

#include "mupm/mesh/distribution.hpp"
#include "mupm/solvers/linear_solve.hpp"

namespace mupm {

// Rows of (local column, value), the owned rows in order.
using LocalRows = std::vector<std::vector<std::pair<LocalId, double>>>;
// n empty rows, each keeping the memory it had (a refill writes the same rows again).
inline void clear_rows(LocalRows& rows, std::size_t n) {
  rows.resize(n);
  for (auto& r : rows)
    r.clear();
}
// Rows of (global row, (global column, value)).
using GlobalRows = std::vector<std::pair<GlobalId, std::vector<std::pair<GlobalId, double>>>>;

namespace detail {
// The position in `c`'s values of each (local row of c, global column) that `each_row(r, add)`
// lists for c's local row r through add(global column); in the order listed.
template <class EachRow>
std::vector<std::size_t> positions_in(const CrsMatrix& c, EachRow&& each_row) {
  const auto cl = c.getLocalMatrixHost();
  const auto& cols = *c.getColMap();
  std::vector<std::size_t> out;
  std::vector<std::pair<LocalId, std::size_t>> row;
  for (LocalId r = 0; r < LocalId(cl.numRows()); ++r) {
    row.clear();
    for (auto q = cl.graph.row_map(r); q < cl.graph.row_map(r + 1); ++q)
      row.push_back({cl.graph.entries(q), std::size_t(q)});
    std::sort(row.begin(), row.end());
    each_row(r, [&](GlobalId g) {
      const LocalId lc = cols.getLocalElement(g);
      const auto it =
          std::lower_bound(row.begin(), row.end(), std::pair<LocalId, std::size_t>(lc, 0));
      if (lc == Teuchos::OrdinalTraits<LocalId>::invalid() || it == row.end() || it->first != lc)
        throw std::logic_error("KeptMatrix: an entry is not in the kept graph");
      out.push_back(it->second);
    });
  }
  return out;
}

// The positions in c's values of a's entries, in a's storage order (a's rows are c's rows).
inline std::vector<std::size_t> positions_of(const CrsMatrix& c, const CrsMatrix& a) {
  const auto al = a.getLocalMatrixHost();
  const auto &arows = *a.getRowMap(), &acols = *a.getColMap(), &crows = *c.getRowMap();
  std::vector<LocalId> from(crows.getNodeNumElements(), -1);  // c's row -> a's
  for (LocalId r = 0; r < LocalId(al.numRows()); ++r) {
    const LocalId cr = crows.getLocalElement(arows.getGlobalElement(r));
    if (cr == Teuchos::OrdinalTraits<LocalId>::invalid())
      throw std::logic_error("KeptMatrix: a row is not in the kept graph");
    from[std::size_t(cr)] = r;
  }
  // Listed in c's row order: reorder to a's storage order.
  std::vector<std::size_t> order;
  const auto listed = positions_in(c, [&](LocalId cr, auto&& add) {
    const LocalId r = from[std::size_t(cr)];
    if (r < 0)
      return;
    for (auto q = al.graph.row_map(r); q < al.graph.row_map(r + 1); ++q) {
      order.push_back(std::size_t(q));
      add(acols.getGlobalElement(al.graph.entries(q)));
    }
  });
  std::vector<std::size_t> out(listed.size());
  for (std::size_t k = 0; k < listed.size(); ++k)
    out[order[k]] = listed[k];
  return out;
}

// c's values (zero first when `first`) += s a, a's entries at `pos` (positions_of).
inline void add_values(CrsMatrix& c, double s, const CrsMatrix& a,
                       const std::vector<std::size_t>& pos, bool first) {
  const auto v = c.getLocalValuesView();
  const auto av = a.getLocalValuesView();
  if (av.extent(0) != pos.size())
    throw std::logic_error("KeptMatrix: a summand's graph changed");
  if (first)
    Kokkos::deep_copy(v, 0.0);
  for (std::size_t q = 0; q < pos.size(); ++q)
    v(pos[q]) += s * av(q);
}

// c's values += the listed rows' values at `pos` (in the rows' order; entries(r) gives a row's
// (column, value) pairs), which must be as many as at build.
template <class Rows, class Entries>
void add_listed(CrsMatrix& c, const std::vector<std::size_t>& pos, const Rows& rows,
                Entries&& entries) {
  const auto v = c.getLocalValuesView();
  std::size_t k = 0;
  for (const auto& r : rows)
    for (const auto& e : entries(r)) {
      if (k == pos.size())
        throw std::logic_error("KeptMatrix: the listed rows' graph changed");
      v(pos[k++]) += e.second;
    }
  if (k != pos.size())
    throw std::logic_error("KeptMatrix: the listed rows' graph changed");
}
}  // namespace detail

// A matrix from LocalRows over fixed maps (the columns of `cols`); fill() takes rows with the
// same columns in the same order.
class KeptRows {
 public:
  void build(const Teuchos::RCP<const Map>& rows, const Teuchos::RCP<const Map>& cols,
             const Teuchos::RCP<const Map>& domain, const Teuchos::RCP<const Map>& range,
             const LocalRows& entries) {
    std::size_t longest = 1;
    for (const auto& r : entries)
      longest = std::max(longest, r.size());
    m_ = Teuchos::rcp(new CrsMatrix(rows, cols, longest));
    std::vector<LocalId> c;
    std::vector<double> v;
    for (std::size_t r = 0; r < entries.size(); ++r) {
      c.clear();
      for (const auto& e : entries[r])
        c.push_back(e.first);
      v.assign(c.size(), 0.0);
      if (!c.empty())
        m_->insertLocalValues(LocalId(r), Teuchos::ArrayView<const LocalId>(c),
                              Teuchos::ArrayView<const double>(v));
    }
    m_->fillComplete(domain, range);
    const auto& cm = *m_->getColMap();
    pos_ = detail::positions_in(*m_, [&](LocalId r, auto&& add) {
      for (const auto& e : entries[std::size_t(r)])
        add(cm.getGlobalElement(e.first));
    });
    fill(entries);
  }
  void fill(const LocalRows& entries) {
    Kokkos::deep_copy(m_->getLocalValuesView(), 0.0);
    detail::add_listed(
        *m_, pos_, entries, [](const auto& r) -> const auto& { return r; });
  }
  const Teuchos::RCP<CrsMatrix>& matrix() const { return m_; }

 private:
  Teuchos::RCP<CrsMatrix> m_;
  std::vector<std::size_t> pos_;
};

// a's rows (or none) plus `extra` GlobalRows as a matrix over `rows` (which holds both); fill()
// takes a with the same graph and extra rows with the same columns in the same order.
class KeptJoin {
 public:
  void build(const CrsMatrix* a, const Teuchos::RCP<const Map>& rows, const GlobalRows& extra,
             const Teuchos::RCP<const Map>& domain, const Teuchos::RCP<const Map>& range) {
    std::size_t longest = a ? std::max<std::size_t>(1, a->getNodeMaxNumRowEntries()) : 1;
    for (const auto& r : extra)
      longest = std::max(longest, r.second.size());
    m_ = Teuchos::rcp(new CrsMatrix(rows, longest));
    std::vector<GlobalId> cols;
    std::vector<double> zeros;
    if (a) {
      const auto &arows = *a->getRowMap(), &acols = *a->getColMap();
      for (LocalId r = 0; r < LocalId(arows.getNodeNumElements()); ++r) {
        CrsMatrix::local_inds_host_view_type idx;
        CrsMatrix::values_host_view_type v;
        a->getLocalRowView(r, idx, v);
        cols.resize(idx.extent(0));
        for (std::size_t k = 0; k < idx.extent(0); ++k)
          cols[k] = acols.getGlobalElement(idx(k));
        zeros.assign(cols.size(), 0.0);
        if (!cols.empty())
          m_->insertGlobalValues(arows.getGlobalElement(r),
                                 Teuchos::ArrayView<const GlobalId>(cols),
                                 Teuchos::ArrayView<const double>(zeros));
      }
    }
    for (const auto& r : extra) {
      cols.clear();
      for (const auto& e : r.second)
        cols.push_back(e.first);
      zeros.assign(cols.size(), 0.0);
      if (!cols.empty())
        m_->insertGlobalValues(r.first, Teuchos::ArrayView<const GlobalId>(cols),
                               Teuchos::ArrayView<const double>(zeros));
    }
    m_->fillComplete(domain, range);
    pa_.clear();
    if (a)
      pa_ = detail::positions_of(*m_, *a);
    // extra's entries, in its order: listed per row of m_, then put back in extra's order.
    const auto& mrows = *m_->getRowMap();
    std::vector<std::vector<std::size_t>> of_row(mrows.getNodeNumElements());
    for (std::size_t k = 0; k < extra.size(); ++k)
      of_row[std::size_t(mrows.getLocalElement(extra[k].first))].push_back(k);
    std::vector<std::pair<std::size_t, std::size_t>> order;  // (extra row, entry)
    const auto listed = detail::positions_in(*m_, [&](LocalId r, auto&& add) {
      for (const std::size_t k : of_row[std::size_t(r)])
        for (std::size_t e = 0; e < extra[k].second.size(); ++e) {
          order.push_back({k, e});
          add(extra[k].second[e].first);
        }
    });
    std::vector<std::size_t> start(extra.size() + 1, 0);
    for (std::size_t k = 0; k < extra.size(); ++k)
      start[k + 1] = start[k] + extra[k].second.size();
    pe_.assign(listed.size(), 0);
    for (std::size_t q = 0; q < listed.size(); ++q)
      pe_[start[order[q].first] + order[q].second] = listed[q];
    fill(a, extra);
  }
  void fill(const CrsMatrix* a, const GlobalRows& extra) {
    if (a)
      detail::add_values(*m_, 1.0, *a, pa_, true);
    else
      Kokkos::deep_copy(m_->getLocalValuesView(), 0.0);
    detail::add_listed(
        *m_, pe_, extra, [](const auto& r) -> const auto& { return r.second; });
  }
  const Teuchos::RCP<CrsMatrix>& matrix() const { return m_; }

 private:
  Teuchos::RCP<CrsMatrix> m_;
  std::vector<std::size_t> pa_, pe_;
};

// s a + t b (a and b over the same rows), Tpetra's sum's graph kept.
class KeptSum {
 public:
  void build(double s, const CrsMatrix& a, double t, const CrsMatrix& b) {
    m_ = Tpetra::MatrixMatrix::add(s, false, a, t, false, b);
    pa_ = detail::positions_of(*m_, a);
    pb_ = detail::positions_of(*m_, b);
    fill(s, a, t, b);
  }
  void fill(double s, const CrsMatrix& a, double t, const CrsMatrix& b) {
    detail::add_values(*m_, s, a, pa_, true);
    detail::add_values(*m_, t, b, pb_, false);
  }
  // build() when `graph` (a new graph), else fill().
  void update(bool graph, double s, const CrsMatrix& a, double t, const CrsMatrix& b) {
    graph ? build(s, a, t, b) : fill(s, a, t, b);
  }
  const Teuchos::RCP<CrsMatrix>& matrix() const { return m_; }

 private:
  Teuchos::RCP<CrsMatrix> m_;
  std::vector<std::size_t> pa_, pb_;
};

// a b diag(s) (s over b's domain map, or none) on a graph kept while a's and b's are. build()
// takes the graph of Tpetra's product and keeps b's rows at a's columns: their structure, and
// the import of b's entries to them (numbered as in KeptTranspose). fill() imports b's values
// and forms a row, with a dense accumulator, only when one of its inputs (a's row, a b row it
// reaches, s at its columns) differs in some bit from the last fill's; each row is summed in the
// same order every time, so a kept row is the one a full product would give. Hence a caller
// must not change matrix()'s values unless a kept row would come out the same. The last fill's
// inputs are kept for the comparison (a's values and b's rows at a's columns: about twice b's
// values). Tpetra's reuse kernel, used before, imported b's remote rows on every call and
// formed every row (perf/README.md).
class KeptProduct {
 public:
  void build(const CrsMatrix& a, const CrsMatrix& b, const TpetraVector* s = nullptr);
  void fill(const CrsMatrix& a, const CrsMatrix& b, const TpetraVector* s = nullptr);
  void update(bool graph, const CrsMatrix& a, const CrsMatrix& b, const TpetraVector* s = nullptr) {
    graph ? build(a, b, s) : fill(a, b, s);
  }
  const Teuchos::RCP<CrsMatrix>& matrix() const { return m_; }
  // The rows the last fill formed, of matrix()'s local rows.
  std::size_t rows_formed() const { return formed_; }

 private:
  Teuchos::RCP<CrsMatrix> m_;
  // b's entries, by their numbers, to b's rows at a's columns (`ext`)
  Teuchos::RCP<const Tpetra::Import<LocalId, GlobalId>> import_;
  // s over b's domain map to m_'s columns (null: the same map)
  Teuchos::RCP<const Tpetra::Import<LocalId, GlobalId>> scale_import_;
  // ext in compressed rows (its row k is b's row at a's column k): m_'s local column of each
  std::vector<std::size_t> ext_start_;
  std::vector<LocalId> ext_col_;
  // the last fill's inputs (compared bit for bit) and whether it scaled
  std::vector<double> a_, ext_, s_;
  bool scaled_ = false, fresh_ = true;
  std::size_t formed_ = 0;
};

// dst: src's values on a copy of src's graph (copied when `graph`: a new graph).
inline void copy_values(Teuchos::RCP<CrsMatrix>& dst, const CrsMatrix& src, bool graph) {
  if (graph)
    dst = Teuchos::rcp(new CrsMatrix(src, Teuchos::Copy));
  Kokkos::deep_copy(dst->getLocalValuesView(), src.getLocalValuesView());
}

// a^T (Tpetra's transposer; its graph follows a's, so a product that takes it keeps its own).
inline Teuchos::RCP<CrsMatrix> transpose(const Teuchos::RCP<const CrsMatrix>& a) {
  Tpetra::RowMatrixTransposer<double, LocalId, GlobalId> t(a);
  return t.createTranspose();
}

// a^T on a graph kept while a's is. Each of a^T's entries is one of a's, moved to the rank that
// owns its column: build() transposes (Tpetra's transposer) a copy of a whose values are the
// global numbers of its entries, which gives each entry of a^T the number of the entry it
// copies, and keeps the import of a's entries, numbered so, to a^T's; fill() then moves a's
// values by that import: one exchange of a's values, where Tpetra's transposer builds a new
// matrix (measured on Example 1 case 2's coupling at 100 x 100: perf/README.md). The values are
// copies, so a^T is the transposer's to the bit.
class KeptTranspose {
 public:
  void build(const Teuchos::RCP<const CrsMatrix>& a);
  void fill(const CrsMatrix& a);
  void update(bool graph, const Teuchos::RCP<const CrsMatrix>& a) { graph ? build(a) : fill(*a); }
  const Teuchos::RCP<CrsMatrix>& matrix() const { return m_; }

 private:
  Teuchos::RCP<CrsMatrix> m_;
  // a's entries, by their numbers, to m_'s
  Teuchos::RCP<const Tpetra::Import<LocalId, GlobalId>> import_;
};

// A diagonal matrix over a vector's map.
class KeptDiagonal {
 public:
  void build(const TpetraVector& d) {
    const auto map = d.getMap();
    m_ = Teuchos::rcp(new CrsMatrix(map, map, 1));
    for (LocalId r = 0; r < LocalId(map->getNodeNumElements()); ++r) {
      const LocalId c = r;
      const double zero = 0.0;
      m_->insertLocalValues(r, Teuchos::ArrayView<const LocalId>(&c, 1),
                            Teuchos::ArrayView<const double>(&zero, 1));
    }
    m_->fillComplete(map, map);
    fill(d);
  }
  void fill(const TpetraVector& d) {
    const auto l = m_->getLocalMatrixHost();
    const auto dv = d.getLocalViewHost(Tpetra::Access::ReadOnly);
    const auto v = m_->getLocalValuesView();
    for (LocalId r = 0; r < LocalId(l.numRows()); ++r)
      v(l.graph.row_map(r)) = dv(r, 0);
  }
  void update(bool graph, const TpetraVector& d) { graph ? build(d) : fill(d); }
  const Teuchos::RCP<CrsMatrix>& matrix() const { return m_; }

 private:
  Teuchos::RCP<CrsMatrix> m_;
};

}  // namespace mupm

#endif
