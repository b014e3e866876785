#pragma once
// The topology part of `sewn check`: the invariants of a mesh's cell complex (cmap/topology.hpp,
// cells identified by their points), as text for a person and as JSON for scripts.

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sewn/cmap/mesh.hpp"
#include "sewn/cmap/topology.hpp"

namespace sewn::app {

struct MeshTopology {
  int dim = 0;          ///< 2 (surface cells only) or 3 (volumes only); 0 when not computed
  std::string skipped;  ///< why the invariants were not computed (mixed dimensions, ...)
  Topology topology;
  /// Mesh point of a vertex (by its dart) and the two points of an edge, for the report.
  std::vector<std::uint32_t> point_of_dart, next_of_dart;
  /// How the report numbers mesh points: the file's number of each (io::MeshFile::point_numbers);
  /// empty: their index in the mesh.
  std::vector<std::int64_t> point_numbers;
  /// Point `p` of the mesh as the report numbers it.
  [[nodiscard]] std::int64_t number(std::uint32_t p) const { return point_numbers.empty() ? std::int64_t{p} : point_numbers[p]; }
};

/// Builds a map of the mesh's dimension and computes every invariant on the complex of the mesh
/// (vertices are points, edges point pairs, faces point sets). Throws MeshError when the builder
/// rejects the mesh (naming `source`). O(n log n) in the number of darts.
MeshTopology mesh_topology(const IndexedMesh& mesh, const std::string& source);

/// Several lines, each starting with two spaces: components, χ, Betti numbers, orientability,
/// boundary components with their genus, non-manifold cells (at most `max_items` of each list).
std::string topology_text(const MeshTopology& t, std::size_t max_items = 20);

/// The same numbers, every item listed: {"dimension", "components": [...], "euler", "betti",
/// "orientable", "boundary": [...], "nonmanifold": [...]} (or {"skipped": reason}).
nlohmann::json topology_json(const MeshTopology& t);

}  // namespace sewn::app
