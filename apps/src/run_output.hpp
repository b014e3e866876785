#pragma once
// The runner's output side: the model's state as a mesh of its live elements, the output folder
// checked before any work, the frame files' names and the last frame's picture.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "sewn/apps/continuum.hpp"
#include "sewn/apps/runner.hpp"
#include "sewn/apps/scene.hpp"
#include "sewn/cmap/mesh.hpp"
#include "sewn/io/write.hpp"
#include "sewn/physics/mss_model.hpp"

namespace sewn::app::detail {

// The current state as a mesh of the live elements, for writing and drawing.
struct Snapshot {
  std::vector<Point3> points, velocity, force, displacement;
  std::vector<double> speed, force_norm, displacement_norm, fixed_scalar, material_scalar, level_scalar;
  std::vector<std::uint8_t> fixed;
  std::vector<CellType> types;
  std::vector<std::uint32_t> offsets{0}, conn;
  std::vector<std::int32_t> material, level, mesh_cell;
  std::vector<physics::Index> element;  // per output cell, its element (a rod's: its first segment's)
  std::vector<std::uint8_t> poly_line;  // empty, or per output cell: 1 for a whole rod

  /// Fills every field from the model's live nodes and elements. O(nodes + elements).
  void take(const physics::MssModel<3>& m);
  /// Replaces the rods' segment cells by one poly-line per rod (rods.chains), appended after
  /// the other cells, with the material and level of its first segment and mesh_cell -1 (it
  /// stands for many mesh cells). O(cells).
  void rods_as_poly_lines(const ContinuumParts& parts, const RodOutput& rods);
  [[nodiscard]] io::CellsView cells() const { return {types, offsets, conn, poly_line}; }
};

// Makes `dir` the output folder, refusing what cannot be one (OutputPathError, bad input) and
// what cannot be written (OutputError), before any work is done.
void prepare_output(const std::filesystem::path& dir);

// Runs one write, turning a file error into the run's OutputError (exit 1) rather than the
// bad-input error a mesh file's FileError means.
template <class F>
void writing(F&& write) {
  try {
    write();
  } catch (const io::FileError& e) {
    throw OutputError(e.file(), e.reason());
  }
}

/// frame_00042.vtu for frame 42.
std::string frame_file(std::uint32_t frame);

// Draws the last frame as the scene asks (colour, size, style), the faces a cut opened in
// `mesh` (the mesh before any edit) highlighted; returns the picture's path in `out`.
std::filesystem::path write_picture(const Scene& scene, double simulated, const std::filesystem::path& out, const IndexedMesh& mesh,
                                    const physics::MssModel<3>& model, Snapshot& snap);

}  // namespace sewn::app::detail
