#include "mupm/io/hdf5_io.hpp"

#include "mupm/core/collective.hpp"
#include "mupm/core/error.hpp"

#include <hdf5.h>

#include <algorithm>
#include <stdexcept>
#include <type_traits>

namespace mupm::io {
namespace {

static_assert(std::is_same_v<hid_t, std::int64_t>, "PointFile stores hid_t as std::int64_t");
static_assert(sizeof(int) == 4, "int fields are stored as 32-bit integers");

// ---------------------------------------------------------------------------------------------
// HDF5 plumbing

// Owns one HDF5 identifier so nothing leaks when an exception unwinds.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  Handle(Handle&& o) noexcept : id_(std::exchange(o.id_, -1)), closer_(o.closer_) {}
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, -1);
      closer_ = o.closer_;
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { reset(); }

  void reset() noexcept {
    if (id_ >= 0 && closer_ != nullptr) {
      closer_(id_);
    }
    id_ = -1;
  }
  hid_t get() const { return id_; }
  hid_t release() noexcept { return std::exchange(id_, -1); }

 private:
  hid_t id_ = -1;
  Closer closer_ = nullptr;
};

// Silences HDF5's automatic stack printing for the scope and restores the caller's setting, so
// errors are reported once, through our exceptions, without changing global state for others.
class QuietErrors {
 public:
  QuietErrors() {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    H5Eclear2(H5E_DEFAULT);
  }
  QuietErrors(const QuietErrors&) = delete;
  QuietErrors& operator=(const QuietErrors&) = delete;
  ~QuietErrors() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

herr_t collect_error(unsigned /*n*/, const H5E_error2_t* e, void* out) {
  auto* descs = static_cast<std::vector<std::string>*>(out);
  if (e->desc != nullptr && e->desc[0] != '\0') {
    descs->emplace_back(e->desc);
  }
  return 0;
}

// Innermost messages of the current HDF5 error stack (they carry the actual cause, e.g. errno).
std::string h5_reason() {
  std::vector<std::string> descs;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, collect_error, &descs);
  H5Eclear2(H5E_DEFAULT);
  if (descs.empty()) {
    return "unknown HDF5 error";
  }
  std::string out;
  for (std::size_t i = 0; i < descs.size() && i < 2; ++i) {
    out += (i > 0 ? "; " : "") + descs[i];
  }
  return out;
}

[[noreturn]] void h5_fail(const std::string& what) {
  throw std::runtime_error(what + " (" + h5_reason() + ")");
}

hid_t check_id(hid_t id, const std::string& what) {
  if (id < 0) {
    h5_fail(what);
  }
  return id;
}

void check_err(herr_t e, const std::string& what) {
  if (e < 0) {
    h5_fail(what);
  }
}

Handle make_plist(hid_t cls, const std::string& what) {
  return Handle(check_id(H5Pcreate(cls), what), H5Pclose);
}

// Runs a local step and agrees on its outcome, so a failure on one rank cannot leave the others
// waiting in the next collective call.
template <class F>
void collective(MPI_Comm comm, F&& step) {
  std::string err;
  try {
    step();
  } catch (const std::exception& e) {
    err = e.what();
    if (err.empty()) {
      err = "unknown error";
    }
  }
  agree(comm, err);
}

// True iff `bytes` equals rank 0's bytes on every rank.
bool same_on_all_ranks(MPI_Comm comm, const std::string& bytes) {
  long long len = static_cast<long long>(bytes.size());
  MPI_Bcast(&len, 1, MPI_LONG_LONG, 0, comm);
  std::string root(static_cast<std::size_t>(len), '\0');
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank == 0) {
    root = bytes;
  }
  MPI_Bcast(root.data(), static_cast<int>(len), MPI_CHAR, 0, comm);
  int same = root == bytes ? 1 : 0;
  int all = 0;
  MPI_Allreduce(&same, &all, 1, MPI_INT, MPI_MIN, comm);
  return all == 1;
}

// ---------------------------------------------------------------------------------------------
// Names, shapes, types

// "a//b/" -> "a/b"; empty if there is no component.
std::string canonical_name(const std::string& name) {
  std::string out;
  std::size_t i = 0;
  while (i < name.size()) {
    const std::size_t j = std::min(name.find('/', i), name.size());
    if (j > i) {
      out += (out.empty() ? "" : "/") + name.substr(i, j - i);
    }
    i = j + 1;
  }
  return out;
}

