// Tests of mupm::io (PointFile, write_xdmf, CsvWriter). Written to pass on any number of MPI
// ranks; the interesting cases need 2 (interleaved ownership, a rank without points).
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

#include "mupm/io/csv.hpp"
#include "mupm/io/hdf5_io.hpp"
#include "mupm/io/xdmf.hpp"

namespace {

using mupm::io::PointFile;

int rank_of() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

int size_of() {
  int s = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &s);
  return s;
}

// Same unique prefix on all ranks: $MUPM_TEST_TMPDIR (or /tmp) + rank 0's pid, so concurrent test
// runs do not clash.
std::string tmp_prefix() {
  static std::string prefix = [] {
    char buf[4096] = {0};
    if (rank_of() == 0) {
      const char* dir = std::getenv("MUPM_TEST_TMPDIR");
      const std::string p = std::string(dir != nullptr && dir[0] != '\0' ? dir : "/tmp") +
                            "/mupm_test_io_" + std::to_string(::getpid()) + "_";
      std::snprintf(buf, sizeof buf, "%s", p.c_str());
    }
    MPI_Bcast(buf, sizeof buf, MPI_CHAR, 0, MPI_COMM_WORLD);
    return std::string(buf);
  }();
  return prefix;
}

// Removes the registered files when the test ends (set MUPM_TEST_KEEP_FILES=1 to keep them).
class TempFiles {
 public:
  std::string add(const std::string& stem) {
    files_.push_back(tmp_prefix() + stem);
    return files_.back();
  }
  ~TempFiles() {
    MPI_Barrier(MPI_COMM_WORLD);  // nobody still has them open
    const char* keep = std::getenv("MUPM_TEST_KEEP_FILES");
    if (rank_of() == 0 && (keep == nullptr || std::string(keep) != "1")) {
      for (const std::string& f : files_) {
        std::remove(f.c_str());
      }
    }
  }

 private:
  std::vector<std::string> files_;
};

// Irregular ownership: runs of varying length, assigned to parts 0..nparts-1 without pattern.
int part_of(long long g, int nparts) {
  return static_cast<int>(((g * g) / 5 + g / 4) % nparts);
}

std::vector<long long> gids_where(long long n, const std::function<bool(long long)>& pred) {
  std::vector<long long> out;
  for (long long g = 0; g < n; ++g) {
    if (pred(g)) {
      out.push_back(g);
    }
  }
  return out;
}

// Values with full mantissas so exact comparison means bitwise round trip.
double dval(long long g, int c) {
  return std::sin(0.37 * static_cast<double>(g) + c) * 1e3 + g;
}
int ival(long long g, int c) {
  return static_cast<int>(g * 7919 - 100000 * c) * (g % 2 ? -1 : 1);
}
unsigned char uval(long long g) {
  return static_cast<unsigned char>((g * 37) % 256);
}
long long llval(long long g) {
  return (g - 17) * 1099511627791LL;
}  // beyond 32 bits

template <class T, class F>
std::vector<T> make(const std::vector<long long>& gids, int ncomp, F f) {
  std::vector<T> v;
  for (long long g : gids) {
    for (int c = 0; c < ncomp; ++c) {
      v.push_back(f(g, c));
    }
  }
  return v;
}

// Runs `f`, which must throw std::runtime_error containing `needle` on this rank; checks all ranks
// threw, i.e. nobody was left behind in a collective call.
void expect_throw_everywhere(const std::function<void()>& f, const std::string& needle) {
  int threw = 0;
  try {
    f();
  } catch (const std::runtime_error& e) {
    threw = 1;
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos)
        << "message: " << e.what() << "\nexpected to contain: " << needle;
  }
  int all = 0;
  MPI_Allreduce(&threw, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  EXPECT_EQ(threw, 1) << "no exception on rank " << rank_of();
  EXPECT_EQ(all, 1) << "some rank did not throw";
}

// Writes n_global points in two passes so that each write selects many runs even on one rank.
template <class T>
void write_two_passes(PointFile& f, const std::string& name, long long n, int ncomp,
                      const std::function<T(long long, int)>& val) {
  const int size = size_of();
  const int rank = rank_of();
  for (int pass = 0; pass < 2; ++pass) {
    const std::vector<long long> gids =
        gids_where(n, [&](long long g) { return part_of(g, 2 * size) == rank + pass * size; });
    const std::vector<T> data = make<T>(gids, ncomp, val);
    f.write_points(name, gids, n, ncomp, data.data());
  }
}

