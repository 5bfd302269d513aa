// Input validation: each class of error names the parameter's full path and what was expected;
// a valid input gets every default; the grid follows from the parameters.
#include <gtest/gtest.h>

#include <cmath>

#include <Teuchos_Array.hpp>

#include "mupm/input/input.hpp"
#include "mupm/input/law_registry.hpp"
#include "mupm/input/model.hpp"

namespace mupm {
namespace {

// An input with the given Discretization entries and other sublists; a solid's required
// material constants are added unless `rest` has a Materials sublist.
std::string xml(const std::string& discretization, const std::string& rest = "") {
  const std::string materials =
      rest.find("name=\"Materials\"") != std::string::npos
          ? ""
          : "<ParameterList name=\"Materials\">"
            "<Parameter name=\"Bulk Modulus\" type=\"double\" value=\"1e8\"/>"
            "<Parameter name=\"Shear Modulus\" type=\"double\" value=\"5e7\"/>"
            "<Parameter name=\"Length Scale\" type=\"double\" value=\"1e-3\"/>"
            "</ParameterList>";
  return "<ParameterList name=\"mupm\"><ParameterList name=\"Discretization\">" + discretization +
         "</ParameterList>" + materials + rest + "</ParameterList>";
}
const std::string kOk =
    "<Parameter name=\"Spacing\" type=\"double\" value=\"0.01\"/>"
    "<Parameter name=\"Counts\" type=\"Array(int)\" value=\"{10, 8}\"/>";

// Validating `text` must throw an InputError whose message contains every piece of `expect`.
void expect_error(const std::string& text, const std::vector<std::string>& expect) {
  try {
    auto pl = parse_input(text);
    validate_input(*pl);
    ADD_FAILURE() << "no error for:\n" << text;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    for (const auto& piece : expect)
      EXPECT_NE(msg.find(piece), std::string::npos) << "'" << piece << "' not in:\n" << msg;
  }
}

TEST(Input, ValidInputGetsDefaults) {
  auto pl = parse_input(xml(kOk));
  validate_input(*pl);
  EXPECT_EQ(pl->sublist("Solver").get<int>("Number of Steps"), 100);
  EXPECT_EQ(pl->sublist("Output").get<std::string>("Folder"), "output");
  EXPECT_DOUBLE_EQ(pl->sublist("Discretization").get<double>("Horizon Factor"), 3.015);
  const auto g = grid_from_input<2>(*pl);
  EXPECT_EQ(g.counts[0], 10);
  EXPECT_EQ(g.counts[1], 8);
  EXPECT_DOUBLE_EQ(g.horizon, 0.03015);
  EXPECT_EQ(g.n_global(), 80);
}

TEST(Input, ExtentsLayersRegions) {
  auto pl = parse_input(
      xml("<Parameter name=\"Spacing\" type=\"double\" value=\"0.01\"/>"
          "<Parameter name=\"Extents\" type=\"Array(double)\" value=\"{0.2, 0.1}\"/>"
          "<Parameter name=\"Horizon\" type=\"double\" value=\"0.04\"/>"
          "<Parameter name=\"Boundary Layers\" type=\"Array(string)\" value=\"{-y, +y}\"/>"
          "<ParameterList name=\"Regions\"><ParameterList name=\"top\">"
          "<Parameter name=\"Min\" type=\"Array(double)\" value=\"{0, 0.09}\"/>"
          "<Parameter name=\"Max\" type=\"Array(double)\" value=\"{0.2, 0.1}\"/>"
          "</ParameterList></ParameterList>"));
  validate_input(*pl);
  const auto g = grid_from_input<2>(*pl);
  EXPECT_EQ(g.counts[0], 20);
  EXPECT_EQ(g.counts[1], 10);
  EXPECT_EQ(g.layers[1][0], 8);  // floor(2 horizons: 2 x 0.04 / 0.01)
  EXPECT_EQ(g.layers[1][1], 8);
  EXPECT_EQ(g.layers[0][0], 0);
  ASSERT_EQ(g.region_names.size(), 3u);
  EXPECT_EQ(g.region_names[0], "top");
  EXPECT_EQ(g.region_names[1], "Layer -y");
  EXPECT_EQ(g.region_names[2], "Layer +y");
}

TEST(Input, UnknownParameter) {
  expect_error(xml(kOk + "<Parameter name=\"Spacingg\" type=\"double\" value=\"1\"/>"),
               {"Spacingg", "mupm->Discretization", "not found in the list of valid"});
  expect_error(xml(kOk,
                   "<ParameterList name=\"Solver\"><Parameter name=\"dt\" type=\"double\" "
                   "value=\"1\"/></ParameterList>"),
               {"dt", "mupm->Solver"});
  expect_error(xml(kOk,
                   "<ParameterList name=\"Materials\"><Parameter name=\"E\" type=\"double\" "
                   "value=\"1\"/></ParameterList>"),
               {"\"E\"", "mupm->Materials"});
}

TEST(Input, UnknownParameterInNamedSublist) {
  expect_error(xml(kOk + "<ParameterList name=\"Regions\"><ParameterList name=\"top\">"
                         "<Parameter name=\"Minimum\" type=\"Array(double)\" value=\"{0, 0}\"/>"
                         "</ParameterList></ParameterList>"),
               {"Minimum", "mupm->Discretization->Regions->top"});
}

TEST(Input, WrongType) {
  expect_error(xml("<Parameter name=\"Spacing\" type=\"string\" value=\"small\"/>"
                   "<Parameter name=\"Counts\" type=\"Array(int)\" value=\"{10, 8}\"/>"),
               {"Spacing", "mupm->Discretization", "double"});
  expect_error(xml(kOk,
                   "<ParameterList name=\"Solver\"><Parameter name=\"Number of Steps\" "
                   "type=\"double\" value=\"1.5\"/></ParameterList>"),
               {"Number of Steps", "mupm->Solver", "int"});
}

TEST(Input, OutOfRange) {
  expect_error(xml(kOk,
                   "<ParameterList name=\"Solver\"><Parameter name=\"Time Step\" "
                   "type=\"double\" value=\"-1e-6\"/></ParameterList>"),
               {"Time Step", "mupm->Solver", "-1e-06"});
  expect_error(xml(kOk + "<Parameter name=\"Dimension\" type=\"int\" value=\"4\"/>"),
               {"Dimension", "mupm->Discretization"});
  expect_error(xml(kOk,
                   "<ParameterList name=\"Output\"><Parameter name=\"Fields\" "
                   "type=\"Array(string)\" value=\"{displacement, temperature}\"/>"
                   "</ParameterList>"),
               {"Fields", "mupm->Output", "temperature"});
}

TEST(Input, MissingRequired) {
  expect_error(xml("<Parameter name=\"Counts\" type=\"Array(int)\" value=\"{10, 8}\"/>"),
               {"mupm->Discretization->Spacing", "missing"});
  expect_error(xml("<Parameter name=\"Spacing\" type=\"double\" value=\"0.01\"/>"),
               {"mupm->Discretization", "Counts", "Extents"});
  expect_error("<ParameterList name=\"mupm\"/>", {"mupm->Discretization", "missing"});
}

TEST(Input, InconsistentValues) {
  expect_error(xml("<Parameter name=\"Spacing\" type=\"double\" value=\"0.01\"/>"
                   "<Parameter name=\"Counts\" type=\"Array(int)\" value=\"{10, 8, 3}\"/>"),
               {"mupm->Discretization->Counts", "2 values"});
  expect_error(xml("<Parameter name=\"Spacing\" type=\"double\" value=\"0.03\"/>"
                   "<Parameter name=\"Extents\" type=\"Array(double)\" value=\"{0.1, 0.09}\"/>"),
               {"mupm->Discretization->Extents", "whole multiple"});
  expect_error(xml(kOk + "<Parameter name=\"Boundary Layers\" type=\"Array(string)\" "
                         "value=\"{+z}\"/>"),
               {"Boundary Layers", "+z"});
  expect_error(xml(kOk,
                   "<ParameterList name=\"Initial Conditions\"><ParameterList name=\"v\">"
                   "<Parameter name=\"Field\" type=\"string\" value=\"Velocity\"/>"
                   "<Parameter name=\"Region\" type=\"string\" value=\"nowhere\"/>"
                   "<Parameter name=\"Value\" type=\"Array(double)\" value=\"{1, 0}\"/>"
                   "</ParameterList></ParameterList>"),
               {"mupm->Initial Conditions->v->Region", "nowhere"});
}

// A horizon below the spacing gives no bonds (a run would take steps of 0 s): refused, naming
// the parameter that set it.
TEST(Input, HorizonBelowSpacingIsRefused) {
  expect_error(xml(kOk + "<Parameter name=\"Horizon Factor\" type=\"double\" value=\"0.5\"/>"),
               {"mupm->Discretization->Horizon Factor", "0.005 m", "no point would have a bond"});
  expect_error(xml(kOk + "<Parameter name=\"Horizon\" type=\"double\" value=\"0.001\"/>"),
               {"mupm->Discretization->Horizon =", "below the spacing 0.01 m"});
  // One spacing exactly still bonds the nearest neighbours.
  auto pl =
      parse_input(xml(kOk + "<Parameter name=\"Horizon Factor\" type=\"double\" value=\"1\"/>"));
  EXPECT_NO_THROW(validate_input(*pl));
}

TEST(Input, ZeroLengthPreCrackIsRefused) {
  expect_error(xml(kOk + "<ParameterList name=\"Pre-Cracks\"><ParameterList name=\"notch\">"
                         "<Parameter name=\"Start\" type=\"Array(double)\" value=\"{0.05, 0.04}\"/>"
                         "<Parameter name=\"End\" type=\"Array(double)\" value=\"{0.05, 0.04}\"/>"
                         "</ParameterList></ParameterList>"),
               {"mupm->Discretization->Pre-Cracks->notch", "needs a length"});
}

TEST(Input, NumbersAreReadStrictly) {
  // Teuchos alone would read these as 0.
  expect_error(xml(kOk + "<Parameter name=\"Origin\" type=\"Array(double)\" value=\"{0, abc}\"/>"),
               {"mupm->Discretization->Origin", "abc", "not a finite double"});
  expect_error(xml(kOk,
                   "<ParameterList name=\"Solver\"><Parameter name=\"Time Step\" "
                   "type=\"double\" value=\"1e-3x\"/></ParameterList>"),
               {"mupm->Solver->Time Step", "1e-3x"});
  expect_error(xml(kOk,
                   "<ParameterList name=\"Solver\"><Parameter name=\"Number of Steps\" "
                   "type=\"int\" value=\"10.5\"/></ParameterList>"),
               {"mupm->Solver->Number of Steps", "not a finite int"});
  expect_error(xml(kOk + "<Parameter name=\"Horizon\" type=\"double\" value=\"nan\"/>"),
               {"mupm->Discretization->Horizon", "nan"});
}

// Mirrored kinematic conditions (input/model.cpp, check_mirrored_kinematic): a lone normal
// Displacement is a symmetry plane, a clamp (x, y and the rotation, each Mirrored) is slaved,
// and the slaved layer's conditions are checked (a repeated component, a layer thicker than the
// body).
TEST(Input, MirroredKinematicConditions) {
  auto cond = [](const std::string& name, const std::string& layer, const std::string& type,
                 const std::string& component) {
    return "<ParameterList name=\"" + name +
           "\"><Parameter name=\"Type\" type=\"string\" value=\"" + type +
           "\"/><Parameter name=\"Region\" type=\"string\" value=\"" + layer +
           "\"/><Parameter name=\"Component\" type=\"string\" value=\"" + component +
           "\"/><Parameter name=\"Boundary Layer Values\" type=\"string\" value=\"Mirrored\"/>"
           "</ParameterList>";
  };
  auto input = [&](const std::string& conditions, const std::string& counts = "{10, 8}") {
    return xml(
        "<Parameter name=\"Spacing\" type=\"double\" value=\"0.01\"/>"
        "<Parameter name=\"Counts\" type=\"Array(int)\" value=\"" +
            counts +
            "\"/>"
            "<Parameter name=\"Boundary Layers\" type=\"Array(string)\" value=\"{-y, +y}\"/>",
        "<ParameterList name=\"Boundary Conditions\">" + conditions + "</ParameterList>");
  };
  const std::string clamp = cond("bx", "Layer -y", "Displacement", "x") +
                            cond("by", "Layer -y", "Displacement", "y") +
                            cond("br", "Layer -y", "Micro-Rotation", "z");
  auto pl = parse_input(input(clamp + cond("top", "Layer +y", "Displacement", "y")));
  validate_input(*pl);
  const auto m = model_from_input<2>(*pl);
  ASSERT_EQ(m.boundary_conditions.size(), 4u);
  for (int k = 0; k < 3; ++k)
    EXPECT_TRUE(m.boundary_conditions[k].slaved) << m.boundary_conditions[k].name;
  EXPECT_TRUE(m.boundary_conditions[3].mirrored);
  EXPECT_FALSE(m.boundary_conditions[3].slaved);  // alone and normal: the symmetry plane
  EXPECT_TRUE(m.grid.mirrored_layers);
  auto refused = [&](const std::string& text, const std::vector<std::string>& expect) {
    try {
      auto bad = parse_input(text);
      validate_input(*bad);
      model_from_input<2>(*bad);
      ADD_FAILURE() << "no error for:\n" << text;
    } catch (const InputError& e) {
      for (const auto& piece : expect)
        EXPECT_NE(std::string(e.what()).find(piece), std::string::npos) << e.what();
    }
  };
  refused(input(clamp + cond("bx2", "Layer -y", "Displacement", "x")),
          {"mupm->Boundary Conditions->bx->Component", "bx2 prescribes the same component"});
  // Layers as thick as the default (more than 2 rows) on a body 2 rows high.
  refused(input(clamp, "{10, 2}"),
          {"mupm->Boundary Conditions->bx->Region", "rows thick, but the body is 2 rows along y"});
  // What each kind takes (the kinds' table, src/input/modules/conditions.cpp): only the
  // mirrorable kinds mirror, a rotation axis is z in 2D, a force is along x or y.
  refused(input(cond("push", "Layer -y", "Body Force", "y")),
          {"mupm->Boundary Conditions->push->Boundary Layer Values = Mirrored",
           "only Pore Pressure, Fracture Pressure, Displacement, Velocity and Micro-Rotation "
           "conditions mirror",
           "Body Force conditions hold the prescribed value"});
  std::string couple = cond("turn", "Layer -y", "Body Couple", "x");
  couple.replace(couple.find("Mirrored"), 8, "Default");
  refused(input(couple), {"mupm->Boundary Conditions->turn->Component = x",
                          "in 2D the micro-rotation is about z"});
  std::string force = cond("pull", "Layer -y", "Body Force", "z");
  force.replace(force.find("Mirrored"), 8, "Default");
  refused(input(force),
          {"mupm->Boundary Conditions->pull->Component = z", "a 2D body has components x and y"});
}

TEST(Input, SolidAndBoundaryConditions) {
  // A solid needs its moduli and length scale.
  expect_error(xml(kOk,
                   "<ParameterList name=\"Materials\"><Parameter name=\"Bulk Modulus\" "
                   "type=\"double\" value=\"1e8\"/></ParameterList>"),
               {"mupm->Materials->Shear Modulus", "> 0"});
  expect_error(xml(kOk,
                   "<ParameterList name=\"Boundary Conditions\"><ParameterList name=\"b\">"
                   "<Parameter name=\"Type\" type=\"string\" value=\"Micro-Rotation\"/>"
                   "<Parameter name=\"Component\" type=\"string\" value=\"x\"/>"
                   "</ParameterList></ParameterList>"),
               {"mupm->Boundary Conditions->b->Component", "about z"});
  expect_error(xml(kOk,
                   "<ParameterList name=\"Boundary Conditions\"><ParameterList name=\"b\">"
                   "<Parameter name=\"Time Function\" type=\"string\" value=\"Table\"/>"
                   "<Parameter name=\"Times\" type=\"Array(double)\" value=\"{0, 1}\"/>"
                   "</ParameterList></ParameterList>"),
               {"mupm->Boundary Conditions->b", "Table"});
  expect_error(xml(kOk,
                   "<ParameterList name=\"Boundary Conditions\"><ParameterList name=\"b\">"
                   "<Parameter name=\"Type\" type=\"string\" value=\"Pressure\"/>"
                   "</ParameterList></ParameterList>"),
               {"Type", "mupm->Boundary Conditions->b", "Pressure"});
  auto pl =
      parse_input(xml(kOk,
                      "<ParameterList name=\"Boundary Conditions\"><ParameterList name=\"pull\">"
                      "<Parameter name=\"Component\" type=\"string\" value=\"y\"/>"
                      "<Parameter name=\"Value\" type=\"double\" value=\"2\"/>"
                      "<Parameter name=\"Time Function\" type=\"string\" value=\"Table\"/>"
                      "<Parameter name=\"Times\" type=\"Array(double)\" value=\"{0, 1, 3}\"/>"
                      "<Parameter name=\"Values\" type=\"Array(double)\" value=\"{0, 1, 0}\"/>"
                      "</ParameterList></ParameterList>"));
  validate_input(*pl);
  const auto bcs = boundary_conditions_from_input(*pl);
  ASSERT_EQ(bcs.size(), 1u);
  EXPECT_EQ(bcs[0].component, 1);
  EXPECT_EQ(bcs[0].kind, BoundaryCondition::Displacement);
  EXPECT_DOUBLE_EQ(bcs[0].time(0.5), 0.5);  // piecewise-linear table
  EXPECT_DOUBLE_EQ(bcs[0].time(2.0), 0.5);
  EXPECT_DOUBLE_EQ(bcs[0].time(5.0), 0.0);  // held after the table
  EXPECT_DOUBLE_EQ(bcs[0].time.rate(2.0), -0.5);
}

// The J criterion's speed cap (J-Integral->Speed Cap, Maximum Crack Speed): by default the
// skeleton's Rayleigh speed c_R = c_s (0.862 + 1.14 nu) / (1 + nu), c_s = sqrt(mu / rho) (here
// K = 1e8, mu = 5e7: nu = 0.2857; rho = 2000 kg/m^3, dry); a given speed replaces it; none
// without the cap; the speed without the J criterion or without the cap is refused.
TEST(Input, JCriterionSpeedCap) {
  const std::string grid =
      kOk +
      "<ParameterList name=\"Pre-Cracks\"><ParameterList name=\"c\">"
      "<Parameter name=\"Start\" type=\"Array(double)\" value=\"{-0.01, 0.04}\"/>"
      "<Parameter name=\"End\" type=\"Array(double)\" value=\"{0.045, 0.04}\"/>"
      "</ParameterList></ParameterList>";
  auto input = [&](const std::string& j, bool criterion = true) {
    return xml(grid,
               std::string(criterion ? "<ParameterList name=\"Fracture\"><Parameter name=\"Bond "
                                       "Breakage\" type=\"string\" value=\"J-Integral\"/>"
                                       "<Parameter name=\"Critical Energy Release Rate\" "
                                       "type=\"double\" value=\"10\"/></ParameterList>"
                                     : "") +
                   "<ParameterList name=\"J-Integral\"><Parameter name=\"Half Widths\" "
                   "type=\"Array(double)\" value=\"{2}\"/>" +
                   j + "</ParameterList>");
  };
  auto speed = [&](const std::string& j) {
    auto pl = parse_input(input(j));
    validate_input(*pl);
    return model_from_input<2>(*pl).j_integral.max_speed;
  };
  const double mu = 5e7, nu = (3 * 1e8 - 2 * mu) / (2 * (3 * 1e8 + mu));
  const double rho = 2000;  // Materials->Solid Density's default, no pores
  EXPECT_NEAR(speed(""), std::sqrt(mu / rho) * (0.862 + 1.14 * nu) / (1 + nu), 1e-9);
  const std::string ten = "<Parameter name=\"Maximum Crack Speed\" type=\"double\" value=\"10\"/>";
  EXPECT_EQ(speed(ten), 10.0);
  const std::string off = "<Parameter name=\"Speed Cap\" type=\"bool\" value=\"false\"/>";
  EXPECT_EQ(speed(off), 0.0);
  expect_error(input(ten + off), {"mupm->J-Integral->Maximum Crack Speed", "Speed Cap = true"});
  expect_error(input(ten, false),
               {"mupm->J-Integral->Maximum Crack Speed", "mupm->Fracture->Bond Breakage"});
}

// Discretization->Plane = Stress gives the elastic law lambda* = 2 lambda mu / (lambda + 2 mu)
// (K = 1e8, mu = 5e7: lambda = 6.667e7, lambda* = 3.333e7); Strain keeps lambda. With pore water
// the pressure's coefficient is 2 mu / (lambda + 2 mu) = 0.6 and the storage gains
// 1 / (lambda + 2 mu) = 6e-9 / Pa in both the solid's and the fluid's parameters (1 and 0 in plane
// strain). Plane stress is refused in 3D, without a skeleton and with Drucker-Prager, pore water
// and the semi-implicit pressure, naming the parameters; with Fracture Flow it is accepted.
TEST(Input, PlaneStress) {
  const std::string stress = "<Parameter name=\"Plane\" type=\"string\" value=\"Stress\"/>";
  const double lambda = 1e8 - 2 * 5e7 / 3.0, mu = 5e7;
  const std::string materials =
      "<ParameterList name=\"Materials\">"
      "<Parameter name=\"Bulk Modulus\" type=\"double\" value=\"1e8\"/>"
      "<Parameter name=\"Shear Modulus\" type=\"double\" value=\"5e7\"/>"
      "<Parameter name=\"Length Scale\" type=\"double\" value=\"1e-3\"/>"
      "<Parameter name=\"Porosity\" type=\"double\" value=\"0.3\"/>"
      "</ParameterList>";
  auto physics = [&](const char* name, const std::string& fracture = "") {
    return "<ParameterList name=\"Solver\"><Parameter name=\"Physics\" type=\"string\" value=\"" +
           std::string(name) +
           "\"/></ParameterList><ParameterList name=\"Fluid\">"
           "<Parameter name=\"Hydraulic Conductivity\" type=\"double\" value=\"1e-5\"/>"
           "</ParameterList>" +
           materials + fracture;
  };
  for (const bool plane_stress : {false, true})
    for (const bool water : {false, true}) {
      SCOPED_TRACE(std::string(plane_stress ? "stress" : "strain") + (water ? ", water" : ""));
      auto pl = parse_input(xml(kOk + (plane_stress ? stress : std::string()),
                                water ? physics("Hydro-Mechanical") : std::string()));
      validate_input(*pl);
      const auto m = model_from_input<2>(*pl);
      EXPECT_DOUBLE_EQ(m.solid.law.lambda,
                       plane_stress ? 2 * lambda * mu / (lambda + 2 * mu) : lambda);
      EXPECT_DOUBLE_EQ(m.solid.law.mu, mu);
      for (const PoreCoupling& c : {m.solid.pore, m.fluid.pore}) {
        EXPECT_DOUBLE_EQ(c.biot, plane_stress ? 2 * mu / (lambda + 2 * mu) : 1.0);
        EXPECT_DOUBLE_EQ(c.lateral_compliance, plane_stress ? 1 / (lambda + 2 * mu) : 0.0);
      }
    }
  expect_error(xml("<Parameter name=\"Dimension\" type=\"int\" value=\"3\"/>"
                   "<Parameter name=\"Spacing\" type=\"double\" value=\"0.01\"/>"
                   "<Parameter name=\"Counts\" type=\"Array(int)\" value=\"{10, 8, 4}\"/>" +
                   stress),
               {"mupm->Discretization->Plane = Stress", "Dimension = 2"});
  expect_error(xml(kOk + stress, physics("Pore Fluid")),
               {"mupm->Discretization->Plane = Stress", "Physics = Pore Fluid", "Plane = Strain"});
  // With Fracture Flow the crack water pushes the faces in the plane: no refusal.
  validate_input(
      *parse_input(xml(kOk + stress, physics("Hydro-Mechanical",
                                             "<ParameterList name=\"Fracture\"><Parameter "
                                             "name=\"Fracture Flow\" type=\"bool\" "
                                             "value=\"true\"/></ParameterList>"))));
  // Drucker-Prager keeps the 3D law for its return (Model::material) and is told the plane.
  auto dp = parse_input(xml(kOk + stress,
                            "<ParameterList name=\"Materials\">"
                            "<Parameter name=\"Bulk Modulus\" type=\"double\" value=\"1e8\"/>"
                            "<Parameter name=\"Shear Modulus\" type=\"double\" value=\"5e7\"/>"
                            "<Parameter name=\"Length Scale\" type=\"double\" value=\"1e-3\"/>"
                            "<Parameter name=\"Model\" type=\"string\" "
                            "value=\"Micropolar Drucker-Prager\"/>"
                            "<Parameter name=\"Cohesion\" type=\"double\" value=\"1e4\"/>"
                            "</ParameterList>"));
  validate_input(*dp);
  const auto m = model_from_input<2>(*dp);
  EXPECT_TRUE(m.plane_stress);
  EXPECT_DOUBLE_EQ(m.material.lambda, lambda);
  EXPECT_DOUBLE_EQ(m.solid.law.lambda, 2 * lambda * mu / (lambda + 2 * mu));
  // With pore water Drucker-Prager is accepted with either pressure integration (the
  // semi-implicit one takes the plastic thickness change a step late, fluid_solver.hpp).
  std::string wet_dp = physics("Hydro-Mechanical");
  wet_dp.insert(wet_dp.find("<Parameter name=\"Porosity\""),
                "<Parameter name=\"Model\" type=\"string\" value=\"Micropolar Drucker-Prager\"/>"
                "<Parameter name=\"Cohesion\" type=\"double\" value=\"1e4\"/>");
  validate_input(*parse_input(xml(kOk + stress, wet_dp)));
  std::string wet_dp_si = wet_dp;
  wet_dp_si.insert(wet_dp_si.find("</ParameterList>"),
                   "<Parameter name=\"Pressure Integration\" type=\"string\" "
                   "value=\"Semi-Implicit\"/>");
  validate_input(*parse_input(xml(kOk + stress, wet_dp_si)));
}

// Materials->Model offers the registered laws (include/mupm/input/law_registry.hpp), the first
// the default; the model points at the registration the input names, whose factory reads the
// law's own parameters from the model's Materials; a name nobody registered is a logic error.
TEST(Input, LawRegistry) {
  const auto& laws = law_registry();
  ASSERT_EQ(laws.size(), 2u);
  EXPECT_EQ(laws[0], &law_registration<MicropolarElastic>());
  EXPECT_EQ(laws[1], &law_registration<MicropolarDruckerPrager<2>>());
  auto pl = parse_input(xml(kOk));
  validate_input(*pl);
  EXPECT_EQ(pl->sublist("Materials").get<std::string>("Model"), laws[0]->name);
  EXPECT_EQ(model_from_input<2>(*pl).law, laws[0]);
  for (const LawRegistration* law : laws) {
    EXPECT_EQ(&law_named(law->name), law);
    ASSERT_TRUE(law->build2 && law->build3) << law->name;
    const std::string rest =
        "<ParameterList name=\"Materials\">"
        "<Parameter name=\"Bulk Modulus\" type=\"double\" value=\"1e8\"/>"
        "<Parameter name=\"Shear Modulus\" type=\"double\" value=\"5e7\"/>"
        "<Parameter name=\"Length Scale\" type=\"double\" value=\"1e-3\"/>"
        "<Parameter name=\"Cohesion\" type=\"double\" value=\"2e4\"/>"
        "<Parameter name=\"Model\" type=\"string\" value=\"" +
        std::string(law->name) + "\"/></ParameterList>";
    auto p = parse_input(xml(kOk, rest));
    validate_input(*p);
    const Model<2> m = model_from_input<2>(*p);
    EXPECT_EQ(m.law, law);
    EXPECT_EQ(m.materials.get<double>("Cohesion"), 2e4);
  }
  // The elastic law's state is defined on slaved layers' energy-free points, the plastic one's
  // is not; the plastic law needs its state and the second-order work.
  EXPECT_TRUE(laws[0]->energy_free_points);
  EXPECT_FALSE(laws[1]->energy_free_points);
  EXPECT_EQ(laws[0]->field_groups, 0u);
  EXPECT_EQ(laws[1]->field_groups, unsigned(kGroupPlastic | kGroupSecondOrderWork));
  EXPECT_THROW(law_named("Micropolar Elastoplastic"), std::logic_error);
  expect_error(xml(kOk,
                   "<ParameterList name=\"Materials\"><Parameter name=\"Model\" "
                   "type=\"string\" value=\"Micropolar Elastoplastic\"/></ParameterList>"),
               {"Model", "Micropolar Elastic", "Micropolar Drucker-Prager"});
}

// The point fields a run allocates follow from its modules: the pore water's with a fluid, the
// crack water's with Fracture Flow, the plastic state and the second-order work with
// Drucker-Prager, and the group of every field Output->Fields names.
TEST(Input, PointFieldGroups) {
  auto groups = [](const std::string& discretization, const std::string& rest) {
    auto pl = parse_input(xml(discretization, rest));
    validate_input(*pl);
    EXPECT_EQ(model_from_input<2>(*pl).run.field_groups, point_field_groups(*pl));
    return point_field_groups(*pl);
  };
  auto fields = [](const std::string& list) {
    return "<ParameterList name=\"Output\"><Parameter name=\"Fields\" type=\"Array(string)\" "
           "value=\"{" +
           list + "}\"/></ParameterList>";
  };
  auto solver = [](const std::string& physics) {
    return "<ParameterList name=\"Solver\"><Parameter name=\"Physics\" type=\"string\" "
           "value=\"" +
           physics +
           "\"/></ParameterList><ParameterList name=\"Fluid\"><Parameter name=\"Hydraulic "
           "Conductivity\" type=\"double\" value=\"1e-5\"/></ParameterList>"
           "<ParameterList name=\"Materials\">"
           "<Parameter name=\"Bulk Modulus\" type=\"double\" value=\"1e8\"/>"
           "<Parameter name=\"Shear Modulus\" type=\"double\" value=\"5e7\"/>"
           "<Parameter name=\"Length Scale\" type=\"double\" value=\"1e-3\"/>"
           "<Parameter name=\"Porosity\" type=\"double\" value=\"0.3\"/></ParameterList>";
  };
  const std::string flow =
      "<ParameterList name=\"Fracture\"><Parameter name=\"Fracture Flow\" type=\"bool\" "
      "value=\"true\"/></ParameterList>";
  const std::string dp =
      "<ParameterList name=\"Materials\">"
      "<Parameter name=\"Bulk Modulus\" type=\"double\" value=\"1e8\"/>"
      "<Parameter name=\"Shear Modulus\" type=\"double\" value=\"5e7\"/>"
      "<Parameter name=\"Length Scale\" type=\"double\" value=\"1e-3\"/>"
      "<Parameter name=\"Model\" type=\"string\" value=\"Micropolar Drucker-Prager\"/>"
      "<Parameter name=\"Cohesion\" type=\"double\" value=\"1e4\"/>"
      "</ParameterList>";
  EXPECT_EQ(groups(kOk, ""), unsigned(kGroupCore));
  EXPECT_EQ(groups(kOk, solver("Pore Fluid")), unsigned(kGroupCore | kGroupPoreWater));
  EXPECT_EQ(groups(kOk, solver("Hydro-Mechanical")), unsigned(kGroupCore | kGroupPoreWater));
  EXPECT_EQ(groups(kOk, solver("Hydro-Mechanical") + flow),
            unsigned(kGroupCore | kGroupPoreWater | kGroupCrackWater));
  EXPECT_EQ(groups(kOk, dp), unsigned(kGroupCore | kGroupPlastic | kGroupSecondOrderWork));
  EXPECT_EQ(groups(kOk, fields("displacement, plastic_strain")),
            unsigned(kGroupCore | kGroupPlastic));
  EXPECT_EQ(groups(kOk, fields("second_order_work")), unsigned(kGroupCore | kGroupSecondOrderWork));
  EXPECT_EQ(groups(kOk, fields("fracture_pressure, darcy_flux")),
            unsigned(kGroupCore | kGroupPoreWater | kGroupCrackWater));
  // Points of the core group alone: the others' fields are empty and not visited, and the bytes
  // per point are the sum of the core fields' sizes.
  Points<2> pts(5, 2, kGroupCore);
  std::size_t bytes = 0;
  int visited = 0;
  pts.for_each_field([&](const auto& view, const FieldSpec& s) {
    EXPECT_EQ(s.group, unsigned(kGroupCore)) << s.name;
    EXPECT_EQ(view.extent(0), 7u) << s.name;
    bytes += sizeof(typename std::decay_t<decltype(view)>::value_type) * std::size_t(s.ncomp);
    ++visited;
  });
  EXPECT_EQ(bytes, Points<2>::bytes_per_point(kGroupCore));
  EXPECT_LT(visited, int(Points<2>::specs().size()));
  EXPECT_EQ(pts.plastic_strain.extent(0), 0u);
  EXPECT_EQ(pts.pf.extent(0), 0u);
  EXPECT_EQ(pts.darcy_flux.extent(0), 0u);
  EXPECT_EQ(pts.second_order_work.extent(0), 0u);
  EXPECT_THROW(pts.require(kGroupPlastic, "test"), std::logic_error);
  EXPECT_NO_THROW(pts.require(kGroupCore, "test"));
}

TEST(Input, MalformedXml) {
  EXPECT_THROW(parse_input("<ParameterList name=\"mupm\"><Parameter name="), InputError);
}

TEST(Input, PrintDefaultsRoundTrip) {
  // The defaults list is itself an input that validates (after adding the required values).
  auto defaults = valid_parameters();
  EXPECT_TRUE(defaults->sublist("Discretization").isParameter("Spacing"));
  EXPECT_FALSE(defaults->sublist("Discretization").getEntry("Spacing").docString().empty());
}

}  // namespace
}  // namespace mupm
