#include "../input_module.hpp"

#include <algorithm>
#include <cmath>

#include "mupm/input/options.hpp"
#include "mupm/kernels/j_integral.hpp"

namespace mupm {

using Teuchos::Array;
using Teuchos::ParameterList;
using Teuchos::rcp;

namespace {

void declare_fracture(ParameterList& f) {
  f.set("Bond Breakage", std::string("None"),
        "None: bonds never break (pre-cracks stay as they are). Energy: a bond breaks once "
        "its energy W (eq 34, accumulated from the force and moment states over the run) "
        "reaches W_cr = 4 G_cr/(pi delta^4) in 3D (eq 36), 3 G_cr/(2 h delta^3) in 2D "
        "(derivation in include/mupm/kernels/fracture.hpp); the energy it holds is booked "
        "as fracture dissipation. J-Integral (2D, Algorithm 3): each crack tip (a pre-crack end "
        "inside the body) advances by J-Integral->Crack Increment along its crack's direction, "
        "at most once a step, whenever J/h of its first J-Integral contour >= G_cr: the bonds "
        "across the increment break.",
        bond_breaking_options().validator());
  f.set("Critical Energy Release Rate", 0.0,
        "G_cr [J/m^2 = N/m] of the Energy and J-Integral criteria (> 0 with them).", at_least(0.0));
  f.set("Critical Damage", 0.3,
        "D_cr in (0, 1]: a point with damage D >= D_cr (eq 37) is a fracture point (eq 104; "
        "the paper gives no value). Points next to a pre-crack are fracture points from the "
        "start.",
        rcp(new Teuchos::EnhancedNumberValidator<double>(1e-6, 1.0)));
  f.set("Bond Energy Force State", std::string("Effective"),
        "Force state whose work is the bond energy W (eq 34). Effective: the skeleton's, "
        "sigma-bar K^-1 xi plus stabilization, as the paper's text says (Terzaghi: the "
        "effective stress breaks the skeleton). Total: with the pore-water part "
        "-S_r p K^-1 xi, as eq 34 is printed. The same without a fluid.",
        bond_energy_state_options().validator());
  f.set("Fracture Flow", false,
        "true: water in the cracks (Solver->Physics = Hydro-Mechanical). The fracture "
        "points carry a fracture pressure p_f that flows along the crack by the cubic law "
        "a^3/(12 mu_w) (mu_w = Fluid->Viscosity), exchanges water with the pores (eq 19) and "
        "pushes the crack's faces apart; solved implicitly every fluid step (Semi-Implicit: in "
        "the pore pressure's solve). Conditions: "
        "Fracture Pressure, Fracture Source. Derivations in "
        "include/mupm/kernels/fracture_flow.hpp.");
  f.set("Crack Water Force", std::string("Face Pressure"),
        "How the crack's water pressure p_f acts on the solid (Fracture Flow). Face "
        "Pressure: p_f pushes the crack's faces apart (central pair forces on the broken "
        "bonds, p_f per unit face area), with the undrained p_f* of the opening the solid is "
        "at (Explicit; Semi-Implicit: the p_f of the joint solve). Eq 17 (Explicit only): as the "
        "paper prints it, bonds between two fracture points carry -S_rf p_f "
        "K^-1 xi in place of -S_r p K^-1 xi; those bonds run along the faces, so p_f barely "
        "acts across the crack (and p_f is that of the last fluid step); its force does work "
        "the crack water does not supply, and with injection it blows up at any time step "
        "(inputs/README.md, Example 1). Derivations and why "
        "in include/mupm/kernels/fracture_flow.hpp.",
        crack_water_force_options().validator());
  f.set("Minimum Aperture", 1e-6,
        "a_min [m]: a film of water in the crack (the paper gives none). The conductance "
        "takes max(a, a_min); the storage the crack's volume a + a_min, whose opening stores "
        "water. Explicit: the crack water's stiffness K_w / a_min enters the solid's stable "
        "step, a small a_min (with a stiff water) means a small step (not Semi-Implicit). With "
        "Fracture Flow, below Spacing "
        "(the film fits in a "
        "crack point's cell).",
        positive());
}

// The film of crack water fits a cell; Fracture Flow needs Hydro-Mechanical; breakage a solid
// and G_cr.
void check_fracture(ParameterList& input) {
  const std::string physics = input.sublist("Solver").get<std::string>("Physics");
  const Physics phys = physics_options()(physics);
  const ParameterList& fr = input.sublist("Fracture");
  // a_min is a film of water in a crack point's cell, whose width is Spacing: its porosity
  // (a + a_min) / (rows dx) reaches 1 at a_min = dx (one row), beyond which the crack would hold
  // more water than its cell; the film's stiffness K_w / a_min in the stable step then is
  // meaningless too (1e308 overflowed to a non-finite aperture, 1e50 ran with nothing moving).
  // Only the crack water uses it.
  if (fr.get<bool>("Fracture Flow")) {
    const double amin = fr.get<double>("Minimum Aperture");
    const double dx = input.sublist("Discretization").get<double>("Spacing");
    if (!(amin < dx)) {
      std::ostringstream s;
      s << "Error, " << path_of(fr, "Minimum Aperture") << " = " << amin
        << " m is not below the point spacing " << dx
        << " m (mupm->Discretization->Spacing): the film of water it stands for must fit in a "
           "crack point's cell (1e-6 m is the default).";
      throw InputError(s.str());
    }
  }
  if (fr.get<bool>("Fracture Flow") && phys != Physics::HydroMechanical)
    throw InputError("Error, " + path_of(fr, "Fracture Flow") +
                     " = true needs Solver->Physics = Hydro-Mechanical (it is " + physics +
                     "): the crack's water lives between the solid's crack faces.");
  if (bond_breaking_options()(fr.get<std::string>("Bond Breakage")) != BondBreaking::None) {
    if (!has_solid(phys))
      throw InputError("Error, " + path_of(fr, "Bond Breakage") + " = " +
                       fr.get<std::string>("Bond Breakage") +
                       " needs Solver->Physics = Micropolar Solid or Hydro-Mechanical (it is " +
                       physics + "): bonds break by the work of the solid's force states.");
    if (!(fr.get<double>("Critical Energy Release Rate") > 0))
      throw InputError("Error, " + path_of(fr, "Critical Energy Release Rate") +
                       " must be > 0 for " + path_of(fr, "Bond Breakage") + " = " +
                       fr.get<std::string>("Bond Breakage") + ".");
  }
}

unsigned fracture_field_groups(const ParameterList& input) {
  return (input.sublist("Fracture").get<bool>("Fracture Flow") ? unsigned(kGroupCrackWater) : 0u) |
         (input.sublist("J-Integral").get<double>("Release Time") > 0 ? unsigned(kGroupRelease)
                                                                      : 0u);
}

void declare_j_integral(ParameterList& j) {
  j.set("Half Widths", Array<double>(),
        "Half width along x of each contour (at most 8; empty: no J-integral), in Units. The "
        "contour's edges are moved to the nearest cell faces.");
  j.set("Half Heights", Array<double>(),
        "Half height along y of each contour, in Units (empty: the Half Widths).");
  j.set("Units", std::string("Spacings"),
        "Units of Half Widths and Half Heights: Spacings (multiples of "
        "Discretization->Spacing) or Metres.",
        contour_units_options().validator());
  j.set("Crack Increment", 0.0,
        "Delta a [m] by which the J criterion (Fracture->Bond Breakage = J-Integral) advances "
        "a tip each time its J/h >= Critical Energy Release Rate (0: one Spacing; at most one "
        "Spacing and the smallest contour half size).",
        at_least(0.0));
  j.set("Speed Cap", true,
        "J criterion: after an advance the next waits Delta a / c_R, c_R = c_s (0.862 + "
        "1.14 nu)/(1 + nu) the skeleton's Rayleigh wave speed at the initial density (a "
        "running mode I crack's limit), or Delta a / Maximum Crack Speed when that is given. "
        "false: an advance whenever J/h >= G_cr, at most one a "
        "step (the paper's Algorithm 3), which lets the crack run at Delta a / dt while the "
        "contours still show the field of before the last increment.");
  j.set("Maximum Crack Speed", 0.0,
        "J criterion with Speed Cap: the speed v [m/s] in the wait Delta a / v between a tip's "
        "advances (0: c_R). A crack that should grow quasi-statically (a hydraulic fracture "
        "against a closed form) takes a v far above its own speed and far below c_R, so that "
        "the field and the crack water settle after each increment before the next J decision.",
        at_least(0.0));
  j.set("Release Time", 0.0,
        "J criterion: the time [s] over which the forces an increment's bonds carried fall "
        "linearly to zero, applied at the bonds' ends as a decaying force (node release; "
        "include/mupm/solvers/solid_solver.hpp). 0: at once, as the paper's breakage. A quasi-"
        "static crack (a hydraulic fracture against a closed form) takes the speed cap's wait "
        "Delta a / Maximum Crack Speed, so that the new faces open as if the tip ran through "
        "the increment at that speed; at most that wait.",
        at_least(0.0));
}

// J-Integral: 2D, a solid, a pre-crack, matching contour sizes that fit the body at the start.
void check_j_integral(ParameterList& input, int dim, Physics phys) {
  ParameterList& j = input.sublist("J-Integral");
  const ParameterList& fr = input.sublist("Fracture");
  const bool criterion =
      bond_breaking_options()(fr.get<std::string>("Bond Breakage")) == BondBreaking::JIntegral;
  const auto w = j.get<Array<double>>("Half Widths");
  auto h = j.get<Array<double>>("Half Heights");
  if (w.empty() && !h.empty())
    throw InputError("Error, " + path_of(j, "Half Heights") + " is given without " +
                     path_of(j, "Half Widths") + ".");
  if (j.get<double>("Release Time") > 0 && !(criterion && j.get<bool>("Speed Cap")))
    throw InputError("Error, " + path_of(j, "Release Time") +
                     " is given, but it releases the J criterion's increments: it needs " +
                     path_of(fr, "Bond Breakage") + " = J-Integral and " + path_of(j, "Speed Cap") +
                     " = true (the next J decision waits for the release).");
  if (w.empty()) {
    if (criterion)
      throw InputError("Error, " + path_of(fr, "Bond Breakage") + " = J-Integral needs " +
                       path_of(j, "Half Widths") + ": at least one contour around the tip.");
    return;
  }
  const std::string what = path_of(j, "Half Widths");
  if (dim != 2)
    throw InputError("Error, " + what + ": the J-integral is 2D (Discretization->Dimension = 2).");
  if (!has_solid(phys))
    throw InputError("Error, " + what +
                     ": the J-integral needs Solver->Physics = Micropolar Solid or "
                     "Hydro-Mechanical.");
  const ParameterList& d = input.sublist("Discretization");
  if (w.size() > kMaxContours)
    throw InputError("Error, " + what + " lists " + std::to_string(w.size()) +
                     " contours; at most " + std::to_string(kMaxContours) + " are supported.");
  if (!h.empty() && h.size() != w.size())
    throw InputError("Error, " + path_of(j, "Half Heights") + " has " + std::to_string(h.size()) +
                     " values and " + what + " " + std::to_string(w.size()) +
                     ": give one per contour, or none.");
  if (h.empty())
    h = w;
  const double dx = d.get<double>("Spacing");
  const double unit =
      contour_units_options()(j.get<std::string>("Units")) == ContourUnits::Metres ? 1.0 : dx;
  for (Teuchos::Ordinal k = 0; k < w.size(); ++k)
    for (double v : {w[k], h[k]})
      if (!(v * unit >= dx))
        throw InputError("Error, " + what + " / Half Heights: contour " + std::to_string(k + 1) +
                         " has a half size of " + std::to_string(v * unit) +
                         " m, below one Spacing (" + std::to_string(dx) +
                         " m): a contour must hold the tip and the points around it.");
  // The tips (kernels/j_integral.hpp, crack_tips): the pre-crack ends inside the real body of
  // the grid the run will build (Discretization's check has passed).
  const GridSpec<2> g = grid_from_input<2>(input);
  const Box body = g.body();
  const auto tips = crack_tips(g.cracks, body);
  if (tips.empty())
    throw InputError(
        "Error, " + what + ": the J-integral's contours surround the crack tips, " +
        "the ends of the Discretization->Pre-Cracks entries inside the body (" +
        std::to_string(body.lo[0]) + " to " + std::to_string(body.hi[0]) + " m by " +
        std::to_string(body.lo[1]) + " to " + std::to_string(body.hi[1]) + " m); there is " +
        (g.cracks.empty() ? std::string("no pre-crack") : std::string("no end inside")) + ".");
  // Every tip's contours at the start inside the real body (their edges go to the nearest cell
  // faces, at most dx/2 away; a contour beyond it runs through no material, and J came out 0.012
  // for 0.93 with a half width past the body's faces) and free of the other tips.
  auto where = [&](std::size_t t) {
    std::ostringstream m;
    m << "tip " << t + 1 << " (" << tips[t].x[0] << ", " << tips[t].x[1] << ") m";
    return m.str();
  };
  for (std::size_t t = 0; t < tips.size(); ++t)
    for (Teuchos::Ordinal k = 0; k < w.size(); ++k) {
      double half[2] = {w[k] * unit, h[k] * unit};
      for (int a = 0; a < 2; ++a)
        if (tips[t].x[a] - half[a] < body.lo[a] - 0.5 * dx ||
            tips[t].x[a] + half[a] > body.hi[a] + 0.5 * dx) {
          std::ostringstream m;
          m << "Error, " << (a == 0 ? what : path_of(j, "Half Heights")) << ": contour " << k + 1
            << " spans " << (a == 0 ? 'x' : 'y') << " = " << tips[t].x[a] - half[a] << " to "
            << tips[t].x[a] + half[a] << " m around " << where(t) << ", beyond the body ("
            << body.lo[a] << " to " << body.hi[a]
            << " m): the contour must run through the material. Give a smaller half size.";
          throw InputError(m.str());
        }
      for (std::size_t o = 0; o < tips.size(); ++o)
        if (o != t && std::abs(tips[o].x[0] - tips[t].x[0]) <= half[0] + 0.5 * dx &&
            std::abs(tips[o].x[1] - tips[t].x[1]) <= half[1] + 0.5 * dx)
          throw InputError("Error, " + what + " / Half Heights: contour " + std::to_string(k + 1) +
                           " around " + where(t) + " holds " + where(o) +
                           ": J around one tip would hold the other's field. Give a smaller half "
                           "size, or cracks farther apart.");
    }
  const double inc = j.get<double>("Crack Increment");
  if (criterion && inc > dx * (1 + 1e-12))
    throw InputError("Error, " + path_of(j, "Crack Increment") + " = " + std::to_string(inc) +
                     " m exceeds one Spacing (" + std::to_string(dx) +
                     " m): an increment breaks the bonds across it at once, and one longer "
                     "than a spacing skips the lattice's cells (0: one Spacing).");
  if (j.get<double>("Maximum Crack Speed") > 0 && !(criterion && j.get<bool>("Speed Cap")))
    throw InputError("Error, " + path_of(j, "Maximum Crack Speed") +
                     " is given, but it sets the J criterion's speed cap: it needs " +
                     path_of(fr, "Bond Breakage") + " = J-Integral and " + path_of(j, "Speed Cap") +
                     " = true.");
  for (Teuchos::Ordinal k = 0; k < w.size(); ++k)
    if (criterion && std::min(w[k], h[k]) * unit < inc)
      throw InputError("Error, " + path_of(j, "Crack Increment") + " = " + std::to_string(inc) +
                       " m exceeds the half size of contour " + std::to_string(k + 1) + " (" +
                       std::to_string(std::min(w[k], h[k]) * unit) +
                       " m): an increment must stay inside the contours (it is in metres).");
}

void check_j(ParameterList& input) {
  check_j_integral(input, input.sublist("Discretization").get<int>("Dimension"),
                   physics_options()(input.sublist("Solver").get<std::string>("Physics")));
}

}  // namespace

InputModule fracture_input() {
  return {"Fracture",
          "Bond breakage (Solver->Physics = Micropolar Solid or Hydro-Mechanical), damage and "
          "fracture points.",
          declare_fracture, check_fracture, fracture_field_groups};
}

InputModule j_integral_input() {
  return {"J-Integral",
          "The micropolar J-integral (eqs 30, 125-126) around every crack tip (each pre-crack "
          "end inside the body: a centre crack has two, an edge crack one; numbered crack by "
          "crack, End before Start), on rectangular contours centred on the tip (2D). "
          "Time-series columns j_integral, j_translational, j_rotational (first contour) and "
          "j_integral_<k> (contour k >= 2) of tip 1, the same with the suffix _tip<t> for tip "
          "t >= 2 (j_integral_tip2, j_integral_tip2_2, ...), "
          "per unit thickness [J/m^2 = Pa m]; with Fracture Flow and Crack Water Force = Face "
          "Pressure J includes the crack water's work on the faces inside the contour (column "
          "j_face), which keeps it path-independent with water in the crack. The tip: with "
          "Fracture->Bond Breakage = "
          "J-Integral the pre-crack's end advanced by its increments (columns j_crack_length, "
          "the first pre-crack's length, and with two or more tips j_crack_length_tip<t>, tip "
          "t's share of its pre-crack plus its advances), otherwise the farthest fracture point "
          "beyond the end along the crack. Derivation and discretization in "
          "include/mupm/kernels/j_integral.hpp.",
          declare_j_integral, check_j, nullptr};
}

}  // namespace mupm
