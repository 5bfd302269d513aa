#include "mupm/solvers/solid_ledger.hpp"

#include <algorithm>
#include <cmath>

namespace mupm {

double SolidEnergy::balance() const {
  // The held and dissipated terms, then the supplied ones, each in the table's order.
  double b = internal + kinetic + kinetic_shift;
  for (const auto& t : kSolidLedger)
    if (t.side > 0)
      b += this->*t.value;
  for (const auto& t : kSolidLedger)
    if (t.side < 0)
      b -= this->*t.value;
  return b;
}

// The supplied terms by magnitude, the held and dissipated ones as they are (a negative fracture
// energy, which the kinetic shift's jump can make, is not the scale).
double SolidEnergy::scale() const {
  double s = std::max(std::abs(internal), kinetic);
  for (const auto& t : kSolidLedger)
    if (t.side != 0)
      s = std::max(s, t.side < 0 ? std::abs(this->*t.value) : this->*t.value);
  return s;
}

void SolidLedger::book(const StepTerms& w) {
  totals_.external_work += w.external_work - w.release_work;
  totals_.fracture -= w.release_work;
  totals_.crack_work += w.crack_work;
  totals_.dissipation += w.dissipation;
  totals_.pore_work += w.pore_work;
  totals_.bond_energy += w.released;
}

void SolidLedger::globals(GlobalRefs& g) {
  for (const auto& t : kSolidLedger)
    if (has(t.part))
      g(t.name, totals_.*t.value);
  g("initial_balance", balance0_);
}

void SolidLedger::series(SeriesRow& row, const SolidEnergy& e) const {
  for (const auto& t : kSolidLedger)
    if (has(t.part))
      row(t.name, e.*t.value);
}

EnergyBalance SolidLedger::balance(const SolidEnergy& e) const {
  EnergyBalance b;
  b.what = "solid";
  b.expression = "E_int + E_kin - dt^2/8 m|a|^2";
  for (int side : {+1, -1})
    for (const auto& t : kSolidLedger)
      if (t.side == side && has(t.part))
        b.expression += std::string(side > 0 ? " + " : " - ") + t.symbol;
  b.expression += " - E_0";
  b.error = std::abs(e.balance() - balance0_);
  b.scale = e.scale();
  b.stored_expression = "E_int + E_kin";
  b.stored = std::abs(e.internal) + e.kinetic;
  b.supplied_expression = "|E_0|";
  b.supplied = std::abs(balance0_);
  for (const auto& t : kSolidLedger)
    if (t.side < 0) {
      b.supplied_expression += std::string(" + |") + t.symbol + "|";
      b.supplied += std::abs(e.*t.value);
    }
  b.external_expression = "E_0 + W_ext";
  b.external = balance0_ + e.external_work;
  b.gross = std::abs(balance0_) + std::abs(e.external_work);
  b.field = "displacement";
  return b;
}

}  // namespace mupm
