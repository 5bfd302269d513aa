#include "mupm/io/csv.hpp"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <locale>
#include <sstream>
#include <stdexcept>

namespace mupm::io {
namespace {

// RFC 4180 quoting, only when the name needs it.
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) {
    return s;
  }
  std::string out = "\"";
  for (char c : s) {
    out += c;
    if (c == '"') {
      out += '"';
    }
  }
  return out + "\"";
}

}  // namespace

CsvWriter::CsvWriter(const std::string& path, const std::vector<std::string>& columns, bool append)
    : path_(path), ncols_(columns.size()) {
  const std::string ctx = "mupm::io: CsvWriter('" + path + "')";
  if (columns.empty()) {
    throw std::runtime_error(ctx + ": no columns");
  }
  std::string header;
  for (std::size_t i = 0; i < columns.size(); ++i) {
    header += (i > 0 ? "," : "") + csv_field(columns[i]);
  }

  bool write_header = true;
  bool need_newline = false;
  if (append) {
    std::ifstream in(path, std::ios::binary);
    std::string first;
    if (in && std::getline(in, first)) {
      if (!first.empty() && first.back() == '\r') {
        first.pop_back();
      }
      if (first != header) {
        throw std::runtime_error(ctx + ": existing header '" + first + "' differs from '" + header +
                                 "'");
      }
      write_header = false;
      // A run killed mid-line leaves no final newline; start the next row on its own line.
      in.clear();
      in.seekg(-1, std::ios::end);
      char last = '\n';
      need_newline = in.get(last) && last != '\n';
    }
  }

  out_.open(path, std::ios::binary | (append ? std::ios::app : std::ios::trunc));
  if (!out_) {
    throw std::runtime_error(ctx + ": cannot open for writing: " + std::strerror(errno));
  }
  out_.imbue(std::locale::classic());  // '.' as decimal point whatever the global locale
  out_.precision(17);                  // default float format + precision 17 == "%.17g"
  if (need_newline) {
    out_ << '\n';
  }
  if (write_header) {
    out_ << header << '\n';
  }
  out_.flush();
  if (!out_) {
    throw std::runtime_error(ctx + ": write failed");
  }
}

void CsvWriter::row(const std::vector<double>& values) {
  if (values.size() != ncols_) {
    throw std::runtime_error("mupm::io: CsvWriter('" + path_ + "'): row of " +
                             std::to_string(values.size()) + " values for " +
                             std::to_string(ncols_) + " columns");
  }
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i > 0) {
      out_ << ',';
    }
    out_ << values[i];
  }
  out_ << '\n';
  out_.flush();
  if (!out_) {
    throw std::runtime_error("mupm::io: CsvWriter('" + path_ + "'): write failed");
  }
}

void keep_rows_through(const std::string& path, double step) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    return;
  std::stringstream all;
  all << in.rdbuf();
  in.close();
  const std::string text = all.str();
  std::string kept;
  std::size_t pos = 0;
  bool header = true;
  while (pos < text.size()) {
    const std::size_t end = text.find('\n', pos);
    if (end == std::string::npos)
      break;  // an unfinished last line: the run stopped while writing it
    const std::string line = text.substr(pos, end - pos + 1);
    pos = end + 1;
    if (!header && !(std::strtod(line.c_str(), nullptr) <= step))
      break;  // rows are in step order: this one and all after it came after the restart step
    header = false;
    kept += line;
  }
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << kept;
    if (!out)
      throw std::runtime_error("mupm::io: cannot rewrite '" + path +
                               "' for the restart: " + std::strerror(errno));
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace mupm::io
