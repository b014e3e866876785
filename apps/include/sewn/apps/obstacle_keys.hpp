#pragma once
// The scene key `obstacles`: rigid obstacles (physics/obstacles) read from a scene file and
// added to a system — kept apart from scene.cpp so the scene layer only lists the key.

#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sewn/apps/schema.hpp"
#include "sewn/physics/obstacles/obstacles.hpp"
#include "sewn/physics/system.hpp"

namespace sewn::app {

struct ObstacleSpec {
  physics::obstacles::Shape shape;
  double stiffness = 0;          ///< N/m per node
  double friction_velocity = 0;  ///< m/s
};

/// The schema of the `obstacles` array (one object per obstacle, selected by `type`).
Field obstacles_schema();
/// Reads a validated `obstacles` array; throws SceneError naming "obstacles[i].key" for values
/// the schema cannot express (a zero normal or axis, box min ≥ max). O(obstacles).
std::vector<ObstacleSpec> read_obstacles(const nlohmann::json& j, const Field& schema, const std::string& file);
/// Adds one Obstacles term per obstacle to sys. O(obstacles).
void add_obstacles(physics::System& sys, const std::vector<ObstacleSpec>& obstacles);
/// One warning per obstacle that particles at `x` (3 per node) start inside, deeper than 1e-9 of
/// their bounding box's diagonal: how many, the deepest with its place, and the penalty energy
/// ½ k d² they hold, which the first steps turn into motion the scene did not supply.
/// O(nodes × obstacles).
std::vector<std::string> obstacle_start_warnings(std::span<const double> x, const std::vector<ObstacleSpec>& obstacles);

}  // namespace sewn::app
