#pragma once
// Connections in scenes (model.connections, connection_keys.hpp): the detected and the named
// joints of a continuum model become PointConnections and CurveConnections terms
// (connect/point_term.hpp, curve_term.hpp) on the model's system, with frames chosen per side
// from the mesh cells around each joint and stiffnesses from the scene or, left out, from the
// materials (docs/connect.md, "Connections in scenes").

#include <cstdint>
#include <string>
#include <vector>

#include "sewn/apps/cell_models.hpp"
#include "sewn/apps/continuum.hpp"
#include "sewn/apps/scene.hpp"
#include "sewn/connect/curve_term.hpp"
#include "sewn/connect/point_term.hpp"
#include "sewn/physics/mss_model.hpp"

namespace sewn::app {

struct ConnectionParts {
  connect::PointConnections* points = nullptr;  ///< null if none
  connect::CurveConnections* curves = nullptr;  ///< null if none
  std::uint32_t point_joints = 0;               ///< point connections built
  std::uint32_t curve_joints = 0;               ///< detected curve connections (shared edges) built
  std::uint32_t curve_elements = 0;             ///< EdgeConnections for them (a rod inside a solid: one per face)
};

/// Builds the energies of `scene.connections` on `model`'s system, after build_continuum (whose
/// `parts` give the rods) and at the rest state. A connection with a rod side makes every rod's
/// twist angles DOFs of the system (Rods::use_angle_dofs, inertia ρ·(I1 + I2) per length of the
/// rods' lightest section), which only the newton integrator takes. Throws SceneError naming the
/// key: an explicit connection where no two bodies meet that way, a frame that cannot be built
/// (the connection's name and the reason), rods with another integrator. Does nothing without
/// the key. O(cells log cells).
ConnectionParts build_connections(const Scene& scene, const IndexedMesh& mesh, const std::vector<CellModel>& models,
                                  const std::vector<physics::MaterialParams>& materials, const ContinuumParts& parts,
                                  physics::MssModel<3>& model);

/// One line for the run's summary: "  energies: 1 point, 4 curve (4 edges)". Empty without connections.
std::string connection_energies_text(const ConnectionParts& c);

}  // namespace sewn::app