// H5Lexists fails (instead of returning false) when an intermediate group is missing, so walk the
// path one component at a time.
bool dataset_exists(hid_t file, const std::string& cname) {
  if (cname.empty()) {
    return false;
  }
  std::size_t pos = 0;
  while (true) {
    pos = cname.find('/', pos + 1);
    const std::string prefix = cname.substr(0, pos);
    if (H5Lexists(file, prefix.c_str(), H5P_DEFAULT) <= 0) {
      H5Eclear2(H5E_DEFAULT);
      return false;
    }
    if (pos == std::string::npos) {
      break;
    }
  }
  Handle obj(H5Oopen(file, cname.c_str(), H5P_DEFAULT), H5Oclose);
  if (obj.get() < 0) {
    H5Eclear2(H5E_DEFAULT);
    return false;
  }
  return H5Iget_type(obj.get()) == H5I_DATASET;
}

std::vector<hsize_t> space_dims(hid_t space) {
  const int nd = H5Sget_simple_extent_ndims(space);
  if (nd < 0) {
    h5_fail("cannot query dataspace rank");
  }
  std::vector<hsize_t> dims(static_cast<std::size_t>(nd));
  if (nd > 0) {
    check_err(H5Sget_simple_extent_dims(space, dims.data(), nullptr), "cannot query dataspace");
  }
  return dims;
}

std::string shape_str(const std::vector<hsize_t>& dims) {
  if (dims.empty()) {
    return "scalar";
  }
  std::string s;
  for (hsize_t d : dims) {
    s += "[" + std::to_string(d) + "]";
  }
  return s;
}

std::string type_str(hid_t t) {
  const std::string bits = std::to_string(8 * H5Tget_size(t));
  switch (H5Tget_class(t)) {
    case H5T_FLOAT:
      return "float" + bits;
    case H5T_INTEGER:
      return (H5Tget_sign(t) == H5T_SGN_NONE ? "uint" : "int") + bits;
    case H5T_STRING:
      return "string";
    default:
      return "non-numeric type";
  }
}

template <class T>
struct Native;
template <>
struct Native<double> {
  static hid_t type() { return H5T_NATIVE_DOUBLE; }
};
template <>
struct Native<int> {
  static hid_t type() { return H5T_NATIVE_INT32; }
};
template <>
struct Native<unsigned char> {
  static hid_t type() { return H5T_NATIVE_UINT8; }
};
template <>
struct Native<long long> {
  static hid_t type() { return H5T_NATIVE_LLONG; }
};

// Rows per dataset and components per row: [n] -> ncomp 1, [n][c] -> ncomp c.
struct RowShape {
  hsize_t rows = 0;
  hsize_t ncomp = 0;
  bool ok = false;
};

RowShape row_shape(const std::vector<hsize_t>& dims) {
  RowShape s;
  if (dims.size() == 1) {
    s = {dims[0], 1, true};
  } else if (dims.size() == 2) {
    s = {dims[0], dims[1], true};
  }
  return s;
}

// ---------------------------------------------------------------------------------------------
// Selections

struct Run {
  hsize_t start;
  hsize_t count;
};

// Consecutive-gid runs of a sorted, unique gid list.
std::vector<Run> runs_of(const std::vector<long long>& gids) {
  std::vector<Run> runs;
  for (std::size_t i = 0; i < gids.size();) {
    std::size_t j = i + 1;
    while (j < gids.size() && gids[j] == gids[j - 1] + 1) {
      ++j;
    }
    runs.push_back({static_cast<hsize_t>(gids[i]), static_cast<hsize_t>(j - i)});
    i = j;
  }
  return runs;
}

// Union of runs [lo, hi) as a selection on a copy of `space`. OR-ing hyperslabs one at a time is
// quadratic in HDF5 1.10 (about 7 min for 1e5 runs), so small groups are OR-ed directly and the
// groups are merged pairwise with H5Scombine_select, which is O(n log n).
Handle select_runs(hid_t space, const std::vector<Run>& runs, std::size_t lo, std::size_t hi,
                   hsize_t ncomp) {
  constexpr std::size_t kLeaf = 32;
  if (hi - lo <= kLeaf) {
    Handle s(check_id(H5Scopy(space), "cannot copy dataspace"), H5Sclose);
    for (std::size_t i = lo; i < hi; ++i) {
      const hsize_t start[2] = {runs[i].start, 0};
      const hsize_t count[2] = {runs[i].count, ncomp};  // [1] is ignored for a 1-D space
      check_err(H5Sselect_hyperslab(s.get(), i == lo ? H5S_SELECT_SET : H5S_SELECT_OR, start,
                                    nullptr, count, nullptr),
                "cannot select rows");
    }
    return s;
  }
  const std::size_t mid = lo + (hi - lo) / 2;
  Handle a = select_runs(space, runs, lo, mid, ncomp);
  Handle b = select_runs(space, runs, mid, hi, ncomp);
  return Handle(check_id(H5Scombine_select(a.get(), H5S_SELECT_OR, b.get()), "cannot merge rows"),
                H5Sclose);
}

