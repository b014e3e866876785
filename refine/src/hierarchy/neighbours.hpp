#pragma once
// The elements around an element on the map: what the 2:1 balance and the incremental T-junction
// update look at.

#include <algorithm>
#include <vector>

#include "sewn/physics/mss_model.hpp"

namespace sewn::refine::detail {

/// Can elements of this kind be refined regularly in a D-map? Quads (1:4) in both, as faces of a
/// 2-map or membranes of a 3-map; hexahedra (1:8) in a 3-map.
template <int D>
constexpr bool refinable_kind(physics::ElementKind k) {
  return k == physics::ElementKind::quad || (D == 3 && k == physics::ElementKind::hexahedron);
}

/// The darts of element e's own cell: its volume, or its face for a 2D cell (in a 3-map a
/// membrane's 3-cell would be its whole connected surface). O(darts of e).
template <int D>
DartList element_darts(const physics::MssModel<D>& m, physics::Index e) {
  const physics::Element& el = m.elements()[e];
  if constexpr (D == 3)
    if (el.kind == physics::ElementKind::hexahedron || el.kind == physics::ElementKind::tetrahedron)
      return m.map().template cell<3>(el.dart);
  return m.map().template cell<2>(el.dart);
}

/// The live elements sharing an edge with element e (faces included), each once, sorted.
/// O(darts of e · edge degree).
template <int D>
std::vector<physics::Index> edge_neighbours(const physics::MssModel<D>& m, physics::Index e) {
  const auto& map = m.map();
  std::vector<physics::Index> out;
  for (Dart x : element_darts(m, e))
    for (Dart y : map.template cell<1>(x))
      if (const physics::Index n = m.element_of(y); n != physics::invalid_index && n != e && m.elements()[n].alive) out.push_back(n);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace sewn::refine::detail