// Gids read back: a different distribution than written, in descending order.
std::vector<long long> read_gids(long long n) {
  const int size = size_of();
  const int rank = rank_of();
  std::vector<long long> gids =
      gids_where(n, [&](long long g) { return g % size == (rank + 1) % size; });
  return std::vector<long long>(gids.rbegin(), gids.rend());
}

}  // namespace

TEST(IoHdf5, DoubleRoundTripOnOtherDistribution) {
  TempFiles tmp;
  const std::string path = tmp.add("double.h5");
  const long long n = 20011;
  {
    PointFile f = PointFile::create(MPI_COMM_WORLD, path);
    write_two_passes<double>(f, "fields/displacement", n, 3, dval);
    write_two_passes<double>(f, "a/b/c/scalar", n, 1, dval);
    f.close();
    EXPECT_FALSE(f.is_open());
  }
  PointFile f = PointFile::open(MPI_COMM_WORLD, path);
  EXPECT_TRUE(f.has_dataset("fields/displacement"));
  EXPECT_TRUE(f.has_dataset("/a/b/c/scalar"));
  EXPECT_FALSE(f.has_dataset("a/b"));  // a group, not a dataset
  EXPECT_FALSE(f.has_dataset("a/x/scalar"));
  EXPECT_EQ(f.dataset_shape("fields/displacement"), (std::vector<long long>{n, 3}));
  EXPECT_EQ(f.dataset_shape("a/b/c/scalar"), (std::vector<long long>{n}));

  const std::vector<long long> gids = read_gids(n);
  std::vector<double> u(gids.size() * 3), s(gids.size());
  f.read_points("fields/displacement", gids, 3, u.data());
  f.read_points("a/b/c/scalar", gids, 1, s.data());
  // Repeated gids are allowed when reading.
  const std::vector<long long> rep{5, 2, 5, n - 1, 2};
  std::vector<double> r(rep.size());
  f.read_points("a/b/c/scalar", rep, 1, r.data());

  // Checks after the last collective call, so a failed ASSERT cannot strand the other ranks.
  for (std::size_t i = 0; i < gids.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(u[3 * i + c], dval(gids[i], c)) << "gid " << gids[i] << " comp " << c;
    }
    ASSERT_EQ(s[i], dval(gids[i], 0)) << "gid " << gids[i];
  }
  for (std::size_t i = 0; i < rep.size(); ++i) {
    EXPECT_EQ(r[i], dval(rep[i], 0));
  }
}

TEST(IoHdf5, IntegerTypesRoundTrip) {
  TempFiles tmp;
  const std::string path = tmp.add("ints.h5");
  const long long n = 517;
  {
    PointFile f = PointFile::create(MPI_COMM_WORLD, path);
    write_two_passes<int>(f, "i32", n, 2, ival);
    write_two_passes<unsigned char>(f, "flags/u8", n, 1, [](long long g, int) { return uval(g); });
    write_two_passes<long long>(f, "i64", n, 1, [](long long g, int) { return llval(g); });
  }
  PointFile f = PointFile::open(MPI_COMM_WORLD, path);
  const std::vector<long long> gids = read_gids(n);
  std::vector<int> iv(gids.size() * 2);
  std::vector<unsigned char> uv(gids.size());
  std::vector<long long> lv(gids.size());
  f.read_points("i32", gids, 2, iv.data());
  f.read_points("flags/u8", gids, 1, uv.data());
  f.read_points("i64", gids, 1, lv.data());
  for (std::size_t i = 0; i < gids.size(); ++i) {
    ASSERT_EQ(iv[2 * i], ival(gids[i], 0));
    ASSERT_EQ(iv[2 * i + 1], ival(gids[i], 1));
    ASSERT_EQ(uv[i], uval(gids[i]));
    ASSERT_EQ(lv[i], llval(gids[i]));
  }
}

