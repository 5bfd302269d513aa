// Boundary conditions by the boundary-layer method (paper section 3): prescribed displacement,
// velocity and micro-rotation components on regions (usually the boundary layers), and
// tractions and body forces as body-force densities; prescribed pore pressure and fluid sources
// (applied by include/mupm/solvers/fluid_solver.hpp). Value types and kernels only.
#ifndef MUPM_BOUNDARY_CONDITIONS_HPP
#define MUPM_BOUNDARY_CONDITIONS_HPP

#include <stdexcept>
#include <string>
#include <vector>

#include "mupm/data/points.hpp"

namespace mupm {

// g(t) of a condition: value * g(t).
struct TimeFunction {
  enum Kind { Constant, Ramp, Rate, Table } kind = Constant;
  double ramp_time = 0;
  std::vector<double> times, values;

  double operator()(double t) const {
    switch (kind) {
      case Constant:
        return 1.0;
      case Ramp:
        return ramp_time > 0 ? (t < ramp_time ? t / ramp_time : 1.0) : 1.0;
      case Rate:
        return t;
      case Table: {
        if (t <= times.front())
          return values.front();
        if (t >= times.back())
          return values.back();
        std::size_t k = 1;
        while (times[k] < t)
          ++k;
        const double s = (t - times[k - 1]) / (times[k] - times[k - 1]);
        return values[k - 1] + s * (values[k] - values[k - 1]);
      }
    }
    return 1.0;
  }
  // dg/dt, for the velocity of a prescribed displacement (one-sided at kinks).
  double rate(double t) const {
    switch (kind) {
      case Constant:
        return 0.0;
      case Ramp:
        return (ramp_time > 0 && t < ramp_time) ? 1.0 / ramp_time : 0.0;
      case Rate:
        return 1.0;
      case Table: {
        if (t < times.front() || t >= times.back())
          return 0.0;
        std::size_t k = 1;
        while (times[k] <= t)
          ++k;
        return (values[k] - values[k - 1]) / (times[k] - times[k - 1]);
      }
    }
    return 0.0;
  }
};

struct BoundaryCondition {
  enum Kind {
    Displacement,
    Velocity,
    MicroRotation,
    Traction,
    BodyForce,
    BodyCouple,
    PorePressure,      // prescribed p [Pa] on the region's points (drained boundary)
    FluidSource,       // water injected [m^3/s; in 2D per metre of thickness], spread by volume
    FluidFlux,         // water flux into the body through a face [m/s], on its boundary layer:
                       // the layer continues p with the gradient of that flux (FluidSolver)
    FracturePressure,  // prescribed p_f [Pa] on the region's fracture points
    FractureSource     // water injected into the fracture points of the region [m^3/s; 2D: /m]
  };
  Kind kind = Displacement;
  std::string name;
  std::uint32_t region_mask = 0;  // 0: all points
  int component = 0;              // axis (rotation component for MicroRotation)
  double value = 0;
  TimeFunction time;
  // Boundary Layer Values = Mirrored. Pore Pressure: the boundary-layer points take
  // 2 g - p(mirror), the odd reflection about the face (FluidSolver::set_pressure).
  // Displacement of the face's normal component: the layer is the mirror image of the body
  // about a symmetry plane moved to g (mirror_kinematic), when it is the only kinematic
  // condition of its layer; otherwise (below) the layer is slaved.
  bool mirrored = false;
  // A mirrored kinematic condition of a slaved layer (slave_layer): set by the input checks
  // (input/model.cpp) when its layer has a mirrored Micro-Rotation, a mirrored tangential
  // Displacement or several mirrored conditions (a clamp).
  bool slaved = false;
  // Column of Discretization::mirror it reflects with: the axis of the face its region lies
  // outside of (face_column in mesh/grid.hpp), or Dim (its points outside one face only).
  int mirror_column = 0;
  // Traction Distribution = Consistent (consistent_traction_load): the face the traction loads
  // (2 axis + side, side 1 the high face; set by the input checks), and the load of a unit Value
  // ([n_owned][Dim + R]: force density, then couple density; filled by the solid solver).
  bool consistent = false;
  int face = -1;
  Vectors unit_load;
  bool kinematic() const {
    return kind == Displacement || kind == Velocity || kind == MicroRotation;
  }
  bool fluid() const {
    return kind == PorePressure || kind == FluidSource || kind == FluidFlux || fracture_fluid();
  }
  // Sets the pressure of its points (Pore Pressure: g; Fluid Flux: the flux's continuation).
  bool prescribes_pressure() const { return kind == PorePressure || kind == FluidFlux; }
  bool fracture_fluid() const { return kind == FracturePressure || kind == FractureSource; }
  // Bit of Points::fixed this condition prescribes.
  template <int Dim>
  std::uint32_t fixed_bit() const {
    return kind == MicroRotation ? 1u << (Dim + component) : 1u << component;
  }
};

// Marks the prescribed components of the owned points.
template <int Dim>
void mark_fixed(const std::vector<BoundaryCondition>& bcs, const Points<Dim>& pts) {
  for (const auto& bc : bcs) {
    if (!bc.kinematic())
      continue;
    const std::uint32_t mask = bc.region_mask, bit = bc.fixed_bit<Dim>();
    auto regions = pts.regions;
    auto fixed = pts.fixed;
    Kokkos::parallel_for(
        "mupm::BC::mark", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
          if (mask == 0 || (regions(i) & mask))
            fixed(i) |= bit;
        });
  }
}

