#pragma once
// Checkpoints of a run (`sewn run --checkpoint-every N`, `--resume FILE`): everything a run
// holds between two steps, in a versioned binary file with a checksum, so that a resumed run
// continues to the same bits as the run that was never stopped.
//
// What is stored, and why that is the whole state of a run (docs/checkpoints.md):
//   - positions and velocities of every particle;
//   - the topology edits applied so far, resolved (the facets each cut unsewed, by dart, the
//     elements each piercing took, each adaptive refinement refined and each coarsening
//     merged): the map, its attributes, the refinement hierarchy with its T-junctions and the
//     node, spring and element tables are rebuilt from the scene and these edits, done again
//     in their order, and a hash of the rebuilt
//     tables (the map's dart count, masses, fixed axes, spring ends, stiffnesses, rest lengths,
//     viscosities, live elements) must equal the stored one;
//   - the integrator's history (symplectic Euler's cached stable step; linearly implicit
//     Euler's warm start and, with cholmod-pcg, the matrix its kept factorization was made
//     of; the step counters and energy watchdogs of these two and of the implicit midpoint
//     rule; Newton's backward Euler's kept cholmod-pcg factorization, as linearly implicit
//     Euler's, and whether its direct factorization once failed) and the energy ledger;
//   - the rods' own state: material angles θ, time-parallel reference frames, tracked
//     reference twists, and the positions θ was last solved at;
//   - the system's angle DOFs and their rates (the rods' θ, when connections make them DOFs),
//     and each connection's incremental history: its accepted twist and its rod sides'
//     reference frames (connect/, ConnectionHistory);
//   - the refinement's counters and the adapter's per-element hysteresis (calm) counters;
//   - the time line: steps and frames done, the next scheduled cut, the frames listed in the
//     .pvd and the rows of frames.csv, and the run summary's running figures.
// Everything else a run holds is rebuilt from the scene or recomputed from the above at the
// next step: obstacles are fixed, and friction's lagged normal forces are k·depth at the last
// accepted positions, which are the stored ones; the solver's matrix pattern, the inversion
// monitor's corner lists and the spring runs follow from the topology, and the tetrahedra
// are moved onto the particles the recorded cuts duplicated, as the run moved them.
//
// File layout (little-endian): "SEWNCKPT", u32 format version, u32 0, u64 payload size,
// u64 FNV-1a-64 checksum of the payload, payload. Every length in the payload is checked
// against the bytes left before anything is allocated for it.

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "sewn/physics/integrate/energy_ledger.hpp"
#include "sewn/physics/integrate/implicit_midpoint.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"
#include "sewn/physics/integrators.hpp"
#include "sewn/physics/rods/rods_term.hpp"
#include "sewn/apps/refine_keys.hpp"

namespace sewn::app {

/// A checkpoint that cannot be resumed from: unreadable, truncated, corrupt (checksum), of
/// another format version, or written by another scene or run. Bad input (the tool exits 2).
class CheckpointError : public std::runtime_error {
 public:
  CheckpointError(const std::string& file, const std::string& reason)
      : std::runtime_error(file + ": " + reason), file_(file), reason_(reason) {}
  [[nodiscard]] const std::string& file() const { return file_; }
  [[nodiscard]] const std::string& reason() const { return reason_; }

 private:
  std::string file_, reason_;
};

/// One topology edit as it was applied: a scheduled cut (the facets it unsewed, by dart and β
/// index) or piercing (the elements it took), or an adaptive refinement (the elements it
/// refined) or coarsening (the parents whose families it merged).
struct AppliedCut {
  std::uint32_t spec = 0;  ///< cut, pierce: index in the scene's cuts
  bool pierce = false, remove = false;
  std::vector<std::uint32_t> darts;  ///< cut: a dart of each facet
  std::vector<std::uint8_t> betas;   ///< cut: the β joining each facet's two sides (2 or 3)
  std::vector<std::uint32_t> elements;  ///< pierce, refinement, coarsening: the elements
  std::uint8_t refinement = 0;          ///< 0: a scheduled cut or piercing; 1: a refinement; 2: a coarsening
};

struct Checkpoint {
  static constexpr std::uint32_t format_version = 4;

  std::uint64_t run_hash = 0;    ///< the scene's text, its built model, steps and frames
  std::uint64_t model_hash = 0;  ///< the model's tables after the cuts below
  std::uint64_t steps_total = 0;
  std::uint32_t frames_total = 0;

  std::uint64_t step = 0;   ///< steps done
  std::uint32_t frame = 0;  ///< frames written
  std::vector<AppliedCut> cuts;  ///< every topology edit, in the order applied

  std::vector<double> x, v;  ///< 3 per particle
  physics::SymplecticEuler::History semi;
  physics::LinearlyImplicitEuler::History implicit;
  physics::ImplicitMidpoint::History midpoint;
  physics::integrate::NewtonEuler::History newton;
  physics::EnergyLedger::State ledger;
  std::vector<physics::rods::Rods::RodHistory> rods;  ///< per rod of the scene, in build order
  std::vector<double> angles, angle_rates;  ///< the system's angle DOFs (rods' θ when connections hold them)
  std::vector<double> point_connections, curve_connections;  ///< each connection term's history(), empty if none
  RefinementRun::State refinement;  ///< the refinement's counters and hysteresis counters

  std::vector<double> frame_times;  ///< of the frames listed in the .pvd
  std::uint32_t csv_columns = 0;
  std::vector<double> csv_rows;     ///< frames.csv so far, row-major

  // the current frame's running figures, and the run summary's
  double frame_ms = 0, frame_cg_sum = 0;
  std::int32_t frame_cg_max = 0;
  std::uint64_t frame_steps = 0;
  std::uint32_t cuts_applied = 0, faces_cut = 0;
  double kinetic_start = 0, kinetic_max = 0, wall = 0;
  std::uint64_t inverted_max = 0;
  std::string first_inversion, first_energy_rise;
};

/// The file's bytes. O(size).
[[nodiscard]] std::string encode_checkpoint(const Checkpoint& c);
/// Reads a checkpoint from its bytes; `file` names it in errors. Throws CheckpointError for
/// anything but a well-formed checkpoint of this format version. O(size).
[[nodiscard]] Checkpoint decode_checkpoint(std::string_view bytes, const std::string& file);
/// Writes the checkpoint aside and renames it over `path`; io::FileError on failure.
void write_checkpoint(const std::filesystem::path& path, const Checkpoint& c);
/// Reads `path`; CheckpointError if it cannot be read or decoded.
[[nodiscard]] Checkpoint read_checkpoint(const std::filesystem::path& path);

/// FNV-1a, 64 bits, continuing from `h`: the checksum of the format and the hashes above.
[[nodiscard]] std::uint64_t fnv1a(std::string_view bytes, std::uint64_t h = 0xcbf29ce484222325ull);

}  // namespace sewn::app
