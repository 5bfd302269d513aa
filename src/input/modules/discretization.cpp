#include "../input_module.hpp"

#include <algorithm>
#include <cmath>

#include "mupm/input/options.hpp"

namespace mupm {

using Teuchos::Array;
using Teuchos::ParameterList;
using Teuchos::rcp;

namespace {

void region_template(ParameterList& r) {
  r.set("Min", Array<double>(), "Lower corner of the box [m] (Dim values, closed).");
  r.set("Max", Array<double>(), "Upper corner of the box [m] (Dim values, closed).");
}
void crack_template(ParameterList& c) {
  c.set("Start", Array<double>(), "2D: first end of the crack segment [m].");
  c.set(
      "End", Array<double>(),
      "2D: second end of the crack segment [m]: the tip, from which crack_length measures growth.");
  c.set("Corner", Array<double>(), "3D: a corner of the crack rectangle [m].");
  c.set("Edge 1", Array<double>(),
        "3D: first edge vector of the rectangle from Corner [m]: the direction of growth for "
        "crack_length (the tip is the far edge).");
  c.set("Edge 2", Array<double>(),
        "3D: second edge vector of the rectangle from Corner [m], orthogonal to Edge 1.");
}

void declare_discretization(ParameterList& d) {
  d.set("Dimension", 2, "2 (plane strain, or plane stress: Plane) or 3.",
        rcp(new Teuchos::EnhancedNumberValidator<int>(2, 3)));
  d.set("Spacing", 1.0, "Point spacing dx [m] (required, > 0).", positive());
  d.set("Counts", Array<int>(),
        "Number of points of the real body along each axis (Dim values >= 1). Give Counts "
        "or Extents.",
        rcp(new Teuchos::ArrayNumberValidator<int>(at_least(1))));
  d.set("Extents", Array<double>(),
        "Size of the real body along each axis [m] (Dim values, each a whole multiple of "
        "Spacing). Give Counts or Extents.");
  d.set("Origin", Array<double>(), "Lower corner of the real body [m] (Dim values; default 0).");
  d.set("Horizon Factor", 3.015,
        "Horizon delta as a multiple of Spacing (used unless Horizon is given).", positive());
  d.set("Horizon", 0.0, "Horizon delta [m]; 0: use Horizon Factor. Give one of the two.",
        at_least(0.0));
  d.set("Thickness", 1.0,
        "Out-of-plane thickness h [m] (2D only): point volumes dx^2 h, so the CSV's energies, "
        "reactions and water masses are those of the thickness h; J is per unit thickness; "
        "Fluid Source and Fracture Source values are per metre of thickness.",
        positive());
  d.set("Plane", std::string("Strain"),
        "2D only. Strain: plane strain (eps_zz = 0). Stress: plane stress (sigma_zz = 0: the "
        "law's in-plane lambda becomes 2 lambda mu / (lambda + 2 mu); derivation in "
        "include/mupm/laws/micropolar_elastic.hpp; with pore water the total sigma_zz = 0: the "
        "pressure's in-plane coefficient becomes 2 mu / (lambda + 2 mu) and the storage gains "
        "1 / (lambda + 2 mu); Drucker-Prager returns to sigma_zz = 0, derivation in "
        "include/mupm/laws/micropolar_drucker_prager.hpp), for Solver->Physics = Micropolar "
        "Solid or Hydro-Mechanical (with Fracture->Fracture Flow the crack water pushes the "
        "faces in the plane, include/mupm/solvers/fracture_flow.hpp; Drucker-Prager with pore "
        "water returns to sigma'_zz = S_r p and gives the water its plastic thickness change; "
        "with Pressure Integration = Semi-Implicit a step late, "
        "include/mupm/solvers/fluid_solver.hpp, lagged_plastic_source).",
        plane_options().validator());
  d.set("Boundary Layer Horizons", 2.0,
        "Thickness of each boundary layer in horizons: floor(value * delta / dx) rows. 2 (the "
        "default) gives the layer points next to the body full families too, which the "
        "correspondence model needs for exact boundary values; the paper's layers are 1. With "
        "Boundary Layers: at least dx / delta (one row), and at most the larger of the body "
        "along the layer's axis and 2 horizons.",
        positive());
  d.set("Boundary Layers", Array<std::string>(),
        "Faces of the body that get a boundary layer of fictitious points outside them (the "
        "paper's boundary-layer method), any of -x +x -y +y -z +z. "
        "Each layer is also a region named 'Layer -y' etc.",
        rcp(new Teuchos::ArrayStringValidator(one_of(kFaces))));
  d.set("Boundary Layer Values", std::string("Constant"),
        "How Pore Pressure and Fracture Pressure conditions set their boundary-layer points, "
        "unless a condition's "
        "own Boundary Layer Values says otherwise. Constant: the prescribed value g (the "
        "paper's method; the face then drains as if it sat about 0.7 delta farther out). "
        "Mirrored: a layer point at distance d outside the face takes 2 g - p(m), p(m) the "
        "pressure of the point m at distance d inside, every fluid substep (the face: the one "
        "the condition's region lies outside of; a Fracture Pressure's points take 2 g - "
        "p_f(m) of the step's start where m is a fracture point no condition holds, else g). "
        "Kinematic conditions stay Constant unless "
        "their own Boundary Layer Values says Mirrored. See "
        "README, 'Boundary layers'.",
        one_of({"Constant", "Mirrored"}));
  ParameterList& r = d.sublist("Regions", false,
                               "Named boxes for boundary and initial conditions and outputs: "
                               "one sublist per region, named as you like (at most 24).");
  region_template(r.sublist("NAME"));
  ParameterList& c = d.sublist("Pre-Cracks", false,
                               "Initial cracks, one sublist each: a segment (Start, End) in 2D, "
                               "a rectangle (Corner, Edge 1, Edge 2) in 3D. Bonds crossing a "
                               "crack start broken; points closer than Spacing to it start as "
                               "fracture points.");
  crack_template(c.sublist("NAME"));
}

// Boundary Layer Horizons gives floor(value delta / dx) rows per layer (grid_from_input). A value
// that gives no row leaves the layers and their conditions empty; a layer thicker than both the
// default 2 horizons and the body it bounds is no boundary layer any more (it is a larger body;
// points farther than 2 horizons from the face reach neither a body point's family nor those of
// its neighbours), and a huge value overflows the grid's row counts.
void check_layer_rows(const ParameterList& d, const Array<std::string>& faces) {
  const double dx = d.get<double>("Spacing"), horizon = horizon_of(d);
  const double value = d.get<double>("Boundary Layer Horizons");
  const double rows = layer_rows(d, value);
  if (rows < 1) {
    std::ostringstream s;
    s << "Error, " << path_of(d, "Boundary Layer Horizons") << " = " << value
      << " gives layers of no row (floor(value * delta / dx) = 0 with delta = " << horizon
      << " m, dx = " << dx << " m): the boundary layers " << path_of(d, "Boundary Layers")
      << " asks for and their conditions would be empty. The minimum is dx / delta = "
      << dx / horizon << " (one row); 2 is usual.";
    throw InputError(s.str());
  }
  const auto counts = d.get<Array<int>>("Counts");
  const auto ext = d.get<Array<double>>("Extents");
  const double default_rows = layer_rows(d, 2);
  for (const auto& f : faces) {
    const int k = f[1] - 'x';
    const double body = counts.empty() ? std::round(ext[k] / dx) : double(counts[k]);
    const double most = std::max(default_rows, body);
    if (rows > most) {
      std::ostringstream s;
      s << "Error, " << path_of(d, "Boundary Layer Horizons") << " = " << value
        << " gives layers of " << rows << " rows, thicker than the body along " << f[1] << " ("
        << body << " rows) and than the default 2 horizons (" << default_rows
        << " rows): a boundary layer's points farther than 2 horizons from the face act on no "
           "point of the body. The maximum here is "
        << most * dx / horizon << " (2 is usual).";
      throw InputError(s.str());
    }
  }
}

// Counts or Extents, the horizon, the layers, the regions and the pre-cracks fit the dimension and
// each other; plane stress has a skeleton.
void check_discretization(ParameterList& input) {
  ParameterList& d = input.sublist("Discretization");
  const int dim = d.get<int>("Dimension");
  const bool has_counts = !d.get<Array<int>>("Counts").empty();
  const bool has_extents = !d.get<Array<double>>("Extents").empty();
  if (has_counts == has_extents)
    throw InputError("Error, " + d.name() +
                     " needs exactly one of Counts (points per axis) and Extents (body size "
                     "in m), each with " +
                     std::to_string(dim) + " values.");
  if (has_counts)
    get_array<int>(d, "Counts", dim, "points per axis");
  if (has_extents) {
    const auto ext = get_array<double>(d, "Extents", dim, "body size per axis in m");
    const double dx = d.get<double>("Spacing");
    for (double e : ext) {
      const double n = e / dx;
      if (!(n >= 1) || std::abs(n - std::round(n)) > 1e-6 * n)
        throw InputError("Error, " + path_of(d, "Extents") + " = " + std::to_string(e) +
                         " is not a positive whole multiple of Spacing = " + std::to_string(dx) +
                         ".");
    }
  }
  if (!d.get<Array<double>>("Origin").empty())
    get_array<double>(d, "Origin", dim, "m");
  if (d.get<double>("Horizon") > 0 && d.isParameter("Horizon Factor") &&
      !d.getEntry("Horizon Factor").isDefault())
    throw InputError("Error, " + d.name() +
                     " gives both Horizon and Horizon Factor: give one of the two.");
  // Lattice neighbours are one spacing apart: a smaller horizon leaves every point without a
  // bond (and a stable step of 0).
  {
    const double dx = d.get<double>("Spacing"), h = d.get<double>("Horizon");
    const bool given = h > 0;
    const double horizon = horizon_of(d);
    if (horizon < dx * (1 - 1e-9)) {
      std::ostringstream s;
      s << "Error, " << path_of(d, given ? "Horizon" : "Horizon Factor") << " = "
        << (given ? h : d.get<double>("Horizon Factor")) << " gives a horizon of " << horizon
        << " m, below the spacing " << dx
        << " m: no point would have a bond. The horizon must be at least one spacing (3.015 "
           "spacings is usual).";
      throw InputError(s.str());
    }
  }
  const Array<std::string> faces = d.get<Array<std::string>>("Boundary Layers");
  for (const auto& f : faces)
    if (f.size() == 2 && (f[1] - 'x') >= dim)
      throw InputError("Error, " + path_of(d, "Boundary Layers") + " names face " + f +
                       ", which a " + std::to_string(dim) + "D body does not have.");
  if (!faces.empty())
    check_layer_rows(d, faces);
  ParameterList& regions = d.sublist("Regions");
  int n_regions = 0;
  for (auto it = regions.begin(); it != regions.end(); ++it, ++n_regions) {
    ParameterList& r = regions.sublist(regions.name(it));
    const auto lo = get_array<double>(r, "Min", dim, "lower corner in m");
    const auto hi = get_array<double>(r, "Max", dim, "upper corner in m");
    for (int k = 0; k < dim; ++k)
      if (hi[k] < lo[k])
        throw InputError("Error, " + r.name() + ": Max must not be below Min on any axis.");
  }
  if (n_regions + 2 * dim > 32)
    throw InputError("Error, " + regions.name() + " holds " + std::to_string(n_regions) +
                     " regions; at most " + std::to_string(32 - 2 * dim) + " are supported.");
  ParameterList& cracks = d.sublist("Pre-Cracks");
  for (auto it = cracks.begin(); it != cracks.end(); ++it) {
    ParameterList& c = cracks.sublist(cracks.name(it));
    if (dim == 2) {
      const auto a = get_array<double>(c, "Start", 2, "2D crack segment start in m");
      const auto b = get_array<double>(c, "End", 2, "2D crack segment end in m");
      if (a[0] == b[0] && a[1] == b[1])
        throw InputError("Error, " + c.name() +
                         ": Start and End are the same point; a pre-crack needs a length.");
      for (const char* k : {"Corner", "Edge 1", "Edge 2"})
        if (!c.get<Array<double>>(k).empty())
          throw InputError("Error, " + path_of(c, k) + " is for 3D cracks; use Start and End.");
    } else {
      get_array<double>(c, "Corner", 3, "3D crack rectangle corner in m");
      const auto e1 = get_array<double>(c, "Edge 1", 3, "edge vector in m");
      const auto e2 = get_array<double>(c, "Edge 2", 3, "edge vector in m");
      const double dot = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
      const double n1 = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
      const double n2 = std::sqrt(e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]);
      if (n1 == 0 || n2 == 0 || std::abs(dot) > 1e-9 * n1 * n2)
        throw InputError("Error, " + c.name() +
                         ": Edge 1 and Edge 2 must be non-zero and orthogonal.");
      for (const char* k : {"Start", "End"})
        if (!c.get<Array<double>>(k).empty())
          throw InputError("Error, " + path_of(c, k) +
                           " is for 2D cracks; use Corner, Edge 1 and Edge 2.");
    }
  }
  const std::string physics = input.sublist("Solver").get<std::string>("Physics");
  const Physics phys = physics_options()(physics);
  const ParameterList& disc = input.sublist("Discretization");
  if (plane_options()(disc.get<std::string>("Plane")) == Plane::Stress) {
    if (dim != 2)
      throw InputError("Error, " + path_of(disc, "Plane") + " = Stress is for Dimension = 2.");
    if (!has_solid(phys))
      throw InputError("Error, " + path_of(disc, "Plane") +
                       " = Stress needs a skeleton (Solver->Physics = " + physics +
                       " has none): use Plane = Strain.");
  }
}

}  // namespace

