#include "sewn/physics/integrate/energy_ledger.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace sewn::physics {

EnergyLedger::EnergyLedger(double rise_tolerance) : tolerance_(rise_tolerance) {}

Momenta momenta(const NodeTable& nodes) {
  double mass = 0;
  Eigen::Vector3d first = Eigen::Vector3d::Zero(), centre = Eigen::Vector3d::Zero();
  Momenta m;
  for (Index i = 0; i < nodes.size(); ++i) {
    if (!nodes.is_alive(i)) continue;
    mass += nodes.mass(i);
    centre += nodes.mass(i) * nodes.position(i);
    m.linear += nodes.mass(i) * nodes.velocity(i);
    first += nodes.mass(i) * nodes.position(i).cross(nodes.velocity(i));
  }
  if (!(mass > 0)) return m;
  centre /= mass;
  // Σ m (x − c) × v = Σ m x × v − c × Σ m v
  m.angular = first - centre.cross(m.linear);
  return m;
}

void EnergyLedger::observe(double moving, double external) {
  // what the start and the fields supplied: total at the start minus the external potential now
  const double supplied = total0_ - external;
  if (supplied > 0) peak_ratio_ = std::max(peak_ratio_, moving / supplied);
}

void EnergyLedger::observe(const EnergyBalance& b) { observe(b.kinetic + b.elastic, b.external_potential); }

void EnergyLedger::start(const System& sys) {
  rebase(sys);
  total0_ = last_total_;
  external0_ = last_external_;
  rises_ = 0;
  peak_ratio_ = 0;
}

void EnergyLedger::restore(const State& s) {
  total0_ = s.total0;
  external0_ = s.external0;
  last_total_ = s.last_total;
  last_moving_ = s.last_moving;
  last_external_ = s.last_external;
  rises_ = s.rises;
  peak_ratio_ = s.peak_ratio;
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
  observe(moving, external);
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
