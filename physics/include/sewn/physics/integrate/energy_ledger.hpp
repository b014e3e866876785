#pragma once
// Energy bookkeeping of a run, and the report of steps that create energy.
//
// At every instant the ledger's figures satisfy, by definition of the last two,
//   total        = kinetic + elastic + external potential (gravity)
//   external_work = external potential at the start − now  (work done by the external fields)
//   dissipated    = total at the start − total now
// so kinetic + elastic = (kinetic + elastic at the start) + external_work − dissipated. The
// dissipated energy is what damping and the integrator's own numerical dissipation removed;
// it is negative when the scheme created energy. A step that raises the total (that is, whose
// kinetic + elastic energy rises beyond the work the external fields did during it) by more
// than a tolerance is reported: implicit Euler must never do so on a conservative system, and
// its linearised form does on fast rotations (PHYSICS_NOTES §4, hard case 4). Symplectic
// Euler's plain energy oscillates within a bound by design, so its runs are not checked.

#include <cstdint>
#include <optional>

#include "sewn/physics/system.hpp"

namespace sewn::physics {

struct EnergyBalance {
  double kinetic = 0, elastic = 0, external_potential = 0, total = 0;
  double external_work = 0, dissipated = 0;
};

/// Linear momentum Σ m v and angular momentum Σ m (x − c) × v about the centre of mass c of the
/// live nodes: both are constant on a free body under central forces. O(n).
struct Momenta {
  Eigen::Vector3d linear = Eigen::Vector3d::Zero(), angular = Eigen::Vector3d::Zero();
};
[[nodiscard]] Momenta momenta(const NodeTable& nodes);

/// One step that created energy.
struct EnergyRise {
  std::uint64_t step = 0;
  double before = 0, after = 0;  ///< total energy, J
  double moved = 0;              ///< kinetic + elastic before, plus the external work in the step: the scale
};

class EnergyLedger {
 public:
  /// rise_tolerance: a step is reported when total_after − total_before > rise_tolerance ·
  /// moved + 1e-12 · energy_scale (round-off of a body at rest).
  explicit EnergyLedger(double rise_tolerance = 1e-4);
  /// Records the energies at the start of the run. O(elements).
  void start(const System& sys);
  /// Forgets the last step's total and takes the current one: after an edit (a cut) that is not
  /// a step. O(elements).
  void rebase(const System& sys);
  /// Call after step number `step`: returns the rise if that step created energy beyond the
  /// tolerance (and counts it). O(elements).
  std::optional<EnergyRise> after_step(const System& sys, std::uint64_t step);
  /// The balance now (see the header comment). O(elements).
  [[nodiscard]] EnergyBalance balance(const System& sys) const;
  /// Number of steps reported so far.
  [[nodiscard]] std::uint64_t rises() const { return rises_; }
  /// Takes the balance now into peak_ratio() (after_step does at every step it sees). O(1).
  void observe(const EnergyBalance& b);
  /// The largest ratio seen so far of kinetic + elastic energy to what the start and the external
  /// fields supplied (kinetic + elastic at the start + external work): at most 1 for a scheme
  /// that creates no energy (damping lowers it), above 1 by what the integrator created. 0 until
  /// anything was supplied.
  [[nodiscard]] double peak_ratio() const { return peak_ratio_; }

  /// Everything the ledger holds, for a checkpoint (restore continues from it exactly).
  struct State {
    double total0 = 0, external0 = 0, last_total = 0, last_moving = 0, last_external = 0;
    std::uint64_t rises = 0;
    double peak_ratio = 0;
  };
  [[nodiscard]] State state() const {
    return {total0_, external0_, last_total_, last_moving_, last_external_, rises_, peak_ratio_};
  }
  void restore(const State& s);

 private:
  double tolerance_;
  double total0_ = 0, external0_ = 0;
  double last_total_ = 0, last_moving_ = 0, last_external_ = 0;
  std::uint64_t rises_ = 0;
  double peak_ratio_ = 0;
  // kinetic + elastic over (their start value + external work), with the external potential now
  void observe(double moving, double external);
};

}  // namespace sewn::physics
