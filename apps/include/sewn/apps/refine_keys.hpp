#pragma once
// The scene key `refinement`: hierarchical adaptive refinement of the hexahedra of a mass-spring
// model during a run (refine/, docs/refinement.md), read from a scene file and driven step by
// step — kept apart from scene.cpp and runner.cpp so they only list the key and call it.

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sewn/apps/scene.hpp"
#include "sewn/physics/mss_model.hpp"

namespace sewn::app {

/// The schema of the `refinement` object.
Field refinement_schema();
/// Reads a validated `refinement` object; throws SceneError naming "refinement.key" for values
/// the schema cannot express (a region by tag or point list: refinement regions are geometric).
RefinementSpec read_refinement(const nlohmann::json& j, const Field& schema, const std::string& file);

/// The refinement of one run: built after the model (its fixed particles and velocities set),
/// it checks that the scene can be refined, pre-refines, and then refines and coarsens after
/// every accepted step.
class RefinementRun {
 public:
  /// Throws SceneError ("refinement...") when the model cannot be refined: not a mass-spring
  /// model, no hexahedron, a pre-refined region with no element. Pre-refines the regions.
  RefinementRun(const Scene& scene, physics::MssModel<3>& model);
  ~RefinementRun();
  RefinementRun(const RefinementRun&) = delete;
  RefinementRun& operator=(const RefinementRun&) = delete;

  /// After an accepted step at time t: refines what the criteria want and coarsens the calm
  /// families. Returns true if the model changed. Throws SceneError ("refinement.max_level")
  /// when the refinement would need more memory than limits.memory allows, the model unchanged.
  bool after_step(physics::MssModel<3>& model, double t);

  [[nodiscard]] std::uint64_t refined() const { return refined_; }
  [[nodiscard]] std::uint64_t coarsened() const { return coarsened_; }
  [[nodiscard]] double dissipated() const { return dissipated_; }  ///< J, by the coarsenings

  /// What the last after_step() changed, in order: the elements it refined, then the parents
  /// whose families it coarsened (both empty if nothing).
  [[nodiscard]] const std::vector<physics::Index>& last_refined() const { return last_refined_; }
  [[nodiscard]] const std::vector<physics::Index>& last_coarsened() const { return last_coarsened_; }
  /// Repeats one such change on the model as it was before it: refines `elements`, or coarsens
  /// each of their families, with the run's options. Throws physics::InputError if one does not
  /// fit the model. How a checkpoint rebuilds a refined model; the counters are not touched.
  void redo(physics::MssModel<3>& model, bool coarsening, std::span<const physics::Index> elements) const;

  /// Everything the run carries from one step to the next beside the model: its counters and
  /// the adapter's hysteresis counters (refine::Adapter::calm_counts).
  struct State {
    std::uint64_t refined = 0, coarsened = 0;
    double dissipated = 0;
    std::vector<std::int32_t> calm;
  };
  [[nodiscard]] State state() const;
  void restore(const State& s);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::uint64_t refined_ = 0, coarsened_ = 0;
  double dissipated_ = 0;
  std::vector<physics::Index> last_refined_, last_coarsened_;
};

}  // namespace sewn::app
