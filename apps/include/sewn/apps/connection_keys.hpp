#pragma once
// The scene key `model.connections` (docs/connect.md, "Connections in scenes"): which joints of
// a continuum model get the rotational energies of connect/ (point and curve connections), and
// how stiff they are — kept apart from scene.cpp so the scene layer only lists the key.
//
//   "model": { "type": "mixed",
//              "connections": { "detect": true, "rigid": false,
//                               "explicit": [ { "kind": "point", "at": [0, 0, -0.1], "bending": 0.5 } ] } }

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sewn/apps/schema.hpp"

namespace sewn::app {

/// One place named by the scene: every detected connection of `kind` at the mesh point nearest
/// `at` (a point connection there; a curve connection: the whole curve the two bodies share
/// through that point), with its own stiffnesses where given.
struct ExplicitConnectionSpec {
  std::string kind;  // point, curve
  std::array<double, 3> at{};
  std::optional<double> twisting, bending, stiffness;
  std::optional<bool> rigid;
};

/// model.connections. Stiffnesses left out are "auto": from the materials (docs/connect.md).
struct ConnectionsSpec {
  bool enabled = false;  ///< the key is present
  bool detect = true;    ///< every detected point and curve connection gets its energy
  std::optional<double> twisting, bending;  ///< point connections, N·m/rad
  std::optional<double> curve_stiffness;    ///< curve connections, N/rad (N·m/rad per metre)
  bool rigid = false;                        ///< the auto stiffnesses × rigid_factor
  double rigid_factor = 1e3;
  std::string update = "incremental_ii";  ///< or incremental_i
  std::vector<ExplicitConnectionSpec> explicit_connections;
};

/// The schema of `model.connections`.
Field connections_schema();
/// Reads a validated `model.connections` object; throws SceneError naming the key for what the
/// schema cannot say (a stiffness that does not apply to the kind). O(entries).
ConnectionsSpec read_connections(const nlohmann::json& j, const Field& schema, const std::string& file);

}  // namespace sewn::app
