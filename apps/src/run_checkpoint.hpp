#pragma once
// The runner's side of checkpoints (sewn/apps/checkpoint.hpp holds the file format): what
// identifies a run and a model, and bringing a freshly built model to a checkpoint's topology,
// motion and history.

#include <cstdint>
#include <span>
#include <string>
#include <utility>

#include "sewn/apps/checkpoint.hpp"
#include "sewn/apps/connections.hpp"
#include "sewn/apps/continuum.hpp"
#include "sewn/apps/scene.hpp"
#include "sewn/physics/mss_model.hpp"

namespace sewn::app::detail {

/// A hash of everything of the model that topology edits change: dart count, node masses,
/// fixed axes and rest positions, springs (ends, stiffness, rest length, viscosity, liveness),
/// live elements. O(nodes + springs + elements).
[[nodiscard]] std::uint64_t model_hash(const physics::MssModel<3>& model);

/// What a checkpoint must have been written by: the scene's text (its file's bytes, or the
/// built-in scene's), the model built from it (which covers mesh files) with its initial
/// motion, the step, the step count and the frame count. O(model).
[[nodiscard]] std::uint64_t run_hash(const Scene& scene, const physics::MssModel<3>& model, std::uint64_t steps,
                                     std::uint32_t frames);

/// Applies the checkpoint's recorded topology edits, in their order, to a model built from its
/// scene (refinements and coarsenings through `refinement`, null if the scene refines
/// nothing), then checks the result against the stored model hash. Throws CheckpointError
/// (naming `file`) for an edit that does not fit the model (a dart or element that does not
/// exist, a refinement in a scene without) or a different result.
void replay_cuts(physics::MssModel<3>& model, const RefinementRun* refinement, const Checkpoint& c, const std::string& file);

/// Checks the checkpoint's scheduled cuts against the scene's, in time order (`cuts`: time and
/// index in the scene's cuts) and returns how many were applied. Throws CheckpointError.
[[nodiscard]] std::size_t check_cut_schedule(const Checkpoint& c, std::span<const std::pair<double, std::size_t>> cuts,
                                             const std::string& file);

/// Brings a model (and its continuum terms) freshly built from the checkpoint's scene to the
/// checkpoint's state: the recorded edits applied again (replay_cuts) and followed by the
/// tetrahedra, the positions and velocities, the angle DOFs, the rods' own state, the
/// connections' histories, the refinement's counters. Throws CheckpointError (naming `file`)
/// for anything that does not fit the model. O(model).
void restore_model(physics::MssModel<3>& model, const ContinuumParts& continuum, const ConnectionParts& joints, RefinementRun* refinement,
                   const Checkpoint& c, const std::string& file);

}  // namespace sewn::app::detail