// Sets the prescribed components at the end of a step from t to t + dt (after the free ones
// were advanced): displacement u = value g(t+dt), v = value g'(t+dt); velocity
// u += dt value g(t + dt/2), v = value g(t+dt); micro-rotation theta = value g(t+dt).
template <int Dim>
void apply_kinematic(const std::vector<BoundaryCondition>& bcs, const Points<Dim>& pts, double t,
                     double dt) {
  for (const auto& bc : bcs) {
    if (!bc.kinematic())
      continue;
    const std::uint32_t mask = bc.region_mask;
    const int c = bc.component;
    auto regions = pts.regions;
    const double tn = t + dt;
    if (bc.kind == BoundaryCondition::MicroRotation) {
      const double th_val = bc.value * bc.time(tn), om_val = bc.value * bc.time.rate(tn);
      auto th = pts.theta, om = pts.omega, al = pts.alpha;
      Kokkos::parallel_for(
          "mupm::BC::rotation", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
            if (mask != 0 && !(regions(i) & mask))
              return;
            th(i, c) = th_val;
            om(i, c) = om_val;
            al(i, c) = 0;
          });
      continue;
    }
    const bool disp = bc.kind == BoundaryCondition::Displacement;
    const double u_val = disp ? bc.value * bc.time(tn) : 0.0;
    const double du = disp ? 0.0 : dt * bc.value * bc.time(t + 0.5 * dt);
    const double v_val = disp ? bc.value * bc.time.rate(tn) : bc.value * bc.time(tn);
    auto u = pts.u, v = pts.v, a = pts.a;
    Kokkos::parallel_for(
        "mupm::BC::motion", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
          if (mask != 0 && !(regions(i) & mask))
            return;
          u(i, c) = disp ? u_val : u(i, c) + du;
          v(i, c) = v_val;
          a(i, c) = 0;
        });
  }
}

