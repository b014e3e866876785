#include "sewn/physics/integrate/energy_ledger.hpp"

#include <cmath>

namespace sewn::physics {

EnergyLedger::EnergyLedger(double rise_tolerance) : tolerance_(rise_tolerance) {}

void EnergyLedger::start(const System& sys) {
  rebase(sys);
  total0_ = last_total_;
  external0_ = last_external_;
  rises_ = 0;
}

void EnergyLedger::restore(const State& s) {
  total0_ = s.total0;
  external0_ = s.external0;
  last_total_ = s.last_total;
  last_moving_ = s.last_moving;
  last_external_ = s.last_external;
  rises_ = s.rises;
}

void EnergyLedger::rebase(const System& sys) {
  last_external_ = sys.potential_energy(EnergyKind::external);
  last_moving_ = sys.kinetic_energy() + sys.potential_energy(EnergyKind::internal);
  last_total_ = last_moving_ + last_external_;
}

std::optional<EnergyRise> EnergyLedger::after_step(const System& sys, std::uint64_t step) {
  const double external = sys.potential_energy(EnergyKind::external);
  const double moving = sys.kinetic_energy() + sys.potential_energy(EnergyKind::internal);
  const double total = moving + external;
  EnergyRise r{step, last_total_, total, last_moving_ + std::abs(last_external_ - external)};
  last_total_ = total;
  last_moving_ = moving;
  last_external_ = external;
  // `!(a <= b)`: a NaN energy is a rise too
  if (!(r.after - r.before <= tolerance_ * r.moved + 1e-12 * sys.energy_scale())) {
    ++rises_;
    return r;
  }
  return std::nullopt;
}

EnergyBalance EnergyLedger::balance(const System& sys) const {
  EnergyBalance b;
  b.kinetic = sys.kinetic_energy();
  b.elastic = sys.potential_energy(EnergyKind::internal);
  b.external_potential = sys.potential_energy(EnergyKind::external);
  b.total = b.kinetic + b.elastic + b.external_potential;
  b.external_work = external0_ - b.external_potential;
  b.dissipated = total0_ - b.total;
  return b;
}

}  // namespace sewn::physics