// File selection of the rows of `sorted_gids` (sorted, unique); a rank without rows selects none
// but still takes part in the collective transfer.
Handle select_rows(hid_t file_space, const std::vector<long long>& sorted_gids, hsize_t ncomp) {
  const std::vector<Run> runs = runs_of(sorted_gids);
  if (runs.empty()) {
    Handle s(check_id(H5Scopy(file_space), "cannot copy dataspace"), H5Sclose);
    check_err(H5Sselect_none(s.get()), "cannot clear selection");
    return s;
  }
  return select_runs(file_space, runs, 0, runs.size(), ncomp);
}

// Contiguous memory buffer of n values; empty selection when n == 0.
Handle memory_space(hsize_t n) {
  const hsize_t dim = std::max<hsize_t>(n, 1);
  Handle s(check_id(H5Screate_simple(1, &dim, nullptr), "cannot create memory space"), H5Sclose);
  if (n == 0) {
    check_err(H5Sselect_none(s.get()), "cannot clear selection");
  }
  return s;
}

// Opens an existing dataset, or throws "not found" / "cannot open" with the context.
Handle open_dataset(hid_t file, const std::string& cname, const std::string& ctx) {
  if (!dataset_exists(file, cname)) {
    throw std::runtime_error(ctx + ": dataset not found");
  }
  return Handle(check_id(H5Dopen2(file, cname.c_str(), H5P_DEFAULT), ctx + ": cannot open"),
                H5Dclose);
}

Handle collective_xfer() {
  Handle dxpl = make_plist(H5P_DATASET_XFER, "cannot create transfer property list");
  check_err(H5Pset_dxpl_mpio(dxpl.get(), H5FD_MPIO_COLLECTIVE), "cannot request collective I/O");
  return dxpl;
}

// Opens an existing dataset after checking its shape and element type, or creates it (with
// intermediate groups). Same outcome on all ranks since the metadata is identical everywhere.
Handle open_or_create(hid_t file, const std::string& cname, const std::vector<hsize_t>& dims,
                      hid_t type, const std::string& ctx) {
  if (dataset_exists(file, cname)) {
    Handle dset(check_id(H5Dopen2(file, cname.c_str(), H5P_DEFAULT), ctx + ": cannot open"),
                H5Dclose);
    Handle space(check_id(H5Dget_space(dset.get()), ctx + ": cannot get dataspace"), H5Sclose);
    Handle ftype(check_id(H5Dget_type(dset.get()), ctx + ": cannot get type"), H5Tclose);
    const std::vector<hsize_t> found = space_dims(space.get());
    const H5T_class_t cls = H5Tget_class(ftype.get());
    if (found != dims || cls != H5Tget_class(type) ||
        H5Tget_size(ftype.get()) != H5Tget_size(type) ||
        (cls == H5T_INTEGER && H5Tget_sign(ftype.get()) != H5Tget_sign(type))) {
      throw std::runtime_error(ctx + ": existing dataset has shape " + shape_str(found) + " " +
                               type_str(ftype.get()) + ", expected " + shape_str(dims) + " " +
                               type_str(type));
    }
    return dset;
  }
  Handle lcpl = make_plist(H5P_LINK_CREATE, ctx + ": cannot create property list");
  check_err(H5Pset_create_intermediate_group(lcpl.get(), 1), ctx + ": intermediate groups");
  Handle dcpl = make_plist(H5P_DATASET_CREATE, ctx + ": cannot create property list");
  // Parallel HDF5 allocates contiguous datasets at creation; filling them would write everything
  // twice.
  check_err(H5Pset_fill_time(dcpl.get(), H5D_FILL_TIME_NEVER), ctx + ": fill time");
  Handle space(check_id(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr),
                        ctx + ": cannot create dataspace"),
               H5Sclose);
  return Handle(check_id(H5Dcreate2(file, cname.c_str(), type, space.get(), lcpl.get(), dcpl.get(),
                                    H5P_DEFAULT),
                         ctx + ": cannot create dataset"),
                H5Dclose);
}

// ---------------------------------------------------------------------------------------------
// Point fields

std::string context(const std::string& path, const char* op, const std::string& name) {
  return "mupm::io: " + path + ": " + op + "('" + name + "')";
}

