#pragma once
// The cases of the cmap suite, shared by our benchmarks and the CGAL ones: grid sizes per scale,
// the indexed meshes both sides build from, and the cell counts every operation must produce,
// derived from the grid's shape alone so that neither map is checked against itself.

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "sewn/cmap/mesh.hpp"
#include "sewn_bench.hpp"

namespace sewn::bench::cmap {

inline constexpr const char* suite = "cmap";

/// Hexahedral grids are n³ cubes, quad grids n² squares.
std::vector<std::uint32_t> hex_sizes(Scale s);
std::vector<std::uint32_t> quad_sizes(Scale s);

/// The input meshes, made once per process (both sides read the same points and cells).
const IndexedMesh& hex_mesh(std::uint32_t n);
const IndexedMesh& quad_mesh(std::uint32_t n);

/// Darts and i-cell counts (index 0..D; unused entries 0) of a map.
struct Counts {
  std::uint64_t darts = 0;
  std::array<std::uint64_t, 4> cells{};
  friend bool operator==(const Counts&, const Counts&) = default;
};
std::string to_string(const Counts& c);

/// A freshly built n³ grid of hexahedra, every shared face 3-sewn.
Counts hex_counts(std::uint32_t n);
/// A freshly built n² grid of quads, every shared edge 2-sewn.
Counts quad_counts(std::uint32_t n);
/// After inserting a vertex in every edge of a map with counts c: each edge becomes two, each
/// dart of it two darts.
Counts after_vertex_in_every_edge(const Counts& c);
/// After inserting an edge in every (quad) face of a 2D map with counts c: each face becomes
/// two, and gains one edge of two darts.
Counts after_edge_in_every_face(const Counts& c);
/// After inserting a vertex in every (quad) face, joined to its four corners: each face becomes
/// four triangles, each side of a face's 4 darts 12.
Counts after_vertex_in_every_face(const Counts& c);
/// After inserting a dangling edge in every boundary face of an n³ grid: one more vertex, edge
/// and two darts per face.
Counts after_dangling_edge_in_every_boundary_face(std::uint32_t n);
/// After 3-unsewing every face of the middle plane z = n/2 of an n³ grid: the plane's faces,
/// edges and vertices are all doubled; no dart is created.
Counts after_unsew_middle_plane(std::uint32_t n);

/// How many copies of an n³ grid close_top_holes closes the top holes of per timing: 4096
/// holes at least (a timing of a few microseconds would be mostly the clock's own cost).
inline std::uint32_t copies_for_holes(std::uint32_t n) { return std::max<std::uint32_t>(1, 4096 / (n * n)); }

/// The z coordinate of the middle plane of an n³ grid with unit spacing (n ≥ 2); its top is z = n.
inline double middle_plane_z(std::uint32_t n) { return static_cast<double>(n / 2); }

/// The operations, in report order; a case is "<grid>/<operation>", e.g. "hex16/build".
namespace op {
inline constexpr const char* build = "build";                    // create and sew every cell
inline const char* const iterate[4] = {"iterate_0cells", "iterate_1cells", "iterate_2cells", "iterate_3cells"};
inline constexpr const char* count_all = "count_all";            // count i-cells for every i
inline constexpr const char* split_edges = "insert_vertex_in_every_edge";
inline constexpr const char* split_faces = "insert_edge_in_every_face";  // 2D grids only
inline constexpr const char* unsew_plane = "unsew3_middle_plane";       // 3D grids only
inline constexpr const char* vertex_in_faces = "insert_vertex_in_every_face";    // 3D grids only
inline constexpr const char* dangling_in_faces = "insert_dangling_edge_in_every_boundary_face";  // 3D
inline constexpr const char* close_holes = "close_top_holes";  // 3D: insert_face_in_hole per top face, copies_for_holes(n) grids
inline constexpr const char* validate = "validate";
}  // namespace op

/// "hex16" for an n³ hexahedral grid (D = 3), "quad512" for an n² quad grid (D = 2).
inline std::string grid_name(int dim, std::uint32_t n) { return (dim == 3 ? "hex" : "quad") + std::to_string(n); }
/// The counts of a freshly built grid of dimension dim (3: hex_counts, 2: quad_counts).
inline Counts built_counts(int dim, std::uint32_t n) { return dim == 3 ? hex_counts(n) : quad_counts(n); }
/// The mesh of a grid of dimension dim (3: hex_mesh, 2: quad_mesh).
inline const IndexedMesh& grid_mesh(int dim, std::uint32_t n) { return dim == 3 ? hex_mesh(n) : quad_mesh(n); }

/// An error message if `got` differs from `want`, empty otherwise.
std::string mismatch(const char* what, const Counts& want, const Counts& got);

}  // namespace sewn::bench::cmap
