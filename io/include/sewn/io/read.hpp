#pragma once
// Mesh file readers: Gmsh .msh (2.2 and 4.1, ASCII and binary), MEDIT .mesh (ASCII), legacy VTK .vtk
// unstructured grids (ASCII and BINARY). Each returns points, cells in VTK vertex order and one
// integer tag per cell; every problem with the file throws an IoError subclass (errors.hpp)
// whose message names the file and the line (or the binary offset / element number).
//
//   sewn::IndexedMesh mesh = sewn::io::read_mesh("part.msh");
//
// What the tag is: Gmsh — the first physical group of the element (2.2: the first element
// tag; 4.1: the first physical tag of its entity), 0 if none; MEDIT — the reference number;
// VTK — an integer cell array (ReadOptions::vtk_tag_array, else the first one-component
// integer CELL_DATA array), 0 if none.
//
// Limits: linear cells only (segment, triangle, quad, tetrahedron, hexahedron, prism,
// pyramid). Gmsh points (type 15) and VTK vertices (types 1, 2) are skipped and counted;
// higher-order types throw UnsupportedError. Node coordinates must be finite.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "sewn/cmap/mesh.hpp"
#include "sewn/io/errors.hpp"

namespace sewn::io {

enum class MeshFormat { gmsh, medit, vtk_legacy };

/// "Gmsh MSH", "MEDIT", "legacy VTK".
const char* to_string(MeshFormat f);

struct ReadOptions {
  /// Legacy VTK: the CELL_DATA array to use as tag ("" = the first one-component integer array).
  std::string vtk_tag_array;
};

/// A named group of cells: Gmsh physical names ($PhysicalNames).
struct TagName {
  int dimension = 0;
  std::int32_t tag = 0;
  std::string name;
};

/// A mesh as read, with what the file said beyond points and cells.
struct MeshFile {
  IndexedMesh mesh;
  MeshFormat format = MeshFormat::gmsh;
  std::string version;                 ///< the format version the file declared ("2.2", "4.1", "3.0", ...)
  std::vector<TagName> tag_names;      ///< Gmsh $PhysicalNames, in file order
  std::size_t skipped_points = 0;      ///< 0D elements left out (Gmsh type 15, VTK vertex / poly-vertex)
  std::size_t file_elements = 0;       ///< elements the file declared, skipped ones included
  std::vector<std::int64_t> node_tags;     ///< Gmsh: the node tag of each point of `mesh` (empty for other formats)
  std::vector<std::int64_t> element_tags;  ///< Gmsh: the element tag of each cell of `mesh` (empty for other formats)
  /// What the file most likely leaves out that its writer meant in (each a full sentence naming
  /// the file): Gmsh saves only the elements of physical groups once any is defined.
  std::vector<std::string> warnings;

  /// How the file numbers point `p` of `mesh`, for messages: its Gmsh node tag, its MEDIT
  /// vertex number (from 1), its VTK point index (from 0).
  [[nodiscard]] std::int64_t point_number(std::uint32_t p) const;
  /// point_number of every point of `mesh`.
  [[nodiscard]] std::vector<std::int64_t> point_numbers() const;
};

/// Reads a Gmsh .msh file, version 2.x or 4.1, ASCII or binary (either byte order). Throws IoError subclasses (see errors.hpp).
MeshFile read_gmsh(const std::filesystem::path& path);
/// Parses Gmsh MSH text or bytes; `source` names it in error messages.
MeshFile parse_gmsh(std::string_view text, const std::string& source);

/// Reads a MEDIT ASCII .mesh file (Vertices, Edges, Triangles, Quadrilaterals, Tetrahedra,
/// Hexahedra, 1-based, keywords case-insensitive). Throws IoError subclasses.
MeshFile read_medit(const std::filesystem::path& path);
/// Parses MEDIT text; `source` names it in error messages.
MeshFile parse_medit(std::string_view text, const std::string& source);

/// Reads a legacy VTK unstructured grid (ASCII or big-endian BINARY, file versions 2.0-5.1).
/// Throws IoError subclasses.
MeshFile read_vtk(const std::filesystem::path& path, const ReadOptions& opt = {});
/// Parses legacy VTK bytes; `source` names them in error messages.
MeshFile parse_vtk(std::string_view bytes, const std::string& source, const ReadOptions& opt = {});

/// Picks the reader from the content (a "$MeshFormat" header, a "# vtk DataFile" header, a
/// "MeshVersionFormatted" keyword), falling back on the extension (.msh, .mesh, .vtk);
/// UnsupportedError when neither identifies a format. Throws IoError subclasses.
MeshFile read_mesh_file(const std::filesystem::path& path, const ReadOptions& opt = {});
/// read_mesh_file(path, opt).mesh.
IndexedMesh read_mesh(const std::filesystem::path& path, const ReadOptions& opt = {});

}  // namespace sewn::io