template <class T>
void write_points_impl(MPI_Comm comm, hid_t file, const std::string& path, const std::string& name,
                       const std::vector<long long>& gids, long long n_global, int ncomp,
                       const T* data) {
  QuietErrors quiet;
  const std::string ctx = context(path, "write_points", name);
  const std::string cname = canonical_name(name);

  // n_global and ncomp must agree everywhere, otherwise ranks would create different datasets.
  long long in[4] = {n_global, -n_global, ncomp, -static_cast<long long>(ncomp)};
  long long mx[4];
  MPI_Allreduce(in, mx, 4, MPI_LONG_LONG, MPI_MAX, comm);
  collective(comm, [&] {
    if (mx[0] != -mx[1] || mx[2] != -mx[3]) {
      throw std::runtime_error(ctx + ": n_global or ncomp differs between ranks");
    }
    if (cname.empty()) {
      throw std::runtime_error(ctx + ": empty dataset name");
    }
    if (ncomp < 1 || n_global < 0) {
      throw std::runtime_error(ctx + ": invalid ncomp " + std::to_string(ncomp) + " or n_global " +
                               std::to_string(n_global));
    }
    if (!gids.empty() && data == nullptr) {
      throw std::runtime_error(ctx + ": null data for " + std::to_string(gids.size()) + " points");
    }
    for (std::size_t i = 0; i < gids.size(); ++i) {
      if (gids[i] < 0 || gids[i] >= n_global) {
        throw std::runtime_error(ctx + ": gid " + std::to_string(gids[i]) + " outside [0, " +
                                 std::to_string(n_global) + ")");
      }
      if (i > 0 && gids[i] <= gids[i - 1]) {
        throw std::runtime_error(ctx + ": gids not sorted ascending and unique at index " +
                                 std::to_string(i));
      }
    }
  });

  const hsize_t nc = static_cast<hsize_t>(ncomp);
  std::vector<hsize_t> dims{static_cast<hsize_t>(n_global)};
  if (ncomp != 1) {
    dims.push_back(nc);
  }
  Handle dset, fsel, mspace, dxpl;
  collective(comm, [&] {
    dset = open_or_create(file, cname, dims, Native<T>::type(), ctx);
    Handle fspace(check_id(H5Dget_space(dset.get()), ctx + ": cannot get dataspace"), H5Sclose);
    fsel = select_rows(fspace.get(), gids, nc);
    mspace = memory_space(gids.size() * nc);
    dxpl = collective_xfer();
  });
  if (n_global == 0) {
    return;  // nothing to write, and HDF5 fails on transfers to a never-allocated dataset
  }
  static const T dummy{};  // HDF5 rejects a null buffer even for an empty selection
  const void* buf = gids.empty() ? static_cast<const void*>(&dummy) : data;
  collective(comm, [&] {
    check_err(H5Dwrite(dset.get(), Native<T>::type(), mspace.get(), fsel.get(), dxpl.get(), buf),
              ctx + ": write failed");
  });
}

