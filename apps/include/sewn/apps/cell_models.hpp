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

namespace sewn::app {

enum class CellModel : std::uint8_t { label, mass_spring, solid, shell, rod };

/// "label", "mass-spring", "solid", "shell", "rod".
const char* to_string(CellModel m);

/// Per cell of `mesh` (one scene mesh, `path` its key path): the last model.groups entry with
/// the cell's tag decides; otherwise a cell in `embedded` (io::embedded_cells) is a label, and
/// any other cell follows model.type (`mixed`: tetrahedra solid, 2D cells shell, segments rod).
/// Throws SceneError naming the key (model.type or model.groups[k].as), the mesh and the first
/// cell of a kind the model cannot take (solid: tetrahedra; shell: triangles; rod: segments).
/// O(cells · groups).
std::vector<CellModel> cell_models(const IndexedMesh& mesh, const std::vector<bool>& embedded, const Scene& scene,
                                   const std::string& path);

/// Throws SceneError at model.groups[k].tag for a group whose tag no cell of `tags_seen` carries.
void check_groups_used(const Scene& scene, const std::vector<std::int32_t>& tags_seen);

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
MeshConnections mesh_connections(const IndexedMesh& mesh, const std::vector<CellModel>& models);

/// {"point": {"rod-shell": n, ...}, "curve": {...}, "surface": {...}, "components": n} with the
/// nonzero counts only, or {"skipped": why}.
nlohmann::json connections_json(const MeshConnections& c);

}  // namespace sewn::app
