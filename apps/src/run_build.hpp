#pragma once
// The runner's first phase: from a scene to the bodies it simulates — the meshes assembled, the
// mass-spring model with its continuum terms, connection energies, obstacles and volume term, the fixed particles
// and initial velocities, and the refinement driver if the scene refines.

#include <memory>
#include <string>

#include <Eigen/Core>

#include "sewn/apps/connections.hpp"
#include "sewn/apps/continuum.hpp"
#include "sewn/apps/motion_keys.hpp"
#include "sewn/apps/refine_keys.hpp"
#include "sewn/apps/runner.hpp"
#include "sewn/apps/scene.hpp"
#include "sewn/physics/mss_model.hpp"

namespace sewn::app::detail {

/// Everything a run steps, built from its scene.
struct Bodies {
  Assembly assembly;
  std::unique_ptr<physics::MssModel<3>> model;
  ContinuumParts continuum;
  ConnectionParts joints;  ///< the rotational energies where the bodies meet (model.connections)
  std::unique_ptr<RefinementRun> refinement;  ///< null if the scene refines nothing
  MotionDriver motion;                        ///< the particles `motion` drives (empty: none)
};

/// Builds the scene's bodies at rest with their initial motion. Fills the summary's
/// connections line (model `mixed`) and the counts of cells the elongation policies altered,
/// and warns of those on stderr unless `quiet`. Throws SceneError / io errors /
/// physics::InputError for bad input, each naming the key or file. O(mesh).
[[nodiscard]] Bodies build_bodies(const Scene& scene, bool quiet, RunSummary& sum);

/// Warnings for materials of solid tetrahedra with ν >= 0.45, where linear tetrahedra lock
/// (too stiff in bending, whatever the mesh size), each naming the material, ν and the cell
/// count with the measured stiffening. O(cells).
[[nodiscard]] std::vector<std::string> locking_warnings(const Scene& scene, const Assembly& assembly);

/// A warning (at most one) for the edges three or more shell triangles share where two of them
/// are one component (connect::detect_connections): no bending term crosses such an edge and no
/// connection joins a component to itself, so the sheet is hinged there. Names the first edge by
/// its points and its triangles by mesh and file cell. O(cells log cells).
[[nodiscard]] std::vector<std::string> junction_warnings(const Assembly& assembly);

/// A warning (at most one) for distinct points of simulated cells within 1e-9 of the model's
/// bounding-box diagonal of each other (duplicate nodes: the cells on them are not joined),
/// naming the first pair's place and a cell on each. O(points log points) unless many points
/// share an x.
[[nodiscard]] std::vector<std::string> coincidence_warnings(const Assembly& assembly);

/// Does selector `s` pick cell `c` of `m` (by centroid, tag, or all its points)?
[[nodiscard]] bool selects_cell(const Selector& s, const IndexedMesh& m, std::uint32_t c);

[[nodiscard]] inline Vec3 to_vec3(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

}  // namespace sewn::app::detail
