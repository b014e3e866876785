#pragma once
// Coarsening (PHYSICS_NOTES §2.8, the 2014 paper's future work): a family of 4 sibling quads or 8
// sibling hexahedra is merged back into their parent. The refinement's insertions are undone in
// reverse order with the map's own removal operations (interior faces, edges, the centre); a side
// midpoint (or a face centre) goes too unless a neighbour still has it as a corner, in which case
// it stays as a T-junction of the parent. The parent's rest data, springs
// (k_E·l_e/l_E), diagonals and masses come back exactly as they were before its refinement.
// Momentum: each particle that loses mass passes that mass times its velocity to the parent's
// corners by the parent's shape functions, and the corners take velocity = momentum / new
// (lumped) mass, so linear momentum is conserved when the parent's corners are not T-junctions
// themselves; the fine-scale kinetic energy that disappears is reported.

#include <cstdint>

#include "sewn/physics/mss_model.hpp"

namespace sewn::refine {

using physics::Index;
using physics::MssModel;

struct CoarsenReport {
  std::uint32_t particles_removed = 0;
  double dissipated_energy = 0;  ///< kinetic energy lost with the fine-scale motion, J (≥ 0)
};

/// True if `parent`'s family can be coarsened now; otherwise `why` says why not (not refined,
/// a child refined further or removed, a cut between siblings). O(family).
template <int D>
[[nodiscard]] bool can_coarsen(const MssModel<D>& m, Index parent, std::string* why = nullptr);

/// Merges the children of `parent` back into it. Throws physics::InputError with the reason of
/// can_coarsen(), the model unchanged. Invalidates the children's element indices (they stay in
/// the element array, not alive) and the removed particles and springs (removed, not compacted).
/// O(family) (hexahedra: O(family · elements), to find which particles neighbours still use) plus
/// the model's resync and the incremental update of the T-junction constraints (the parent's
/// particles and the elements around them, plus the constraints' reordering).
template <int D>
CoarsenReport coarsen(MssModel<D>& m, Index parent);

}  // namespace sewn::refine
