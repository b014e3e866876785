#pragma once
// Divergence detection shared by the integrators: an energy budget checked periodically and,
// between periodic checks, whenever the fastest velocity component has grown by a set factor
// since the last check. A divergence grows geometrically, so once it starts every step
// triggers a check and the run stops within a few steps, while the values are still far
// from overflow; a smooth motion triggers only O(log(v_end / v_start)) checks.

#include <cstdint>
#include <optional>
#include <string>

#include "sewn/physics/system.hpp"

namespace sewn::physics {

struct HealthOptions {
  /// Check positions, velocities and forces for NaN/Inf every step (one pass over 9n values).
  bool check_finite = true;
  /// Steps between periodic energy checks (0: no energy check at all, triggered ones included).
  /// Each check costs about one force evaluation.
  int energy_check_interval = 100;
  /// A check also runs after any step whose largest |velocity component| exceeds this factor
  /// times its peak over the steps up to the last check (√2: the fastest node's kinetic energy
  /// doubled). The
  /// per-step cost is one max-reduction inside the integrator's update loop. 0 disables it.
  double speed_trigger = 1.4142135623730951;
  /// Blow-up when E_kin + E_internal > factor · (E_kin + E_internal at the baseline + work of
  /// external fields since) + floor. Symplectic Euler's plain energy legitimately swings by
  /// up to 1/(1 - hω/2) near the limit, hence the generous default.
  double energy_growth_factor = 100.0;
  /// floor = fraction · System::energy_scale() (springs: Σ ½kl²), so that round-off noise
  /// around a rest state is not reported.
  double energy_floor_fraction = 1e-6;
};

/// What a failed energy check found; the integrator adds its suggested step and throws.
struct EnergyBlowup {
  std::string message;  ///< energies, budget, fastest node and its speed
  Index node = invalid_index;
};

/// The energy watchdog. Its baseline is taken before the first step and again whenever
/// System::version() changes (a cut or an edit may legitimately change the energy).
class EnergyWatchdog {
 public:
  /// Takes a baseline if there is none or the system changed; returns true if it did. O(1),
  /// else O(elements).
  bool baseline_if_needed(const System& sys);
  /// Called after step number `step` with the largest |velocity component| of the new state
  /// (max_speed): runs check() when a periodic or a triggered check is due. O(1) when none is.
  [[nodiscard]] std::optional<EnergyBlowup> after_step(const System& sys, const HealthOptions& opt, std::uint64_t step,
                                                       double max_speed);
  /// Compares the energy with its budget now. O(elements).
  [[nodiscard]] std::optional<EnergyBlowup> check(const System& sys, const HealthOptions& opt, std::uint64_t step) const;
  void reset() { has_baseline_ = false; }

  /// What the watchdog remembers, for a checkpoint: its baseline, the speeds its triggered
  /// checks compare against, and whether the baseline belongs to the system as it is now.
  struct State {
    bool has_baseline = false;
    bool baseline_current = false;  ///< taken at the system's present version
    double internal0 = 0, external0 = 0, speed_at_check = 0, peak_speed = 0;
  };
  [[nodiscard]] State state(const System& sys) const;
  /// Continues from `s` on `sys` (a system rebuilt to the same state): a current baseline
  /// stays current whatever sys.version() now counts.
  void restore(const System& sys, const State& s);

 private:
  bool has_baseline_ = false;
  double internal0_ = 0, external0_ = 0;
  double scale_ = 0;  // System::energy_scale() at the baseline: it changes only with the version
  double speed_at_check_ = 0;  // the largest speed up to the last check
  double peak_speed_ = 0;      // the largest speed since
  std::uint64_t version_ = 0;
};

/// Largest |component| of a 3n array, NaN and infinities ordering above every finite value:
/// the same integer comparison of the absolute values' bit patterns that the integrators'
/// update loops use. O(n).
[[nodiscard]] double max_abs_component(std::span<const double> values);

}  // namespace sewn::physics
