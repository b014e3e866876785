#pragma once
// Which triangle lies across each edge of a triangle list: the one query hinges and patch
// bending both build on.

#include <array>
#include <span>
#include <vector>

#include "sewn/physics/types.hpp"

namespace sewn::physics::shells {

/// The triangle across an edge and its corner opposite that edge; tri == invalid_index on a
/// boundary (one triangle) or non-manifold (three or more) edge.
struct Across {
  Index tri = invalid_index;
  int corner = 0;
};

/// Per triangle t and corner i, what lies across the edge opposite corner i (the edge
/// (v[i+1], v[i+2])). Throws InputError naming the node when a triangle refers to a node
/// ≥ n_nodes, and CellInputError naming the later triangle and its edge when an interior edge
/// is traversed the same way by both of its triangles (inconsistent orientation: a fold would
/// read as the fold plus π). O(T log T).
[[nodiscard]] std::vector<std::array<Across, 3>> triangles_across(std::span<const std::array<Index, 3>> triangles,
                                                                  std::size_t n_nodes);

}  // namespace sewn::physics::shells
