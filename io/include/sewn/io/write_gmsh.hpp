#pragma once
// Gmsh MSH 2.2 ASCII output: points, cells (segments, triangles, quads, tetrahedra, hexahedra,
// prisms, pyramids) with their tags as physical groups, and the physical names given. What the
// mesh generators of the paper scenes write (`sewn make-mesh`), read back by read_gmsh.
#include <filesystem>
#include <span>
#include <string>

#include "sewn/cmap/mesh.hpp"
#include "sewn/io/read.hpp"

namespace sewn::io {

/// The file's text. Each cell's tag is written as its physical and its elementary tag; `names`
/// become $PhysicalNames (omitted when empty). Coordinates with 17 significant digits, so a
/// read gives the same doubles. Throws std::invalid_argument for a name with a double quote or
/// a line break (Gmsh has no escape for them).
std::string gmsh_text(const IndexedMesh& mesh, std::span<const TagName> names);

/// Writes gmsh_text atomically (a reader never sees half a file). Throws FileError.
void write_gmsh(const std::filesystem::path& path, const IndexedMesh& mesh, std::span<const TagName> names);

}  // namespace sewn::io
