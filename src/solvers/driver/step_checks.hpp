// The checks after each step: the energy balances and the primary fields' NaN/Inf.
// A part of the driver (src/solvers/simulation.cpp), which alone includes it.
#ifndef MUPM_DRIVER_STEP_CHECKS_HPP
#define MUPM_DRIVER_STEP_CHECKS_HPP

#include <mpi.h>

#include <cmath>
#include <map>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "assembly.hpp"
#include "mupm/core/error.hpp"
#include "mupm/data/points.hpp"
#include "mupm/input/model.hpp"
#include "mupm/io/point_rows.hpp"
#include "run_environment.hpp"

namespace mupm::driver {

// The largest global id of an owned point whose registry fields marked kFinite (the primary
// state: u, v, a, theta and its rates, p, p_f; every other field derives from them) hold a NaN
// or Inf, or -1. One pass.
template <int Dim>
GlobalId non_finite_point(const Points<Dim>& p) {
  constexpr int kMax = 16;
  Kokkos::Array<Vectors, kMax> f;
  int nf = 0;
  for (const auto& v : p.double_fields(kFinite))
    if (nf < kMax)
      f[nf++] = v;
  auto gid = p.gid;
  GlobalId g = -1;
  Kokkos::parallel_reduce(
      "mupm::Diagnostics::finite", range(0, p.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, GlobalId& m) {
        bool ok = true;
        for (int k = 0; k < nf; ++k)
          for (std::size_t c = 0; c < f[k].extent(1); ++c)
            ok = ok && std::isfinite(f[k](i, c));
        if (!ok && gid(i) > m)
          m = gid(i);
      },
      Kokkos::Max<GlobalId>(g));
  return g;
}

// After each step: the energy balances (eqs 140 and 149) against the tolerance, and the
// primary fields for NaN/Inf. Throws CollectiveError to stop the run.
template <int Dim>
class StepChecks {
 public:
  StepChecks(const RunSettings& run, const Discretization<Dim>& disc, MPI_Comm mpi, int rank,
             std::ostream& out)
      : run_(run), disc_(disc), mpi_(mpi), rank_(rank), out_(out) {}

  void operator()(const std::vector<Module*>& modules, long long steps_done, long long step,
                  double time) {
    if (run_.check_finite)
      finite(step, time);
    std::vector<EnergyBalance> all;
    for (Module* m : modules)
      for (auto& b : m->energy_balances())
        all.push_back(std::move(b));
    for (const auto& b : all)
      diverged(b, steps_done, step, time);
    coupled(all, steps_done, step, time);
    for (const auto& b : all)
      energy(b, steps_done, step, time);
  }

  // At the end of the run: the state is finite whatever Diagnostics->Check Finite says (a run
  // never ends with exit 0 on NaN), and how many energy warnings there were.
  void finish(long long step, double time) {
    finite(step, time);
    for (const auto& [what, n] : warnings_)
      if (rank_ == 0 && n > kShownWarnings)
        out_ << "mupm: " << n << " " << what << " energy-balance warnings in all ("
             << kShownWarnings << " shown in full, then every 1000th)\n";
  }

 private:
  static constexpr long long kShownWarnings = 5;
  // A stored energy this many times what the start and the loads supplied is a blow-up.
  static constexpr double kDivergence = 1e3;

  // Energy grown far beyond what was supplied: the scheme is unstable; stop now rather than at
  // the NaN many steps later (or never, in a short run).
  // Not after the first step: loads that start at 0 have then done no booked work (the
  // trapezoid books it on the step's displacement increment, zero on the first step), while the
  // step-end kinetic energy already holds their half kick. Any other supply, however small (a
  // drained layer at 1 Pa), then made a ramped run "diverge" at step 1 (inputs/consolidation.xml).
  void diverged(const EnergyBalance& b, long long steps_done, long long step, double time) {
    if (steps_done < 2 || !(b.supplied > 0 && b.stored > kDivergence * b.supplied))
      return;
    std::ostringstream why;
    why << "more than " << kDivergence << " times the energy supplied, " << b.supplied_expression
        << " = " << b.supplied << " J";
    stop(b, why.str(), step, time);
  }

