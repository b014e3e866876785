#pragma once
// Tidying a mesh as read from a file before it is built into a map.
//
// Mesh generators save the boundary of a solid as cells of their own (Gmsh without physical
// groups writes every triangle of the surface and every line of the edges next to the
// tetrahedra; MEDIT files list boundary triangles with their references). Built as they are,
// those would become shells and rods glued onto the solid. embedded_cells finds them (a scene
// may keep them as boundary labels, apps/cell_models.hpp); drop_embedded_cells removes them.

#include <cstdint>
#include <vector>

#include "sewn/cmap/mesh.hpp"

namespace sewn::io {

/// Per cell: true for a 2D cell whose points are exactly a face of a 3D cell, and for a
/// segment whose points are an edge of a 2D or 3D cell (cells of the same dimension are never
/// compared). Requires valid indices. O(cells log cells).
std::vector<bool> embedded_cells(const IndexedMesh& mesh);

/// Removes the cells embedded_cells() marks. Returns how many cells were removed; the order of
/// the others is kept. Requires valid indices.
std::size_t drop_embedded_cells(IndexedMesh& mesh);

/// Removes points no cell uses and renumbers the cells. Returns, per old point, its new index
/// (or 0xffffffff if removed).
std::vector<std::uint32_t> drop_unused_points(IndexedMesh& mesh);

}  // namespace sewn::io
