// Small CSV time-series writer (one rank only), e.g. for energies or probe values per step.
#ifndef MUPM_CSV_HPP
#define MUPM_CSV_HPP

#include <cstddef>
#include <fstream>
#include <string>
#include <vector>

namespace mupm::io {

class CsvWriter {
 public:
  // Writes the header line unless `append` is set and the file exists and is non-empty; in that
  // case the existing header must equal `columns` (so a restart cannot silently mix layouts).
  // Throws std::runtime_error naming the path if the file cannot be opened.
  CsvWriter(const std::string& path, const std::vector<std::string>& columns, bool append = false);

  // Writes one line of values with 17 significant digits ("%.17g") and flushes it, so the file is
  // usable while the run is going and survives a crash. Throws if values.size() differs from the
  // number of columns or the write fails.
  void row(const std::vector<double>& values);

  const std::string& path() const { return path_; }
  std::size_t num_columns() const { return ncols_; }

 private:
  std::string path_;
  std::size_t ncols_ = 0;
  std::ofstream out_;
};

// For a restart at `step`: drops the rows of `path` whose first column (the step) is beyond it,
// and an unfinished last line, so the continued run does not repeat rows. The file is replaced
// whole once the kept rows are written. A missing file is left missing. Throws on I/O errors.
void keep_rows_through(const std::string& path, double step);

}  // namespace mupm::io

#endif  // MUPM_CSV_HPP