// Mirrored Displacement conditions (the boundary-layer issue): every component of a layer point
// i with a mirror m = mirror(i, col) (the point at the same distance inside the face, owned or
// ghost, current) is set from m's by the reflection R about the face, shifted so that the
// normal component passes through g at the face:
//   u_n(i) = 2 g - u_n(m),  u_t(i) = u_t(m),
//   theta(i) = det(R) R theta(m): theta_n(i) = theta_n(m), theta_t(i) = -theta_t(m) (an axial
//   vector; in 2D theta_z lies in the face's plane: theta(i) = -theta(m)),
// and likewise the velocity v (g' for g); the micro-rotation rate, which is not ghosted, is set
// to 0 (prescribed components carry no kinetic energy: it is output only). Only points outside
// exactly one face (the condition's) are mirrored, so every mirror is a body point, which no
// mirrored condition writes: the result does not depend on the order of the conditions or on
// the rank count. Corner (and 3D edge) points and points of the region inside the body are left
// to apply_kinematic (g on the condition's component) and to other conditions. Why R: the
// micropolar operator commutes with R (and with -R), so the layered operator stays symmetric and
// the explicit scheme stable; an odd reflection of the held components alone (-I on u, as the
// pressure's) is not an invariant subspace, and was measured to grow without bound at any step. R
// is a symmetry plane (a frictionless roller with theta_t = 0) at u_n = g: exact for fields with
// that symmetry (a bar stretched along n), not for a clamp (u_t = 0 is not a symmetry of the body);
// exact for such fields when the layer is 2 delta thick (every layer point bonded to the body then
// has a whole family).
template <int Dim>
void mirror_kinematic(const BoundaryCondition& bc, const Points<Dim>& pts,
                      const View2<LocalId>& mirror, double t) {
  constexpr int R = kRotDim<Dim>;
  const std::uint32_t mask = bc.region_mask;
  const int n = bc.component, col = bc.mirror_column;
  const double g = bc.value * bc.time(t), g_rate = bc.value * bc.time.rate(t);
  auto regions = pts.regions;
  auto u = pts.u, v = pts.v, a = pts.a, th = pts.theta, om = pts.omega, al = pts.alpha;
  Kokkos::parallel_for(
      "mupm::BC::mirror_kinematic", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        if (mask != 0 && !(regions(i) & mask))
          return;
        if (mirror(i, Dim) < 0)  // not outside exactly one face
          return;
        const LocalId m = mirror(i, col);
        for (int k = 0; k < Dim; ++k) {
          u(i, k) = k == n ? 2 * g - u(m, k) : u(m, k);
          v(i, k) = k == n ? 2 * g_rate - v(m, k) : v(m, k);
          a(i, k) = 0;
        }
        for (int r = 0; r < R; ++r) {
          const double s = (R == 3 && r == n) ? 1.0 : -1.0;
          th(i, r) = s * th(m, r);
          om(i, r) = 0;
          al(i, r) = 0;
        }
      });
}

// Slaved boundary layers (README "Boundary layers"; a clamp, u = theta = 0 at the face, is the
// case they are for). The points of the layer that lie outside its face only carry no strain
// energy (kFixedNoEnergy: pass 1 gives them zero states, include/mupm/kernels/solid.hpp), so the
// body's energy Psi is its real points' alone. Each prescribed component c of a layer point L
// takes the odd reflection of its mirror m (the body point at the same distance inside):
//   q_c(L) = 2 g - q_c(m)   (q = u or theta; the velocity likewise),
// so that the nonlocal gradients see a field that passes through g at the face. The force the
// body's states put on L, f_L = -(dPsi/du_L) / V_L, is folded back onto the mirror by the chain
// rule of u_L = 2 g - u_m (pack_layer_forces, add_folded): f_m -= f_L V_L / V_m. The operator on
// the real points is then P^T K P, K the stiffness of Psi and P the (affine) slaving: symmetric and
// positive semi-definite for any reflection, so the explicit scheme stays stable (an odd
// reflection of layers that keep their own energy is neither). The boundary's generalized force
// is dPsi/dg = -2 sum_L f_L V_L (the reaction, and the external work on the increment 2 dg:
// slaved_increment). Components of the layer without a condition stay free (energy-free points
// that the body's gradients see and move). Corner (and 3D edge) points of the region are not
// slaved: they hold g and keep their energy (apply_kinematic). The layer must not be thicker
// than the body along its normal (input/model.cpp), so that each body point is the mirror of at
// most one layer point per face.