TEST(IoHdf5, OneRankOwnsNothing) {
  TempFiles tmp;
  const std::string path = tmp.add("empty_rank.h5");
  const long long n = 64;
  const int rank = rank_of();
  const int size = size_of();
  {
    PointFile f = PointFile::create(MPI_COMM_WORLD, path);
    // The last rank owns nothing (on one rank: everything is owned by rank 0).
    const std::vector<long long> gids = gids_where(n, [&](long long g) {
      return size == 1 || (part_of(g, size - 1) == rank && rank != size - 1);
    });
    const std::vector<double> data = make<double>(gids, 2, dval);
    f.write_points("v", gids, n, 2, data.data());
    // A dataset nobody has points of (n_global = 0) is valid too.
    f.write_points("nothing", {}, 0, 1, static_cast<const double*>(nullptr));
  }
  PointFile f = PointFile::open(MPI_COMM_WORLD, path);
  EXPECT_EQ(f.dataset_shape("nothing"), (std::vector<long long>{0}));
  // Rank 0 reads nothing this time, the others read everything.
  const std::vector<long long> gids = rank == 0 && size > 1
                                          ? std::vector<long long>{}
                                          : gids_where(n, [](long long) { return true; });
  std::vector<double> v(gids.size() * 2);
  f.read_points("v", gids, 2, v.data());
  for (std::size_t i = 0; i < gids.size(); ++i) {
    ASSERT_EQ(v[2 * i], dval(gids[i], 0));
    ASSERT_EQ(v[2 * i + 1], dval(gids[i], 1));
  }
}

TEST(IoHdf5, ErrorsThrowOnEveryRank) {
  TempFiles tmp;
  const std::string path = tmp.add("errors.h5");
  const long long n = 40;
  const int rank = rank_of();
  const int size = size_of();
  const std::vector<long long> mine = gids_where(n, [&](long long g) { return g % size == rank; });
  const std::vector<double> data = make<double>(mine, 3, dval);
  {
    PointFile f = PointFile::create(MPI_COMM_WORLD, path);
    f.write_points("u", mine, n, 3, data.data());

    // Unsorted gids on the last rank only: every rank must still throw.
    std::vector<long long> bad = mine;
    if (rank == size - 1 && bad.size() >= 2) {
      std::swap(bad[0], bad[1]);
    }
    expect_throw_everywhere([&] { f.write_points("w", bad, n, 3, data.data()); }, "sorted");
    // Rewriting with another shape is refused.
    expect_throw_everywhere([&] { f.write_points("u", mine, n + 1, 3, data.data()); }, "shape");
    expect_throw_everywhere(
        [&] { f.write_points("u", mine, n, 3, static_cast<const double*>(nullptr)); }, "null data");
  }

  PointFile f = PointFile::open(MPI_COMM_WORLD, path);
  std::vector<double> out(mine.size() * 3);
  expect_throw_everywhere([&] { f.read_points("u", mine, 2, out.data()); }, "'u'");
  expect_throw_everywhere([&] { f.read_points("u", mine, 2, out.data()); }, "[40][3]");
  expect_throw_everywhere([&] { f.read_points("missing", mine, 3, out.data()); }, "not found");
  expect_throw_everywhere([&] { f.read_points("no/such/group", mine, 3, out.data()); },
                          "not found");
  std::vector<int> iout(mine.size() * 3);
  expect_throw_everywhere([&] { f.read_points("u", mine, 3, iout.data()); }, "float64");
  // An out-of-range gid on the last rank only.
  std::vector<long long> far = mine;
  if (rank == size - 1) {
    far.push_back(n + 5);
  }
  std::vector<double> far_out(far.size() * 3);
  expect_throw_everywhere([&] { f.read_points("u", far, 3, far_out.data()); }, "outside");
  // Read-only file.
  expect_throw_everywhere([&] { f.write_points("x", mine, n, 3, data.data()); }, "'x'");

  // The file is still usable after all that.
  f.read_points("u", mine, 3, out.data());
  EXPECT_EQ(out, data);
}

TEST(IoHdf5, OpenFailureThrowsOnEveryRank) {
  const std::string missing = tmp_prefix() + "does_not_exist.h5";
  expect_throw_everywhere([&] { PointFile::open(MPI_COMM_WORLD, missing); }, missing);
  const std::string bad_dir = tmp_prefix() + "no_such_dir/file.h5";
  expect_throw_everywhere([&] { PointFile::create(MPI_COMM_WORLD, bad_dir); }, bad_dir);

  // Not an HDF5 file.
  TempFiles tmp;
  const std::string text = tmp.add("not_hdf5.h5");
  if (rank_of() == 0) {
    std::ofstream(text) << "hello\n";
  }
  MPI_Barrier(MPI_COMM_WORLD);
  expect_throw_everywhere([&] { PointFile::open(MPI_COMM_WORLD, text); }, text);
}

