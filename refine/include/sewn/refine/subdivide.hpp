#pragma once
// Regular refinement of the 2014 paper (PHYSICS_NOTES §2.2-2.5): a quad of level l splits 1:4 and
// a hexahedron 1:8 into children of level 2l. Side midpoints (and, in 3D, face centres) that a
// finer neighbour already made are found by the middle-dart search (integer dyadic sums of 1/l_e)
// and reused; missing ones are inserted with the map's own insertions, splitting the edge into two
// springs of level 2·l_e and leaving T-junctions in the neighbours. The physics follows exactly:
// the parent's mass ρV/c per corner becomes ρ(V/k)/c per child corner (c = 4 or 8 corners, k = 4
// or 8 children), new particles take the multilinear interpolation of the corners' rest
// positions, positions and velocities (so linear momentum is conserved), rest lengths come from
// the rest configuration (refining under load keeps the stress), each child adds Baudet's
// stiffness at its own size to its sides by the series rule k_E·l_e/l_E, and the parent's
// diagonals are replaced by 2 (4) per child. After each call the system's T-junction
// constraints are brought up to date (update_t_junctions, hierarchy.hpp).

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "sewn/physics/mss_model.hpp"

namespace sewn::refine {

using physics::Index;
using physics::MssModel;

struct RefineOptions {
  int max_level = 6;  ///< the finest level allowed, as an index (1 + log2 l): 6 is l = 32
  /// adapt() refuses a pass that would leave more live elements than this (a bound on memory:
  /// an adaptive run whose criterion keeps firing would otherwise grow until memory runs out).
  std::uint64_t max_elements = std::uint64_t{1} << 32;
  /// 2:1 balance (PHYSICS_NOTES §2.6): before an element is refined, every live element sharing
  /// an edge with it that is coarser than it is refined first (recursively, with balance), so
  /// that no two elements sharing an edge differ by more than one level. Elements the balance
  /// refines are below the refined element's level, hence within max_level.
  bool balance = false;
};

/// What a refinement changed.
struct RefineReport {
  std::uint32_t elements = 0;   ///< elements refined
  std::uint32_t particles = 0;  ///< particles created (side midpoints and centres)
  std::vector<Index> children;  ///< the new elements, 4 per refined element, in refinement order
};

/// Refines element e: a quad 1:4 (a face of a 2-map, or a membrane of a 3-map: a face with no
/// volume, as `sewn run` builds 2D meshes), a hexahedron of a 3-map 1:8. Returns its children
/// (Element::first_child .. +3 or +7; quad child k has the parent's k-th corner in β1 order as
/// its local vertex 0, hexahedron child v holds the parent's corner v as its local vertex v).
/// Throws physics::InputError, the model unchanged, for an element that does not exist, was removed or refined, is not a quad
/// or hexahedron — triangles and tetrahedra have no regular refinement here — or whose children
/// would pass options.max_level. Invalidates nothing held by the
/// caller (particles, springs and elements are appended; the parent stays, not alive).
/// O(darts of the element and of the paths its insertions walk) plus the model's resync of the
/// touched particles and the incremental update of the T-junction constraints (update_t_junctions:
/// the children's particles and the elements around them, plus the constraints' reordering).
template <int D>
RefineReport refine_element(MssModel<D>& m, Index e, const RefineOptions& options = {});

/// Refines each listed element in turn (each must be refinable when its turn comes; an element
/// refined earlier in the list is an error, unless the balance refined it). O(Σ of the above).
template <int D>
RefineReport refine_elements(MssModel<D>& m, std::span<const Index> elements, const RefineOptions& options = {});

/// True if no two live elements sharing an edge (quads, hexahedra) differ
/// by more than one level (2:1 balance); otherwise `why` names the first such pair. O(darts ·
/// edge degree).
template <int D>
[[nodiscard]] bool is_balanced(const MssModel<D>& m, std::string* why = nullptr);

/// True if merging parent's family back would keep the 2:1 balance: no element sharing an edge
/// with one of its children is more than one level finer than the parent. O(family's darts ·
/// edge degree).
template <int D>
[[nodiscard]] bool coarsening_keeps_balance(const MssModel<D>& m, Index parent);

/// Refines every live element once: a uniform refinement. A conforming hexahedral model
/// (refines_in_one_pass) is refined by the map's batch pass (CMap::subdivide_hexahedra) and its
/// physics rebuilt once in bulk: the model refine_elements() on every element makes, its new
/// particles and springs numbered in another order (see refine/src/hierarchy/hex_batch.cpp); any
/// other model element by element. Throws as refine_element(), the model unchanged, if an element
/// would pass options.max_level. O(model).
template <int D>
RefineReport refine_all(MssModel<D>& m, const RefineOptions& options = {});

/// True if refine_all(m) takes the batch pass: a 3-map whose live elements are all hexahedra of
/// one level, each a closed volume of 24 darts (no T-junction, no slave node), every edge of that
/// level carrying a live spring of its own, and no face element. O(elements + edges).
template <int D>
[[nodiscard]] bool refines_in_one_pass(const MssModel<D>& m);

}  // namespace sewn::refine
