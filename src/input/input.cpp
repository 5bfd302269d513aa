#include "mupm/input/input.hpp"

#include "input_module.hpp"

#include "mupm/data/bonds.hpp"
#include "mupm/data/points.hpp"
#include "mupm/input/options.hpp"

#include <unistd.h>
#include <Teuchos_Array.hpp>
#include <Teuchos_CommHelpers.hpp>
#include <Teuchos_DefaultMpiComm.hpp>
#include <Teuchos_StandardParameterEntryValidators.hpp>
#include <Teuchos_StringInputSource.hpp>
#include <Teuchos_XMLObject.hpp>
#include <Teuchos_XMLParameterListCoreHelpers.hpp>
#include <algorithm>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

namespace mupm {

using Teuchos::Array;
using Teuchos::ParameterList;
using Teuchos::RCP;
using Teuchos::rcp;

RCP<ParameterList> valid_parameters() {
  auto pl = rcp(new ParameterList("mupm"));
  for (const InputModule& m : input_modules())
    m.declare(pl->sublist(m.list, false, m.doc));
  return pl;
}

unsigned point_field_groups(const ParameterList& input) {
  unsigned g = kGroupCore;
  for (const InputModule& m : input_modules())
    if (m.field_groups)
      g |= m.field_groups(input);
  return g;
}

namespace {

// Teuchos' messages name the (sub)list and the entry and list what is valid; keep them, and
// drop the preamble and the "Throw number" trailer.
std::string clean_teuchos(const std::exception& e) {
  std::string msg = e.what();
  const auto pos = msg.find("Error");
  if (pos != std::string::npos && pos > 0)
    msg = msg.substr(pos);
  const auto tr = msg.find("Throw number");
  if (tr != std::string::npos)
    msg = msg.substr(0, tr);
  while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' '))
    msg.pop_back();
  return msg;
}

// The XML reader names the root "ANONYMOUS"; give every list its full path from "mupm".
void name_lists(ParameterList& list, const std::string& path) {
  list.setName(path);
  for (auto it = list.begin(); it != list.end(); ++it)
    if (list.entry(it).isList())
      name_lists(list.sublist(list.name(it)), path + "->" + list.name(it));
}

void validate_level(ParameterList& list, const ParameterList& valid) {
  // Sublists whose children are user-named are checked entry by entry against "NAME".
  for (auto it = list.begin(); it != list.end(); ++it) {
    const std::string& name = list.name(it);
    const auto* ventry = valid.getEntryPtr(name);
    if (ventry && ventry->isList() && list.entry(it).isList() &&
        Teuchos::getValue<ParameterList>(*ventry).isSublist("NAME")) {
      ParameterList& user = list.sublist(name);
      const ParameterList& tmpl = Teuchos::getValue<ParameterList>(*ventry).sublist("NAME");
      for (auto jt = user.begin(); jt != user.end(); ++jt) {
        const std::string& child = user.name(jt);
        if (!user.entry(jt).isList())
          throw InputError("Error, " + path_of(user, child) +
                           " is a parameter, but here every entry must be a sublist (one per "
                           "named item) with the parameters: " +
                           tmpl.currentParametersString());
        validate_level(user.sublist(child), tmpl);
      }
    }
  }
  // This level: names, types and ranges (Teuchos), then defaults; recursion into the fixed
  // sublists below.
  ParameterList shallow(valid.name());
  for (auto it = valid.begin(); it != valid.end(); ++it) {
    const std::string& name = valid.name(it);
    if (valid.entry(it).isList()) {
      ParameterList& s = shallow.sublist(name);
      if (Teuchos::getValue<ParameterList>(valid.entry(it)).isSublist("NAME"))
        s.disableRecursiveValidation();
    } else {
      shallow.setEntry(name, valid.entry(it));
    }
  }
  // Validators' own messages do not say where the entry is: add its full path.
  for (auto it = list.begin(); it != list.end(); ++it) {
    const auto* ventry = valid.getEntryPtr(list.name(it));
    if (!ventry || ventry->isList() || list.entry(it).isList())
      continue;
    const auto& any = list.entry(it).getAny(false);
    if (any.type() != ventry->getAny(false).type())
      throw InputError("Error, " + path_of(list, list.name(it)) + " has type \"" + any.typeName() +
                       "\" (value \"" + Teuchos::toString(any) + "\"); the expected type is \"" +
                       ventry->getAny(false).typeName() + "\": " + ventry->docString());
    if (ventry->validator().is_null())
      continue;
    try {
      ventry->validator()->validate(list.entry(it), list.name(it), list.name());
    } catch (const std::exception& e) {
      throw InputError("Error, " + path_of(list, list.name(it)) + " = " +
                       Teuchos::toString(list.entry(it).getAny(false)) +
                       " is not valid. Expected: " + ventry->docString() + "\n" + clean_teuchos(e));
    }
  }
  try {
    list.validateParameters(shallow, 0);
  } catch (const std::exception& e) {
    throw InputError(clean_teuchos(e));
  }
  for (auto it = valid.begin(); it != valid.end(); ++it) {
    const std::string& name = valid.name(it);
    if (!valid.entry(it).isList()) {
      // A filled-in default is marked as such (isDefault), without the validator, so the
      // resolved list written back is plain values.
      if (!list.isParameter(name)) {
        Teuchos::ParameterEntry e;
        e.setAnyValue(valid.entry(it).getAny(false), true);
        e.setDocString(valid.entry(it).docString());
        list.setEntry(name, e);
      }
      continue;
    }
    ParameterList& sub = list.sublist(name);
    const ParameterList& vsub = Teuchos::getValue<ParameterList>(valid.entry(it));
    if (vsub.isSublist("NAME"))
      continue;  // children checked above
    validate_level(sub, vsub);
  }
}

