#pragma once
// The elements around an element on the map: what the 2:1 balance and the incremental T-junction
// update look at.

#include <algorithm>
#include <vector>

#include "sewn/physics/mss_model.hpp"

namespace sewn::refine::detail {

/// The live elements sharing an edge with element e (faces included), each once, sorted.
/// O(darts of e · edge degree).
template <int D>
std::vector<physics::Index> edge_neighbours(const physics::MssModel<D>& m, physics::Index e) {
  const auto& map = m.map();
  std::vector<physics::Index> out;
  for (Dart x : map.template cell<D>(m.elements()[e].dart))
    for (Dart y : map.template cell<1>(x))
      if (const physics::Index n = m.element_of(y); n != physics::invalid_index && n != e && m.elements()[n].alive) out.push_back(n);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace sewn::refine::detail
