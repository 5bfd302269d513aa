// XDMF 2 index of point-cloud output stored in HDF5, so ParaView opens it as a time series.
#ifndef MUPM_XDMF_HPP
#define MUPM_XDMF_HPP

#include <string>
#include <vector>

namespace mupm::io {

struct XdmfField {
  std::string name;
  int ncomp;            // 1: Scalar, 2-3: Vector, 9: Tensor, otherwise Matrix
  std::string h5_file;  // relative to the .xmf file's folder
  std::string h5_path;  // dataset path inside h5_file, e.g. "/fields/u"
  // Element type of the dataset; the defaults match doubles written by PointFile.
  std::string number_type = "Float";  // XDMF NumberType: Float, Int, UInt, Char, UChar
  int precision = 8;                  // bytes per value
};

struct XdmfStep {
  double time;
  std::vector<XdmfField> fields;
};

// Writes the whole time series to `xmf_path` (via a temporary file and rename, so readers never see
// a partial file). Call on one rank. Every step shares the geometry dataset of shape
// [n_points][dim] (dim 2 or 3, float64). Throws std::runtime_error on invalid input or I/O failure.
void write_xdmf(const std::string& xmf_path, int dim, long long n_points,
                const std::string& geometry_h5_file, const std::string& geometry_h5_path,
                const std::vector<XdmfStep>& steps);

}  // namespace mupm::io

#endif  // MUPM_XDMF_HPP