// Teuchos reads numbers with operator>>, which turns "abc" or "1e-3x" in an Array(double) into
// 0 without a word. Check every numeric value's text strictly before Teuchos converts it.
bool strict_number(const std::string& token, bool integer) {
  std::size_t b = token.find_first_not_of(" \t\n"), e = token.find_last_not_of(" \t\n");
  if (b == std::string::npos)
    return false;
  const std::string t = token.substr(b, e - b + 1);
  char* end = nullptr;
  errno = 0;
  if (integer) {
    const long long v = std::strtoll(t.c_str(), &end, 10);
    if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
      return false;
  } else {
    const double v = std::strtod(t.c_str(), &end);
    if (!std::isfinite(v))
      return false;
  }
  return errno == 0 && end == t.c_str() + t.size();
}

void check_numbers(const Teuchos::XMLObject& node, const std::string& path) {
  std::set<std::string> seen;
  for (int k = 0; k < node.numChildren(); ++k) {
    const Teuchos::XMLObject& c = node.getChild(k);
    if (!c.hasAttribute("name"))
      continue;
    const std::string name = c.getAttribute("name");
    // Teuchos keeps the last of two entries of one name without a word.
    if (!seen.insert(name).second)
      throw InputError("Error, " + path + "->" + name +
                       " is given twice; give each parameter and sublist once.");
    if (c.getTag() == "ParameterList") {
      check_numbers(c, path + "->" + name);
      continue;
    }
    if (c.getTag() != "Parameter" || !c.hasAttribute("type") || !c.hasAttribute("value"))
      continue;
    const std::string type = c.getAttribute("type"), value = c.getAttribute("value");
    const bool is_int = type == "int" || type == "Array(int)";
    const bool is_double = type == "double" || type == "Array(double)";
    if (!is_int && !is_double)
      continue;
    std::vector<std::string> tokens;
    if (type.rfind("Array", 0) == 0) {
      std::size_t b = value.find('{'), e = value.rfind('}');
      if (b == std::string::npos || e == std::string::npos || e < b)
        throw InputError("Error, " + path + "->" + name + " = \"" + value +
                         "\" is not an array: write {a, b, ...}.");
      const std::string inner = value.substr(b + 1, e - b - 1);
      if (inner.find_first_not_of(" \t\n") != std::string::npos) {
        std::stringstream ss(inner);
        for (std::string tok; std::getline(ss, tok, ',');)
          tokens.push_back(tok);
      }
    } else {
      tokens.push_back(value);
    }
    for (const auto& tok : tokens)
      if (!strict_number(tok, is_int))
        throw InputError("Error, " + path + "->" + name + " = \"" + value + "\": \"" + tok +
                         "\" is not a finite " + (is_int ? "int" : "double") + " number.");
  }
}

}  // namespace

RCP<ParameterList> parse_input(const std::string& xml) {
  try {
    const auto root = Teuchos::StringInputSource(xml).getObject();
    if (root.getTag() == "ParameterList" &&
        (!root.hasAttribute("name") || root.getAttribute("name") != "mupm"))
      throw InputError("Error, the input's root list is named '" +
                       (root.hasAttribute("name") ? root.getAttribute("name") : std::string()) +
                       "'; a mupm input is <ParameterList name=\"mupm\">.");
    check_numbers(root, "mupm");
  } catch (const InputError&) {
    throw;
  } catch (const std::exception&) {
    // Malformed XML: reported below by the parameter-list reader with its line number.
  }
  try {
    auto pl = Teuchos::getParametersFromXmlString(xml);
    name_lists(*pl, "mupm");
    return pl;
  } catch (const std::exception& e) {
    // Keep the parser's own sentence ("XML parse error at line N: ..."), not its source location.
    std::string msg = e.what();
    const auto pos = msg.find("XML parse error");
    if (pos != std::string::npos)
      msg = msg.substr(pos);
    throw InputError("Error, the input is not a valid Teuchos XML parameter list: " + msg);
  }
}