// Marks the layer points (outside exactly one face) of the mirrored kinematic conditions: every
// component prescribed for a symmetry plane (mirror_kinematic sets them all), kFixedNoEnergy for
// a slaved layer (its components are marked by their own conditions, mark_fixed).
template <int Dim>
void mark_mirrored_layers(const std::vector<BoundaryCondition>& bcs, const Points<Dim>& pts,
                          const View2<LocalId>& mirror) {
  constexpr std::uint32_t all = (1u << (Dim + kRotDim<Dim>)) - 1;
  for (const auto& bc : bcs) {
    if (!(bc.kinematic() && bc.mirrored))
      continue;
    const std::uint32_t mask = bc.region_mask, bits = bc.slaved ? kFixedNoEnergy : all;
    auto regions = pts.regions;
    auto fixed = pts.fixed;
    Kokkos::parallel_for(
        "mupm::BC::mark_mirrored", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
          if ((mask == 0 || (regions(i) & mask)) && mirror(i, Dim) >= 0)
            fixed(i) |= bits;
        });
  }
}

// The odd reflection v_c(L) = 2 g - v_c(m) of a slaved condition's component on its layer
// points (header above), for u (theta) and v; the mirrors must be current on the ghosts. g, g_rate:
// the prescribed displacement (rotation) and its rate at this time: value g(t) and value g'(t) for
// Displacement and Micro-Rotation, the displacement integrated so far and value g(t) for Velocity
// (SolidSolver), 0 for the linear operator (the stable-step estimate). The micro-rotation rate of
// a slaved rotation is set to g_rate (it is not ghosted; a prescribed component carries no kinetic
// energy, so it is output only).
// `rates` = false: u (theta) only, the velocities and accelerations left as they are (the
// stable-step estimate's iterates, g = 0).
template <int Dim>
void slave_layer(const BoundaryCondition& bc, const Points<Dim>& pts, const View2<LocalId>& mirror,
                 double g, double g_rate, bool rates = true) {
  const bool rot = bc.kind == BoundaryCondition::MicroRotation;
  const std::uint32_t mask = bc.region_mask;
  const int c = bc.component;
  auto regions = pts.regions;
  auto fixed = pts.fixed;
  auto q = rot ? pts.theta : pts.u, dq = rot ? pts.omega : pts.v, ddq = rot ? pts.alpha : pts.a;
  Kokkos::parallel_for(
      "mupm::BC::slave_layer", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        if ((mask != 0 && !(regions(i) & mask)) || !(fixed(i) & kFixedNoEnergy))
          return;
        const LocalId m = mirror(i, Dim);
        q(i, c) = 2 * g - q(m, c);
        if (!rates)
          return;
        dq(i, c) = rot ? g_rate : 2 * g_rate - dq(m, c);
        ddq(i, c) = 0;
      });
}

// The increment the boundary works on in a step: 2 dg on a slaved condition's component
// (dPsi/dg = -2 sum f_L V_L; the layer point's own increment 2 dg - du_m is not what the
// boundary moves), `twice_dg` = 2 dg. Written into the step's increments `du`
// ([point][Dim + R]), which then serve the external work only (slaved layers are refused with
// bond breakage, whose bond energies use the increments too).
template <int Dim>
void slaved_increment(const BoundaryCondition& bc, const Points<Dim>& pts, const Vectors& du,
                      double twice_dg) {
  const std::uint32_t mask = bc.region_mask;
  const int c = bc.kind == BoundaryCondition::MicroRotation ? Dim + bc.component : bc.component;
  auto regions = pts.regions;
  auto fixed = pts.fixed;
  Kokkos::parallel_for(
      "mupm::BC::slaved_increment", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        if ((mask == 0 || (regions(i) & mask)) && (fixed(i) & kFixedNoEnergy))
          du(i, c) = twice_dg;
      });
}

