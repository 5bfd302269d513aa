// Point data of the whole model as a struct of Kokkos Views, owned points first, then ghosts
// (ExaMiniMD `system.h`, CabanaPD `Particles`), and the registry of those fields.
//
// The registry (Points::for_each_field) declares every per-point field once: its name, its
// component count and its traits (include/mupm/data/fields.hpp). Allocation, the bytes per
// point, the ghost exchanges, the checkpoint, the output list and its validator, the
// initial-condition names, the NaN check and the README's field list (checked by a test) all
// follow from it. A new field is one member below and one line in for_each_field. Each field
// belongs to a FieldGroup; a run allocates only the groups its modules use.
#ifndef MUPM_POINTS_HPP
#define MUPM_POINTS_HPP

#include <cstddef>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "mupm/core/types.hpp"
#include "mupm/data/fields.hpp"

namespace mupm {

// Bits of Points::flags. Region membership is kept apart in Points::regions (one bit a region).
enum PointFlag : std::uint32_t {
  kFlagBoundaryLayer = 1u << 0,  // a boundary-layer (fictitious) point outside the real body
  kFlagPreCrack = 1u << 1,       // adjacent to an initial crack
  // Face of the boundary layer the point belongs to: bit kFlagLayerFace0 << (2*axis + side).
  kFlagLayerFace0 = 1u << 2,
  // Next to an increment of the J criterion with fracture flow (bits 2-7 are the layer faces):
  // a fracture point at once, as a pre-crack's neighbour (include/mupm/solvers/j_integral.hpp).
  kFlagCut = 1u << 8,
};

// Bit of Points::fixed marking a prescribed pore pressure (bits 0..Dim+RotDim-1: u and theta).
inline constexpr std::uint32_t kFixedPressure = 1u << 31;
// Bit of Points::fixed marking a point that carries no strain energy: a boundary-layer point
// slaved to its mirror (Boundary Layer Values = Mirrored on a clamp). Pass 1 gives it zero
// states (include/mupm/kernels/solid.hpp), so the body's energy is its real points' alone.
inline constexpr std::uint32_t kFixedNoEnergy = 1u << 30;

// Called in kernels (boundary conditions, the grid's fill): a device function.
KOKKOS_INLINE_FUNCTION constexpr std::uint32_t layer_face_flag(int axis, int side) {
  return kFlagLayerFace0 << (2 * axis + side);
}

template <int Dim>
struct Points {
  static constexpr int dim = Dim;
  static constexpr int rot_dim = kRotDim<Dim>;

  std::size_t n_owned = 0;
  std::size_t n_ghost = 0;
  // FieldGroup bits of the allocated fields: the registry's other fields stay empty Views, and
  // for_each_field does not visit them.
  unsigned groups = kAllGroups;
  std::size_t size() const { return n_owned + n_ghost; }

