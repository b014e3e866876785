#pragma once
// Inverted elements of a 3D mass-spring model. A corner of a hexahedron (its three edges from
// that corner) or a tetrahedron (its three edges from vertex 0) is inverted when the signed
// volume of those edges has the opposite sign to the same corner's at rest: the element has
// been turned inside out there, which springs alone do not resist (they see lengths, not
// orientation). Cuts keep it meaningful: a duplicated particle keeps its original's rest
// position. Quads, triangles and segments have no orientation in 3D and are not counted.

#include <cstdint>
#include <vector>

#include "sewn/physics/mss_model.hpp"

namespace sewn::physics {

struct InversionCount {
  Index elements = 0;                ///< live hexahedra and tetrahedra with an inverted corner
  Index first = invalid_index;       ///< the first of them, by element index
  std::uint32_t first_cell = 0;      ///< its mesh cell
};

/// Counts inverted elements, keeping every corner's nodes and rest sign between calls.
class InversionMonitor {
 public:
  /// The count at the current positions: one signed volume per corner of the live hexahedra and
  /// tetrahedra. When the model changed since the last call (System::version(): a cut, an
  /// edit), the corners are first read again from the map, O(elements) with an allocation each.
  [[nodiscard]] InversionCount count(const MssModel<3>& model);

 private:
  struct Corner {
    Index o, a, b, c;   // the corner and its three neighbours
    bool rest_positive;
    Index element;
  };
  std::vector<Corner> corners_;  // grouped by element, in element order
  std::uint64_t version_ = ~std::uint64_t{0};
};

/// One count with a fresh monitor (reads every element from the map: use a monitor to repeat).
[[nodiscard]] InversionCount count_inverted(const MssModel<3>& model);

}  // namespace sewn::physics
