// View, space and index aliases shared by every layer (ExaMiniMD `types.h` style).
#ifndef MUPM_TYPES_HPP
#define MUPM_TYPES_HPP

#include <Kokkos_Core.hpp>
#include <cstdint>
#include <string>

namespace mupm {

using ExecSpace = Kokkos::DefaultExecutionSpace;
using MemSpace = ExecSpace::memory_space;
using HostSpace = Kokkos::HostSpace;
using DeviceType = Kokkos::Device<ExecSpace, MemSpace>;

using LocalId = int;             // index of a point on one rank (owned first, then ghosts)
using GlobalId = long long;      // rank-independent point id (Tpetra global ordinal)
using BondIndex = std::int64_t;  // CSR offset: may exceed 2^31 on a large rank

template <class T>
using View1 = Kokkos::View<T*, Kokkos::LayoutRight, MemSpace>;
template <class T>
using View2 = Kokkos::View<T**, Kokkos::LayoutRight, MemSpace>;

using Scalars = View1<double>;
using Vectors = View2<double>;  // [n][ncomp], ncomp = Dim, RotDim or Dim*Dim
using Flags = View1<std::uint32_t>;
using Bytes = View1<std::uint8_t>;
using GlobalIds = View1<GlobalId>;

template <class T>
using ConstRandomView1 = Kokkos::View<const T*, Kokkos::LayoutRight, MemSpace,
                                      Kokkos::MemoryTraits<Kokkos::RandomAccess>>;
template <class T>
using ConstRandomView2 = Kokkos::View<const T**, Kokkos::LayoutRight, MemSpace,
                                      Kokkos::MemoryTraits<Kokkos::RandomAccess>>;

// A rank-1 View seen as a [n][1] rank-2 View over the same memory (LayoutRight), so scalar and
// vector fields travel through one code path.
inline Vectors as_vectors(const Scalars& s) {
  return Vectors(s.data(), s.extent(0), 1);
}

inline constexpr double kPi = 3.14159265358979323846;
// Standard gravity [m/s^2]: converts a hydraulic conductivity to k/mu_w = K_h / (rho_w g_0).
inline constexpr double kStandardGravity = 9.80665;

// Micro-rotation components: 1 in 2D (theta about z), 3 in 3D.
template <int Dim>
inline constexpr int kRotDim = Dim == 2 ? 1 : 3;

// A Kokkos profiling region for the lifetime of the object (Kokkos 3.4 has no ScopedRegion).
class ScopedRegion {
 public:
  explicit ScopedRegion(const std::string& name) { Kokkos::Profiling::pushRegion(name); }
  ~ScopedRegion() { Kokkos::Profiling::popRegion(); }
  ScopedRegion(const ScopedRegion&) = delete;
  ScopedRegion& operator=(const ScopedRegion&) = delete;
};

inline Kokkos::RangePolicy<ExecSpace> range(std::size_t begin, std::size_t end) {
  return Kokkos::RangePolicy<ExecSpace>(begin, end);
}

}  // namespace mupm

#endif
