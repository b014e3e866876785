#pragma once
// Running a scene: assembling its bodies into one mesh, building the mass-spring model on the
// map, stepping it with scheduled cuts, and writing what a person opens afterwards (a ParaView
// series, frames.csv, a picture of the last frame).

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "sewn/apps/cell_models.hpp"
#include "sewn/apps/scene.hpp"
#include "sewn/cmap/mesh.hpp"
#include "sewn/cmap/indexed_message.hpp"

namespace sewn::app {

/// The output folder cannot be one: an existing file, a name too long for the file system, a
/// parent that is a file. Bad input (the tool exits 2); thrown before anything is built.
class OutputPathError : public std::invalid_argument {
 public:
  OutputPathError(const std::filesystem::path& path, const std::string& reason)
      : std::invalid_argument(path.string() + ": " + reason), path_(path) {}
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// An output file or folder cannot be written (no permission, full disk, file size limit): the
/// run failed (the tool exits 1). Files written before stay complete and valid.
class OutputError : public std::runtime_error {
 public:
  OutputError(const std::filesystem::path& path, const std::string& reason)
      : std::runtime_error(path.string() + ": " + reason), path_(path) {}
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// All bodies of a scene in one mesh, each cell with its material index (materials in name order)
/// and its model; the cells that are only labels (cell_models.hpp) apart, on the same points.
struct Assembly {
  IndexedMesh mesh;
  IndexedMesh labels;
  std::vector<CellModel> model_of_cell;
  std::vector<int> group_of_cell;  ///< the model.groups entry that selected the cell, -1: none
  std::vector<std::uint32_t> material_of_cell;
  std::vector<std::string> material_names;
  std::vector<std::uint32_t> first_cell;  ///< per scene mesh, its first cell in `mesh`
  std::vector<std::uint32_t> first_point; ///< per scene mesh, its first point in `mesh`
  std::vector<MeshSource> sources;        ///< per scene mesh, how its file names its cells and points
  std::vector<std::uint32_t> file_cell;   ///< per cell of `mesh`, its index in its scene mesh's file (MeshSource)
  std::uint32_t split_asked = 0;  ///< hexahedra too elongated for Baudet's stiffness, split (materials' elongated = "split")
  std::uint32_t split_cells = 0;  ///< source cells cut into near-cubes (those and their sheets' neighbours)
  std::uint32_t source_cells = 0; ///< cells before the split
  std::uint32_t source_points = 0; ///< points before the split (the split adds its points after them)
  std::vector<std::uint32_t> split_source;  ///< per cell of `mesh`, the cell before the split it is (a piece of); empty: none split