TEST(IoHdf5, AttributesAndGlobals) {
  TempFiles tmp;
  const std::string path = tmp.add("attrs.h5");
  const std::vector<double> g{1.5, -2.25, std::acos(-1.0), 1e-300};
  {
    PointFile f = PointFile::create(MPI_COMM_WORLD, path);
    f.write_attribute("time", 0.1);
    f.write_attribute("time", 0.30000000000000004);  // replaces
    f.write_attribute("step", 1LL << 40);
    f.write_attribute("label", std::string("run \"A\", über"));
    f.write_attribute("empty", std::string());
    f.write_global("globals/params", g);
    f.write_global("none", {});
    if (size_of() > 1) {
      expect_throw_everywhere([&] { f.write_attribute("r", static_cast<long long>(rank_of())); },
                              "differs");
    }
    PointFile moved = std::move(f);  // the moved-to object owns the file
    EXPECT_FALSE(f.is_open());
    EXPECT_TRUE(moved.is_open());
  }
  PointFile f = PointFile::open(MPI_COMM_WORLD, path);
  EXPECT_EQ(f.read_attribute_double("time"), 0.30000000000000004);
  EXPECT_EQ(f.read_attribute_int("step"), 1LL << 40);
  EXPECT_EQ(f.read_attribute_double("step"), static_cast<double>(1LL << 40));
  EXPECT_EQ(f.read_attribute_string("label"), "run \"A\", über");
  EXPECT_EQ(f.read_attribute_string("empty"), "");
  EXPECT_TRUE(f.has_attribute("step"));
  EXPECT_FALSE(f.has_attribute("nope"));
  expect_throw_everywhere([&] { f.read_attribute_int("time"); }, "float64");
  expect_throw_everywhere([&] { f.read_attribute_double("nope"); }, "not found");
  expect_throw_everywhere([&] { f.read_attribute_string("step"); }, "int64");
  EXPECT_EQ(f.read_global("globals/params"), g);
  EXPECT_TRUE(f.read_global("none").empty());
  expect_throw_everywhere([&] { f.read_global("missing"); }, "not found");
}

namespace {

struct ItemRef {
  std::string dims, file, path;
};

std::vector<std::string> all_matches(const std::string& text, const std::regex& re) {
  std::vector<std::string> out;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), re); it != std::sregex_iterator();
       ++it) {
    out.push_back((*it)[1]);
  }
  return out;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string basename_of(const std::string& p) {
  return p.substr(p.find_last_of('/') + 1);
}

}  // namespace

