#pragma once
// Indexed meshes (points + cells listing point indices), the local topology of each cell type,
// and regular grid generators. Vertex orders follow VTK; every face table lists faces with
// outward orientation (right-hand rule) for a positively oriented cell.

#include <array>
#include <initializer_list>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace sewn {

enum class CellType : std::uint8_t { segment, triangle, quad, tetrahedron, hexahedron, prism, pyramid };

/// Topological dimension of a cell type (1, 2 or 3).
constexpr int cell_dimension(CellType t) {
  switch (t) {
    case CellType::segment: return 1;
    case CellType::triangle:
    case CellType::quad: return 2;
    default: return 3;
  }
}
/// Number of vertices of a cell type.
constexpr int cell_vertex_count(CellType t) {
  switch (t) {
    case CellType::segment: return 2;
    case CellType::triangle: return 3;
    case CellType::quad: return 4;
    case CellType::tetrahedron: return 4;
    case CellType::hexahedron: return 8;
    case CellType::prism: return 6;
    case CellType::pyramid: return 5;
  }
  return 0;
}
/// "hexahedron", "triangle", ...
const char* to_string(CellType t);

/// The faces of a polyhedral cell type as local vertex lists (outward). Empty for 1D/2D types.
std::span<const std::span<const std::uint32_t>> cell_faces(CellType t);

using Point3 = std::array<double, 3>;

/// Points and cells. Cells are stored flat: cell c has type types[c], vertices
/// conn[offsets[c] .. offsets[c+1]), and an integer tag (region / physical group, 0 if none).
struct IndexedMesh {
  std::vector<Point3> points;
  std::vector<CellType> types;
  std::vector<std::uint32_t> offsets{0};
  std::vector<std::uint32_t> conn;
  std::vector<std::int32_t> tags;

  /// Appends a cell; returns its index. Throws MeshError if the vertex count does not match the type.
  std::uint32_t add_cell(CellType t, std::span<const std::uint32_t> vertices, std::int32_t tag = 0);
  std::uint32_t add_cell(CellType t, std::initializer_list<std::uint32_t> vertices, std::int32_t tag = 0) {
    return add_cell(t, std::span<const std::uint32_t>(vertices.begin(), vertices.size()), tag);
  }
  [[nodiscard]] std::uint32_t num_cells() const { return static_cast<std::uint32_t>(types.size()); }
  [[nodiscard]] std::uint32_t num_points() const { return static_cast<std::uint32_t>(points.size()); }
  [[nodiscard]] std::span<const std::uint32_t> cell(std::uint32_t c) const {
    return {conn.data() + offsets[c], conn.data() + offsets[c + 1]};
  }
  /// Number of cells of each topological dimension 1..3 (index 0 unused).
  [[nodiscard]] std::array<std::uint32_t, 4> count_by_dimension() const;
  /// Throws MeshError naming the first cell with an index out of range or a repeated vertex.
  void check_indices(const std::string& source = "mesh") const;
};

/// Spacing and origin of a regular grid.
struct GridSpec {
  Point3 spacing{1.0, 1.0, 1.0};
  Point3 origin{0.0, 0.0, 0.0};
};

/// nx × ny × nz hexahedra; point (i, j, k) has index i + (nx+1)(j + (ny+1)k).
IndexedMesh hex_grid(std::uint32_t nx, std::uint32_t ny, std::uint32_t nz, const GridSpec& g = {});
/// How a hexahedral grid is cut into tetrahedra: 6 per cell around the (0,6) diagonal (Kuhn),
/// or 5 per cell with alternating parity so that neighbouring cells conform.
enum class TetSplit { kuhn6, five };
IndexedMesh tet_grid(std::uint32_t nx, std::uint32_t ny, std::uint32_t nz, TetSplit split, const GridSpec& g = {});
/// nx × ny quads in the z = origin plane; point (i, j) has index i + (nx+1)j.
IndexedMesh quad_grid(std::uint32_t nx, std::uint32_t ny, const GridSpec& g = {});
/// nx × ny quads each cut into 2 triangles along the (i,j)-(i+1,j+1) diagonal.
IndexedMesh tri_grid(std::uint32_t nx, std::uint32_t ny, const GridSpec& g = {});
/// A box of lattice cells [lo, hi) along x, y and z (integer cell coordinates, may be negative).
struct LatticeBox {
  std::array<int, 3> lo{}, hi{};
};
/// The hexahedra of a union of lattice boxes: cells covered by several boxes appear once and
/// neighbouring boxes share their points, so boxes that touch by a face form one glued body
/// (a voxel shape); boxes touching only along an edge or at a corner share those points.
/// Cell (i, j, k) spans origin + (i, j, k)·spacing to origin + (i+1, j+1, k+1)·spacing.
/// Throws MeshError for an empty box list, an empty or inverted box, a bad spacing, or a
/// bounding box of more than 2^28 cells.
IndexedMesh box_union(std::span<const LatticeBox> boxes, const GridSpec& g = {});
/// A straight polyline of n segments along x.
IndexedMesh polyline_x(std::uint32_t n, double spacing = 1.0);
/// A polyline through the given points (at least 2), in order.
IndexedMesh polyline(std::span<const Point3> points);
/// A triangulated disc in the z = 0 plane centred at the origin: a centre point and rings
/// k = 1..rings of sectors·k points; ring annulus k holds sectors·(2k-1) triangles. With
/// rings = 8, sectors = 8: 289 points and 512 triangles (the 2019 paper's frisbee).
IndexedMesh disc(double radius, std::uint32_t rings, std::uint32_t sectors);
/// A cylinder along z (base centred at the origin): layers of the disc above joined by prisms,
/// each cut into 3 positively oriented tetrahedra, conforming across shared faces.
IndexedMesh cylinder(double radius, double height, std::uint32_t rings, std::uint32_t sectors, std::uint32_t layers);
/// Maps (x, y, z) to the plane named "xy" (unchanged), "xz" ((x, 0, y)) or "yz" ((0, x, y)).
void place_in_plane(IndexedMesh& mesh, const std::string& plane);
/// x <- scale·x + offset for every point.
void transform(IndexedMesh& mesh, double scale, const Point3& offset);
/// Appends `other`'s points and cells (indices shifted); returns the index of its first point.
std::uint32_t append(IndexedMesh& mesh, const IndexedMesh& other);

}  // namespace sewn
