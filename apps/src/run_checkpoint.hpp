#pragma once
// The runner's side of checkpoints (sewn/apps/checkpoint.hpp holds the file format): which
// runs can be checkpointed, what identifies a run and a model, and bringing a freshly built
// model to a checkpoint's topology and motion.

#include <cstdint>
#include <string>

#include "sewn/apps/checkpoint.hpp"
#include "sewn/apps/scene.hpp"
#include "sewn/physics/mss_model.hpp"

namespace sewn::app::detail {

/// Throws SceneError naming the key when the scene's run keeps state a checkpoint does not
/// hold (a CHOLMOD factorization, the refinement hierarchy, rods' frames and twist, the elastic
/// terms' node lists after a cut), so that a resumed run never continues differently. `option`
/// names the command-line option asked for; `simulates_rods` says whether any cell is a rod.
void require_checkpointable(const Scene& scene, const physics::MssModel<3>& model, bool simulates_rods,
                            const std::string& option);

/// A hash of everything of the model that topology edits change: dart count, node masses,
/// fixed axes and rest positions, springs (ends, stiffness, rest length, viscosity, liveness),
/// live elements. O(nodes + springs + elements).
[[nodiscard]] std::uint64_t model_hash(const physics::MssModel<3>& model);

/// What a checkpoint must have been written by: the scene's text (its file's bytes, or the
/// built-in scene's), the model built from it (which covers mesh files) with its initial
/// motion, the step, the step count and the frame count. O(model).
[[nodiscard]] std::uint64_t run_hash(const Scene& scene, const physics::MssModel<3>& model, std::uint64_t steps,
                                     std::uint32_t frames);

/// Applies the checkpoint's recorded cuts to a model built from its scene, then checks the
/// result against the stored model hash. Throws CheckpointError (naming `file`) for a cut that
/// does not fit the model (a dart or element that does not exist) or a different result.
void replay_cuts(physics::MssModel<3>& model, const Checkpoint& c, const std::string& file);

}  // namespace sewn::app::detail
