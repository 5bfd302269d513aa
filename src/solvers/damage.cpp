#include "mupm/solvers/damage.hpp"

namespace mupm {

template <int Dim>
void Damage<Dim>::series(SeriesRow& row) const {
  const auto& p = disc_.points;
  auto damage = p.damage;
  auto volume = p.volume;
  double sums[2] = {0, 0};
  Kokkos::parallel_reduce(
      "mupm::Diagnostics::damage", range(0, p.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, double& d, double& v) {
        d += damage(i) * volume(i);
        v += volume(i);
      },
      sums[0], sums[1]);
  long long broken = 0;
  auto intact = disc_.bonds.intact;
  Kokkos::parallel_reduce(
      "mupm::Diagnostics::broken_bonds", range(0, disc_.bonds.size()),
      KOKKOS_LAMBDA(const std::size_t b, long long& c) { c += intact(b) ? 0 : 1; }, broken);
  MPI_Allreduce(MPI_IN_PLACE, sums, 2, MPI_DOUBLE, MPI_SUM, comm_);
  MPI_Allreduce(MPI_IN_PLACE, &broken, 1, MPI_LONG_LONG, MPI_SUM, comm_);
  row("mean_damage", sums[1] > 0 ? sums[0] / sums[1] : 0.0);
  row("broken_bonds", double(broken) / 2);
  if (disc_.grid.cracks.empty())
    return;
  const Tip tip = crack_tip();
  row("crack_length", tip.length);
  const char* names[3] = {"crack_tip_x", "crack_tip_y", "crack_tip_z"};
  for (int d = 0; d < Dim; ++d)
    row(names[d], tip.x[d]);
}

template <int Dim>
auto Damage<Dim>::crack_tip() const -> Tip {
  const Crack& c = disc_.grid.cracks.front();
  double S[3] = {0, 0, 0}, T[3] = {0, 0, 0}, d[3] = {0, 0, 0}, len = 0;
  for (int k = 0; k < Dim; ++k) {
    S[k] = c.a[k];
    T[k] = Dim == 2 ? c.b[k] : c.a[k] + c.b[k];
    d[k] = T[k] - S[k];
    len += d[k] * d[k];
  }
  len = std::sqrt(len);
  for (int k = 0; k < Dim; ++k)
    d[k] /= len;
  const Reach r = farthest(T, d);
  // The pre-crack's part inside the real body: its length along d, and the middle of its tip
  // edge there (a 3D rectangle overhanging the body measured as the same cut clipped to it).
  const CrackPart part = crack_inside<Dim>(c, disc_.grid.body());
  Tip tip;
  tip.length = inside_length(c) + std::max(r.s, 0.0);
  for (int k = 0; k < Dim; ++k)
    tip.x[k] = r.s > 0 ? r.x[k]
               : part.s1 >= part.s0
                   ? S[k] + part.s1 * (T[k] - S[k]) + (Dim == 3 ? part.t * c.c[k] : 0.0)
                   : T[k];
  return tip;
}

template <int Dim>
auto Damage<Dim>::farthest(const double* T, const double* d) const -> Reach {
  Ahead ahead;
  ahead.x = disc_.points.x;
  ahead.frac = disc_.points.fracture;
  ahead.flags = disc_.points.flags;
  for (int k = 0; k < Dim; ++k) {
    ahead.T[k] = T[k];
    ahead.d[k] = d[k];
  }
  const std::size_t n = disc_.points.n_owned;
  auto gid = disc_.points.gid;
  auto x = disc_.points.x;
  // Largest s, then the lowest global id among the points that have it, then its position.
  Reach r;
  Kokkos::parallel_reduce(
      "mupm::Diagnostics::crack_extent", range(0, n),
      KOKKOS_LAMBDA(const std::size_t i, double& m) {
        double s;
        if (ahead(i, s))
          m = s > m ? s : m;
      },
      Kokkos::Max<double>(r.s));
  MPI_Allreduce(MPI_IN_PLACE, &r.s, 1, MPI_DOUBLE, MPI_MAX, comm_);
  if (!(r.s > 0))
    return r;
  const double best = r.s;
  long long mine = std::numeric_limits<long long>::max(), who = -1;
  Kokkos::parallel_reduce(
      "mupm::Diagnostics::crack_tip", range(0, n),
      KOKKOS_LAMBDA(const std::size_t i, long long& m) {
        double s;
        if (ahead(i, s) && s == best && (long long)gid(i) < m)
          m = (long long)gid(i);
      },
      Kokkos::Min<long long>(mine));
  MPI_Allreduce(&mine, &who, 1, MPI_LONG_LONG, MPI_MIN, comm_);
  for (int k = 0; k < Dim; ++k) {
    double xk = 0;
    Kokkos::parallel_reduce(
        "mupm::Diagnostics::crack_tip_position", range(0, n),
        KOKKOS_LAMBDA(const std::size_t i, double& acc) {
          if ((long long)gid(i) == who)
            acc += x(i, k);
        },
        xk);
    MPI_Allreduce(&xk, &r.x[k], 1, MPI_DOUBLE, MPI_SUM, comm_);
  }
  return r;
}

template <int Dim>
double Damage<Dim>::inside_length(const Crack& c) const {
  const CrackPart part = crack_inside<Dim>(c, disc_.grid.body());
  double len2 = 0;
  for (int k = 0; k < Dim; ++k) {
    const double d = Dim == 2 ? c.b[k] - c.a[k] : c.b[k];
    len2 += d * d;
  }
  return std::max(part.s1 - part.s0, 0.0) * std::sqrt(len2);
}

template class Damage<2>;
template class Damage<3>;

}  // namespace mupm