RCP<ParameterList> read_input(const Teuchos::Comm<int>& comm, const std::string& path) {
  std::string text;
  int ok = 1;
  if (comm.getRank() == 0) {
    std::ifstream f(path);
    std::error_code ec;
    if (!f || std::filesystem::is_directory(path, ec)) {
      ok = 0;
    } else {
      std::ostringstream s;
      s << f.rdbuf();
      text = s.str();
    }
  }
  Teuchos::broadcast(comm, 0, &ok);
  if (!ok)
    throw InputError("Error, cannot read the input file '" + path + "'.");
  long long n = static_cast<long long>(text.size());
  Teuchos::broadcast(comm, 0, &n);
  text.resize(static_cast<std::size_t>(n));
  if (n > 0)
    Teuchos::broadcast(comm, 0, static_cast<int>(n), &text[0]);
  return parse_input(text);
}

void validate_input(ParameterList& input) {
  if (input.isSublist("Discretization") && !input.sublist("Discretization").isParameter("Spacing"))
    throw InputError("Error, the required parameter " + input.name() +
                     "->Discretization->Spacing (point spacing in m, a double > 0) is missing.");
  if (!input.isSublist("Discretization"))
    throw InputError("Error, the required sublist " + input.name() +
                     "->Discretization is missing.");
  validate_level(input, *valid_parameters());
  for (const InputModule& m : input_modules())
    if (m.check)
      m.check(input);
}

namespace {

template <int Dim>
MemoryNeed memory_need_of(const ParameterList& input, int ranks) {
  const GridSpec<Dim> g = grid_from_input<Dim>(input);
  MemoryNeed m;
  m.points = double(g.n_global());
  // Bonds per point: the lattice offsets within the horizon.
  const int r = int(g.horizon / g.dx);
  long long family = 0;
  for (int i = -r; i <= r; ++i)
    for (int j = -r; j <= r; ++j)
      for (int k = (Dim == 3 ? -r : 0); k <= (Dim == 3 ? r : 0); ++k) {
        const double d2 = double(i * i + j * j + k * k) * g.dx * g.dx;
        family += (d2 > 0 && d2 <= g.horizon * g.horizon * (1 + 1e-12)) ? 1 : 0;
      }
  m.bonds_per_point = double(family);
  // A rank's part: a box of n points with a halo of r rows of ghosts.
  const double n = std::ceil(m.points / ranks);
  const double side = std::pow(n, 1.0 / Dim);
  const double ghosts = std::min(std::pow(side + 2 * r, Dim) - n, m.points - n);
  // Per point: the registry's fields, plus solver state, shape tensors and ghost-exchange buffers
  // (SolidState, FluidState, solver arrays, two MultiVectors of the widest refresh): 512 B in 2D,
  // 1 KiB in 3D. Per bond: the bond registry (with the pair force states of bond breakage),
  // plus the sort keys of the neighbour build.
  m.point_field_bytes = double(Points<Dim>::bytes_per_point(point_field_groups(input)));
  const double per_point = m.point_field_bytes + (Dim == 2 ? 512 : 1024);
  const bool breaks =
      bond_breaking_options()(input.sublist("Fracture").get<std::string>("Bond Breakage")) ==
      BondBreaking::Energy;
  const double per_bond =
      double(Bonds::bytes_per_bond(breaks ? Dim + kRotDim<Dim> : 0)) + sizeof(GlobalId);
  m.bytes_per_rank = (n + ghosts) * per_point + n * m.bonds_per_point * per_bond;
  return m;
}

double mem_available_bytes() {
  std::ifstream f("/proc/meminfo");
  std::string key;
  double kb = 0;
  while (f >> key >> kb) {
    if (key == "MemAvailable:")
      return kb * 1024;
    f.ignore(256, '\n');
  }
  return 0;  // unknown
}

}  // namespace

