#pragma once
// Geometric sanity checks run on a mesh before it is simulated: non-finite coordinates,
// inverted cells (negative orientation) and degenerate cells (zero length / area / volume, or a
// corner where the cell folds over). Orientation follows VTK vertex order (mesh.hpp).
//
// Volumes are judged by their corner Jacobians: at each corner, the determinant of the three
// edges leaving it (in the order that makes it positive for a well-shaped cell), divided by the
// product of their lengths. This "scaled Jacobian" is in [-1, 1], independent of size, and
// positive at every corner exactly when a hexahedron, prism or pyramid is valid; for a
// tetrahedron it has the sign of the volume. A corner whose value is below `min_scaled_jacobian`
// in magnitude is degenerate; a cell negative at every corner is inverted; a cell with some
// corners positive and some not is folded (reported as degenerate).

#include <cstdint>
#include <string>
#include <vector>

#include "sewn/cmap/errors.hpp"
#include "sewn/cmap/mesh.hpp"

namespace sewn::io {

/// Base of the geometric errors; derives from sewn::MeshError so a caller can catch both kinds of
/// bad mesh at once. cell() is the offending cell (or no_cell for an unused bad point).
class GeometryError : public MeshError {
 public:
  static constexpr std::uint32_t no_cell = 0xffffffffu;
  GeometryError(const std::string& message, std::uint32_t cell, std::vector<std::uint32_t> points)
      : MeshError(message), cell_(cell), points_(std::move(points)) {}
  [[nodiscard]] std::uint32_t cell() const noexcept { return cell_; }
  /// The cell's points (or the bad point alone when no cell uses it).
  [[nodiscard]] const std::vector<std::uint32_t>& points() const noexcept { return points_; }

 private:
  std::uint32_t cell_;
  std::vector<std::uint32_t> points_;
};

/// A point has a NaN or infinite coordinate.
class NonFiniteCoordinateError : public GeometryError {
 public:
  using GeometryError::GeometryError;
};
/// A volume cell is negatively oriented (negative scaled Jacobian at every corner).
class InvertedCellError : public GeometryError {
 public:
  using GeometryError::GeometryError;
};
/// A cell has (near) zero length, area or volume, or folds over at some corner.
class DegenerateCellError : public GeometryError {
 public:
  using GeometryError::GeometryError;
};

/// A cell has the same type and the same points (in any order) as an earlier one.
class DuplicateCellError : public GeometryError {
 public:
  using GeometryError::GeometryError;
};

struct GeometryOptions {
  /// Scaled Jacobians (volumes) and scaled areas (2D cells) at or below this count as degenerate.
  double min_scaled_jacobian = 1e-8;
  /// Segments shorter than this times the mesh's bounding-box diagonal count as degenerate.
  double min_relative_length = 1e-12;
  /// find_geometry_issues stops after this many issues.
  std::size_t max_issues = 100;
  /// How messages number the points: the file's numbers (io::MeshFile::point_numbers after the
  /// same renumbering as the mesh), or by index in the mesh if empty.
  std::vector<std::int64_t> point_numbers;
  /// Each cell's Gmsh element tag (io::MeshFile::element_tags), named after the cell's index; empty: none.
  std::vector<std::int64_t> element_tags;
};

enum class GeometryProblem { non_finite_point, inverted, degenerate, duplicate };

struct GeometryIssue {
  GeometryProblem kind;
  std::uint32_t cell;  ///< GeometryError::no_cell for an unused non-finite point
  std::vector<std::uint32_t> points;  ///< indices in the mesh (the message numbers them as GeometryOptions says)
  std::string message;  ///< complete, starting with the source name
};

/// Smallest scaled Jacobian over the corners of a 3D cell (see above), or the smallest scaled
/// corner area of a 2D cell; 0 for a corner with a zero-length edge. Requires valid indices.
double min_scaled_jacobian(const IndexedMesh& mesh, std::uint32_t cell);

/// Signed measure of a cell: volume for 3D cells (from their outward faces, so negative when
/// inverted; faces are fanned from their first vertex), area for 2D cells, length for segments.
double cell_measure(const IndexedMesh& mesh, std::uint32_t cell);

/// Every geometric problem (up to max_issues): non-finite points, then bad cells in cell order,
/// then duplicate cells (cost O(n log n) in the cells).
/// Throws MeshError if an index is out of range (mesh.check_indices).
std::vector<GeometryIssue> find_geometry_issues(const IndexedMesh& mesh, const std::string& source = "mesh",
                                                const GeometryOptions& opt = {});

/// Throws the first problem find_geometry_issues would report, as NonFiniteCoordinateError,
/// InvertedCellError, DegenerateCellError or DuplicateCellError; messages name `source`, the cell and its points.
void check_mesh_geometry(const IndexedMesh& mesh, const std::string& source = "mesh", const GeometryOptions& opt = {});

}  // namespace sewn::io