  // Constant per point: exchanged once.
  GlobalIds gid;   // global id
  Vectors x;       // reference position [n][Dim]
  Scalars volume;  // V_i (2D: area times thickness)
  Flags flags;     // PointFlag bits
  Flags regions;   // bit r: the point lies in named region r
  Flags fixed;     // bit d: u_d prescribed; bit Dim + r: theta_r prescribed; kFixedPressure: p
  // Kinematics of the solid (central difference, eqs 127-136).
  Vectors u, v, a;              // displacement, velocity, acceleration [n][Dim]
  Vectors theta, omega, alpha;  // micro-rotation and its rates [n][RotDim]
  // Fluid (eqs 141-146) and fracture fluid (eqs 119-120).
  Scalars p, p_rate;      // pore water pressure and its rate
  Scalars pf, pf_rate;    // fracture pressure and its rate (fracture network points)
  Scalars pf_saturation;  // S_rf of the fracture space; > 0 exactly on the fracture network
  Scalars pf_content;     // water that entered the point's fracture space, per unit volume
  Scalars pf_aperture;    // mean opening c_f at the last fracture-flow step (volume change)
  Scalars pf_modulus;     // M_f [Pa/m]: p_f* = p_f - M_f (c_f - pf_aperture) (undrained split)
  Scalars pf_area;        // A_i = V_i / (n_i dx): the point's share of the crack's face area
  Scalars porosity, saturation;
  Scalars rel_perm;             // relative permeability k_r (eq 56)
  Vectors darcy_flux;           // q [m/s] (eq 54) [n][Dim]
  Scalars vol_strain;           // tr(eps) of the solid (eq 117; + pore_shift of the plastic law)
  Scalars vol_strain_ref;       // tr(eps) at the last fluid update
  Scalars fluid_content;        // water volume per unit volume, phi S_r (1 + p/K_w) at t = 0 plus
                                // the increments C dp + S_r d(tr eps) of every fluid step
  Scalars solid_pressure;       // p* of the forces the solid last applied (undrained split)
  Vectors applied_force;        // force density f of the forces the solid last applied [n][Dim]
  Vectors applied_moment;       // moment density of the forces the solid last applied [n][RotDim]
  Vectors applied_crack_force;  // the crack water's force density last applied [n][Dim]
  Scalars undrained_modulus;    // S_r / C [Pa]: dp = -(S_r/C) d(tr eps) at fixed water content;
                                // 0 where p is prescribed or without a fluid (undrained split)
  // Fracture.
  Scalars damage;                // D_i (eq 37)
  Bytes fracture;                // 1: fracture point (D >= D_cr or next to a pre-crack)
  Scalars aperture;              // crack aperture a_f [m] (eqs 38-39) of points with broken bonds
  Scalars bond_energy_released;  // energy released by the point's broken bonds [J], half of
                                 // W V_i V_j per bond (the other half is at the other end)
  // Constitutive state: effective stress, couple stress, and the plastic state of Materials->
  // Model = Micropolar Drucker-Prager (include/mupm/laws/micropolar_drucker_prager.hpp; not
  // allocated with the elastic law unless Output->Fields names one of its fields, then zero).
  Vectors stress;                     // sigma-bar [n][Dim*Dim], row-major, non-symmetric
  Vectors couple_stress;              // m [n][RotDim*Dim]
  Vectors plastic_strain;             // eps^p [n][Dim*Dim], row-major (the additive split, eq 82)
  Scalars plastic_strain_zz;          // eps^p_zz of plane strain (2D; 3D has it in eps^p)
  Vectors plastic_wryness;            // kappa^p [n][RotDim*Dim] (eq 83)
  Scalars equivalent_plastic_strain;  // eps-hat^p (eq 95)
  Scalars plastic_volumetric_strain;  // tr eps^p (3D trace), positive = dilation
  Scalars cohesion;                   // c (eq 92)
  Scalars stress_zz;                  // sigma_zz of the plastic law (plane strain)
  Vectors plastic_step_start;         // the plastic state and stress at the step's start (law)
  Scalars second_order_work;          // d2E of the last window [N/m^2] (eq 42)
  Vectors second_order_work_start;    // sigma-bar, eps, m, kappa at the window's start
  Vectors release_force;  // force and moment densities the J criterion's increments release
                          // [n][Dim + RotDim] (include/mupm/solvers/solid_solver.hpp)

  // The registry: f(view, spec) for every field, in this order (the checkpoint's and the
  // output list's). Traits: kConstant (sent to the ghosts once), kGhosted (refreshed on the
  // ghosts at a start and a restart), kCheckpoint, kOutput (selectable in Output->Fields),
  // kFinite (checked for NaN/Inf every step); the fourth argument is the name under which
  // an initial condition sets the field (Initial Conditions->NAME->Field), or nullptr; the fifth
  // its FieldGroup (W pore water, C crack water, P plastic, S second-order work, G the J
  // criterion's release; else core). Only
  // the fields of the allocated groups are visited.
  template <class F>
  void for_each_field(F&& f) {
    visit(*this, f);
  }
  template <class F>
  void for_each_field(F&& f) const {
    visit(*this, f);
  }

  Points() = default;
  Points(std::size_t owned, std::size_t ghost, unsigned field_groups = kAllGroups) {
    allocate(owned, ghost, field_groups);
  }

