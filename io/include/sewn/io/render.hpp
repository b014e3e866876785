#pragma once
// Pictures of a mesh state as PNG (drawn with cairo): the boundary faces of volumes (faces not
// shared by two cells), every 2D cell and segment, seen by a simple camera, Lambert-shaded,
// coloured by a per-point scalar through a perceptual colormap with a colour bar, optional cell
// edges and a title. Hidden surfaces are resolved by drawing back to front (painter's algorithm)
// after dropping boundary faces that look away from the camera.
//
//   sewn::io::RenderOptions o;
//   o.title = "beam, t = 0.25 s";
//   o.scalar_name = "|u| [m]";
//   sewn::io::render_png("last.png", x, sewn::io::CellsView::of(mesh), displacement_norm, o);

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "sewn/cmap/mesh.hpp"
#include "sewn/io/errors.hpp"
#include "sewn/io/write.hpp"

namespace sewn::io {

struct Camera {
  enum class Projection { orthographic, perspective };
  Projection projection = Projection::orthographic;
  /// Direction the camera looks from, turned about the vertical (+z) axis: 0 = from -y (front),
  /// positive = from the right.
  double azimuth_deg = 35.0;
  /// Height of the viewpoint above the horizontal plane. Unset: 25°, or 60° when the mesh is flat
  /// in z (a sheet in the xy-plane is then seen from above rather than edge-on).
  std::optional<double> elevation_deg;
  /// Full vertical opening angle for the perspective projection.
  double fov_deg = 30.0;
};

enum class RenderMode {
  shaded,    ///< filled, lit faces (with edges if RenderOptions::edges)
  wireframe  ///< every edge of the drawn faces and segments, hidden ones included
};

/// Picture sizes render_png accepts, in pixels (smaller leaves no room for the colour bar).
inline constexpr int min_render_width = 200, min_render_height = 150, max_render_size = 16384;

struct RenderOptions {
  int width = 1200;
  int height = 800;
  RenderMode mode = RenderMode::shaded;
  bool edges = true;  ///< outline each drawn face (shaded mode)
  Camera camera;
  std::string title;        ///< one line at the top ("" = none)
  std::string scalar_name;  ///< label of the colour bar
  /// Colour range; unset = the finite minimum and maximum of the scalar.
  std::optional<std::pair<double, double>> range;
  /// Boundary faces (given by their point indices) to draw in highlight_colour instead of the
  /// scalar's colours, e.g. the faces a cut opened (the 2013 paper draws them red). Unset: none.
  std::function<bool(std::span<const std::uint32_t>)> highlight;
  std::array<double, 3> highlight_colour{0.86, 0.12, 0.10};
};

/// Viridis (matplotlib's perceptually uniform map) at t in [0, 1] (clamped), as RGB in [0, 1].
std::array<double, 3> viridis(double t);

/// A face to draw: a boundary face of a volume (outward vertex order) or a whole 2D cell.
struct BoundaryFace {
  std::uint32_t cell;
  std::uint8_t size;                 ///< 3 or 4
  std::array<std::uint32_t, 4> v;    ///< mesh point indices
};

/// The faces of 3D cells that belong to exactly one cell, then every 2D cell, in cell order.
/// Faces shared by three or more volumes (non-manifold) are interior and left out.
std::vector<BoundaryFace> boundary_faces(CellsView cells);

/// Renders points + cells to a PNG file. `scalar` is empty (uniform colour) or has one value per
/// point (non-finite values are drawn grey). Primitives touching a non-finite point are left
/// out. Throws std::invalid_argument for a wrong scalar size or image size, FileError if the PNG
/// cannot be written.
void render_png(const std::filesystem::path& path, std::span<const Point3> points, CellsView cells,
                std::span<const double> scalar = {}, const RenderOptions& opt = {});

}  // namespace sewn::io