template <class T>
void read_points_impl(MPI_Comm comm, hid_t file, const std::string& path, const std::string& name,
                      const std::vector<long long>& gids, int ncomp, T* out) {
  QuietErrors quiet;
  const std::string ctx = context(path, "read_points", name);
  const std::string cname = canonical_name(name);

  // The file selection follows file order, so unsorted or repeated gids are read through a sorted
  // unique list and scattered afterwards.
  const bool direct = std::is_sorted(gids.begin(), gids.end()) &&
                      std::adjacent_find(gids.begin(), gids.end()) == gids.end();
  std::vector<long long> uniq;
  if (!direct) {
    uniq = gids;
    std::sort(uniq.begin(), uniq.end());
    uniq.erase(std::unique(uniq.begin(), uniq.end()), uniq.end());
  }
  const std::vector<long long>& sel = direct ? gids : uniq;
  const hsize_t nc = static_cast<hsize_t>(std::max(ncomp, 1));

  Handle dset, fsel, mspace, dxpl;
  hsize_t rows = 0;
  collective(comm, [&] {
    if (cname.empty()) {
      throw std::runtime_error(ctx + ": empty dataset name");
    }
    if (ncomp < 1) {
      throw std::runtime_error(ctx + ": invalid ncomp " + std::to_string(ncomp));
    }
    if (!gids.empty() && out == nullptr) {
      throw std::runtime_error(ctx + ": null output for " + std::to_string(gids.size()) +
                               " points");
    }
    dset = open_dataset(file, cname, ctx);
    Handle fspace(check_id(H5Dget_space(dset.get()), ctx + ": cannot get dataspace"), H5Sclose);
    Handle ftype(check_id(H5Dget_type(dset.get()), ctx + ": cannot get type"), H5Tclose);
    const std::vector<hsize_t> dims = space_dims(fspace.get());
    const RowShape rs = row_shape(dims);
    if (!rs.ok || rs.ncomp != nc) {
      throw std::runtime_error(ctx + ": dataset has shape " + shape_str(dims) + ", expected [n]" +
                               (ncomp == 1 ? "" : "[" + std::to_string(ncomp) + "]"));
    }
    if (H5Tget_class(ftype.get()) != H5Tget_class(Native<T>::type())) {
      throw std::runtime_error(ctx + ": dataset holds " + type_str(ftype.get()) +
                               ", cannot read as " + type_str(Native<T>::type()));
    }
    if (!sel.empty() && (sel.front() < 0 || static_cast<hsize_t>(sel.back()) >= rs.rows)) {
      const long long bad = sel.front() < 0 ? sel.front() : sel.back();
      throw std::runtime_error(ctx + ": gid " + std::to_string(bad) + " outside dataset of " +
                               std::to_string(rs.rows) + " rows");
    }
    rows = rs.rows;
    fsel = select_rows(fspace.get(), sel, nc);
    mspace = memory_space(sel.size() * nc);
    dxpl = collective_xfer();
  });
  if (rows == 0) {
    return;  // no gid can be valid, and HDF5 fails on transfers from an unallocated dataset
  }

  std::vector<T> tmp(direct ? 0 : sel.size() * nc);
  static T dummy{};
  void* buf = sel.empty() ? static_cast<void*>(&dummy)
                          : (direct ? static_cast<void*>(out) : static_cast<void*>(tmp.data()));
  collective(comm, [&] {
    check_err(H5Dread(dset.get(), Native<T>::type(), mspace.get(), fsel.get(), dxpl.get(), buf),
              ctx + ": read failed");
  });
  if (!direct) {
    for (std::size_t i = 0; i < gids.size(); ++i) {
      const std::size_t k = static_cast<std::size_t>(
          std::lower_bound(uniq.begin(), uniq.end(), gids[i]) - uniq.begin());
      std::copy_n(tmp.data() + k * nc, nc, out + i * nc);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Attributes

void write_root_attribute(hid_t file, const std::string& name, hid_t type, const void* buf,
                          const std::string& ctx) {
  if (name.empty()) {
    throw std::runtime_error(ctx + ": empty attribute name");
  }
  const htri_t exists = H5Aexists(file, name.c_str());
  if (exists < 0) {
    h5_fail(ctx + ": cannot query attribute");
  }
  if (exists > 0) {
    check_err(H5Adelete(file, name.c_str()), ctx + ": cannot replace attribute");
  }
  Handle space(check_id(H5Screate(H5S_SCALAR), ctx + ": cannot create dataspace"), H5Sclose);
  Handle attr(check_id(H5Acreate2(file, name.c_str(), type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                       ctx + ": cannot create attribute"),
              H5Aclose);
  check_err(H5Awrite(attr.get(), type, buf), ctx + ": cannot write attribute");
}

// Opens a root attribute holding exactly one value.
Handle open_root_attribute(hid_t file, const std::string& name, const std::string& ctx) {
  const htri_t exists = name.empty() ? 0 : H5Aexists(file, name.c_str());
  if (exists <= 0) {
    H5Eclear2(H5E_DEFAULT);
    throw std::runtime_error(ctx + ": attribute not found");
  }
  Handle attr(check_id(H5Aopen(file, name.c_str(), H5P_DEFAULT), ctx + ": cannot open attribute"),
              H5Aclose);
  Handle space(check_id(H5Aget_space(attr.get()), ctx + ": cannot get dataspace"), H5Sclose);
  if (H5Sget_simple_extent_npoints(space.get()) != 1) {
    throw std::runtime_error(ctx + ": attribute is not a single value (shape " +
                             shape_str(space_dims(space.get())) + ")");
  }
  return attr;
}

// Reads a numeric attribute of one of the allowed type classes into `mem_type`.
template <class T>
T read_numeric_attribute(MPI_Comm comm, hid_t file, const std::string& path,
                         const std::string& name, const char* op, hid_t mem_type,
                         bool allow_integer, bool allow_float) {
  QuietErrors quiet;
  const std::string ctx = context(path, op, name);
  T v{};
  collective(comm, [&] {
    Handle attr = open_root_attribute(file, name, ctx);
    Handle ftype(check_id(H5Aget_type(attr.get()), ctx + ": cannot get type"), H5Tclose);
    const H5T_class_t cls = H5Tget_class(ftype.get());
    if (!((cls == H5T_INTEGER && allow_integer) || (cls == H5T_FLOAT && allow_float))) {
      throw std::runtime_error(ctx + ": attribute has type " + type_str(ftype.get()));
    }
    check_err(H5Aread(attr.get(), mem_type, &v), ctx + ": cannot read attribute");
  });
  return v;
}

std::string value_bytes(const void* p, std::size_t n) {
  return std::string(static_cast<const char*>(p), n);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// PointFile

namespace {

// Opens or creates the file on a private communicator; throws on all ranks if any rank fails.
hid_t open_file(MPI_Comm comm, const std::string& path, bool create) {
  QuietErrors quiet;
  Handle file;
  collective(comm, [&] {
    const std::string ctx =
        std::string("mupm::io: cannot ") + (create ? "create" : "open") + " '" + path + "'";
    Handle fapl = make_plist(H5P_FILE_ACCESS, ctx);
    check_err(H5Pset_fapl_mpio(fapl.get(), comm, MPI_INFO_NULL), ctx + ": MPI-IO driver");
    const hid_t f = create ? H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get())
                           : H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl.get());
    file = Handle(check_id(f, ctx), H5Fclose);
  });
  return file.release();  // ownership passes to the PointFile
}

}  // namespace

namespace {

// The file gets its own duplicate of the communicator, freed with the file (or here on failure).
template <class Make>
PointFile with_dup(MPI_Comm comm, Make&& make) {
  MPI_Comm dup = MPI_COMM_NULL;
  MPI_Comm_dup(comm, &dup);
  try {
    return make(dup);
  } catch (...) {
    MPI_Comm_free(&dup);
    throw;
  }
}

}  // namespace

PointFile PointFile::create(MPI_Comm comm, const std::string& path) {
  return with_dup(comm,
                  [&](MPI_Comm dup) { return PointFile(dup, open_file(dup, path, true), path); });
}

PointFile PointFile::open(MPI_Comm comm, const std::string& path) {
  return with_dup(comm,
                  [&](MPI_Comm dup) { return PointFile(dup, open_file(dup, path, false), path); });
}

PointFile::PointFile(PointFile&& other) noexcept
    : comm_(std::exchange(other.comm_, MPI_COMM_NULL)),
      file_(std::exchange(other.file_, -1)),
      path_(std::move(other.path_)) {}

PointFile& PointFile::operator=(PointFile&& other) noexcept {
  if (this != &other) {
    release();
    comm_ = std::exchange(other.comm_, MPI_COMM_NULL);
    file_ = std::exchange(other.file_, -1);
    path_ = std::move(other.path_);
  }
  return *this;
}

PointFile::~PointFile() {
  release();
}

void PointFile::release() noexcept {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (finalized) {
    return;  // too late to close collectively; the OS reclaims the file
  }
  if (file_ >= 0) {
    QuietErrors quiet;
    H5Fclose(file_);
    file_ = -1;
  }
  if (comm_ != MPI_COMM_NULL) {
    MPI_Comm_free(&comm_);
  }
}

void PointFile::close() {
  if (file_ < 0) {
    return;
  }
  QuietErrors quiet;
  std::string err;
  if (H5Fclose(file_) < 0) {
    err = "mupm::io: " + path_ + ": close failed (" + h5_reason() + ")";
  }
  file_ = -1;
  MPI_Comm comm = std::exchange(comm_, MPI_COMM_NULL);
  try {
    agree(comm, err);
  } catch (...) {
    MPI_Comm_free(&comm);
    throw;
  }
  MPI_Comm_free(&comm);
}

void PointFile::write_points(const std::string& name, const std::vector<long long>& gids,
                             long long n_global, int ncomp, const double* data) {
  write_points_impl(comm_, file_, path_, name, gids, n_global, ncomp, data);
}
void PointFile::write_points(const std::string& name, const std::vector<long long>& gids,
                             long long n_global, int ncomp, const int* data) {
  write_points_impl(comm_, file_, path_, name, gids, n_global, ncomp, data);
}
void PointFile::write_points(const std::string& name, const std::vector<long long>& gids,
                             long long n_global, int ncomp, const unsigned char* data) {
  write_points_impl(comm_, file_, path_, name, gids, n_global, ncomp, data);
}
void PointFile::write_points(const std::string& name, const std::vector<long long>& gids,
                             long long n_global, int ncomp, const long long* data) {
  write_points_impl(comm_, file_, path_, name, gids, n_global, ncomp, data);
}

void PointFile::read_points(const std::string& name, const std::vector<long long>& gids, int ncomp,
                            double* out) const {
  read_points_impl(comm_, file_, path_, name, gids, ncomp, out);
}
void PointFile::read_points(const std::string& name, const std::vector<long long>& gids, int ncomp,
                            int* out) const {
  read_points_impl(comm_, file_, path_, name, gids, ncomp, out);
}
void PointFile::read_points(const std::string& name, const std::vector<long long>& gids, int ncomp,
                            unsigned char* out) const {
  read_points_impl(comm_, file_, path_, name, gids, ncomp, out);
}
void PointFile::read_points(const std::string& name, const std::vector<long long>& gids, int ncomp,
                            long long* out) const {
  read_points_impl(comm_, file_, path_, name, gids, ncomp, out);
}

void PointFile::write_attribute(const std::string& name, double v) {
  QuietErrors quiet;
  const std::string ctx = context(path_, "write_attribute", name);
  const bool same = same_on_all_ranks(comm_, value_bytes(&v, sizeof v));
  collective(comm_, [&] {
    if (!same) {
      throw std::runtime_error(ctx + ": value differs between ranks");
    }
    write_root_attribute(file_, name, H5T_NATIVE_DOUBLE, &v, ctx);
  });
}

void PointFile::write_attribute(const std::string& name, long long v) {
  QuietErrors quiet;
  const std::string ctx = context(path_, "write_attribute", name);
  const bool same = same_on_all_ranks(comm_, value_bytes(&v, sizeof v));
  collective(comm_, [&] {
    if (!same) {
      throw std::runtime_error(ctx + ": value differs between ranks");
    }
    write_root_attribute(file_, name, H5T_NATIVE_LLONG, &v, ctx);
  });
}

void PointFile::write_attribute(const std::string& name, const std::string& v) {
  QuietErrors quiet;
  const std::string ctx = context(path_, "write_attribute", name);
  const bool same = same_on_all_ranks(comm_, v);
  collective(comm_, [&] {
    if (!same) {
      throw std::runtime_error(ctx + ": value differs between ranks");
    }
    // Fixed-length, null-terminated UTF-8: the simplest string type every reader understands.
    Handle type(check_id(H5Tcopy(H5T_C_S1), ctx + ": string type"), H5Tclose);
    check_err(H5Tset_size(type.get(), v.size() + 1), ctx + ": string type");
    check_err(H5Tset_strpad(type.get(), H5T_STR_NULLTERM), ctx + ": string type");
    check_err(H5Tset_cset(type.get(), H5T_CSET_UTF8), ctx + ": string type");
    write_root_attribute(file_, name, type.get(), v.c_str(), ctx);
  });
}

double PointFile::read_attribute_double(const std::string& name) const {
  return read_numeric_attribute<double>(comm_, file_, path_, name, "read_attribute_double",
                                        H5T_NATIVE_DOUBLE, true, true);
}

long long PointFile::read_attribute_int(const std::string& name) const {
  return read_numeric_attribute<long long>(comm_, file_, path_, name, "read_attribute_int",
                                           H5T_NATIVE_LLONG, true, false);
}

std::string PointFile::read_attribute_string(const std::string& name) const {
  QuietErrors quiet;
  const std::string ctx = context(path_, "read_attribute_string", name);
  std::string v;
  collective(comm_, [&] {
    Handle attr = open_root_attribute(file_, name, ctx);
    Handle ftype(check_id(H5Aget_type(attr.get()), ctx + ": cannot get type"), H5Tclose);
    if (H5Tget_class(ftype.get()) != H5T_STRING) {
      throw std::runtime_error(ctx + ": attribute has type " + type_str(ftype.get()));
    }
    Handle mtype(check_id(H5Tcopy(ftype.get()), ctx + ": string type"), H5Tclose);
    const htri_t vlen = H5Tis_variable_str(ftype.get());
    if (vlen < 0) {
      h5_fail(ctx + ": string type");
    }
    if (vlen > 0) {  // e.g. written by h5py
      char* p = nullptr;
      check_err(H5Aread(attr.get(), mtype.get(), &p), ctx + ": cannot read attribute");
      v = p != nullptr ? std::string(p) : std::string();
      H5free_memory(p);
    } else {
      std::string buf(H5Tget_size(ftype.get()), '\0');
      check_err(H5Aread(attr.get(), mtype.get(), buf.data()), ctx + ": cannot read attribute");
      if (H5Tget_strpad(ftype.get()) == H5T_STR_SPACEPAD) {
        buf.erase(buf.find_last_not_of(' ') + 1);
      }
      v = buf.substr(0, buf.find('\0'));
    }
  });
  return v;
}

bool PointFile::has_attribute(const std::string& name) const {
  QuietErrors quiet;
  bool exists = false;
  collective(comm_, [&] {
    const htri_t e = name.empty() ? 0 : H5Aexists(file_, name.c_str());
    H5Eclear2(H5E_DEFAULT);
    exists = e > 0;
  });
  return exists;
}

bool PointFile::has_dataset(const std::string& name) const {
  QuietErrors quiet;
  bool exists = false;
  collective(comm_, [&] { exists = dataset_exists(file_, canonical_name(name)); });
  return exists;
}

std::vector<long long> PointFile::dataset_shape(const std::string& name) const {
  QuietErrors quiet;
  const std::string ctx = context(path_, "dataset_shape", name);
  std::vector<long long> shape;
  collective(comm_, [&] {
    const std::string cname = canonical_name(name);
    if (!dataset_exists(file_, cname)) {
      throw std::runtime_error(ctx + ": dataset not found");
    }
    Handle dset(check_id(H5Dopen2(file_, cname.c_str(), H5P_DEFAULT), ctx + ": cannot open"),
                H5Dclose);
    Handle space(check_id(H5Dget_space(dset.get()), ctx + ": cannot get dataspace"), H5Sclose);
    for (hsize_t d : space_dims(space.get())) {
      shape.push_back(static_cast<long long>(d));
    }
  });
  return shape;
}

void PointFile::write_global(const std::string& name, const std::vector<double>& values) {
  QuietErrors quiet;
  const std::string ctx = context(path_, "write_global", name);
  const std::string cname = canonical_name(name);
  const long long n = static_cast<long long>(values.size());
  long long in[2] = {n, -n};
  long long mx[2];
  MPI_Allreduce(in, mx, 2, MPI_LONG_LONG, MPI_MAX, comm_);
  int rank = 0;
  MPI_Comm_rank(comm_, &rank);

  Handle dset, fspace, mspace, dxpl;
  collective(comm_, [&] {
    if (mx[0] != -mx[1]) {
      throw std::runtime_error(ctx + ": array length differs between ranks");
    }
    if (cname.empty()) {
      throw std::runtime_error(ctx + ": empty dataset name");
    }
    dset = open_or_create(file_, cname, {static_cast<hsize_t>(n)}, H5T_NATIVE_DOUBLE, ctx);
    fspace = Handle(check_id(H5Dget_space(dset.get()), ctx + ": cannot get dataspace"), H5Sclose);
    // Only rank 0 contributes data; the others take part in the collective call with nothing.
    const bool writer = rank == 0 && n > 0;
    if (!writer) {
      check_err(H5Sselect_none(fspace.get()), ctx + ": selection");
    }
    mspace = memory_space(writer ? static_cast<hsize_t>(n) : 0);
    dxpl = collective_xfer();
  });
  if (n == 0) {
    return;  // HDF5 fails on transfers to a never-allocated dataset
  }
  static const double dummy = 0.0;
  const void* buf = values.empty() ? static_cast<const void*>(&dummy) : values.data();
  collective(comm_, [&] {
    check_err(H5Dwrite(dset.get(), H5T_NATIVE_DOUBLE, mspace.get(), fspace.get(), dxpl.get(), buf),
              ctx + ": write failed");
  });
}

std::vector<double> PointFile::read_global(const std::string& name) const {
  QuietErrors quiet;
  const std::string ctx = context(path_, "read_global", name);
  const std::string cname = canonical_name(name);
  std::vector<double> values;
  Handle dset, dxpl;
  collective(comm_, [&] {
    dset = open_dataset(file_, cname, ctx);
    Handle space(check_id(H5Dget_space(dset.get()), ctx + ": cannot get dataspace"), H5Sclose);
    Handle ftype(check_id(H5Dget_type(dset.get()), ctx + ": cannot get type"), H5Tclose);
    const std::vector<hsize_t> dims = space_dims(space.get());
    if (dims.size() != 1 || H5Tget_class(ftype.get()) != H5T_FLOAT) {
      throw std::runtime_error(ctx + ": dataset has shape " + shape_str(dims) + " " +
                               type_str(ftype.get()) + ", expected a 1-D float array");
    }
    values.resize(dims[0]);
    dxpl = collective_xfer();
  });
  if (!values.empty()) {
    collective(comm_, [&] {
      check_err(H5Dread(dset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, dxpl.get(), values.data()),
                ctx + ": read failed");
    });
  }
  return values;
}

}  // namespace mupm::io