  void allocate(std::size_t owned, std::size_t ghost, unsigned field_groups = kAllGroups) {
    n_owned = owned;
    n_ghost = ghost;
    groups = field_groups | kGroupCore;
    const std::size_t n = owned + ghost;
    for_each_field([n](auto& view, const FieldSpec& s) { allocate_field(view, s, n); });
  }

  // Resident bytes of one point (the registry's fields of the given groups).
  static std::size_t bytes_per_point(unsigned field_groups = kAllGroups) {
    std::size_t b = 0;
    Points probe;
    probe.groups = field_groups | kGroupCore;
    probe.for_each_field([&b](const auto& view, const FieldSpec& s) {
      b += sizeof(typename std::decay_t<decltype(view)>::value_type) * std::size_t(s.ncomp);
    });
    return b;
  }

  // The double fields with every trait of t, each as [n][ncomp] (e.g. the kGhosted ones for a
  // ghost refresh).
  std::vector<Vectors> double_fields(unsigned t) const {
    std::vector<Vectors> out;
    for_each_field([&](const auto& view, const FieldSpec& s) {
      using V = std::decay_t<decltype(view)>;
      if constexpr (std::is_same_v<typename V::value_type, double>) {
        if (!s.has(t))
          return;
        if constexpr (V::rank == 1)
          out.push_back(as_vectors(view));
        else
          out.push_back(view);
      }
    });
    return out;
  }

  // Throws std::logic_error unless the fields of `group` are allocated: a module's check that
  // the run allocated what it uses (an empty View would be read out of bounds).
  void require(unsigned group, const char* module) const {
    if ((groups & group) != group)
      throw std::logic_error(std::string(module) + " needs point fields that were not allocated (" +
                             "FieldGroup " + std::to_string(group) +
                             "; point_field_groups in src/input/input.cpp)");
  }

  // The specs alone (names, components, traits, groups) of every field, e.g. for the input's
  // validators.
  static std::vector<FieldSpec> specs() {
    std::vector<FieldSpec> out;
    Points().for_each_field([&out](const auto&, const FieldSpec& s) { out.push_back(s); });
    return out;
  }

