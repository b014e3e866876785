#pragma once
// Adaptive refinement (PHYSICS_NOTES §2.7): after an accepted step, a criterion picks the live
// elements to refine; adapt() refines each at most once (one level per element per step) and
// never past the maximum level. The 2014 paper's criterion is the strain of the diagonals;
// others (strain energy, distance to a tool, a user region) implement Criterion.

#include <cstdint>
#include <utility>
#include <vector>

#include "sewn/physics/mss_model.hpp"
#include "sewn/refine/coarsen.hpp"
#include "sewn/refine/subdivide.hpp"

namespace sewn::refine {

template <int D>
class Criterion {
 public:
  virtual ~Criterion() = default;
  /// True if live element e should be refined now.
  [[nodiscard]] virtual bool wants_refinement(const MssModel<D>& m, Index e) const = 0;
  /// True if leaf e is calm enough for its family to be coarsened (hysteresis: a lower bar
  /// than refinement's). Default: never.
  [[nodiscard]] virtual bool allows_coarsening(const MssModel<D>&, Index) const { return false; }
};

/// The paper's criterion: refine when a diagonal of the element has 100·|l − l₀|/l₀ above the
/// threshold (in percent; l₀ the diagonal's rest length at the element's level); allow
/// coarsening below half of it. Rotation-invariant. O(diagonals of the element).
template <int D>
class DiagonalStrain : public Criterion<D> {
 public:
  /// Throws physics::InputError unless 0 < threshold_percent < 100.
  explicit DiagonalStrain(double threshold_percent);
  [[nodiscard]] bool wants_refinement(const MssModel<D>& m, Index e) const override;
  [[nodiscard]] bool allows_coarsening(const MssModel<D>& m, Index e) const override;
  /// The largest diagonal strain of element e, in percent (0 for an element without diagonals).
  [[nodiscard]] static double strain_percent(const MssModel<D>& m, Index e);

 private:
  double threshold_;
};

/// Refines, once each, the live quads (2-maps) or hexahedra (3-maps) the criterion wants,
/// skipping those whose children would pass options.max_level. Throws physics::InputError, the
/// model unchanged, if the pass would leave more than options.max_elements live elements (the
/// criterion's picks; with options.balance, the neighbours the balance refines come on top).
/// O(elements · criterion) plus the refinements.
/// `chosen`, if given, receives the elements refined, in the order refined: refine_elements()
/// of that list on the model as it was repeats the pass exactly.
template <int D>
RefineReport adapt(MssModel<D>& m, const Criterion<D>& criterion, const RefineOptions& options = {},
                   std::vector<Index>* chosen = nullptr);

/// Refinement and coarsening driven step by step (PHYSICS_NOTES §2.7-2.8): call update() after
/// each accepted step. It refines what the criterion wants (adapt()), then counts, per live leaf,
/// the consecutive updates the criterion allowed coarsening (hysteresis), and coarsens every
/// family whose children have all been calm for `calm_steps` updates and that can_coarsen()
/// (and, with options.refine.balance, whose merge keeps the 2:1 balance).
/// O(elements · criterion) plus the operations.
template <int D>
class Adapter {
 public:
  struct Options {
    RefineOptions refine;
    int calm_steps = 20;
    bool coarsen = true;
  };
  struct Report {
    RefineReport refined;
    std::uint32_t coarsened = 0;
    double dissipated_energy = 0;  ///< J, by the coarsenings
    /// What the update did, in order: refine_elements() of the first, then coarsen() of each
    /// of the second, on the model as it was, repeat it (how a checkpoint rebuilds the model).
    std::vector<Index> refined_elements, coarsened_parents;
  };
  Adapter(const Criterion<D>& criterion, Options options) : criterion_(criterion), options_(options) {}
  Report update(MssModel<D>& m);
  /// The hysteresis counters (per element, the consecutive updates it was calm), the adapter's
  /// only state beside the model: with the model rebuilt, restoring them continues exactly.
  [[nodiscard]] const std::vector<int>& calm_counts() const { return calm_; }
  void restore_calm_counts(std::vector<int> calm) { calm_ = std::move(calm); }

 private:
  const Criterion<D>& criterion_;
  Options options_;
  std::vector<int> calm_;  // per element
};

}  // namespace sewn::refine