  // All balances as one. A balance's own `supplied` holds the work it exchanges with the other
  // modules, which grows with a blow-up of the coupling itself: Example 1 with Crack Water
  // Force = Eq 17 blew up at 1.245, 0.3 and 0.1 us alike (inputs/README.md) while each
  // balance's stored energy stayed below its own supply. Energy conservation of the coupled
  // system bounds the summed stored energy by the summed external supply S (EnergyBalance::
  // external: the exchanges cancel); a blow-up is a summed store beyond kDivergence S or, where
  // S is small or negative (it fell to -3e3 J in that run while the stores reached 7e4 J),
  // beyond kGross times the external terms' magnitudes G, which a consistent scheme keeps
  // below G (the pores-crack exchange is in G on both sides, so G grows with such a blow-up
  // too: the stores reached 20-140 G in that run).
  static constexpr double kGross = 10;
  void coupled(const std::vector<EnergyBalance>& all, long long steps_done, long long step,
               double time) {
    if (steps_done < 2 || all.empty())
      return;
    EnergyBalance c;
    c.what = all.size() == 1 ? all[0].what : "coupled system";
    double largest = -1, gross = 0;
    for (const auto& b : all) {
      const std::string plus = c.stored_expression.empty() ? "" : " + ";
      c.stored_expression += plus + "(" + b.stored_expression + ")";
      c.supplied_expression += plus + "(" + b.external_expression + ")";
      c.stored += b.stored;
      c.supplied += b.external;
      gross += b.gross;
      if (!b.hint.empty())
        c.hint = b.hint;
      if (b.stored > largest) {  // locate the blow-up in the field of the largest store
        largest = b.stored;
        c.field = b.field;
      }
    }
    if (!(c.stored > kDivergence * c.supplied && c.stored > kGross * gross))
      return;
    std::ostringstream why;
    why << "more than " << kDivergence << " times the energy supplied from outside, "
        << c.supplied_expression << " = " << c.supplied << " J, and more than " << kGross
        << " times the sum of those terms' magnitudes, " << gross << " J";
    stop(c, why.str(), step, time);
  }

  void stop(const EnergyBalance& b, const std::string& why, long long step, double time) {
    const auto at = largest(b.field);
    std::ostringstream s;
    s << "Error, the " << b.what << " diverged at step " << step << " (t = " << time
      << " s): its stored energy " << b.stored_expression << " = " << b.stored << " J is " << why
      << ". The largest |" << b.field << "|, " << at.value << ", is at the point with global id "
      << at.gid << ", reference position (" << at.x[0] << ", " << at.x[1]
      << (Dim == 3 ? ", " + std::to_string(at.x[2]) : std::string())
      << ") m. The time step is likely beyond the stable one: use Solver->Automatic Time Step "
         "or a smaller Solver->Time Step (and for the fluid Solver->Fluid Substeps = 0).";
    if (!b.hint.empty())
      s << " " << b.hint;
    throw CollectiveError(s.str());
  }

  void energy(const EnergyBalance& b, long long steps_done, long long step, double time) {
    if (steps_done <= run_.energy_check_start ||
        !(b.error > run_.energy_tolerance * b.scale && b.scale > 0))
      return;
    std::ostringstream s;
    s << b.what << " energy balance violated at step " << step << " (t = " << time << " s): |"
      << b.expression << "| = " << b.error << " J is " << b.error / b.scale
      << " of the largest term (Solver->Energy Tolerance = " << run_.energy_tolerance << ")";
    if (run_.stop_on_energy_violation)
      throw CollectiveError("Error, " + s.str() + ".");
    long long& warnings = warnings_[b.what];
    if (rank_ == 0 && (warnings < kShownWarnings || warnings % 1000 == 0))
      out_ << "mupm: WARNING: " << s.str() << "\n";
    if (rank_ == 0 && warnings + 1 == kShownWarnings)
      out_ << "mupm: further " << b.what
           << " energy-balance warnings are suppressed (every 1000th is shown; the count is "
              "given at the end)\n";
    ++warnings;
  }