// Blocks of the fold buffer: one block of Dim + R columns per face that has slaved layers
// (slot[2 axis + side], -1 for the others), so that every entry has exactly one writer (a body
// point is the mirror of at most one layer point per face) and the sum over ranks adds zeros
// only: bit-identical on any rank count.
using FaceSlots = Kokkos::Array<int, 6>;

// Pack of the fold: buf(m, slot * (Dim + R) + c) = -F_c(L) V_L / V_m for every prescribed
// component c of every owned slaved point L (F = force, then moment), m = mirror(L) (owned or
// ghost). `buf` ([owned + ghosts][blocks * (Dim + R)]) must be zero; the ghost rows then go to
// their owners (Distribution::add_to_owners) and add_folded adds them.
template <int Dim>
void pack_layer_forces(const Points<Dim>& pts, const View2<LocalId>& mirror, const FaceSlots& slot,
                       const Vectors& force, const Vectors& moment, const Vectors& buf) {
  constexpr int R = kRotDim<Dim>, N = Dim + R;
  auto fixed = pts.fixed;
  auto flags = pts.flags;
  auto vol = pts.volume;
  Kokkos::parallel_for(
      "mupm::BC::pack_layer_forces", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        const std::uint32_t fx = fixed(i);
        const LocalId m = mirror(i, Dim);
        if (!(fx & kFixedNoEnergy) ||
            m < 0)  // (mark_mirrored_layers marks points with a mirror only)
          return;
        int axis = 0;
        for (int d = 0; d < Dim; ++d)
          if (mirror(i, d) >= 0)
            axis = d;
        const int side = (flags(i) & layer_face_flag(axis, 1)) ? 1 : 0;
        const int block = slot[2 * axis + side];
        if (block < 0)  // a face without slaved conditions (every slaved face has a block)
          return;
        const int c0 = block * N;
        const double s = vol(i) / vol(m);
        for (int c = 0; c < N; ++c)
          if (fx & (1u << c))
            buf(m, c0 + c) = -(c < Dim ? force(i, c) : moment(i, c - Dim)) * s;
      });
}

// force, moment of the owned points += the folded blocks of `buf` (in block order).
template <int Dim>
void add_folded(const Points<Dim>& pts, const Vectors& buf, const Vectors& force,
                const Vectors& moment) {
  constexpr int R = kRotDim<Dim>, N = Dim + R;
  const int blocks = int(buf.extent(1)) / N;
  Kokkos::parallel_for(
      "mupm::BC::add_folded", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        for (int b = 0; b < blocks; ++b) {
          for (int k = 0; k < Dim; ++k)
            force(i, k) += buf(i, b * N + k);
          for (int r = 0; r < R; ++r)
            moment(i, r) += buf(i, b * N + Dim + r);
        }
      });
}

// The stress of a unit traction in direction c on the face 2 axis + side (kernels/solid.hpp,
// uniform_stress_pass1): the symmetric sigma with sigma n = e_c, n = +-e_axis the outward normal,
// and no other component (sigma_ca = sigma_ac = n_axis). Only sigma n enters the force on a flat
// face (f_i = sigma g_i with g_i along n); the complementary sigma_ac enters the moment there.
inline Kokkos::Array<double, 9> unit_traction_stress(int dim, int face, int c) {
  Kokkos::Array<double, 9> s{};
  const int a = face / 2;
  const double n = face % 2 ? 1.0 : -1.0;
  s[c * dim + a] = s[a * dim + c] = n;
  return s;
}

