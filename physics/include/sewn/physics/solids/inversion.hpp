#pragma once
// Inverted elements of a 3D mass-spring model. A corner of a hexahedron (its three edges from
// that corner) or a tetrahedron (its three edges from vertex 0) is inverted when the signed
// volume of those edges has the opposite sign to the same corner's at rest: the element has
// been turned inside out there, which springs alone do not resist (they see lengths, not
// orientation). Cuts keep it meaningful: a duplicated particle keeps its original's rest
// position. Quads, triangles and segments have no orientation in 3D and are not counted.

#include <cstdint>

#include "sewn/physics/mss_model.hpp"

namespace sewn::physics {

struct InversionCount {
  Index elements = 0;                ///< live hexahedra and tetrahedra with an inverted corner
  Index first = invalid_index;       ///< the first of them, by element index
  std::uint32_t first_cell = 0;      ///< its mesh cell
};

/// Counts the inverted elements at the current positions. O(live 3D elements); allocates one
/// small vector per element (element_nodes()), so call it per frame or per step, not per force.
[[nodiscard]] InversionCount count_inverted(const MssModel<3>& model);

}  // namespace sewn::physics