  // The point whose registry field `name` has the largest magnitude: value, global id, position.
  struct Location {
    double value = 0;
    GlobalId gid = -1;
    double x[3] = {0, 0, 0};
  };
  Location largest(const std::string& name) const {
    const auto& pts = disc_.points;
    std::vector<double> rows;
    int nc = 1;
    bool found = false;
    pts.for_each_field([&](const auto& view, const FieldSpec& s) {
      using V = std::decay_t<decltype(view)>;
      if constexpr (std::is_same_v<typename V::value_type, double>)
        if (name == s.name) {
          rows = io::owned_rows(view, pts.n_owned);
          nc = s.ncomp;
          found = true;
        }
    });
    if (!found)  // not a double field, or its group not allocated
      throw std::logic_error("StepChecks: no allocated point field " + name);
    struct {
      double v;
      int rank;
    } best{-1.0, rank_}, all{};
    std::size_t at = 0;
    for (std::size_t i = 0; i < pts.n_owned; ++i) {
      double m = 0;
      for (int c = 0; c < nc; ++c)
        m +=
            rows[i * std::size_t(nc) + std::size_t(c)] * rows[i * std::size_t(nc) + std::size_t(c)];
      if (m > best.v) {
        best.v = m;
        at = i;
      }
    }
    MPI_Allreduce(&best, &all, 1, MPI_DOUBLE_INT, MPI_MAXLOC, mpi_);
    // The owner supplies the point; the sum over ranks hands it to everyone.
    double buf[5] = {0, 0, 0, 0, 0};
    if (all.rank == rank_ && pts.n_owned > 0) {
      auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.gid);
      auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.x);
      buf[0] = std::sqrt(best.v);
      buf[1] = double(gid(at));
      for (int k = 0; k < Dim; ++k)
        buf[2 + k] = x(at, k);
    }
    MPI_Allreduce(MPI_IN_PLACE, buf, 5, MPI_DOUBLE, MPI_SUM, mpi_);
    Location l;
    l.value = buf[0];
    l.gid = GlobalId(buf[1]);
    for (int k = 0; k < 3; ++k)
      l.x[k] = buf[2 + k];
    return l;
  }

  void finite(long long step, double time) {
    const auto& pts = disc_.points;
    GlobalId bad = non_finite_point(pts);
    MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPI_LONG_LONG, MPI_MAX, mpi_);
    if (bad < 0)
      return;
    // The owner supplies the position; the sum over ranks hands it to everyone.
    double where[3] = {0, 0, 0};
    auto gid = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.gid);
    auto x = Kokkos::create_mirror_view_and_copy(HostSpace(), pts.x);
    for (std::size_t i = 0; i < pts.n_owned; ++i)
      if (gid(i) == bad)
        for (int k = 0; k < Dim; ++k)
          where[k] = x(i, k);
    MPI_Allreduce(MPI_IN_PLACE, where, 3, MPI_DOUBLE, MPI_SUM, mpi_);
    std::ostringstream s;
    s << "Error, a field is NaN or Inf at step " << step << " (t = " << time
      << " s), at the point with global id " << bad << ", reference position (" << where[0] << ", "
      << where[1] << (Dim == 3 ? ", " + std::to_string(where[2]) : std::string()) << ") m.";
    throw CollectiveError(s.str());
  }

  const RunSettings& run_;
  const Discretization<Dim>& disc_;
  MPI_Comm mpi_;
  int rank_;
  std::ostream& out_;
  std::map<std::string, long long> warnings_;
};

// The largest displacement magnitude over all points.
template <int Dim>
double max_displacement(const Points<Dim>& pts, MPI_Comm mpi) {
  auto u = pts.u;
  double umax2 = 0;
  Kokkos::parallel_reduce(
      "mupm::Diagnostics::max_displacement", range(0, pts.n_owned),
      KOKKOS_LAMBDA(const std::size_t i, double& m) {
        double s = 0;
        for (int k = 0; k < Dim; ++k)
          s += u(i, k) * u(i, k);
        m = s > m ? s : m;
      },
      Kokkos::Max<double>(umax2));
  MPI_Allreduce(MPI_IN_PLACE, &umax2, 1, MPI_DOUBLE, MPI_MAX, mpi);
  return std::sqrt(umax2);
}

}  // namespace mupm::driver

#endif
