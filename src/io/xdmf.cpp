#include "mupm/io/xdmf.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <locale>
#include <sstream>
#include <stdexcept>

#include <unistd.h>

namespace mupm::io {
namespace {

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

const char* attribute_type(int ncomp) {
  if (ncomp == 1) {
    return "Scalar";
  }
  if (ncomp == 2 || ncomp == 3) {
    return "Vector";
  }
  if (ncomp == 9) {
    return "Tensor";
  }
  return "Matrix";
}

// XDMF expects "file.h5:/path"; accept dataset paths given without the leading slash.
std::string hdf_ref(const std::string& file, const std::string& path) {
  return xml_escape(file + ":" + (path.empty() || path[0] != '/' ? "/" : "") + path);
}

void data_item(std::ostream& os, const std::string& dims, const std::string& number_type,
               int precision, const std::string& file, const std::string& path) {
  os << "          <DataItem Format=\"HDF\" Dimensions=\"" << dims << "\" NumberType=\""
     << xml_escape(number_type) << "\" Precision=\"" << precision << "\">" << hdf_ref(file, path)
     << "</DataItem>\n";
}

}  // namespace

void write_xdmf(const std::string& xmf_path, int dim, long long n_points,
                const std::string& geometry_h5_file, const std::string& geometry_h5_path,
                const std::vector<XdmfStep>& steps) {
  const std::string ctx = "mupm::io: write_xdmf('" + xmf_path + "')";
  if (dim != 2 && dim != 3) {
    throw std::runtime_error(ctx + ": dim must be 2 or 3, got " + std::to_string(dim));
  }
  if (n_points < 0) {
    throw std::runtime_error(ctx + ": negative n_points");
  }
  for (const XdmfStep& step : steps) {
    for (const XdmfField& f : step.fields) {
      if (f.ncomp < 1 || f.precision < 1) {
        throw std::runtime_error(ctx + ": field '" + f.name + "' has invalid ncomp or precision");
      }
    }
  }

  std::ostringstream os;
  os.imbue(std::locale::classic());  // '.' as decimal point whatever the global locale
  os.precision(17);                  // round-trips doubles, like %.17g
  const std::string n = std::to_string(n_points);
  os << "<?xml version=\"1.0\" ?>\n"
     << "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
     << "<Xdmf Version=\"2.0\">\n"
     << "  <Domain>\n"
     << "    <Grid Name=\"points\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (std::size_t s = 0; s < steps.size(); ++s) {
    const XdmfStep& step = steps[s];
    os << "      <Grid Name=\"step_" << s << "\" GridType=\"Uniform\">\n"
       << "        <Time Value=\"" << step.time << "\"/>\n"
       << "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" << n
       << "\" NodesPerElement=\"1\"/>\n"
       << "        <Geometry GeometryType=\"" << (dim == 2 ? "XY" : "XYZ") << "\">\n";
    data_item(os, n + " " + std::to_string(dim), "Float", 8, geometry_h5_file, geometry_h5_path);
    os << "        </Geometry>\n";
    for (const XdmfField& f : step.fields) {
      os << "        <Attribute Name=\"" << xml_escape(f.name) << "\" AttributeType=\""
         << attribute_type(f.ncomp) << "\" Center=\"Node\">\n";
      data_item(os, f.ncomp == 1 ? n : n + " " + std::to_string(f.ncomp), f.number_type,
                f.precision, f.h5_file, f.h5_path);
      os << "        </Attribute>\n";
    }
    os << "      </Grid>\n";
  }
  os << "    </Grid>\n"
     << "  </Domain>\n"
     << "</Xdmf>\n";

  // Same folder as the target so the rename is atomic; pid avoids clashes between writers.
  const std::string tmp = xmf_path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      throw std::runtime_error(ctx + ": cannot open '" + tmp +
                               "' for writing: " + std::strerror(errno));
    }
    out << os.str();
    out.close();
    if (!out) {
      std::remove(tmp.c_str());
      throw std::runtime_error(ctx + ": write to '" + tmp + "' failed");
    }
  }
  if (std::rename(tmp.c_str(), xmf_path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(tmp.c_str());
    throw std::runtime_error(ctx + ": cannot rename '" + tmp + "': " + reason);
  }
}

}  // namespace mupm::io
