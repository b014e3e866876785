#pragma once
// The refinement hierarchy of the 2014 paper (PHYSICS_NOTES §2.1) as it lives on a mass-spring
// model: every element and every edge has a level (1, 2, 4, ...: a power of two, doubled by each
// refinement; printed as the index 1 + log2), an element's sides are its hierarchical edges,
// each starting at a hierarchical dart (a dart at one of the element's 4 corners), and a particle
// strictly inside a side is a T-junction of that element, slaved to the side's two corners.
//
// The levels are stored by the model itself (physics::Element::level, physics::SpringRef::level)
// and the hierarchical darts by its per-dart corner codes (MssModel::is_corner_dart), so every
// map operation run through MssModel::edit() (cuts included) keeps them where they belong.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "sewn/physics/mss_model.hpp"

namespace sewn::refine {

using physics::Index;
using physics::MssModel;

/// The index printed for a level: 1 + log2(level) (level 1 -> 1, 2 -> 2, 4 -> 3, ...).
[[nodiscard]] int level_index(std::uint32_t level);

/// A particle strictly inside a side (border T-junction) or, in 3D, strictly inside a face
/// (middle T-junction) of a live element: its position and velocity are the linear (bilinear)
/// interpolation of the side's 2 (the face's 4) corners, with weights from its dyadic rest place.
struct TJunction {
  Index node = physics::invalid_index;
  Index element = physics::invalid_index;  ///< the coarsest element it is not a corner of
  int masters = 2;                          ///< 2 (border) or 4 (middle)
  std::array<Index, 4> master{physics::invalid_index, physics::invalid_index, physics::invalid_index, physics::invalid_index};
  std::array<double, 4> weight{};
};

/// Every T-junction of the live quads and hexahedra, once each (from the coarsest element it
/// lies strictly inside a side or face of), ordered coarse to fine, so that masters that are
/// themselves T-junctions come first. O(darts of the live elements).
template <int D>
[[nodiscard]] std::vector<TJunction> t_junctions(const MssModel<D>& m);

/// Makes the T-junctions the system's slave nodes (physics::SlaveNodes) with the given
/// treatment: the virtual-work reduction, or the 2014 paper's equal force shares among the
/// particles of the elements the T-junction is a corner of, then projection. cut() calls it after
/// every cut with the treatment in place (refinement and coarsening update incrementally,
/// update_t_junctions). O(model).
template <int D>
void constrain_t_junctions(MssModel<D>& m, physics::SlaveTreatment treatment);

/// Brings the system's T-junction constraints up to date after an operation that created or
/// revived only the `changed` elements (a refinement: the children; a coarsening: the parent):
/// the constraints of their particles are found again (each from the coarsest live element it
/// lies strictly inside a side or face of, as t_junctions() does; such elements share an edge
/// with a changed one), those of removed particles dropped, the others kept, and the list put back
/// in master-before-slave order: the constraints constrain_t_junctions() would build. With the
/// paper's projection (whose force shares reach further) it rebuilds everything.
/// O(changed elements' darts · edge degree + their neighbours' darts + slaves).
template <int D>
void update_t_junctions(MssModel<D>& m, std::span<const Index> changed);

/// What check_hierarchy() found: one line per violated invariant, naming the element, dart or
/// particle.
struct HierarchyReport {
  std::vector<std::string> problems;
  [[nodiscard]] bool ok() const { return problems.empty(); }
  [[nodiscard]] std::string str() const;
};

/// Checks the hierarchy invariants of every live element, beside the map's own validate():
/// levels are powers of two, a child's level is twice its parent's, a refined element is not
/// alive. Quads: the face ring holds exactly 4 hierarchical darts, the first the canonical dart.
/// Hexahedra: each corner is met by 3 hierarchical darts. Along each side (hierarchical edge)
/// the edge levels satisfy Σ 1/l_e = 1/l_E with every l_e ≥ l_E (exact, in integers) and every
/// particle inside lies at its dyadic parameter between the side's corners at rest (to 1e-12 of
/// the side). Every diagonal spring belongs to a live element, at its rest distance. When all
/// live elements are quads or hexahedra: every particle's mass is Σ ρ·measure/c over the
/// elements it is a corner of, and every edge spring's stiffness is Σ k_E·l_e/l_E over the
/// elements whose sides hold it (to 1e-12, relative). O(darts + springs).
template <int D>
[[nodiscard]] HierarchyReport check_hierarchy(const MssModel<D>& m);

}  // namespace sewn::refine