  /// The scene mesh (index in `sources`) that cell `c` of `mesh` comes from.
  [[nodiscard]] std::size_t mesh_of_cell(std::uint32_t c) const;
  /// The scene mesh that point `p` of `mesh` comes from; none for a point the split added.
  [[nodiscard]] std::optional<std::size_t> mesh_of_point(std::uint32_t p) const;
  /// Cell `c` of `mesh` as its file names it (MeshSource::cell), "piece p of cell k ..." for a
  /// piece of a cell the split cut; with `key` its scene mesh first ("meshes[1] cell 3 ...").
  [[nodiscard]] std::string cell_name(std::uint32_t c, bool key) const;
  /// Point `p` of `mesh` as its file numbers it (MeshSource::point), with `key` its scene mesh
  /// first ("meshes[1] point 40 of b.msh"); a point the split added says so.
  [[nodiscard]] std::string point_name(std::uint32_t p, bool key) const;
  /// A message about cells and points of `mesh` (physics::CellInputError, MeshCellError),
  /// restated as "<scene_file>: <message>" with each named as its file does (cell_name,
  /// MeshSource::point) and each material by its scene name; a message about one scene mesh
  /// starts at its key ("meshes[1]: ...").
  [[nodiscard]] std::string in_files(const std::string& scene_file, const IndexedMessage& m) const;
};

/// Generates or reads every mesh of the scene, places it, and assigns materials by region.
/// Throws SceneError (scene values), io::IoError (files) or MeshError (geometry), each naming
/// the mesh and what is wrong.
Assembly assemble(const Scene& scene);

struct RunOptions {
  std::filesystem::path out;                 ///< empty: out/<scene name>/
  std::optional<std::uint32_t> frames;       ///< overrides the scene's output frames
  std::optional<double> until;               ///< s; ends the run early (never extends it)
  bool quiet = false;                        ///< no progress bar, no summary
  bool progress = true;                      ///< draw the progress bar (only on a terminal)
  /// Write <name>.checkpoint in the output folder after every this many frames (0: never).
  std::uint32_t checkpoint_every = 0;
  /// Continue the run saved in this checkpoint (written by the same scene with the same
  /// frames and end) instead of starting it: the outputs come out as the run never stopped.
  std::filesystem::path resume;
  /// Stop (successfully, without the picture) once this many checkpoints were written by this
  /// call (0: run to the end): a long run split into jobs.
  std::uint32_t stop_after_checkpoints = 0;
};

struct RunSummary {
  std::uint64_t steps = 0;
  std::uint32_t frames = 0;         ///< frames written, frame 0 included
  std::uint32_t cuts = 0;           ///< scheduled cuts applied
  std::uint32_t faces_cut = 0;      ///< facets those cuts unsewed
  std::uint64_t refined = 0;        ///< elements refined (pre-refinement included)
  std::uint64_t coarsened = 0;      ///< families merged back into their parent
  double simulated = 0;             ///< s
  double wall = 0;                  ///< s, stepping and cuts (output excluded)
  double ms_per_step = 0;
  double stepping = 0;                   ///< s, this call's steps and cuts (no refinement, no output)
  double stepping_cpu = 0;               ///< s, the same as the process's CPU time (all threads): on a busy machine, the work alone
  std::uint64_t newton_iterations = 0;   ///< integrator `newton`: Newton iterations of this call's steps
  std::uint64_t linear_iterations = 0;   ///< implicit integrators: CG iterations of this call's steps
  double kinetic_start = 0, kinetic_end = 0, kinetic_max = 0;  ///< J
  std::uint64_t energy_rises = 0;   ///< implicit steps that created energy (see physics::EnergyLedger)
  std::uint64_t substepped = 0;     ///< midpoint steps Newton could only take in sub-steps (the summary says so)
  int most_substeps = 0;             ///< the most sub-steps one of them took
  std::string first_energy_rise;    ///< the warning printed for the first of them ("" if none)
  std::uint64_t newton_short_stops = 0;  ///< Newton steps that stopped right after a line search cut the step below ¼ (doubtful)
  std::string first_newton_short_stop;   ///< the warning printed for the first of them ("" if none)
  std::uint64_t clamped_cells = 0;   ///< cells whose stiffness the `clamp` policy altered (a warning says so)
  std::uint64_t split_cells = 0;     ///< source cells the `split` policy cut into near-cubes (a warning says so)
  std::uint64_t inverted_max = 0;   ///< most inverted hexahedra and tetrahedra seen at once (frames, or steps if checked)
  std::string first_inversion;      ///< the first inverted element seen, with step and time ("" if none)
  std::filesystem::path out, pvd, csv, picture;
  std::filesystem::path checkpoint;  ///< the last checkpoint written ("" if none)
  std::uint64_t resumed_at = 0;      ///< the step the run resumed at (0: started afresh)
  bool stopped = false;              ///< stopped after a checkpoint (stop_after_checkpoints)
  std::string connections;           ///< model `mixed`: where its bodies meet (connections_text), else ""
  std::string connection_energies;    ///< model.connections: the energies built (connection_energies_text), else ""
  std::vector<std::string> model_warnings;  ///< what is doubtful in the model built (near-incompressible linear tetrahedra, a sheet hinged at a non-manifold edge, coincident unshared points, particles starting inside an obstacle), each printed as a warning
};

/// Runs the scene to its end. Throws SceneError / io errors / physics::InputError / OutputPathError
/// for bad input (exit 2), physics::StabilityError when a semi-implicit step is above its stable
/// bound (exit 2: choose a smaller step), physics::BlowupError / SolverError / OutputError when
/// the run fails (exit 1). Every output file is replaced whole (written aside and renamed), the
/// .pvd lists only frames whose .vtu is complete, and nothing is written outside the output
/// folder. Throws std::runtime_error naming the element at the first inversion if the scene
/// stops there (exit 1). With a checkpoint to resume from, throws CheckpointError (exit 2) if it
/// cannot be read or was not written by this scene and run; SceneError if the scene's integrator
/// or solver keeps state checkpoints do not hold (and one is asked for).
RunSummary run(const Scene& scene, const RunOptions& options);

}  // namespace sewn::app