 private:
  template <class Pts, class F>
  static void visit(Pts& p, F& fn) {
    constexpr int D = Dim, R = rot_dim;
    constexpr unsigned kState = kCheckpoint | kOutput;
    constexpr unsigned W = kGroupPoreWater, C = kGroupCrackWater, P = kGroupPlastic,
                       S = kGroupSecondOrderWork, G = kGroupRelease;
    auto f = [&](auto& view, const FieldSpec& s) {
      if (s.group & p.groups)
        fn(view, s);
    };
    // clang-format off
    f(p.gid,               FieldSpec{"global_id", 1, 0});
    f(p.x,                 FieldSpec{"coordinates", D, kConstant});
    f(p.volume,            FieldSpec{"volume", 1, kConstant});
    f(p.flags,             FieldSpec{"flags", 1, kConstant | kOutput});
    f(p.regions,           FieldSpec{"regions", 1, kConstant | kOutput});
    f(p.fixed,             FieldSpec{"fixed", 1, 0});
    f(p.u,                 FieldSpec{"displacement", D, kState | kGhosted | kFinite, "Displacement"});
    f(p.v,                 FieldSpec{"velocity", D, kState | kGhosted | kFinite, "Velocity"});
    f(p.a,                 FieldSpec{"acceleration", D, kState | kFinite});
    f(p.theta,             FieldSpec{"micro_rotation", R, kState | kGhosted | kFinite, "Micro-Rotation"});
    f(p.omega,             FieldSpec{"micro_rotation_rate", R, kState | kFinite, "Micro-Rotation Rate"});
    f(p.alpha,             FieldSpec{"micro_rotation_acceleration", R, kCheckpoint | kFinite});
    f(p.p,                 FieldSpec{"pore_pressure", 1, kState | kGhosted | kFinite, "Pore Pressure"});
    f(p.p_rate,            FieldSpec{"pore_pressure_rate", 1, kCheckpoint, nullptr, W});
    f(p.pf,                FieldSpec{"fracture_pressure", 1, kState | kGhosted | kFinite,
                                     nullptr, C});
    f(p.pf_rate,           FieldSpec{"fracture_pressure_rate", 1, kCheckpoint, nullptr, C});
    f(p.pf_saturation,     FieldSpec{"fracture_saturation", 1, kState | kGhosted, nullptr, C});
    f(p.pf_content,        FieldSpec{"fracture_fluid_content", 1, kState, nullptr, C});
    f(p.pf_aperture,       FieldSpec{"fracture_storage_aperture", 1, kCheckpoint, nullptr, C});
    f(p.pf_modulus,        FieldSpec{"fracture_undrained_modulus", 1, kCheckpoint, nullptr, C});
    f(p.pf_area,           FieldSpec{"fracture_face_area", 1, kCheckpoint, nullptr, C});
    f(p.porosity,          FieldSpec{"porosity", 1, kState, "Porosity"});
    f(p.saturation,        FieldSpec{"saturation", 1, kState, "Saturation"});
    f(p.rel_perm,          FieldSpec{"relative_permeability", 1, kState, nullptr, W});
    f(p.darcy_flux,        FieldSpec{"darcy_flux", D, kState, nullptr, W});
    f(p.vol_strain,        FieldSpec{"volumetric_strain", 1, kState});
    f(p.vol_strain_ref,    FieldSpec{"volumetric_strain_reference", 1, kCheckpoint});
    f(p.fluid_content,     FieldSpec{"fluid_content", 1, kState, nullptr, W});
    f(p.solid_pressure,    FieldSpec{"solid_pressure", 1, kCheckpoint});
    f(p.applied_force,     FieldSpec{"applied_force", D, kCheckpoint});
    f(p.applied_moment,    FieldSpec{"applied_moment", R, kCheckpoint});
    f(p.applied_crack_force, FieldSpec{"applied_crack_force", D, kCheckpoint, nullptr, C});
    f(p.undrained_modulus, FieldSpec{"undrained_modulus", 1, 0});
    f(p.damage,            FieldSpec{"damage", 1, kState | kGhosted});
    f(p.fracture,          FieldSpec{"fracture", 1, kState});
    f(p.aperture,          FieldSpec{"aperture", 1, kState});
    f(p.bond_energy_released, FieldSpec{"bond_energy_released", 1, kState});
    f(p.stress,            FieldSpec{"stress", D * D, kState});
    f(p.couple_stress,     FieldSpec{"couple_stress", R * D, kState});
    f(p.plastic_strain,    FieldSpec{"plastic_strain", D * D, kState, nullptr, P});
    f(p.plastic_strain_zz, FieldSpec{"plastic_strain_zz", 1, kCheckpoint, nullptr, P});
    f(p.plastic_wryness,   FieldSpec{"plastic_wryness", R * D, kState, nullptr, P});
    f(p.equivalent_plastic_strain, FieldSpec{"equivalent_plastic_strain", 1, kState, nullptr, P});
    f(p.plastic_volumetric_strain, FieldSpec{"plastic_volumetric_strain", 1, kState, nullptr, P});
    f(p.cohesion,          FieldSpec{"cohesion", 1, kState, nullptr, P});
    f(p.stress_zz,         FieldSpec{"stress_zz", 1, kCheckpoint, nullptr, P});
    f(p.plastic_step_start, FieldSpec{"plastic_step_start", 2 * D * D + 2 * R * D + 3,
                                      kCheckpoint, nullptr, P});
    f(p.second_order_work, FieldSpec{"second_order_work", 1, kState, nullptr, S});
    f(p.second_order_work_start, FieldSpec{"second_order_work_start", 2 * (D * D + R * D),
                                           kCheckpoint, nullptr, S});
    f(p.release_force,     FieldSpec{"release_force", D + R, kCheckpoint, nullptr, G});
    // clang-format on
  }
};

}  // namespace mupm

#endif