// Traction Distribution = Consistent (the boundary-layer issue, item 5): the load of a unit
// traction in direction c on a face, as the body-force and couple densities that balance the
// forces the discrete operator makes of the uniform stress that traction carries
// (`force`, `moment`: uniform_stress_forces of unit_traction_stress, folded like the run's forces
// where layers are slaved). On the points of the strip along the face within `depth` of it
// (inside, and the boundary layer beyond it) whose other coordinates lie in [lo, hi]:
//   b_i = -f_i[sigma] . e_c e_c,   c_i = -l_i[sigma];
// zero elsewhere. A uniform stress field that carries the traction is then in equilibrium to
// round-off up to the loaded face (a patch test), where a traction / dx on the outer row leaves
// it out of balance within 2 delta of the face (the face then acts ~0.2 dx off in a bar under
// tension, and a traction-loaded Cosserat layer with a slaved top layer 0.55 dx: README
// "Boundary layers"). Sum_i b_i V_i is the traction times the face's area to round-off on a
// flat face (the discrete divergence theorem: f = 0 in the interior and sum_i f_i V_i = 0).
// Only the component c of f is kept: at the face's edges, where the strip meets a free face, the
// uniform shear stress would also need the complementary traction on that free face.
template <int Dim>
void consistent_traction_load(const Points<Dim>& pts, int face, int c, double depth,
                              const Kokkos::Array<double, 3>& lo,
                              const Kokkos::Array<double, 3>& hi, double plane,
                              const Vectors& force, const Vectors& moment, const Vectors& out) {
  constexpr int R = kRotDim<Dim>;
  const int axis = face / 2;
  const double n = face % 2 ? 1.0 : -1.0;
  auto x = pts.x;
  Kokkos::parallel_for(
      "mupm::BC::consistent_traction", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
        bool in = n * (plane - x(i, axis)) < depth;  // inside within depth, or beyond the face
        for (int d = 0; d < Dim; ++d)
          if (d != axis && (x(i, d) < lo[d] || x(i, d) > hi[d]))
            in = false;
        for (int k = 0; k < Dim; ++k)
          out(i, k) = in && k == c ? -force(i, k) : 0.0;
        for (int r = 0; r < R; ++r)
          out(i, Dim + r) = in ? -moment(i, r) : 0.0;
      });
}

// Body-force density [N/m^3] at time t: body forces on their regions, and tractions [Pa] spread
// over the points of their region as traction / dx (the region should be the outermost real
// row of points of the loaded face, one spacing thick), or, with Traction Distribution =
// Consistent, as value g(t) times their unit_load (force and couple densities).
// Body couples [N m/m^3] go to `couple` (component = rotation component).
template <int Dim>
void body_force_density(const std::vector<BoundaryCondition>& bcs, const Points<Dim>& pts,
                        double dx, double t, const Vectors& body, const Vectors& couple) {
  Kokkos::deep_copy(body, 0.0);
  Kokkos::deep_copy(couple, 0.0);
  for (const auto& bc : bcs) {
    if (bc.kinematic() || bc.fluid())
      continue;
    if (bc.consistent) {  // its load built by the solid solver (build_consistent_tractions)
      constexpr int R = kRotDim<Dim>;
      if (bc.unit_load.extent(0) != pts.n_owned)
        throw std::logic_error("body_force_density: consistent traction '" + bc.name +
                               "' without its load");
      const double s = bc.value * bc.time(t);
      auto load = bc.unit_load;
      Kokkos::parallel_for(
          "mupm::BC::consistent_traction_add", range(0, pts.n_owned),
          KOKKOS_LAMBDA(const std::size_t i) {
            for (int k = 0; k < Dim; ++k)
              body(i, k) += s * load(i, k);
            for (int r = 0; r < R; ++r)
              couple(i, r) += s * load(i, Dim + r);
          });
      continue;
    }
    const Vectors target = bc.kind == BoundaryCondition::BodyCouple ? couple : body;
    const std::uint32_t mask = bc.region_mask;
    const int c = bc.component;
    const double b = bc.value * bc.time(t) / (bc.kind == BoundaryCondition::Traction ? dx : 1.0);
    auto regions = pts.regions;
    Kokkos::parallel_for(
        "mupm::BC::body_force", range(0, pts.n_owned), KOKKOS_LAMBDA(const std::size_t i) {
          if (mask == 0 || (regions(i) & mask))
            target(i, c) += b;
        });
  }
}

}  // namespace mupm

#endif
