#pragma once
// What quad and hexahedron coarsening share.

#include <cstdint>
#include <string>

#include "hierarchy/model_access.hpp"
#include "sewn/refine/coarsen.hpp"

namespace sewn::refine::detail {

/// Runs f inside MssModel::edit() with element merges allowed.
template <int D, class F>
void A_edit(physics::MssModel<D>& m, F&& f) {
  ModelAccess<D>::set_refining(m, true);
  try {
    m.edit([&](auto&) { f(); });
  } catch (...) {
    ModelAccess<D>::set_refining(m, false);
    throw;
  }
  ModelAccess<D>::set_refining(m, false);
}

/// The children of p stop being elements (their diagonals go) and p lives again with
/// `diagonals` fresh diagonal springs (attached by the caller once its codes are set).
template <int D>
void revive_parent(physics::MssModel<D>& m, physics::Index p, physics::Index children, std::size_t diagonals) {
  auto& elements = ModelAccess<D>::elements(m);
  const physics::Index first = elements[p].first_child;
  for (physics::Index c = first; c < first + children; ++c) {
    elements[c].alive = false;
    for (physics::Index& s : elements[c].diagonal)
      if (s != physics::invalid_index) {
        m.springs().remove(s);
        s = physics::invalid_index;
      }
  }
  physics::Element& el = elements[p];
  el.alive = true;
  el.first_child = physics::invalid_index;
  for (std::size_t d = 0; d < diagonals; ++d)
    el.diagonal[d] = m.springs().add(0, 1, el.diagonal_k, 0.0, physics::SpringKind::diagonal);
  ModelAccess<D>::set_live_elements(m, m.num_live_elements() - (children - 1));
  ModelAccess<D>::grow_darts(m);
}

CoarsenReport coarsen_hex(physics::MssModel<3>& m, physics::Index p);

/// Why the removals of coarsen_hex could not run on p's family because of cuts on its outer
/// faces (a face centre or an edge midpoint that should go where a cut ends), or empty. O(family).
std::string hex_cut_conflict(const physics::MssModel<3>& m, physics::Index p);

}  // namespace sewn::refine::detail
