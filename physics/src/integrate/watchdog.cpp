#include "sewn/physics/integrate/watchdog.hpp"
#include "../format.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

namespace sewn::physics {

double max_abs_component(std::span<const double> values) {
  std::uint64_t m = 0;
  for (double x : values) m = std::max<std::uint64_t>(m, std::bit_cast<std::uint64_t>(x) & 0x7fffffffffffffffull);
  return std::bit_cast<double>(m);
}

bool EnergyWatchdog::baseline_if_needed(const System& sys) {
  const std::uint64_t v = sys.version();
  if (has_baseline_ && v == version_) return false;
  internal0_ = sys.kinetic_energy() + sys.potential_energy(EnergyKind::internal);
  external0_ = sys.potential_energy(EnergyKind::external);
  scale_ = sys.energy_scale();
  speed_at_check_ = max_abs_component(sys.nodes().v());
  peak_speed_ = 0;
  version_ = v;
  has_baseline_ = true;
  return true;
}

EnergyWatchdog::State EnergyWatchdog::state(const System& sys) const {
  return {has_baseline_, has_baseline_ && version_ == sys.version(), internal0_, external0_, speed_at_check_, peak_speed_};
}

void EnergyWatchdog::restore(const System& sys, const State& s) {
  has_baseline_ = s.has_baseline;
  // a stale baseline must be retaken at the next step, as it would have been
  version_ = s.baseline_current ? sys.version() : sys.version() + 1;
  scale_ = sys.energy_scale();
  internal0_ = s.internal0;
  external0_ = s.external0;
  speed_at_check_ = s.speed_at_check;
  peak_speed_ = s.peak_speed;
}

std::optional<EnergyBlowup> EnergyWatchdog::after_step(const System& sys, const HealthOptions& opt, std::uint64_t step,
                                                       double max_speed) {
  if (opt.energy_check_interval <= 0 || !has_baseline_) return std::nullopt;
  const bool periodic = step % static_cast<std::uint64_t>(opt.energy_check_interval) == 0;
  // `!(a <= b)` so that a NaN speed triggers too
  const bool triggered = opt.speed_trigger > 0 && !(max_speed <= opt.speed_trigger * speed_at_check_);
  peak_speed_ = std::max(peak_speed_, max_speed);
  if (!periodic && !triggered) return std::nullopt;
  // The reference is the peak since the last check, not the speed now: an oscillating speed
  // checked at a trough would otherwise trigger again at every crest.
  speed_at_check_ = std::isnan(max_speed) ? max_speed : peak_speed_;
  peak_speed_ = 0;
  return check(sys, opt, step);
}

std::optional<EnergyBlowup> EnergyWatchdog::check(const System& sys, const HealthOptions& opt, std::uint64_t step) const {
  if (!has_baseline_) return std::nullopt;
  const double internal = sys.kinetic_energy() + sys.potential_energy(EnergyKind::internal);
  const double work = external0_ - sys.potential_energy(EnergyKind::external);
  const double budget = internal0_ + std::max(0.0, work);
  // the scale is the baseline's unless the system changed since (a check without a baseline step)
  const double floor = opt.energy_floor_fraction * (version_ == sys.version() ? scale_ : sys.energy_scale());
  if (internal <= opt.energy_growth_factor * budget + floor) return std::nullopt;
  const NodeTable& nodes = sys.nodes();
  Index fastest = invalid_index;
  double vmax = -1;
  for (Index i = 0; i < nodes.size(); ++i) {
    const auto v = nodes.v().subspan(3 * std::size_t{i}, 3);
    const double s = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (s > vmax || (std::isnan(s) && fastest == invalid_index)) {
      vmax = s;
      fastest = i;
    }
  }
  return EnergyBlowup{"energy blow-up at step " + std::to_string(step) + ": kinetic + internal energy " + detail::format_number(internal) +
                          " J exceeds " + detail::format_number(opt.energy_growth_factor) + " x its budget " + detail::format_number(budget) +
                          " J (baseline energy plus work of external fields) + floor " + detail::format_number(floor) +
                          " J; fastest node " + std::to_string(fastest) + " has speed " + detail::format_number(vmax) + " m/s",
                      fastest};
}

}  // namespace sewn::physics
