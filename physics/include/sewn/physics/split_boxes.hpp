#pragma once
// Splitting elongated hexahedra into near-cubes, the `split` treatment of boxes too elongated
// for Baudet's stiffness (PHYSICS_NOTES §1.2: an edge stiffness turns negative beyond ~1.5:1).
// Clamping those stiffnesses keeps the mesh but makes the body far too stiff in bending (issue
// 17: 860× at 10:1); splitting each box into pieces of aspect at most √2 keeps Baudet's formula
// valid, at the price of more particles.
//
// A hexahedron's edges along one of its axes must be split into the same number of pieces as
// those of every hexahedron sharing one of them, or the mesh would not conform: the edges are
// grouped into sheets (edges parallel within some hexahedron, transitively) and every edge of a
// sheet gets the largest count any of its hexahedra asks for. New points on shared edges and
// faces are computed once, from the edge's or face's own corners, so both sides agree exactly.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "sewn/cmap/mesh.hpp"

namespace sewn::physics {

struct BoxSplit {
  /// The split mesh: the source's points first (same indices), then the new ones; cells in
  /// source order, a split cell's pieces in its place.
  IndexedMesh mesh;
  std::vector<std::uint32_t> source_cell;  ///< per cell of `mesh`, the source cell it is (part of)
  std::uint32_t asked = 0;                 ///< hexahedra that asked to be split
  std::uint32_t split = 0;                 ///< source cells cut into more than one piece (sheets included)
};

/// Mean length of a hexahedron's 4 edges along each of its local axes (VTK order: 0→1, 0→3,
/// 0→4), the box the mass-spring model gives it. O(1).
[[nodiscard]] std::array<double, 3> box_axis_lengths(const IndexedMesh& mesh, std::uint32_t cell);

/// Splits every hexahedron c with wanted[c] into n0 × n1 × n2 near-cubes, n_a the count in
/// {⌊L_a/s⌋, ⌈L_a/s⌉} (s its shortest axis length) whose pieces are closer to cubes, and the
/// hexahedra sharing a sheet with it along that axis likewise. Throws InputError naming the cell
/// (and `source`) if a cell that is not a hexahedron has an edge that would be split (it could
/// not follow), or if a count would exceed 4096. O(cells + new points · log).
[[nodiscard]] BoxSplit split_boxes(const IndexedMesh& mesh, std::span<const std::uint8_t> wanted, const std::string& source);

}  // namespace sewn::physics
