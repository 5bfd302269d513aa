// Parallel HDF5 I/O of point fields keyed by global id.
//
// Every dataset written by write_points has one row per global id (row g holds point g), so a file
// written on P ranks can be read back on any number of ranks with any distribution of points.
// All member functions are collective over the communicator given to create()/open(): every rank
// must call them in the same order with the same name (and the same n_global/ncomp/attribute value
// where noted). Errors are agreed on collectively, so a failure throws std::runtime_error with the
// same message on every rank instead of leaving some ranks hanging in a collective call.
#ifndef MUPM_HDF5_IO_HPP
#define MUPM_HDF5_IO_HPP

#include <mpi.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace mupm::io {

class PointFile {
 public:
  // Creates (truncating) or opens read-only a file with the MPI-IO driver.
  static PointFile create(MPI_Comm comm, const std::string& path);
  static PointFile open(MPI_Comm comm, const std::string& path);

  PointFile(PointFile&& other) noexcept;
  PointFile& operator=(PointFile&& other) noexcept;
  PointFile(const PointFile&) = delete;
  PointFile& operator=(const PointFile&) = delete;
  // Closes the file (collective); errors are swallowed here, call close() to see them.
  ~PointFile();

  // Collective; throws on failure. The object is empty afterwards.
  void close();
  bool is_open() const { return file_ >= 0; }
  const std::string& path() const { return path_; }

  // Writes dataset `name` ("a/b/c" creates groups a and a/b) of shape [n_global] if ncomp == 1,
  // else [n_global][ncomp]. `gids` (this rank's points) must be sorted ascending, unique and in
  // [0, n_global); `data` is [gids.size()][ncomp] row-major in that order. Rows no rank owns are
  // left undefined (no fill value, to avoid writing the dataset twice). Rewriting an existing
  // dataset is allowed if its shape and type match.
  void write_points(const std::string& name, const std::vector<long long>& gids, long long n_global,
                    int ncomp, const double* data);
  void write_points(const std::string& name, const std::vector<long long>& gids, long long n_global,
                    int ncomp, const int* data);  // stored as 32-bit int
  void write_points(const std::string& name, const std::vector<long long>& gids, long long n_global,
                    int ncomp, const unsigned char* data);  // stored as uint8
  void write_points(const std::string& name, const std::vector<long long>& gids, long long n_global,
                    int ncomp, const long long* data);  // stored as 64-bit int

  // Reads the rows of `gids` (any order, duplicates allowed) into out[gids.size()][ncomp]. Throws
  // if the dataset is missing, its ncomp or type class (float/integer) differs, or a gid is out of
  // range.
  void read_points(const std::string& name, const std::vector<long long>& gids, int ncomp,
                   double* out) const;
  void read_points(const std::string& name, const std::vector<long long>& gids, int ncomp,
                   int* out) const;
  void read_points(const std::string& name, const std::vector<long long>& gids, int ncomp,
                   unsigned char* out) const;
  void read_points(const std::string& name, const std::vector<long long>& gids, int ncomp,
                   long long* out) const;

  // Scalar attributes on the root group; replaced if present. All ranks must pass the same value
  // (checked: throws otherwise).
  void write_attribute(const std::string& name, double v);
  void write_attribute(const std::string& name, long long v);
  void write_attribute(const std::string& name, const std::string& v);
  double read_attribute_double(const std::string& name) const;  // also accepts integer attributes
  long long read_attribute_int(const std::string& name) const;
  std::string read_attribute_string(const std::string& name) const;  // fixed or variable length
  bool has_attribute(const std::string& name) const;

  bool has_dataset(const std::string& name) const;
  // Dimensions of an existing dataset (throws if missing).
  std::vector<long long> dataset_shape(const std::string& name) const;

  // Small 1-D double array identical on all ranks (length checked; rank 0's values are written).
  void write_global(const std::string& name, const std::vector<double>& values);
  std::vector<double> read_global(const std::string& name) const;

 private:
  PointFile(MPI_Comm comm, std::int64_t file, std::string path)
      : comm_(comm), file_(file), path_(std::move(path)) {}
  void release() noexcept;

  // hid_t is int64_t since HDF5 1.10 (static_assert in the .cpp); kept out of this header so users
  // do not need the HDF5 include path.
  MPI_Comm comm_ = MPI_COMM_NULL;  // private duplicate, freed on close
  std::int64_t file_ = -1;
  std::string path_;
};

}  // namespace mupm::io

#endif  // MUPM_HDF5_IO_HPP