InputModule discretization_input() {
  return {"Discretization",
          "The point grid: a box of cell-centred points of spacing Spacing, boundary layers, "
          "pre-cracks and named regions.",
          declare_discretization, check_discretization, nullptr};
}

std::vector<std::string> region_names(const ParameterList& d) {
  std::vector<std::string> names;
  const ParameterList& regions = d.sublist("Regions");
  for (auto it = regions.begin(); it != regions.end(); ++it)
    names.push_back(regions.name(it));
  const int dim = d.get<int>("Dimension");
  const auto faces = d.get<Array<std::string>>("Boundary Layers");
  for (int k = 0; k < dim; ++k)
    for (int side = 0; side < 2; ++side) {
      const std::string f = std::string(side ? "+" : "-") + char('x' + k);
      if (std::find(faces.begin(), faces.end(), f) != faces.end())
        names.push_back("Layer " + f);
    }
  return names;
}

// The grid of Discretization (include/mupm/input/input.hpp).
template <int Dim>
GridSpec<Dim> grid_from_input(const ParameterList& input) {
  const ParameterList& d = input.sublist("Discretization");
  GridSpec<Dim> g;
  g.dx = d.get<double>("Spacing");
  g.horizon = horizon_of(d);
  g.thickness = Dim == 2 ? d.get<double>("Thickness") : 1.0;
  const auto counts = d.get<Array<int>>("Counts");
  const auto ext = d.get<Array<double>>("Extents");
  const auto origin = d.get<Array<double>>("Origin");
  for (int k = 0; k < Dim; ++k) {
    g.counts[k] = counts.empty() ? std::llround(ext[k] / g.dx) : counts[k];
    g.origin[k] = origin.empty() ? 0.0 : origin[k];
  }
  // check_layer_rows has bounded it.
  const int rows = static_cast<int>(layer_rows(d, d.get<double>("Boundary Layer Horizons")));
  for (const auto& f : d.get<Array<std::string>>("Boundary Layers"))
    g.layers[f[1] - 'x'][f[0] == '-' ? 0 : 1] = rows;
  const ParameterList& regions = d.sublist("Regions");
  for (auto it = regions.begin(); it != regions.end(); ++it) {
    const ParameterList& r = regions.sublist(regions.name(it));
    Box b;
    const auto lo = r.get<Array<double>>("Min"), hi = r.get<Array<double>>("Max");
    for (int k = 0; k < Dim; ++k) {
      b.lo[k] = lo[k];
      b.hi[k] = hi[k];
    }
    g.regions.push_back(b);
  }
  // Boundary layers as regions: the rows outside the face, across the whole lattice.
  for (int k = 0; k < Dim; ++k)
    for (int side = 0; side < 2; ++side) {
      if (g.layers[k][side] == 0)
        continue;
      Box b;
      for (int j = 0; j < Dim; ++j) {
        b.lo[j] = g.origin[j] - (g.layers[j][0] + 1) * g.dx;
        b.hi[j] = g.origin[j] + (g.counts[j] + g.layers[j][1] + 1) * g.dx;
      }
      const double lo_face = g.origin[k], hi_face = g.origin[k] + g.counts[k] * g.dx;
      if (side == 0)
        b.hi[k] = lo_face - 0.25 * g.dx;
      else
        b.lo[k] = hi_face + 0.25 * g.dx;
      g.regions.push_back(b);
    }
  g.region_names = region_names(d);  // in the boxes' order
  const ParameterList& cracks = d.sublist("Pre-Cracks");
  for (auto it = cracks.begin(); it != cracks.end(); ++it) {
    const ParameterList& c = cracks.sublist(cracks.name(it));
    Crack cr;
    if (Dim == 2) {
      const auto a = c.get<Array<double>>("Start"), b = c.get<Array<double>>("End");
      for (int k = 0; k < 2; ++k) {
        cr.a[k] = a[k];
        cr.b[k] = b[k];
      }
    } else {
      const auto a = c.get<Array<double>>("Corner"), e1 = c.get<Array<double>>("Edge 1"),
                 e2 = c.get<Array<double>>("Edge 2");
      for (int k = 0; k < 3; ++k) {
        cr.a[k] = a[k];
        cr.b[k] = e1[k];
        cr.c[k] = e2[k];
      }
    }
    // A crack that misses the body breaks no bond and would measure no length.
    const CrackPart part = crack_inside<Dim>(cr, g.body());
    if (!(part.s1 > part.s0))
      throw InputError("Error, " + c.name() +
                       " lies outside the body (or touches it in a point or along its surface "
                       "only): it would cut no bond. Check its coordinates against the body, "
                       "which spans Origin to Origin + Counts x Spacing.");
    g.cracks.push_back(cr);
  }
  return g;
}

template GridSpec<2> grid_from_input<2>(const ParameterList&);
template GridSpec<3> grid_from_input<3>(const ParameterList&);

}  // namespace mupm
