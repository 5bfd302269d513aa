// Small geometric predicates used inside kernels: horizon test, bond/crack crossing, distance to
// a crack. Plain functions of coordinates, callable on host and in Kokkos kernels.
#ifndef MUPM_GEOMETRY_HPP
#define MUPM_GEOMETRY_HPP

#include <Kokkos_Core.hpp>
#include <vector>

namespace mupm {

// A pre-crack: in 2D the segment a -> b (c unused); in 3D the rectangle with corner a and
// orthogonal edges b and c.
struct Crack {
  double a[3] = {0, 0, 0};
  double b[3] = {0, 0, 0};
  double c[3] = {0, 0, 0};
};

// An axis-aligned box [lo, hi] (closed).
struct Box {
  double lo[3] = {0, 0, 0};
  double hi[3] = {0, 0, 0};
};

// |xi|^2 <= delta^2, with a relative slack so that delta = 3 dx exactly keeps the points at 3 dx
// whatever the rounding of the coordinates.
KOKKOS_INLINE_FUNCTION bool within_horizon(double d2, double delta2) {
  return d2 <= delta2 * (1.0 + 1e-10);
}

template <int Dim>
KOKKOS_INLINE_FUNCTION bool in_box(const Box& b, const double* x, double tol) {
  for (int d = 0; d < Dim; ++d)
    if (x[d] < b.lo[d] - tol || x[d] > b.hi[d] + tol)
      return false;
  return true;
}

KOKKOS_INLINE_FUNCTION double orient2d(const double* a, const double* b, const double* p) {
  return (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
}

// Does the bond p -> q cross the crack? The two ends must lie strictly on opposite sides of the
// crack line (plane); the crossing point may touch the crack's edge. A point lying exactly on the
// crack is therefore on neither side: place cracks between lattice lines.
// The ends are taken in lexicographic order of their coordinates, so that p -> q and q -> p
// evaluate the same arithmetic: a bond through a crack's tip (a lattice node when the tip is on
// cell boundaries) otherwise came out broken one way and intact the other by round-off (a bond
// through the tip (-0.01, 0.05) at dx = 2.5 mm: its two copies disagreed, and the pore water of a
// hydro-mechanical run with that tip inside a boundary layer was not conserved, -1.7e-7 of it).
template <int Dim>
KOKKOS_INLINE_FUNCTION bool bond_crosses(const Crack& c, const double* p0, const double* q0) {
  bool swap = false;
  for (int d = 0; d < Dim; ++d)
    if (p0[d] != q0[d]) {
      swap = q0[d] < p0[d];
      break;
    }
  const double* p = swap ? q0 : p0;
  const double* q = swap ? p0 : q0;
  if constexpr (Dim == 2) {
    const double d1 = orient2d(c.a, c.b, p);
    const double d2 = orient2d(c.a, c.b, q);
    if (!(d1 * d2 < 0.0))
      return false;
    const double d3 = orient2d(p, q, c.a);
    const double d4 = orient2d(p, q, c.b);
    return d3 * d4 <= 0.0;
  } else {
    const double n[3] = {c.b[1] * c.c[2] - c.b[2] * c.c[1], c.b[2] * c.c[0] - c.b[0] * c.c[2],
                         c.b[0] * c.c[1] - c.b[1] * c.c[0]};
    double sp = 0, sq = 0;
    for (int d = 0; d < 3; ++d) {
      sp += n[d] * (p[d] - c.a[d]);
      sq += n[d] * (q[d] - c.a[d]);
    }
    if (!(sp * sq < 0.0))
      return false;
    const double t = sp / (sp - sq);
    double s1 = 0, s2 = 0, e1 = 0, e2 = 0;
    for (int d = 0; d < 3; ++d) {
      const double xd = p[d] + t * (q[d] - p[d]) - c.a[d];
      s1 += xd * c.b[d];
      s2 += xd * c.c[d];
      e1 += c.b[d] * c.b[d];
      e2 += c.c[d] * c.c[d];
    }
    const double tol = 1e-12;
    return s1 >= -tol * e1 && s1 <= (1 + tol) * e1 && s2 >= -tol * e2 && s2 <= (1 + tol) * e2;
  }
}

// Squared distance from x to the crack segment (2D) or rectangle (3D).
template <int Dim>
KOKKOS_INLINE_FUNCTION double distance2_to_crack(const Crack& c, const double* x) {
  if constexpr (Dim == 2) {
    const double e[2] = {c.b[0] - c.a[0], c.b[1] - c.a[1]};
    const double r[2] = {x[0] - c.a[0], x[1] - c.a[1]};
    const double ee = e[0] * e[0] + e[1] * e[1];
    double t = ee > 0 ? (r[0] * e[0] + r[1] * e[1]) / ee : 0.0;
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    const double dx = r[0] - t * e[0], dy = r[1] - t * e[1];
    return dx * dx + dy * dy;
  } else {
    double r[3], s1 = 0, s2 = 0, e1 = 0, e2 = 0;
    for (int d = 0; d < 3; ++d) {
      r[d] = x[d] - c.a[d];
      s1 += r[d] * c.b[d];
      s2 += r[d] * c.c[d];
      e1 += c.b[d] * c.b[d];
      e2 += c.c[d] * c.c[d];
    }
    double t1 = e1 > 0 ? s1 / e1 : 0, t2 = e2 > 0 ? s2 / e2 : 0;
    t1 = t1 < 0 ? 0 : (t1 > 1 ? 1 : t1);
    t2 = t2 < 0 ? 0 : (t2 > 1 ? 1 : t2);
    double d2 = 0;
    for (int d = 0; d < 3; ++d) {
      const double dd = r[d] - t1 * c.b[d] - t2 * c.c[d];
      d2 += dd * dd;
    }
    return d2;
  }
}

// The part of a pre-crack inside a box (host only). A crack point is a + s D + t c, (s, t) in
// [0, 1]^2, with D its direction (b - a in 2D, the edge b in 3D; t and c only in 3D). The part
// inside is a convex polygon in (s, t): the unit square (2D: the segment t = 0) clipped by the
// box's 2 Dim faces (Sutherland-Hodgman). Returns its extent [s0, s1] along D and the mean t of
// its vertices at s1 (the middle of its tip edge inside the box); s0 > s1 when it misses the box.
struct CrackPart {
  double s0 = 1, s1 = 0, t = 0;
};
template <int Dim>
CrackPart crack_inside(const Crack& c, const Box& box) {
  struct P {
    double s, t;
  };
  std::vector<P> poly =
      Dim == 2 ? std::vector<P>{{0, 0}, {1, 0}} : std::vector<P>{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int k = 0; k < Dim; ++k)
    for (int side = 0; side < 2; ++side) {
      const double D = Dim == 2 ? c.b[k] - c.a[k] : c.b[k], E = Dim == 2 ? 0.0 : c.c[k];
      // f >= 0 inside this face's half-space.
      auto f = [&](const P& p) {
        const double x = c.a[k] + p.s * D + p.t * E;
        return side == 0 ? x - box.lo[k] : box.hi[k] - x;
      };
      std::vector<P> out;
      for (std::size_t i = 0; i < poly.size(); ++i) {
        const P& p = poly[i];
        const P& q = poly[(i + 1) % poly.size()];
        const double fp = f(p), fq = f(q);
        if ((fp >= 0) != (fq >= 0)) {
          const double w = fp / (fp - fq);
          out.push_back({p.s + w * (q.s - p.s), p.t + w * (q.t - p.t)});
        }
        if (fq >= 0)
          out.push_back(q);
      }
      poly = out;
      if (poly.empty())
        return {};
    }
  CrackPart part{1e300, -1e300, 0};
  for (const P& p : poly) {
    part.s0 = p.s < part.s0 ? p.s : part.s0;
    part.s1 = p.s > part.s1 ? p.s : part.s1;
  }
  int n = 0;
  for (const P& p : poly)
    if (p.s >= part.s1 - 1e-12) {
      part.t += p.t;
      ++n;
    }
  part.t /= n;
  return part;
}

}  // namespace mupm

#endif
