#pragma once
// What each cell of a scene's mesh is simulated as: a solid, a shell, a rod, mass-spring
// elements, or only a label (a name for selectors). Mesh generators write a solid's boundary
// faces and edges as cells of their own (tetgen's face list, Gmsh's physical surfaces): those
// are labels unless the scene's model.groups says they are shells or rods.
//
//   const auto models = sewn::app::cell_models(mesh, io::embedded_cells(mesh), scene, "meshes[0]");
//
// The same rule, with no scene, is what `sewn check` reports as the simulated complex.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sewn/apps/scene.hpp"
#include "sewn/cmap/mesh.hpp"
#include "sewn/connect/detect.hpp"
#include "sewn/io/geometry.hpp"
#include "sewn/io/read.hpp"

namespace sewn::app {

enum class CellModel : std::uint8_t { label, mass_spring, solid, shell, rod };

/// "label", "mass-spring", "solid", "shell", "rod".
const char* to_string(CellModel m);

/// What a scene mesh offers to model.groups' names: its key path, its format ("Gmsh MSH",
/// "MEDIT", "legacy VTK", or "generated"), and the Gmsh physical names it declares (none for
/// the others: MEDIT references and generated tags are numbers only).
struct MeshNames {
  std::string path;
  std::string format = "generated";
  std::vector<io::TagName> names;
};

/// Which model.groups entries select the cells of one mesh: per cell the last entry that
/// names it (-1: none), and per entry whether it names any cell (even one a later entry wins).
/// An entry names a cell by its `tag`, or by its `name` through the mesh's physical names (of
/// any dimension; a name declared twice selects both tags).
struct GroupMatch {
  std::vector<int> of_cell;
  std::vector<bool> named_a_cell;
};

/// O(cells · groups + groups · names).
GroupMatch match_groups(const IndexedMesh& mesh, const MeshNames& names, const Scene& scene);

/// Where a scene mesh's cells come from, so that a message names a cell as the user's file does:
/// the mesh's key path ("meshes[1]"), its file ("" if generated), and per cell its Gmsh element
/// tag (empty for other formats). A cell's index is its place in the file's element order (Gmsh
/// points and VTK vertices left out, as the reader does).
struct MeshSource {
  std::string key;
  std::string file;
  std::vector<std::int64_t> element_tags;
  std::vector<std::int64_t> point_numbers;  ///< per point, the file's number of it (empty: generated, from 0)
  /// "cell 12 (Gmsh element 40) of b.msh", "cell 3" for a generated mesh (`key` names the mesh).
  [[nodiscard]] std::string cell(std::uint32_t c) const;
  /// "point 40 of b.msh" (a Gmsh node tag, a MEDIT vertex from 1, a VTK point from 0), "point 3"
  /// for a generated mesh.
  [[nodiscard]] std::string point(std::uint32_t p) const;
};

/// The mesh of `file` without the points no cell uses (what `sewn run` simulates and `sewn check`
/// checks), with in `numbering` the file's numbers of its points and Gmsh tags of its cells, so
/// that geometry messages name them as the file does. O(mesh).
IndexedMesh used_part(const io::MeshFile& file, io::GeometryOptions& numbering);

/// Per cell of `mesh` (one scene mesh, `source` naming it): the model.groups entry `groups`
/// gives (match_groups().of_cell) decides; otherwise a cell in `embedded`
/// (io::embedded_cells) is a label, and any other cell follows model.type (`mixed`:
/// tetrahedra solid, 2D cells shell, segments rod). Throws SceneError naming the key
/// (model.type or model.groups[k].as), the mesh and the first cell of a kind the model cannot
/// take (solid: tetrahedra; shell: triangles; rod: segments). O(cells).
std::vector<CellModel> cell_models(const IndexedMesh& mesh, const std::vector<bool>& embedded, const Scene& scene,
                                   const MeshSource& source, const std::vector<int>& groups);
/// The same, for a mesh with no physical names (groups selected by tag only), `path` naming it.
std::vector<CellModel> cell_models(const IndexedMesh& mesh, const std::vector<bool>& embedded, const Scene& scene,
                                   const std::string& path);

/// Throws SceneError for a model.groups entry that named no cell of any mesh (`named_a_cell`,
/// or-ed over the meshes): at .tag, "no cell of any mesh carries tag t"; at .name, either the
/// physical group that has no cell, or, for a name no mesh declares, every mesh's physical
/// names (and which meshes have numbers only).
void check_groups_used(const Scene& scene, const std::vector<bool>& named_a_cell, const std::vector<MeshNames>& meshes);

/// The simulated part of a mesh as read: cells counted by dimension and the components of the
/// complex they form (cells sharing a point are connected), and the labels by tag.
struct SimulatedComplex {
  std::array<std::uint32_t, 4> cells{};  ///< simulated cells per dimension 1..3 (index 0 unused)
  std::uint32_t components = 0;          ///< connected through shared points
  std::uint32_t points = 0;              ///< points of simulated cells
  struct Label {
    std::int32_t tag = 0;
    int dimension = 0;
    std::uint32_t cells = 0;
  };
  std::vector<Label> labels;  ///< per (tag, dimension), in that order
};

/// Counts what `models` makes of `mesh` (models[c] == label: a label). O(cells α(points)).
SimulatedComplex simulated_complex(const IndexedMesh& mesh, const std::vector<CellModel>& models);

/// Where the simulated bodies of a mesh meet (connect/detect.hpp): each non-label cell as its
/// model takes it (rod, shell, solid; a mass-spring cell by its dimension, as `mixed` would).
/// `skipped` says why nothing was computed: a simulated cell that is not a segment, triangle or
/// tetrahedron. O(cells log cells).
struct MeshConnections {
  connect::FoundConnections found;
  std::string skipped;
};
/// `chain`: per mesh cell a rod segment's chain key (connect::CellList::chain), empty: none.
MeshConnections mesh_connections(const IndexedMesh& mesh, const std::vector<CellModel>& models,
                                 const std::vector<std::uint32_t>& chain = {});

/// {"point": {"rod-shell": n, ...}, "curve": {...}, "surface": {...}, "components": n} with the
/// nonzero counts only, or {"skipped": why}.
nlohmann::json connections_json(const MeshConnections& c);

}  // namespace sewn::app
