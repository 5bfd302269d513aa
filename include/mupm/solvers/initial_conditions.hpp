// Initial conditions (Initial Conditions->NAME): a registry field set to a value on a region, or
// the hydrostatic pore pressure.
#ifndef MUPM_INITIAL_CONDITIONS_HPP
#define MUPM_INITIAL_CONDITIONS_HPP

#include <vector>

#include "mupm/data/points.hpp"
#include "mupm/input/input.hpp"

namespace mupm {

// Applies the initial conditions to owned and ghost points alike (they are pointwise), in order.
// A field condition sets the registry field whose initial_condition name is ic.field.
// "Hydrostatic Pore Pressure" sets p = rho_w g . (x - x_0), x_0 (the Value) a point of the
// water table, from rho_w_g = rho_w g.
template <int Dim>
void apply_initial_conditions(const std::vector<InitialCondition>& ics, Points<Dim>& p,
                              Kokkos::Array<double, 3> rho_w_g = {}) {
  for (const auto& ic : ics) {
    const std::uint32_t mask = ic.region_mask;
    auto regions = p.regions;
    if (ic.field == kHydrostaticPorePressure) {
      Kokkos::Array<double, 3> x0{};
      for (std::size_t c = 0; c < ic.value.size() && c < 3; ++c)
        x0[c] = ic.value[c];
      auto x = p.x;
      auto pw = p.p;
      Kokkos::parallel_for(
          "mupm::Setup::hydrostatic", range(0, p.size()), KOKKOS_LAMBDA(const std::size_t i) {
            if (mask != 0 && (regions(i) & mask) == 0)
              return;
            double s = 0;
            for (int d = 0; d < Dim; ++d)
              s += rho_w_g[d] * (x(i, d) - x0[d]);
            pw(i) = s;
          });
      continue;
    }
    Kokkos::Array<double, 3> value{};
    for (std::size_t c = 0; c < ic.value.size() && c < 3; ++c)
      value[c] = ic.value[c];
    p.for_each_field([&](auto& view, const FieldSpec& s) {
      using V = std::decay_t<decltype(view)>;
      if constexpr (std::is_same_v<typename V::value_type, double>) {
        if (!s.initial_condition || ic.field != s.initial_condition)
          return;
        auto target = view;
        const int nc = s.ncomp;
        Kokkos::parallel_for(
            "mupm::Setup::initial_condition", range(0, p.size()),
            KOKKOS_LAMBDA(const std::size_t i) {
              if (mask != 0 && (regions(i) & mask) == 0)
                return;
              for (int c = 0; c < nc; ++c) {
                if constexpr (V::rank == 1)
                  target(i) = value[c];
                else
                  target(i, c) = value[c];
              }
            });
      }
    });
  }
  Kokkos::fence();
}

}  // namespace mupm

#endif
