#pragma once
// Connections in scenes (model.connections, connection_keys.hpp): the detected and the named
// joints of a continuum model become PointConnections and CurveConnections terms
// (connect/point_term.hpp, curve_term.hpp) on the model's system, with frames chosen per side
// from the mesh cells around each joint and stiffnesses from the scene or, left out, from the
// materials (docs/connect.md, "Connections in scenes").

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "sewn/apps/cell_models.hpp"
#include "sewn/apps/continuum.hpp"
#include "sewn/apps/scene.hpp"
#include "sewn/connect/curve_term.hpp"
#include "sewn/connect/point_term.hpp"
#include "sewn/physics/mss_model.hpp"

namespace sewn::app {

/// Where one stencil node of a connection comes from: corner `corner` of model element
/// `element` (in MssModel::element_nodes order) gives the node at stencil slot `slot`
/// (PointConnection::position_nodes, EdgeConnection::stencil_nodes).
struct JointSource {
  physics::Index element = 0;
  std::uint32_t corner = 0;
  std::uint32_t slot = 0;
};
/// Per connection of each term, in the term's order, the sources of its stencil nodes.
struct JointSources {
  std::vector<std::vector<JointSource>> points, curves;
};

struct ConnectionParts {
  connect::PointConnections* points = nullptr;  ///< null if none
  connect::CurveConnections* curves = nullptr;  ///< null if none
  std::uint32_t point_joints = 0;               ///< point connections built
  std::uint32_t curve_joints = 0;               ///< detected curve connections (shared edges) built
  std::uint32_t curve_elements = 0;             ///< EdgeConnections for them (a rod inside a solid: one per face)
  std::shared_ptr<JointSources> sources;        ///< what follow_connections() follows (shared with the model's listener)
};

/// Builds the energies of `scene.connections` on `model`'s system, after build_continuum (whose
/// `parts` give the rods) and at the rest state. A connection with a rod side makes every rod's
/// twist angles DOFs of the system (Rods::use_angle_dofs, inertia ρ·(I1 + I2) per length of the
/// rods' lightest section), which only the newton integrator takes. Registers
/// follow_connections with the model. Throws SceneError naming the key: an explicit connection
/// where no two bodies meet that way, a frame that cannot be built (the connection's name and
/// the reason), rods with another integrator, refinement; `point_name` names a mesh point in
/// those messages (as its file numbers it: Assembly::point_name; none: "mesh point <index>").
/// Does nothing without the key. O(cells log cells).
ConnectionParts build_connections(const Scene& scene, const IndexedMesh& mesh, const std::vector<CellModel>& models,
                                  const std::vector<physics::MaterialParams>& materials, const ContinuumParts& parts,
                                  physics::MssModel<3>& model, const std::function<std::string(std::uint32_t)>& point_name = {});

/// The rule under cuts and piercings (docs/connect.md): each connection's nodes are taken again
/// from the model elements its sides were built on. A connection is kept, on the nodes those
/// elements now have, when every one of them is alive and they still agree on every shared node
/// (the joint of a point connection, the edge of a curve one: the sides still share it);
/// otherwise it is removed — the cut separated its sides (or took one away), and the joint is
/// left to the shared positions, if any. So no connection dangles. build_connections registers
/// it to run after every edit of the model (MssModel::after_edits, before a piercing compacts
/// the particles); calling it again changes nothing. O(connections).
void follow_connections(const ConnectionParts& joints, const physics::MssModel<3>& model);

/// One line for the run's summary: "  energies: 1 point, 4 curve (4 edges)", or "  energies: none (...)"
/// when model.connections built none. Empty when model.connections is not given.
std::string connection_energies_text(const ConnectionParts& c);

}  // namespace sewn::app