TEST(IoXdmf, TwoStepsReferenceExistingDatasets) {
  TempFiles tmp;
  const long long n = 37;
  const int dim = 2;
  const std::string geo = tmp.add("geo.h5");
  const std::vector<std::string> step_files{tmp.add("step0.h5"), tmp.add("step1.h5")};
  const std::string xmf = tmp.add("series.xmf");
  const int rank = rank_of();
  const int size = size_of();
  const std::vector<long long> mine =
      gids_where(n, [&](long long g) { return part_of(g, size) == rank; });
  {
    PointFile f = PointFile::create(MPI_COMM_WORLD, geo);
    const std::vector<double> x = make<double>(mine, dim, dval);
    f.write_points("coordinates", mine, n, dim, x.data());
  }
  std::vector<mupm::io::XdmfStep> steps;
  for (int s = 0; s < 2; ++s) {
    PointFile f = PointFile::create(MPI_COMM_WORLD, step_files[s]);
    const std::vector<double> u = make<double>(mine, 2, dval);
    const std::vector<double> p = make<double>(mine, 1, dval);
    const std::vector<int> id = make<int>(mine, 1, ival);
    f.write_points("fields/u", mine, n, 2, u.data());
    f.write_points("fields/p", mine, n, 1, p.data());
    f.write_points("fields/id", mine, n, 1, id.data());
    const std::string h5 = basename_of(step_files[s]);
    steps.push_back({0.1 * s,
                     {{"u", 2, h5, "/fields/u"},
                      {"p", 1, h5, "fields/p"},
                      {"id", 1, h5, "/fields/id", "Int", 4}}});
  }
  if (rank == 0) {
    mupm::io::write_xdmf(xmf, dim, n, basename_of(geo), "/coordinates", steps);
  }
  MPI_Barrier(MPI_COMM_WORLD);

  const std::string text = slurp(xmf);
  EXPECT_NE(text.find("<Xdmf Version=\"2.0\">"), std::string::npos);
  EXPECT_NE(text.find("CollectionType=\"Temporal\""), std::string::npos);
  EXPECT_EQ(all_matches(text, std::regex("<(Grid)[ >]")).size(), 3u);
  EXPECT_EQ(all_matches(text, std::regex("<Time Value=\"([^\"]*)\"")),
            (std::vector<std::string>{"0", "0.10000000000000001"}));
  EXPECT_EQ(all_matches(text, std::regex("TopologyType=\"(Polyvertex)\"")).size(), 2u);
  EXPECT_EQ(all_matches(text, std::regex("GeometryType=\"([^\"]*)\"")),
            (std::vector<std::string>{"XY", "XY"}));
  EXPECT_EQ(all_matches(text, std::regex("AttributeType=\"([^\"]*)\"")),
            (std::vector<std::string>{"Vector", "Scalar", "Scalar", "Vector", "Scalar", "Scalar"}));

  // Every DataItem must name an existing dataset of the declared shape.
  const std::regex item_re(
      "<DataItem[^>]*Dimensions=\"([^\"]*)\"[^>]*>([^<:]*):([^<]*)</DataItem>");
  std::vector<ItemRef> items;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), item_re);
       it != std::sregex_iterator(); ++it) {
    items.push_back({(*it)[1], (*it)[2], (*it)[3]});
  }
  ASSERT_EQ(items.size(), 8u);  // per step: geometry + 3 fields
  EXPECT_EQ(items[0].dims, "37 2");
  EXPECT_EQ(items[1].dims, "37 2");
  EXPECT_EQ(items[2].dims, "37");
  EXPECT_EQ(items[4].dims, "37 2");
  const std::string dir = xmf.substr(0, xmf.find_last_of('/') + 1);
  for (const ItemRef& item : items) {
    PointFile f = PointFile::open(MPI_COMM_WORLD, dir + item.file);
    if (!f.has_dataset(item.path)) {  // same answer on all ranks
      ADD_FAILURE() << "missing " << item.file << ":" << item.path;
      continue;
    }
    std::string shape;
    for (long long d : f.dataset_shape(item.path)) {
      shape += (shape.empty() ? "" : " ") + std::to_string(d);
    }
    EXPECT_EQ(shape, item.dims) << item.file << ":" << item.path;
  }

  // Invalid input is rejected and leaves no file behind.
  if (rank == 0) {
    EXPECT_THROW(mupm::io::write_xdmf(tmp_prefix() + "bad.xmf", 4, n, "g.h5", "/x", steps),
                 std::runtime_error);
    EXPECT_FALSE(std::ifstream(tmp_prefix() + "bad.xmf").good());
    EXPECT_THROW(mupm::io::write_xdmf(tmp_prefix() + "no_dir/a.xmf", 3, n, "g.h5", "/x", steps),
                 std::runtime_error);
  }
}

TEST(IoCsv, HeaderRowsAppendAndErrors) {
  if (rank_of() != 0) {
    return;  // CsvWriter is used on one rank
  }
  const std::string path = tmp_prefix() + "series.csv";
  std::remove(path.c_str());
  {
    mupm::io::CsvWriter w(path, {"time", "energy"}, /*append=*/false);
    w.row({0.0, 1.5});
    w.row({0.1, -1.0 / 3});
    EXPECT_THROW(w.row({1.0}), std::runtime_error);
    EXPECT_THROW(w.row({1.0, 2.0, 3.0}), std::runtime_error);
    // Flushed per row: readable while the writer is alive.
    EXPECT_EQ(slurp(path), "time,energy\n0,1.5\n0.10000000000000001,-0.33333333333333331\n");
  }
  {
    mupm::io::CsvWriter w(path, {"time", "energy"}, /*append=*/true);
    w.row({0.2, 3.0});
  }
  EXPECT_EQ(slurp(path),
            "time,energy\n0,1.5\n0.10000000000000001,-0.33333333333333331\n"
            "0.20000000000000001,3\n");
  EXPECT_THROW(mupm::io::CsvWriter(path, {"time", "other"}, true), std::runtime_error);
  {
    mupm::io::CsvWriter w(path, {"a", "b,c"}, /*append=*/false);  // truncates
  }
  EXPECT_EQ(slurp(path), "a,\"b,c\"\n");
  std::remove(path.c_str());
  {
    mupm::io::CsvWriter w(path, {"x"}, /*append=*/true);  // appending to a new file: header
    w.row({42.0});
  }
  EXPECT_EQ(slurp(path), "x\n42\n");
  std::remove(path.c_str());

  const std::string bad = tmp_prefix() + "no_dir/x.csv";
  try {
    mupm::io::CsvWriter w(bad, {"x"}, false);
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
}