MemoryNeed memory_need(const Teuchos::Comm<int>& comm, const ParameterList& input) {
  MemoryNeed m = input_dimension(input) == 2 ? memory_need_of<2>(input, comm.getSize())
                                             : memory_need_of<3>(input, comm.getSize());
  MPI_Comm raw = MPI_COMM_SELF;
  if (const auto* mc = dynamic_cast<const Teuchos::MpiComm<int>*>(&comm))
    raw = (*mc->getRawMpiComm())();
  MPI_Comm node;
  MPI_Comm_split_type(raw, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
  int on_node = 1;
  MPI_Comm_size(node, &on_node);
  MPI_Comm_free(&node);
  double avail = mem_available_bytes() / on_node;
  MPI_Allreduce(MPI_IN_PLACE, &avail, 1, MPI_DOUBLE, MPI_MIN, raw);
  m.available_per_rank = avail;
  return m;
}

MemoryNeed check_memory(const Teuchos::Comm<int>& comm, const ParameterList& input) {
  const MemoryNeed m = memory_need(comm, input);
  if (m.available_per_rank > 0 && m.bytes_per_rank > m.available_per_rank) {
    std::ostringstream s;
    s.precision(3);
    s << "Error, the discretization (mupm->Discretization->Counts or Extents, Spacing, Horizon) "
         "needs about "
      << m.bytes_per_rank / (1 << 30) << " GiB per rank (" << m.points << " points, "
      << m.bonds_per_point << " bonds each, " << comm.getSize() << " rank(s)): more than the "
      << m.available_per_rank / (1 << 30)
      << " GiB available per rank (MemAvailable over the ranks of a node). Use more nodes or a "
         "coarser Spacing.";
    throw InputError(s.str());
  }
  return m;
}

void check_files(const Teuchos::Comm<int>& comm, const ParameterList& input) {
  std::string why;
  if (comm.getRank() == 0) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const std::string restart = input.sublist("Solver").get<std::string>("Restart From");
    if (!restart.empty()) {
      std::ifstream f(restart, std::ios::binary);
      char sig[8] = {};
      const char hdf5[8] = {'\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};
      if (fs::is_directory(restart, ec))
        why = "Error, mupm->Solver->Restart From = '" + restart +
              "' is a directory; give the checkpoint file, e.g. '" + restart + "/checkpoint.h5'.";
      else if (!f)
        why = "Error, mupm->Solver->Restart From = '" + restart +
              "': no such file (or it cannot be read).";
      else if (!f.read(sig, 8) || !std::equal(sig, sig + 8, hdf5))
        why = "Error, mupm->Solver->Restart From = '" + restart +
              "' is not an HDF5 file; give a checkpoint.h5 a mupm run wrote.";
    }
    // The output folder, or the nearest existing folder above it, must be writable.
    const std::string folder = input.sublist("Output").get<std::string>("Folder");
    fs::path p = fs::absolute(folder, ec);
    while (!p.empty() && !fs::exists(p, ec) && p != p.parent_path())
      p = p.parent_path();
    if (why.empty() && fs::exists(folder, ec) && !fs::is_directory(folder, ec))
      why = "Error, mupm->Output->Folder = '" + folder + "' is a file, not a folder.";
    else if (why.empty() && !p.empty() && fs::exists(p, ec) && !fs::is_directory(p, ec))
      // A component of the path is a file: no folder can be made below it.
      why = "Error, mupm->Output->Folder = '" + folder + "': '" + p.string() +
            "' is a file, not a folder.";
    else if (why.empty() && access(p.c_str(), W_OK | X_OK) != 0)
      why = "Error, mupm->Output->Folder = '" + folder + "': '" + p.string() +
            "' is not writable (" + std::strerror(errno) + ").";
  }
  long long n = static_cast<long long>(why.size());
  Teuchos::broadcast(comm, 0, &n);
  why.resize(static_cast<std::size_t>(n));
  if (n > 0) {
    Teuchos::broadcast(comm, 0, static_cast<int>(n), &why[0]);
    throw InputError(why);
  }
}

std::string end_time_steps_error(double end_time, double time, double dt,
                                 const std::string& dt_source) {
  const double steps = (end_time - time) / dt;
  if (!(end_time > 0) || !(dt > 0) || steps <= kMaxEndTimeSteps)
    return "";
  std::ostringstream s;
  s << "Error, mupm->Solver->End Time = " << end_time << " s takes " << steps
    << " steps of dt = " << dt << " s (" << dt_source << ")";
  if (time > 0)
    s << " from the checkpoint's time " << time << " s";
  s << ": more than " << kMaxEndTimeSteps
    << ", which no run reaches (the step counter and the time series are exact below it). "
       "Check End Time and the time step.";
  return s.str();
}

int input_dimension(const ParameterList& input) {
  return input.sublist("Discretization").get<int>("Dimension");
}

}  // namespace mupm
