#pragma once
// Closed surface meshes and their voxelization: real shapes (the 2014 paper's rabbit) turned
// into hexahedra that the mass-spring model and the refinement take.
//
//   sewn::io::Surface s = sewn::io::read_surface("bunny00.off");
//   sewn::IndexedMesh hexes = sewn::io::voxelize(s, 32);   // 32 cells along the longest side
//
// Formats: OFF (ASCII; COFF, NOFF, STOFF and their combinations too, the per-vertex extras
// ignored), Wavefront OBJ (v and f records; other records ignored) and STL (ASCII, one solid or
// several, or binary; vertices merged when bitwise equal). Polygons are fanned into triangles. Every
// problem throws an IoError subclass naming the file (and line, for text formats).

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "sewn/cmap/mesh.hpp"
#include "sewn/io/errors.hpp"

namespace sewn::io {

/// A triangulated surface.
struct Surface {
  std::vector<Point3> points;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// Reads an OFF, OBJ or STL file (by its content: an "OFF" header, "solid" then "facet" for
/// ASCII STL; else by the extension .off, .obj, .stl). Throws IoError subclasses: a missing
/// file, a bad token, an index out of range, a non-finite coordinate, a face of fewer than 3
/// vertices, no triangle.
Surface read_surface(const std::filesystem::path& path);
/// The same on bytes already read: `source` names them in errors and its extension is the
/// fallback when the content does not tell the format.
Surface parse_surface(std::string_view data, const std::string& source);

/// The hexahedra of a regular grid whose centres lie inside a closed surface: `cells` cells
/// along the longest side of its bounding box (cubes of side longest/cells), inside decided by
/// the parity of crossings of a ray along +x (exactly once per crossing: points on an edge or a
/// vertex are assigned by a symbolic perturbation). Cells of a row form one lattice box; the
/// boxes are glued by box_union. `source` names the surface in errors. Throws SemanticError if
/// the surface is not closed (an edge not shared by exactly 2 triangles, naming it), if no cell
/// centre lies inside (too few cells), for cells < 1, for a grid of more than 2^22 cells (its
/// mesh alone could take 300 MB), for an extent that overflows or cannot be cut into cells, and
/// for cells smaller than 1e-9 of the surface's distance from the origin (corners would round together).
/// O(cells² · triangles' extent in rows + cells inside).
IndexedMesh voxelize(const Surface& s, std::uint32_t cells, const std::string& source);

}  // namespace sewn::io
