// The solid's energy ledger (eqs 137-140): the energies of the current state and the terms
// accumulated since t = 0. Each accumulated term is declared once, in kSolidLedger: its
// time-series column and restart global, its symbol and side in the balance; the columns, the
// globals, the balance and its check follow from that table.
#ifndef MUPM_SOLID_LEDGER_HPP
#define MUPM_SOLID_LEDGER_HPP

#include <string>

#include "mupm/solvers/module.hpp"

namespace mupm {

// The solid's energies at one time [J].
struct SolidEnergy {
  // Of the current state (SolidSolver::energy), summed over ranks.
  double internal = 0, kinetic = 0;
  // The central difference's kinetic energy is 1/2 m v^{n-1/2}.v^{n+1/2} = E_kin - dt^2/8
  // m|a^n|^2 (v^{n+-1/2} = v^n +- dt/2 a^n): with it, the strain energy of a linear operator
  // and the trapezoid's work, the balance closes exactly, whatever the loads do. Summed over
  // steps, m(v^{n+3/2} - v^{n-1/2}) = dt (f^n + f^{n+1}) - dt K (u^n + u^{n+1}) times
  // (u^{n+1} - u^n) / (2 dt) = v^{n+1/2} / 2 gives
  //   [1/2 m v^{n+1/2}.v^{n+3/2} + E(u^{n+1})] - [1/2 m v^{n-1/2}.v^{n+1/2} + E(u^n)]
  //     = 1/2 (f^n + f^{n+1}).(u^{n+1} - u^n).
  // With 1/2 m|v^n|^2 instead, the balance carries dt^2/8 m|a^n|^2, which a load that starts
  // at once puts into the fastest modes: 1-2 % of the largest term at steps 21-30 of Example 1
  // case 1 (its crack water's undrained spring sets the step). The shift is positive-definite
  // with E_int only below the stable step (omega dt < 2), so a blow-up still shows.
  double kinetic_shift = 0;  // -dt^2/8 sum V (rho |a|^2 + J |alpha|^2) over free components
  // Accumulated since t = 0 (kSolidLedger).
  double external_work = 0;  // work of the boundary and body forces (trapezoid rule)
  double dissipation = 0;    // damping
  // Work of the pore water on the skeleton: sum over steps of sum_i V_i S_r p* d(tr eps_i)
  // (the -S_r p* 1 part of the total stress, eq 46; p* linear in tr eps within a step, so the
  // trapezoid rule is exact), with eq 17's crack-water forces and the semi-implicit pressure
  // correction's work.
  double pore_work = 0;
  double projection_work = 0;  // the pressure correction's part of pore_work (Semi-Implicit)
  // The part of external_work done by the crack water's face forces (Fracture Flow with the
  // face pressure): the solid's side of the crack water's work on the skeleton, which the
  // fracture network books as Sigma V p_f S_rf dphi_f (solvers/fracture_flow.hpp).
  double crack_work = 0;
  double fracture = 0;     // strain energy lost when bonds broke (fracture dissipation)
  double bond_energy = 0;  // sum of W V_i V_j of the broken bonds (the criterion's energy)
  double plastic = 0;      // plastic dissipation (Materials->Model = Micropolar Drucker-Prager)

  // E_int + E_kin + D - W_ext - W_pore, which the scheme keeps constant (eq 140).
  double balance() const;
  // The largest of the balance's terms.
  double scale() const;
};

// When an accumulated term exists (is a column, a restart global, in the balance's formula).
enum class LedgerPart { Always, SemiImplicit, CrackForce, Breakage, Plastic };

struct LedgerTerm {
  const char* name;  // time-series column and restart global
  double SolidEnergy::*value;
  const char* symbol;  // in the balance's formula
  int side;            // eq 140: +1 held or dissipated, -1 supplied, 0 part of another
  LedgerPart part;
};

// In the order of the time-series columns.
inline constexpr LedgerTerm kSolidLedger[] = {
    {"external_work", &SolidEnergy::external_work, "W_ext", -1, LedgerPart::Always},
    {"dissipation", &SolidEnergy::dissipation, "D", +1, LedgerPart::Always},
    {"pore_pressure_work", &SolidEnergy::pore_work, "W_pore", -1, LedgerPart::Always},
    {"projection_work", &SolidEnergy::projection_work, "", 0, LedgerPart::SemiImplicit},
    {"crack_force_work", &SolidEnergy::crack_work, "", 0, LedgerPart::CrackForce},
    {"fracture_energy", &SolidEnergy::fracture, "D_frac", +1, LedgerPart::Breakage},
    {"bond_energy_released", &SolidEnergy::bond_energy, "", 0, LedgerPart::Breakage},
    {"plastic_dissipation", &SolidEnergy::plastic, "D_plast", +1, LedgerPart::Plastic},
};

// One rank's terms of a step before its one reduction (SolidSolver: from finish_forces to
// complete).
struct StepTerms {
  double external_work = 0;  // [J] (the trapezoid rule)
  double crack_work = 0;     // [J] the crack water force's share of external_work
  double dissipation = 0;    // [J] damping
  double pore_work = 0;      // [J] pore pressure and eq 17's water force
  double stored_before = 0;  // [J] strain energy before the breakage (after_breakage)
  double broken = 0;         // directed bonds broken (energy and J criteria)
  double released = 0;       // [J] the bond energy they released (energy criterion)
  double release_work = 0;   // [J] the J criterion's release force's share of external_work
                             // (SolidSolver: booked as fracture dissipation, not as W_ext)
};

class SolidLedger {
 public:
  // The parts the run has (semi-implicit pressure, crack water's face force, breakage,
  // plastic law).
  SolidLedger(bool semi_implicit, bool crack_force, bool breakage, bool plastic)
      : has_{true, semi_implicit, crack_force, breakage, plastic} {}
  bool has(LedgerPart part) const { return has_[static_cast<int>(part)]; }

  // The accumulated terms (internal, kinetic and kinetic_shift unset).
  const SolidEnergy& totals() const { return totals_; }
  // A step's terms, summed over ranks.
  void book(const StepTerms& w);
  void add(double SolidEnergy::*term, double value) { totals_.*term += value; }
  // The balance at t = 0 (eq 140 keeps it).
  void set_initial_balance(double b) { balance0_ = b; }
  double initial_balance() const { return balance0_; }

  // The existing terms and the initial balance as restart globals.
  void globals(GlobalRefs& g);
  // The existing terms' columns, of `e`.
  void series(SeriesRow& row, const SolidEnergy& e) const;
  // Eq 140's check of `e` (the current energies with these totals).
  EnergyBalance balance(const SolidEnergy& e) const;

 private:
  bool has_[5];
  SolidEnergy totals_;
  double balance0_ = 0;
};

}  // namespace mupm

#endif
