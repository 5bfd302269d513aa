// Point data of the whole model as a struct of Kokkos Views, owned points first, then ghosts
// (ExaMiniMD `system.h`, CabanaPD `Particles`).
#ifndef MUPM_POINTS_HPP
#define MUPM_POINTS_HPP

#include <cstddef>
#include <string>

#include "mupm/types.hpp"

namespace mupm {

// Bits of Points::flags. Region membership is kept apart in Points::regions (one bit a region).
enum PointFlag : std::uint32_t {
  kFlagBoundaryLayer = 1u << 0,  // a boundary-layer (fictitious) point outside the real body
  kFlagPreCrack = 1u << 1,       // adjacent to an initial crack
  // Face of the boundary layer the point belongs to: bit kFlagLayerFace0 << (2*axis + side).
  kFlagLayerFace0 = 1u << 2,
};

// Bit of Points::fixed marking a prescribed pore pressure (bits 0..Dim+RotDim-1: u and theta).
inline constexpr std::uint32_t kFixedPressure = 1u << 31;

inline constexpr std::uint32_t layer_face_flag(int axis, int side) {
  return kFlagLayerFace0 << (2 * axis + side);
}

template <int Dim>
struct Points {
  static constexpr int dim = Dim;
  static constexpr int rot_dim = kRotDim<Dim>;

  std::size_t n_owned = 0;
  std::size_t n_ghost = 0;
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
  Scalars p, p_rate;    // pore water pressure and its rate
  Scalars pf, pf_rate;  // fracture pressure and its rate
  Scalars porosity, saturation;
  Scalars rel_perm;           // relative permeability k_r (eq 56)
  Vectors darcy_flux;         // q [m/s] (eq 54) [n][Dim]
  Scalars vol_strain;         // tr(eps) of the solid (eq 117)
  Scalars vol_strain_ref;     // tr(eps) at the last fluid update
  Scalars solid_pressure;     // p* of the forces the solid last applied (undrained split)
  Scalars undrained_modulus;  // S_r / C [Pa]: dp = -(S_r/C) d(tr eps) at fixed water content;
                              // 0 where p is prescribed or without a fluid (undrained split)
  Scalars fluid_content;      // water volume per unit volume, phi S_r (1 + p/K_w) at t = 0 plus
                              // the increments C dp + S_r d(tr eps) of every fluid step
  // Fracture.
  Scalars damage;  // D_i (eq 37)
  Bytes fracture;  // 1: fracture point (D >= D_cr or next to a pre-crack)
  // Constitutive state: effective stress, couple stress, equivalent plastic strain.
  Vectors stress;          // sigma-bar [n][Dim*Dim], row-major, non-symmetric
  Vectors couple_stress;   // m [n][RotDim*Dim]
  Scalars plastic_strain;  // equivalent plastic strain (eq 95)

  Points() = default;
  Points(std::size_t owned, std::size_t ghost) { allocate(owned, ghost); }

  void allocate(std::size_t owned, std::size_t ghost) {
    n_owned = owned;
    n_ghost = ghost;
    const std::size_t n = owned + ghost;
    gid = GlobalIds("mupm::gid", n);
    x = Vectors("mupm::x", n, Dim);
    volume = Scalars("mupm::volume", n);
    flags = Flags("mupm::flags", n);
    regions = Flags("mupm::regions", n);
    fixed = Flags("mupm::fixed", n);
    u = Vectors("mupm::u", n, Dim);
    v = Vectors("mupm::v", n, Dim);
    a = Vectors("mupm::a", n, Dim);
    theta = Vectors("mupm::theta", n, rot_dim);
    omega = Vectors("mupm::omega", n, rot_dim);
    alpha = Vectors("mupm::alpha", n, rot_dim);
    p = Scalars("mupm::p", n);
    p_rate = Scalars("mupm::p_rate", n);
    pf = Scalars("mupm::pf", n);
    pf_rate = Scalars("mupm::pf_rate", n);
    porosity = Scalars("mupm::porosity", n);
    saturation = Scalars("mupm::saturation", n);
    rel_perm = Scalars("mupm::relative_permeability", n);
    darcy_flux = Vectors("mupm::darcy_flux", n, Dim);
    vol_strain = Scalars("mupm::volumetric_strain", n);
    vol_strain_ref = Scalars("mupm::volumetric_strain_ref", n);
    fluid_content = Scalars("mupm::fluid_content", n);
    undrained_modulus = Scalars("mupm::undrained_modulus", n);
    solid_pressure = Scalars("mupm::solid_pressure", n);
    damage = Scalars("mupm::damage", n);
    fracture = Bytes("mupm::fracture", n);
    stress = Vectors("mupm::stress", n, Dim * Dim);
    couple_stress = Vectors("mupm::couple_stress", n, rot_dim * Dim);
    plastic_strain = Scalars("mupm::plastic_strain", n);
  }

  // Resident bytes of one point (all fields above).
  static constexpr std::size_t bytes_per_point() {
    return sizeof(GlobalId) + sizeof(double) * (Dim + 1) + 3 * sizeof(std::uint32_t) +
           sizeof(double) * (3 * Dim + 3 * rot_dim + 4 + 2 + 1) + 1 + sizeof(double) * (Dim + 6) +
           sizeof(double) * (Dim * Dim + rot_dim * Dim + 1);
  }
};

}  // namespace mupm

#endif
